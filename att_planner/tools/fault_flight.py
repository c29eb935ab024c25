"""A maneuver flown through faults in process: a wheel isolated mid-slew brakes, re-plans and flies on.

:class:`Replanner`, set as :attr:`att_planner.tools.closed_loop.ClosedLoop.recovery`, is called when
the fault monitor's healthy wheels change. During a maneuver it brakes
(:class:`att_planner.fdir.replan.Brake`: the estimated attitude held at rest on the healthy wheels);
once braked it plans the rest of the maneuver from the estimated attitude to the goal among the scenario's zones
for the envelope of the healthy wheels (:func:`att_planner.fdir.envelope.planning_spacecraft`),
verified by the planner's own checks (:func:`~att_planner.tools.closed_loop.plan_in_process`), and
flies it. Without a verified plan, or healthy wheels that cannot control the attitude, safe mode.
:func:`fly` drives a loop through a plan with this recovery and returns what happened.
"""
from __future__ import annotations

from dataclasses import dataclass, field

from att_msgs_py.errors import RequestError
from att_msgs_py.types import ControlKind, ControlMode, ManeuverResult, Plan
from att_planner.fdir.envelope import planning_spacecraft
from att_planner.fdir.replan import REPLAN, SAFE, Brake, utc_epoch
from att_planner.tools.closed_loop import ClosedLoop, plan_in_process

SAFE_HOLD_S = 120.0       # s of sim time :func:`fly` watches safe mode held before it stops


@dataclass
class Replanner:
    """The goal of the maneuver flown (``goal``: the keys of
    :func:`att_planner.service.warm.maneuver_from_scenario`) and what the recovery did."""

    goal: dict
    brake: Brake = field(default_factory=Brake)
    healthy: tuple[bool, ...] | None = None
    replans: list[dict] = field(default_factory=list)      # each: t, healthy, verified, method, duration, why
    safe_mode: bool = False
    why: str = ""

    @property
    def braking_since(self) -> float | None:
        return self.brake.since

    def __call__(self, loop: ClosedLoop, before, after) -> None:
        self.healthy = after
        if loop.controller.maneuver is None and self.brake.since is None and not self.replans:
            return                     # not flying: the hold or pointing goes on on the healthy wheels
        self.brake.begin(loop.controller, loop.sim.t)

    def poll(self, loop: ClosedLoop) -> None:
        """At each step: once braked, re-plan and fly (or safe mode)."""
        said = self.brake.poll(loop.controller, loop.sim.t)
        if said == SAFE:
            self._safe(loop, self.brake.why)
        elif said == REPLAN:
            self.replan(loop)

    def replan(self, loop: ClosedLoop) -> None:
        ctl, s, g = loop.controller, loop.scenario, self.goal
        healthy = self.healthy if self.healthy is not None else (True,) * s.spacecraft.n_wheels
        entry = {"t": float(loop.sim.t), "healthy": list(healthy), "verified": False}
        self.replans.append(entry)
        try:
            sc = planning_spacecraft(s.spacecraft, healthy)
        except ValueError as err:
            entry["why"] = str(err)
            self._safe(loop, f"no re-plan: {err}")
            return
        try:
            plan = plan_in_process(s, ctl.state.q, g["qf"], g["sensor"], g["cones"], g["zones"], g["method"],
                                   g["time_budget"], epoch=utc_epoch(s.epoch, loop.sim.t), spacecraft=sc)
        except RequestError as err:
            entry["why"] = f"code {int(err.code)}: {err.message}"
            self._safe(loop, f"no verified re-plan: {entry['why']}")
            return
        if plan.control_kind == ControlKind.WHEEL_TORQUE:
            entry["why"] = "the plan is of wheel torques on the healthy set only"
            self._safe(loop, entry["why"])
            return
        refused = loop.execute(plan, f"replan{len(self.replans)}")
        if refused is not None:
            entry["why"] = f"code {int(refused.code)}: {refused.message}"
            self._safe(loop, f"the re-plan did not start: {entry['why']}")
            return
        entry.update(verified=True, method=plan.method, duration_s=float(plan.duration))
        loop.result = None

    def _safe(self, loop: ClosedLoop, why: str) -> None:
        self.safe_mode, self.why = True, why
        loop.controller.set_mode(ControlMode.SAFE)


@dataclass
class Flight:
    """What :func:`fly` saw: the last maneuver's result, the recovery, the end time."""

    result: ManeuverResult | None
    replanner: Replanner
    t_end: float


def fly(loop: ClosedLoop, plan: Plan, goal: dict, until: float, safe_hold_s: float = SAFE_HOLD_S) -> Flight:
    """Fly ``plan`` now on ``loop`` (its fault table on) with the re-planning recovery toward ``goal``,
    until a maneuver ends successfully, ``safe_hold_s`` of sim time after safe mode began (to see it
    held), or sim time ``until``. The loop's ``recovery`` is set."""
    replanner = Replanner(goal)
    loop.recovery = replanner
    refused = loop.execute(plan)
    if refused is not None:
        return Flight(ManeuverResult(False, int(refused.code), refused.message), replanner, loop.sim.t)
    loop.result = None
    safe_since = None
    while loop.sim.t < until and not loop.sim.halted:
        loop.tick()
        replanner.poll(loop)
        if loop.result is not None and loop.result.success and replanner.braking_since is None:
            break
        if loop.controller.mode == ControlMode.SAFE:
            safe_since = loop.sim.t if safe_since is None else safe_since
            if loop.sim.t - safe_since >= safe_hold_s:
                break
        else:
            safe_since = None
    return Flight(loop.result, replanner, loop.sim.t)
