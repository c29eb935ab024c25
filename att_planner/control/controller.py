"""The controller's mode manager without ROS: state and estimate inputs, plans, mode changes, maneuvers.

:class:`Controller` holds the latest state, the mode, the received plans, the
:class:`~.maneuver.Maneuver` being executed (its zones: :mod:`.maneuver`), the pointing law it hands
over to at its end and the attitude held after it, and authenticates mode requests
(:mod:`.mode_authentication`). It starts, aborts, completes and holds maneuvers; what each control
instant commands in the mode it is in is :mod:`.step` (:meth:`Controller.step`, and
:func:`~.step.step_controllers` for several controllers at once; both, with :class:`~.step.StepOutput`
and :data:`~.step.USABLE`, are imported from here too).
Its inputs are plain types (:mod:`att_msgs_py.types`), its outputs a :class:`~.step.StepOutput` per
control instant (actuator command, status, action feedback, the result of a maneuver that ended).
The node (:mod:`att_planner.nodes.controller_node`) only translates messages; tests drive the
core directly, like :class:`att_sim.truth.simulation.Simulation`.

Inputs are hostile until checked: a state passes :class:`~.state_gate.StateGate` (fields, time,
source) or changes nothing; a plan passes :func:`~.plan_checks.check_plan` (fields, spacecraft,
signature) before it is cached or flown, its id can never be taken by a different plan, and it
starts only near the current state (:func:`~.plan_checks.check_start`). The cache is bounded by
count and bytes (oldest first, never the plan being flown). A controller whose first state shows
the spacecraft rotating faster than ``safe_rate_threshold`` goes to safe mode by itself.
"""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from att_msgs_py.errors import ErrorCode, RequestError
from att_msgs_py.types import (
    CONTROL_MODES,
    AttitudeEstimate,
    Command,
    ControllerStatus,
    ControlMode,
    Health,
    ManeuverResult,
    Plan,
    PointingMode,
    State,
)
from att_planner.control import tracking
from att_planner.control.coil_check import CoilCheck
from att_planner.control.controller_config import ControllerConfig
from att_planner.control.maneuver import Maneuver, plan_zones
from att_planner.control.measured_state import MeasuredState
from att_planner.control.mode_authentication import ModeAuthentication
from att_planner.control.plan_cache import PlanCache
from att_planner.control.plan_checks import PlanContext, check_start, plan_start
from att_planner.control.state_gate import GateConfig, StateGate
from att_planner.control.step import USABLE, StepOutput, step_controllers
from att_planner.control.wheel_check import WheelCheck
from att_planner.guidance.laws import PointingGeometry
from att_planner.guidance.modes import law_of
from att_sim.models import rotations as rot
from att_sim.models.dynamics import Spacecraft
from att_sim.models.ephemeris import Ephemeris


@dataclass
class StateOutcome:
    """What one received state did: ``refused`` (discarded, why), a ``note`` to report (a new
    timeline, safe mode at start) and the result of a maneuver that this ended."""

    refused: RequestError | None = None
    note: str | None = None
    ended: ManeuverResult | None = None


