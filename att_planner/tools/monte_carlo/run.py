"""One run of a Monte Carlo campaign: the plan made once on the nominal model, flown on the run's
dispersed truth (:mod:`att_sim.truth.dispersions`) by :class:`~att_planner.tools.closed_loop.ClosedLoop`
— the simulator, estimator and controller cores the nodes run — and judged as the planner judges
its plans (:func:`att_planner.verification.rejection` with :data:`~att_planner.verification.TOLERANCES`)
on the flown truth.

A run: the simulation starts at the maneuver's initial attitude and rest, dispersed; the loop
ticks until the estimate is CONVERGED (at most the campaign's ``converge_timeout_s``), as the demo
waits before it sends a goal; then the controller flies the plan and holds its end for
``settle_time_s``. The outcomes are taken at every control instant of the flown truth.

The runs of a task fly as a batch (:func:`fly_batch`): each run's flight software steps on its
own, the heavy numerics of a step are done for all the runs at once — the estimators' propagations,
the plan's reference and the tracking law, one RK4 step of every simulation — each run's row by the
operations it gets alone: a run's row does not depend on the runs it flew with (to rounding), and a
run is reproduced from its seed alone.
"""
from __future__ import annotations

import math
import time
from dataclasses import dataclass, replace

import numpy as np
from cryptography.hazmat.primitives.asymmetric.ed25519 import Ed25519PrivateKey

from att_msgs_py.types import Health, ManeuverResult, Plan, Verification
from att_planner.control.controller import Controller, step_controllers
from att_planner.control.tracking import ReferenceMemo
from att_planner.estimation.estimator import replay
from att_planner.tools.closed_loop import ClosedLoop, Reprocessing, plan_in_process
from att_planner.tools.demo import maneuver_from_scenario, zone_margins
from att_planner.verification import rejection
from att_sim.models import rotations as rot
from att_sim.models import scenario as scen
from att_sim.truth import dispersions as disp
from att_sim.truth.batch import SimulationBatch
from att_sim.truth.dispersions import DEG
from att_sim.truth.simulation import Checks, Simulation

OUTCOMES = ("success", "code", "final_error_deg", "final_rate", "min_margin_deg", "peak_wheel_ratio",
            "peak_torque_ratio", "settling_time", "start_time", "cpu_seconds", "reason")


@dataclass(frozen=True)
class Setup:
    """What every run of a campaign shares (shipped once to each worker)."""

    campaign: disp.Campaign
    scenario: scen.Scenario
    maneuver: dict
    plan: Plan


def checked(campaign: disp.Campaign, seeds=()) -> Setup:
    """The campaign's scenario and its ``demo:`` maneuver, not yet planned, with the draw of every
    seed of ``seeds`` checked (ValueError naming what is missing or the seed of a non-physical draw)."""
    try:
        scenario = scen.load(campaign.scenario)
    except KeyError as exc:
        raise ValueError(f"campaign {campaign.path}: campaign.scenario: {exc.args[0]}") from None
    setup = Setup(campaign, scenario, maneuver_from_scenario(scenario), Plan())
    for seed in seeds:
        dispersed(setup, seed)
    return setup


def planned(setup: Setup) -> Setup:
    """``setup`` with the plan for its maneuver, made once on the nominal model as the planner
    service makes it (RequestError when there is none)."""
    s, m = setup.scenario, setup.maneuver
    plan = plan_in_process(s, m["q0"], m["qf"], m["sensor"], m["cones"], m["zones"], m["method"], m["time_budget"])
    return replace(setup, plan=plan)


def dispersed(setup: Setup, seed: int) -> tuple[disp.Truth, dict]:
    """The truth of the run of seed ``seed`` and its applied values (ValueError when not physical)."""
    return disp.seed_truth(setup.campaign, setup.scenario, seed, q0=setup.maneuver["q0"])


def applied_columns(values: dict, loop: ClosedLoop) -> dict:
    """The applied dispersions as table columns (``name[i]``), with the sensor biases the run's
    seed drew from the datasheets (the gyro's turn-on bias, the magnetometer's bias)."""
    out = {f"{name}[{i}]": float(x) for name, v in values.items() for i, x in enumerate(np.atleast_1d(v))}
    sensors = loop.sim.sensors
    if sensors is not None and sensors.gyro is not None:
        out.update({f"gyro_bias_deg_per_h[{i}]": float(b) / DEG * 3600 for i, b in enumerate(sensors.gyro.turn_on)})
    if sensors is not None and sensors.magnetometer is not None:
        out.update({f"magnetometer_bias_nT[{i}]": float(b) * 1e9 for i, b in enumerate(sensors.magnetometer.bias)})
    return out


