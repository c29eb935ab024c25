"""The controller's numerics without ROS: mode, plan cache, the maneuver being flown, one step at a time.

:class:`Controller` is the mode manager: it holds the latest state, the mode, the received plans,
the :class:`~.maneuver.Maneuver` being executed (its zones: :mod:`.maneuver`), the handover to a
pointing law at its end and the attitude held after it, and authenticates mode requests
(:mod:`.mode_authentication`).
Its inputs are plain types (:mod:`att_msgs_py.types`), its outputs a :class:`StepOutput` per
control instant (actuator command, status, action feedback, the result of a maneuver that ended).
The node (:mod:`att_planner.nodes.controller_node`) only translates messages; tests drive the
core directly, like :class:`att_sim.truth.simulation.Simulation`.

Inputs are hostile until checked: a state passes :class:`~.state_gate.StateGate` (fields, time,
source) or changes nothing; a plan passes :func:`~.plan_checks.check_plan` (fields, spacecraft,
signature) before it is cached or flown, its id can never be taken by a different plan, and it
starts only near the current state (:func:`~.plan_checks.check_start`). The cache is bounded by
count and bytes (oldest first, never the plan being flown). A controller whose first state shows
the spacecraft rotating faster than ``safe_rate_threshold`` goes to safe mode by itself.

Laws per mode, each a pure function of its module: IDLE commands nothing; MAGNETORQUER_PD the
PD-like law of Bruni & Celani (:mod:`.magnetorquer`); SAFE rate damping, then Sun pointing
(:mod:`.safe`); POINTING a guidance law's reference (:mod:`.pointing`); PLAN_TRACKING the plan's
feedforward plus the PD law (:mod:`.tracking`) for the plan's duration plus a settle time, then a
hold of its final attitude. The wheel laws share one PD law (:mod:`.pd`) and one realisation by
the wheels (:mod:`.wheels`). :func:`step_controllers` steps several controllers at once (the runs
of a Monte Carlo task), the tracking law evaluated as rows of runs; :meth:`Controller.step` is that
step of one controller.
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
    ControlKind,
    ControllerStatus,
    ControlMode,
    Health,
    ManeuverFeedback,
    ManeuverResult,
    Plan,
    PointingMode,
    State,
)
from att_planner.control import momentum, safe, tracking, wheels
from att_planner.control.coil_check import CoilCheck, feedforward
from att_planner.control.controller_config import ControllerConfig
from att_planner.control.magnetorquer import dipole_command
from att_planner.control.maneuver import Maneuver, plan_zones
from att_planner.control.measured_state import MeasuredState
from att_planner.control.mode_authentication import ModeAuthentication
from att_planner.control.plan_cache import PlanCache
from att_planner.control.plan_checks import PlanContext, check_start, plan_start
from att_planner.control.pointing import handover_law, law_reference, pointing_torque
from att_planner.control.state_gate import GateConfig, StateGate
from att_planner.control.wheel_check import WheelCheck, excite
from att_planner.guidance import Reference, at_rest, stack
from att_planner.guidance.laws import PointingGeometry
from att_planner.guidance.modes import law_of
from att_sim.models import rotations as rot
from att_sim.models.dynamics import Spacecraft
from att_sim.models.ephemeris import Ephemeris


@dataclass
class StepOutput:
    """What one control instant produces."""

    command: Command
    status: ControllerStatus
    feedback: ManeuverFeedback | None = None
    result: ManeuverResult | None = None       # the maneuver that ended at this step


@dataclass
class StateOutcome:
    """What one received state did: ``refused`` (discarded, why), a ``note`` to report (a new
    timeline, safe mode at start) and the result of a maneuver that this ended."""

    refused: RequestError | None = None
    note: str | None = None
    ended: ManeuverResult | None = None


USABLE = (Health.CONVERGED, Health.PROPAGATING)   # estimates the attitude laws may fly on


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

    def hold(self, message: str) -> ManeuverResult | None:
        """End the running maneuver unsuccessfully (``message``) and hold the latest attitude at rest
        (plan tracking about it): the brake before a re-plan; the ended maneuver's result."""
        ended = self._end(False, ErrorCode.ABORTED, message) if self.maneuver is not None else None
        self.mode, self.pointing, self.hold_q_RN = ControlMode.PLAN_TRACKING, None, self.state.q.copy()
        return ended

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
        (:func:`step_controllers` of this controller alone)."""
        return step_controllers([self], [cancel_requested])[0]

    def tracking_reference(self) -> Reference | None:
        """The reference the next step's plan tracking flies about (the plan's now, its torque the
        mean over the control period the command is held for; or the held attitude), None when it
        flies none."""
        if self.mode != ControlMode.PLAN_TRACKING:
            return None
        if self.maneuver is not None:
            return self.references(self.maneuver.plan, self.state.t - self.maneuver.t0, self.config.control_period)
        return at_rest(self.hold_q_RN) if self.hold_q_RN is not None else None

    def tracks_body_torque(self) -> bool:
        """Whether the next step's command is the tracking law realised by the wheels (a plan of body
        torques, or the hold after a maneuver; a plan of wheel torques feeds its torques forward)."""
        m = self.maneuver
        return m is None or m.plan.control_kind != ControlKind.WHEEL_TORQUE

    def tracking_law(self) -> tuple:
        """What the tracking law depends on besides the state and the reference: the model (the
        object), gains, null-space control and friction compensation. Controllers of one law
        evaluate it as rows (:func:`step_controllers`)."""
        k = self.config
        return (id(self.spacecraft), k.tracking_kp, k.tracking_kd, k.null_space_speed, k.null_space_gain, self.friction,
                self.healthy)

    def tracking_command(self, states: list[State], ref: Reference) -> np.ndarray:
        """Wheel torques (rows) of this controller's tracking law for rows of ``states`` about the
        rows of ``ref``: :func:`~.tracking.tracking_torque` through :func:`~.wheels.wheel_command`."""
        sc, c = self.spacecraft, self.config
        omega_BN_B = np.array([s.omega for s in states])
        torque_B = tracking.tracking_torque(np.array([s.q for s in states]), omega_BN_B, ref, c.tracking_kp,
                                            c.tracking_kd)
        return wheels.wheel_command(sc, torque_B, omega_BN_B, np.array([s.wheel_speeds for s in states]),
                                    c.null_space_speed, c.null_space_gain, self.friction, healthy=self.healthy)

    def step_with(self, cancel_requested: bool, ref: Reference | None, tracked: np.ndarray | None) -> StepOutput:
        """The step of :func:`step_controllers` once the tracking law is evaluated: ``ref`` from
        :meth:`tracking_reference`, ``tracked`` its wheel torques (when :meth:`tracks_body_torque`)."""
        s = self.state
        cmd = Command(mode=self.mode, wheel_torques=np.zeros(self.spacecraft.n_wheels), t=s.t,
                      frame_id=self.body_frame_id)
        status = ControllerStatus(mode=self.mode, t=s.t, frame_id=self.body_frame_id)
        out = StepOutput(cmd, status)
        if self.mode == ControlMode.MAGNETORQUER_PD:
            blank = self.measured is not None and self.measured.blank(s.t, self.config.control_period)
            if not blank:
                cmd.dipole = dipole_command(s.q, s.omega, s.field_body, self.config.kp, self.config.kd, self.m_max)
        elif self.mode == ControlMode.SAFE:
            self._safe(out)
        elif self.mode == ControlMode.POINTING and self.pointing is not None:
            self._point(out, self.pointing)
        elif self.mode == ControlMode.PLAN_TRACKING and self.maneuver is not None:
            self._track(out, cancel_requested, ref, tracked)
        elif self.mode == ControlMode.PLAN_TRACKING and self.hold_q_RN is not None:
            cmd.wheel_torques = tracked
            status.message = "holding the final attitude of the last maneuver"
            status.reference_q, status.attitude_error = self.hold_q_RN, float(rot.angle_between(s.q, self.hold_q_RN))
        # the active checks run while a law or a plan (or its final attitude) is followed
        following = (self.mode == ControlMode.POINTING and self.pointing is not None
                     or self.mode == ControlMode.PLAN_TRACKING
                     and (self.maneuver is not None or self.hold_q_RN is not None))
        if following and self.coil_check is not None and self.measured is not None:
            self._check_coils(cmd)
        if following and self.wheel_check is not None:
            self._check_wheels(cmd)
        status.dumping = self.dumping
        if self.measured is not None:
            self.measured.dipoles.record(s.t, cmd.dipole)
            self.measured.record_command(s.t, cmd.wheel_torques, cmd.dipole)
        return out

    def stale_command(self) -> tuple[Command, ControllerStatus]:
        """What the watchdog sends when no state arrives: zero wheel torques in safe mode."""
        t = self.state.t if self.state is not None else 0.0
        return (Command(mode=ControlMode.SAFE, wheel_torques=np.zeros(self.spacecraft.n_wheels), t=t,
                        frame_id=self.body_frame_id),
                ControllerStatus(mode=self.mode, t=t, state_stale=True, message="no state (wall clock)",
                                 frame_id=self.body_frame_id))

    def _wheels(self, torque_B: np.ndarray, gyroscopic_speeds: np.ndarray | None = None) -> np.ndarray:
        """Motor torques that put ``torque_B`` on the body at the latest state (:func:`~.wheels.wheel_command`
        of one row; ``gyroscopic_speeds``: the spin rates the gyroscopic term uses, default the state's)."""
        s, c = self.state, self.config
        return wheels.wheel_command(self.spacecraft, np.asarray(torque_B, float)[None], s.omega[None],
                                    s.wheel_speeds[None], c.null_space_speed, c.null_space_gain, self.friction,
                                    None if gyroscopic_speeds is None else gyroscopic_speeds[None],
                                    healthy=self.healthy)[0]

    def _check_coils(self, cmd: Command) -> None:
        """The active coil check's dipole (:mod:`.coil_check`) in place of the command's, when a check
        sample follows within its dwell: the difference of their magnetic torques fed forward to the
        healthy wheels (clipped at their limit)."""
        s, sc = self.state, self.spacecraft
        m = self.coil_check.dipole(s.t, self.config.control_period, self.m_max)
        if m is None or not np.any(s.field_body) or not sc.n_wheels:
            return
        A = sc.wheel_axes_pinv if self.healthy is None else wheels.healthy_allocation(sc.wheel_axes, self.healthy)
        u = np.asarray(cmd.wheel_torques, float) + feedforward(m - np.asarray(cmd.dipole, float), s.field_body, A)
        u = np.clip(u, -sc.wheel_torque_max, sc.wheel_torque_max)
        cmd.wheel_torques = u if self.healthy is None else u * np.asarray(self.healthy, bool)
        cmd.dipole = m

    def _check_wheels(self, cmd: Command) -> None:
        """The active wheel check's null-space torques (:mod:`.wheel_check`) added to the command, scaled
        to the headroom under the wheels' limit; nothing without a null space on the healthy wheels."""
        sc = self.spacecraft
        if sc.n_wheels < 4 or cmd.wheel_torques is None:
            return
        delta = self.wheel_check.torques(self.state.t, sc.wheel_axes, self.healthy)
        if delta is not None:
            cmd.wheel_torques = excite(cmd.wheel_torques, delta, sc.wheel_torque_max)

    def _point(self, out: StepOutput, law) -> None:
        """Track ``law``'s reference (:func:`~.pointing.pointing_torque`) through the wheels, dumping
        momentum with the magnetorquers when that is on (their torque fed forward to the wheels)."""
        s, sc, c = self.state, self.spacecraft, self.config
        ref = law_reference(law, s.t)
        tau = pointing_torque(sc, s.q, s.omega, ref, c.tracking_kp, c.tracking_kd)
        blank = self.measured is not None and self.measured.blank(s.t, c.control_period)
        if self.dumping and not blank and sc.n_wheels:
            h_wheels_B = sc.wheel_axes @ (sc.wheel_inertia * s.wheel_speeds)
            out.command.dipole = momentum.desaturation_dipole(h_wheels_B, np.zeros(3), s.field_body, c.dumping_gain,
                                                              self.m_max)
        out.command.wheel_torques = self._wheels(tau - rot.cross(out.command.dipole, s.field_body))
        st = out.status
        st.guidance, st.reference_q, st.reference_rate = law.name, ref.q_RN, ref.omega_RN_R
        st.attitude_error = float(rot.angle_between(s.q, ref.q_RN))
        if law.degenerate:
            st.message = f"pointing {law.name}: the directions are parallel now; holding the last attitude"

    def _safe(self, out: StepOutput) -> None:
        """The safe-mode law (:mod:`.safe`): rate damping; once the rates are below
        ``safe_rate_threshold``, with a Sun to see and an attitude to trust, the safe Sun pointing
        (``safe_sun_axis`` on the Sun, the orbit normal as secondary)."""
        s, c = self.state, self.config
        act = self.safe_actuation(s) if self.safe_actuation is not None else None
        if act is not None:             # the healthy wheels or the gyro no longer do: what is left
            if act.on_wheels:
                out.command.wheel_torques = self._wheels(act.torque_B)
            else:
                out.command.dipole = act.dipole_B
            out.status.message = f"safe mode on what is left ({act.law})"
            return
        sun_ok = self.guidance_sky is not None and self.guidance_sky.sun_N is not None and \
            (self.measured is None or self.estimate_health in USABLE)
        if not sun_ok or not safe.damped(s.omega, c.safe_rate_threshold):
            out.command.wheel_torques = self._wheels(safe.damping_torque(s.omega, c.safe_kd))
            return
        if self.safe_law is None:
            try:
                self.safe_law = law_of(safe.sun_mode(c.safe_sun_axis), self.guidance_sky, s.t, s.q)
            except RequestError:
                out.command.wheel_torques = self._wheels(safe.damping_torque(s.omega, c.safe_kd))
                return
        self._point(out, self.safe_law)

    def _track(self, out: StepOutput, cancel_requested: bool, ref: Reference, tracked: np.ndarray | None) -> None:
        """One plan-tracking step about ``ref`` (``tracked``: the tracking law's wheel torques):
        command, feedback every ``feedback_period``, the end."""
        s, m, sc = self.state, self.maneuver, self.spacecraft
        plan = m.plan
        elapsed = s.t - m.t0
        if plan.control_kind == ControlKind.WHEEL_TORQUE:
            # the plan's wheel torques as feedforward, PD feedback about its reference states
            fb = tracking.tracking_torque(s.q, s.omega, ref, self.config.tracking_kp, self.config.tracking_kd,
                                          feedforward=False)
            u = ref.torque_R + self._wheels(fb, np.zeros(sc.n_wheels))
            u = np.clip(u, -sc.wheel_torque_max, sc.wheel_torque_max)
            if self.healthy is not None:
                u = u * np.asarray(self.healthy, bool)
        else:
            u = tracked
        out.command.wheel_torques = u
        out.command.plan_id = out.status.plan_id = plan.plan_id
        m.ticks += 1
        if m.ticks % self.config.feedback_every == 0:
            span = max(plan.duration + self.config.settle_time, 1e-9)
            out.feedback = ManeuverFeedback(
                elapsed=float(elapsed), progress=float(min(1.0, max(0.0, elapsed) / span)),
                attitude_error=float(rot.angle_between(s.q, ref.q_RN)),
                min_cone_margin=float(m.zones.margins(s.t, s.q, true=True).min()) if m.zones else math.inf)
        if cancel_requested:
            out.result = self.abort("cancelled")
            return
        out.status.plan_progress = float(min(1.0, max(0.0, elapsed) / max(plan.duration, 1e-9)))
        out.status.reference_q, out.status.reference_rate = ref.q_RN, ref.omega_RN_R
        out.status.attitude_error = float(rot.angle_between(s.q, ref.q_RN))
        if m.after is not None and elapsed >= plan.duration:
            # the law takes over at this step: its reference, not the plan's held past its end
            law = handover_law(m.after, plan, m.t0 + plan.duration, s.t, self.config.handover_blend)
            out.result = self._end(True, ErrorCode.OK, f"maneuver complete; pointing {law.name}")
            self.mode, self.pointing, self.hold_q_RN = ControlMode.POINTING, law, None
            out.command.mode = out.status.mode = ControlMode.POINTING
            self._point(out, law)
            out.status.message = f"maneuver complete; pointing {law.name}"
            return
        if elapsed >= plan.duration + self.config.settle_time:
            out.result = self._end(True, ErrorCode.OK, "maneuver complete")
            out.status.message = "maneuver complete; holding the final attitude"

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


def step_controllers(controllers: list[Controller], cancel_requested: list[bool] | None = None) -> list[StepOutput]:
    """Step each controller (at its latest state; ``cancel_requested``: per controller, default
    none) as it steps alone; the tracking law of those flying it through the wheels is evaluated
    as rows, one evaluation per group of controllers of one :meth:`~Controller.tracking_law`
    (the runs of a Monte Carlo task: one nominal model, the same gains)."""
    cancel = [False] * len(controllers) if cancel_requested is None else cancel_requested
    refs = [c.tracking_reference() for c in controllers]
    tracked: list[np.ndarray | None] = [None] * len(controllers)
    waiting = [i for i, (c, ref) in enumerate(zip(controllers, refs)) if ref is not None and c.tracks_body_torque()]
    while waiting:
        first = controllers[waiting[0]]
        law = first.tracking_law()
        group = [i for i in waiting if controllers[i].tracking_law() == law]
        rows = first.tracking_command([controllers[i].state for i in group], stack([refs[i] for i in group]))
        for i, row in zip(group, rows):
            tracked[i] = row
        waiting = [i for i in waiting if tracked[i] is None]
    return [c.step_with(k, ref, u) for c, k, ref, u in zip(controllers, cancel, refs, tracked)]