class Controller:
    def __init__(self, context: PlanContext, config: ControllerConfig | None = None,
                 mode: int = ControlMode.IDLE, body_frame_id: str = "body", gate: GateConfig | None = None,
                 sky: Ephemeris | None = None, measured: MeasuredState | None = None, friction=None,
                 guidance_sky: PointingGeometry | None = None):
        """``measured``: fly on attitude estimates (:meth:`accept_estimate`) with measured wheel
        speeds and field, blanking the magnetometer; None: on truth states (:meth:`accept_state`).
        ``friction``: the wheel drives' expected friction torque at relative speeds ν (a callable,
        :meth:`att_sim.models.actuator_specs.WheelDriveSpec.friction`), compensated in every wheel command.
        ``guidance_sky``: the onboard orbit, Sun and Earth the pointing laws look at."""
        config = ControllerConfig() if config is None else config
        self.context, self.config, self.mode, self.body_frame_id = context, config, mode, body_frame_id
        self.measured, self.friction = measured, friction
        self.estimate_health: Health | None = None     # of the latest accepted estimate
        self.sky = sky                                 # the scenario's (time: sim time), None without an epoch
        self.gate = StateGate(context.spacecraft, context.frame_id, body_frame_id, gate or GateConfig())
        self.next_control = -math.inf
        self.maneuver: Maneuver | None = None
        self.hold_q_RN: np.ndarray | None = None       # final attitude held after a maneuver
        self.cache = PlanCache(context, config.max_cached_plans, config.max_cache_bytes)
        self.references = tracking.ReferenceMemo()     # the plan's reference (shared by the runs of a task)
        self.guidance_sky = guidance_sky
        self.pointing = None                           # the pointing law of MODE_POINTING (guidance.laws)
        self.safe_law = None                           # the safe mode's Sun pointing, built when first used
        self.dumping = config.dumping
        self.authentication = ModeAuthentication()     # of mode requests (no key: none)
        self.healthy: tuple[bool, ...] | None = None   # the wheels the demand is allocated on (None: every one)
        self.safe_actuation = None                     # safe mode on what is left: state -> SafeActuation | None
        self.safe_zones = None                         # the zones safe mode keeps clear of (FittedZones), None: none
        self.coil_check: CoilCheck | None = None       # the active magnetorquer check (None: none; .coil_check)
        self.wheel_check: WheelCheck | None = None     # the null-space wheel excitation (None: none; .wheel_check)

    @property
    def spacecraft(self) -> Spacecraft:
        return self.context.spacecraft

    @property
    def state(self) -> State | None:
        return self.gate.last

    @property
    def mode_key(self):
        """The Ed25519 public key mode requests must verify against (None: no check)."""
        return self.authentication.key

    @mode_key.setter
    def mode_key(self, key) -> None:
        self.authentication.key = key

    @property
    def mode_sequence(self) -> int:
        """The sequence number of the last authenticated mode request."""
        return self.authentication.sequence

    @property
    def m_max(self) -> float:
        return min(self.config.m_max, self.spacecraft.dipole_max)

    @property
    def plans(self):
        """The cached plans by id (:class:`~.plan_cache.PlanCache`)."""
        return self.cache.plans

    @property
    def cache_bytes(self) -> int:
        return self.cache.bytes

    def receive_plan(self, plan: Plan, payload: bytes) -> RequestError | None:
        """Cache a published plan once it passes its checks (never evicting the one being flown)."""
        return self.cache.receive(plan, payload, self.maneuver.plan.plan_id if self.maneuver is not None else None)

    def resolve(self, plan_id: str, inline: Plan | None = None,
                payload: bytes = b"") -> tuple[Plan | None, RequestError | None]:
        """The plan to execute (``inline`` with its signed ``payload``, or the cached ``plan_id``),
        or why there is none."""
        return self.cache.resolve(plan_id, inline, payload)

    # -- inputs ---------------------------------------------------------------------------------
    def accept_state(self, state: State, wall: float = 0.0, clock: float | None = None,
                     source: bytes | None = None) -> StateOutcome:
        """Keep ``state`` (received at monotonic ``wall`` s, node clock ``clock``, from publisher
        ``source``) as the latest if :class:`StateGate` admits it; what it changed."""
        first = self.gate.last is None
        admission = self.gate.admit(state, wall, clock, source)
        if admission.error is not None:
            return StateOutcome(refused=admission.error)
        out = StateOutcome()
        if admission.resynced:
            out.note = f"state timeline restarted: {admission.previous_t:.3f} s then {state.t:.3f} s"
            if admission.handover:
                out.note += " (the held publisher left the ROS graph: a new source)"
            if self.maneuver is not None:
                out.ended = self.abort(f"aborted: {out.note}")
            self.next_control = -math.inf
        if first and self.mode == ControlMode.IDLE:
            rate = float(np.linalg.norm(admission.state.omega))
            if rate > self.config.safe_rate_threshold:
                self.mode = ControlMode.SAFE
                out.note = (f"the spacecraft rotates at {rate:.4g} rad/s (above safe_rate_threshold_rad_s "
                            f"{self.config.safe_rate_threshold:g} rad/s): rate damping (safe mode)")
        return out

    def accept_estimate(self, estimate: AttitudeEstimate, wall: float = 0.0,
                        source: bytes | None = None) -> StateOutcome:
        """Fly on ``estimate`` (with the measured wheel speeds and field) if the state it makes passes
        the gate; an estimate that cannot be flown (initialising, diverged) ends a maneuver and the
        attitude modes in safe mode (rate damping on the gyro's rate)."""
        try:
            state = self.measured.compose(estimate, None if self.state is None else self.state.t)
        except RequestError as err:
            return StateOutcome(refused=err)
        out = self.accept_state(state, wall, None, source)
        if out.refused is not None:
            return out
        self.estimate_health = Health(estimate.health)
        if self.estimate_health in USABLE:
            return out
        why = f"the attitude estimate is {self.estimate_health.name.lower()}"
        if self.maneuver is not None:
            out.ended = self.abort(f"aborted: {why}")
            out.note = f"{why}: maneuver aborted, safe mode (rate damping)"
        elif self.mode in (ControlMode.MAGNETORQUER_PD, ControlMode.PLAN_TRACKING, ControlMode.POINTING):
            self.mode, self.hold_q_RN, self.pointing = ControlMode.SAFE, None, None
            out.note = f"{why}: safe mode (rate damping)"
        return out

    def estimate_refusal(self) -> RequestError | None:
        """Why the attitude laws cannot start now on the estimate (None in truth mode or when they can)."""
        if self.measured is None or self.estimate_health == Health.CONVERGED:
            return None
        health = "none yet" if self.estimate_health is None else self.estimate_health.name.lower()
        return RequestError(ErrorCode.ESTIMATE_UNHEALTHY, f"the attitude estimate is not converged ({health}); "
                                                          "attitude modes start on a converged estimate")

    def authorize_mode(self, payload: bytes, signature: bytes, signer: str, sequence: int) -> RequestError | None:
        """Why a mode request (signed bytes ``payload``) is not authentic, when :attr:`mode_key` is
        set; its ``sequence`` must be above the last accepted one (no replay)."""
        return self.authentication.check(payload, signature, signer, sequence)

    def set_mode(self, mode: int, pointing: PointingMode | None = None,
                 dumping: bool | None = None) -> tuple[ErrorCode, str, ManeuverResult | None]:
        """Change the mode (MODE_POINTING: to the law of ``pointing``) and, when given, switch the
        momentum dumping; the result of a maneuver this aborts comes back too."""
        if mode not in CONTROL_MODES:
            return ErrorCode.INVALID_MODE, f"mode {mode} is not one of {CONTROL_MODES} (ActuatorCommand.MODE_*)", None
        if mode == ControlMode.PLAN_TRACKING:
            return ErrorCode.INVALID_MODE, "plan tracking starts with the execute action, not with set_mode", None
        if self.maneuver is not None and mode != ControlMode.SAFE:
            return ErrorCode.BUSY, (f"maneuver '{self.maneuver.plan.plan_id}' is executing: only MODE_SAFE "
                                    "(abort) is accepted until it ends or is cancelled"), None
        law = None
        try:
            if mode in (ControlMode.MAGNETORQUER_PD, ControlMode.POINTING):
                refused = self.estimate_refusal()
                if refused is not None:
                    raise refused
            if mode == ControlMode.POINTING:
                law = self.pointing_law(pointing)
        except RequestError as err:
            return err.code, err.message, None
        ended = self.abort("aborted by a switch to safe mode") if self.maneuver is not None else None
        self.mode, self.pointing = mode, law
        if dumping is not None:
            self.dumping = bool(dumping)
        what = f"pointing {law.name}" if law is not None else f"mode set to {mode}"
        return ErrorCode.OK, f"{what}; momentum dumping {'on' if self.dumping else 'off'}", ended

    def pointing_law(self, pointing: PointingMode | None):
        """The law of a requested pointing mode, checked now (RequestError: 304 without a state,
        314 for a bad field or no attitude); a law built onboard (one with an ``attitude``, e.g. a
        strip's :class:`att_planner.guidance.strip.StripLaw`) as it is."""
        if self.state is None:
            raise RequestError(ErrorCode.NO_STATE, "no spacecraft state received yet")
        if pointing is not None and not isinstance(pointing, PointingMode):
            if callable(getattr(pointing, "attitude", None)):
                return pointing
            raise RequestError(ErrorCode.INVALID_POINTING, f"a pointing mode or a pointing law is expected; found "
                                                           f"a {type(pointing).__name__}")
        if pointing is None:
            raise RequestError(ErrorCode.INVALID_POINTING, "MODE_POINTING needs a pointing mode")
        if self.guidance_sky is None:
            raise RequestError(ErrorCode.INVALID_POINTING, "this controller has no orbit to point from")
        return law_of(pointing, self.guidance_sky, self.state.t, self.state.q)

    def start(self, plan: Plan, after: PointingMode | None = None) -> RequestError | None:
        """Start flying ``plan`` (resolved) from the latest state, if it starts there; at its end
        hand over to the pointing mode ``after`` (None: hold its final attitude)."""
        if self.state is None:
            return RequestError(ErrorCode.NO_STATE, "no spacecraft state received yet")
        refused = self.estimate_refusal() or check_start(plan, self.state, self.context)
        if refused is not None:
            return refused
        try:
            law = None if after is None else self.pointing_law(after)
        except RequestError as err:
            return err
        try:
            zones = plan_zones(plan, self.sky)
        except ValueError as err:
            return RequestError(ErrorCode.INVALID_PLAN, f"plan '{plan.plan_id}': its zones cannot be placed in the "
                                                        f"sky now: {err}")
        t0 = plan_start(plan, self.state, self.context)
        if isinstance(t0, RequestError):
            return t0
        self.maneuver = Maneuver(plan, t0, zones, after=law)
        self.mode, self.pointing = ControlMode.PLAN_TRACKING, None
        return None

    def abort(self, message: str) -> ManeuverResult:
        """End the running maneuver unsuccessfully (cancelled, or safe mode); safe mode follows."""
        return self._end(False, ErrorCode.ABORTED, message)

    def complete(self, message: str, law=None) -> ManeuverResult:
        """End the running maneuver successfully (``message``): hold its final attitude, or hand
        over to the pointing ``law`` (MODE_POINTING) when one is given."""
        result = self._end(True, ErrorCode.OK, message)
        if law is not None:
            self.mode, self.pointing, self.hold_q_RN = ControlMode.POINTING, law, None
        return result

    def hold(self, message: str) -> ManeuverResult | None:
        """End the running maneuver unsuccessfully (``message``) and hold the latest attitude at rest
        (plan tracking about it): the brake before a re-plan; the ended maneuver's result."""
        ended = self._end(False, ErrorCode.ABORTED, message) if self.maneuver is not None else None
        self.mode, self.pointing, self.hold_q_RN = ControlMode.PLAN_TRACKING, None, self.state.q.copy()
        return ended

    def _end(self, success: bool, code: ErrorCode, message: str) -> ManeuverResult:
        """Close the running maneuver; its figures are those of the latest state (there is one:
        :meth:`start` needs it)."""
        s, plan = self.state, self.maneuver.plan
        result = ManeuverResult(
            success=success, error_code=int(code), message=message,
            duration=max(0.0, float(s.t - self.maneuver.t0)),   # 0 when a new timeline began
            final_attitude_error=float(rot.angle_between(s.q, plan.q[-1])),
            final_rate=float(np.linalg.norm(s.omega)))
        self.hold_q_RN = plan.q[-1] if success else None
        self.maneuver = None
        if code == ErrorCode.ABORTED:
            self.mode = ControlMode.SAFE
        return result

    # -- the control loop -------------------------------------------------------------------------
    def due(self) -> bool:
        """Whether the latest state is at or after the next control instant (then it becomes the
        current one)."""
        if self.state is None or self.state.t < self.next_control - 1e-9:
            return False
        self.next_control = self.state.t + self.config.control_period
        return True

    def step(self, cancel_requested: bool = False) -> StepOutput:
        """Command and status for the latest state; ``cancel_requested`` aborts a running maneuver
        (:func:`~.step.step_controllers` of this controller alone)."""
        return step_controllers([self], [cancel_requested])[0]

    def stale_command(self) -> tuple[Command, ControllerStatus]:
        """What the watchdog sends when no state arrives: zero wheel torques in safe mode."""
        t = self.state.t if self.state is not None else 0.0
        return (Command(mode=ControlMode.SAFE, wheel_torques=np.zeros(self.spacecraft.n_wheels), t=t,
                        frame_id=self.body_frame_id),
                ControllerStatus(mode=self.mode, t=t, state_stale=True, message="no state (wall clock)",
                                 frame_id=self.body_frame_id))