def loop_for(setup: Setup, truth: disp.Truth, key: Ed25519PrivateKey | None = None,
             fault_table=None) -> ClosedLoop:
    """The closed loop of the nominal scenario's flight software on the dispersed truth (``key``:
    its plan-signing key, default a new one; ``fault_table``: watched and acted on, see
    :class:`~att_planner.tools.closed_loop.ClosedLoop`)."""
    s = truth.scenario
    sim = Simulation.for_scenario(s, q0=truth.q0, omega0=truth.omega0, seed=truth.seed,
                                  checks=Checks(body_frame_id=s.body_frame_id), dispersed_faults=truth.faults)
    return ClosedLoop(setup.scenario, simulation=sim, key=key, fault_table=fault_table)


@dataclass
class _Flight:
    """One run of :func:`fly_batch`: converging, then flying its plan (``deadline``: of the phase)."""

    setup: Setup
    loop: ClosedLoop
    row: dict
    deadline: float
    issued: tuple                   # the plan as the loops' one key issued it
    flying: bool = False
    start: float = math.nan

    def going(self) -> bool:
        """Whether the run takes another step — the checks of converging (until CONVERGED or
        ``converge_timeout_s``) and of :meth:`ClosedLoop.fly` (until the controller ends the maneuver),
        in their order; an ended run gets its outcomes."""
        setup, loop = self.setup, self.loop
        sim, est = loop.sim, loop.estimator
        if not self.flying:
            if est is not None and est.health(sim.t) != Health.CONVERGED:
                if sim.t < self.deadline and not sim.halted:
                    return True
                return self.end(313, f"the estimate did not converge within {setup.campaign.converge_timeout_s:g} s")
            self.start, self.flying = sim.t, True
            refused = loop.execute(setup.plan, issued=self.issued)
            if refused is not None:
                return self.end(int(refused.code), refused.message)
            loop.result = None
            self.deadline = sim.t + setup.plan.duration + loop.controller.config.settle_time + 10
        if loop.result is None and sim.t < self.deadline and not sim.halted:
            return True
        result = loop.result or ManeuverResult(False, 305, "the maneuver did not end in time")
        return self.end(result.error_code, result.message)

    def end(self, code: int, message: str) -> bool:
        start = self.start if self.flying else self.loop.sim.t
        self.row.update(outcomes(self.setup, self.loop, start, code, message))
        if self.loop.monitor is not None:
            history = self.loop.monitor.history
            self.row.update(fault_reports=len(history), fault_ids=sorted({f.fault_id for f in history}))
        return False


def fly_batch(setup: Setup, runs: list[tuple[int, int]], tap=None, fault_table=None) -> list[dict]:
    """The rows of ``(run, seed)`` pairs (applied values and outcomes, :data:`OUTCOMES`), flown as one
    batch: each run converges, then flies the plan, as it would alone; at each step the runs'
    sensors are read on rows (:meth:`SimulationBatch.sense <att_sim.truth.batch.SimulationBatch.sense>`),
    their estimators reprocess together (:func:`~att_planner.estimation.estimator.replay`:
    their propagations as one stack), their controllers share the plan's reference (one plan object,
    issued once with the loops' one key: :class:`~att_planner.control.tracking.ReferenceMemo`) and
    compute its tracking law as rows (:func:`~att_planner.control.controller.step_controllers`), and
    the simulations of the runs still going advance as one batch (:class:`att_sim.truth.batch.SimulationBatch`).
    ``cpu_seconds``: the group's CPU time shared equally. ``tap``: see :attr:`ClosedLoop.tap` (a full
    log; one run). ``fault_table``: each run's loop watches it and acts on it (:func:`loop_for`); the
    rows then carry ``fault_reports`` and ``fault_ids``."""
    cpu = time.process_time()
    flights, key, references, issued = [], Ed25519PrivateKey.generate(), ReferenceMemo(), None
    for run, seed in runs:
        truth, values = dispersed(setup, seed)
        loop = loop_for(setup, truth, key, fault_table)
        loop.tap, loop.controller.references = tap, references
        issued = issued or loop.issue(setup.plan)
        flights.append(_Flight(setup, loop, {"run": run, "seed": seed, **applied_columns(values, loop)},
                               loop.sim.t + setup.campaign.converge_timeout_s, issued))
    going, batch = flights, None
    while going:
        still = [f for f in going if f.going()]
        if len(still) != len(going) or batch is None:
            batch = SimulationBatch([f.loop.sim for f in still]) if still else None
        going = still
        readings = batch.sense() if batch is not None else []
        exchanges = [f.loop.exchange_steps(r) for f, r in zip(going, readings)]
        outputs = {}
        while exchanges:                # each turn: every exchange to its next job, those of a kind done together
            turn = [(steps, _resume(steps, outputs.pop(steps, None))) for steps in exchanges]
            replay([job for _, job in turn if isinstance(job, Reprocessing)])
            stepping = [(steps, job) for steps, job in turn if isinstance(job, Controller)]
            for (steps, _), out in zip(stepping, step_controllers([job for _, job in stepping])):
                outputs[steps] = out
            exchanges = [steps for steps, job in turn if job is not None]
        if batch is not None:
            batch.advance(going[0].loop.step)
    share = (time.process_time() - cpu) / max(len(flights), 1)
    return [{**f.row, "cpu_seconds": share} for f in flights]


def _resume(steps, value):
    """The generator ``steps`` sent ``value``: its next job, None when it has finished."""
    try:
        return steps.send(value)
    except StopIteration:
        return None


def fly(setup: Setup, seed: int, run: int = -1, tap=None) -> dict:
    """The row of the run of seed ``seed`` (``run``: its index in the campaign), alone: :func:`fly_batch`."""
    return fly_batch(setup, [(run, seed)], tap)[0]


def settling_time(t: np.ndarray, error: np.ndarray, t_end: float, tolerance: float) -> float:
    """Time after ``t_end`` from which ``error`` stays at or below ``tolerance`` (NaN: never)."""
    after = t >= t_end - 1e-9
    if not after.any() or error[after][-1] > tolerance:
        return math.nan
    outside = np.flatnonzero(error[after] > tolerance)
    return 0.0 if outside.size == 0 else float(t[after][outside[-1] + 1] - t_end)


def outcomes(setup: Setup, loop: ClosedLoop, start: float, code: int, message: str) -> dict:
    """The flown truth measured as a plan's verification measures its integration."""
    a = loop.trace.arrays("t", "q_true", "omega_true", "wheel_speeds", "wheel_torques")
    sc, m = setup.scenario.spacecraft, setup.maneuver
    if a["t"].size == 0:
        return {"success": False, "code": int(code), "final_error_deg": math.nan, "final_rate": math.nan,
                "min_margin_deg": math.nan, "peak_wheel_ratio": math.nan, "peak_torque_ratio": math.nan,
                "settling_time": math.nan, "start_time": start, "reason": message}
    error = rot.angle_between(a["q_true"], m["qf"])
    names, margins = zone_margins(setup.scenario, m, a["t"], a["q_true"])
    per_zone = margins.min(axis=0) if margins.size else np.zeros(0)
    wheel = float(np.abs(a["wheel_speeds"]).max() / sc.wheel_speed_max) if sc.n_wheels else 0.0
    torque = float(np.abs(a["wheel_torques"]).max() / sc.wheel_torque_max) if sc.n_wheels else 0.0
    ver = Verification(final_attitude_error=float(error[-1]), final_rate=float(np.linalg.norm(a["omega_true"][-1])),
                       min_cone_margin=float(per_zone.min()) if per_zone.size else math.inf,
                       cone_margins=per_zone.tolist(), torque_ratio=torque, wheel_speed_ratio=wheel,
                       rate_max=float(np.linalg.norm(a["omega_true"], axis=1).max()), dense_samples=int(a["t"].size),
                       zone_names=names)
    why = rejection(ver)
    success = code == 0 and why is None
    return {"success": success, "code": int(code), "final_error_deg": math.degrees(ver.final_attitude_error),
            "final_rate": ver.final_rate, "min_margin_deg": math.degrees(ver.min_cone_margin),
            "peak_wheel_ratio": wheel, "peak_torque_ratio": torque,
            "settling_time": settling_time(a["t"], error, start + setup.plan.duration,
                                           setup.campaign.settle_tolerance),
            "start_time": start, "reason": "" if success else (why or message)}
