"""The controller's numerics without ROS: mode, plan cache, the maneuver being flown, one step at a time.

:class:`Controller` holds what the controller node used to keep in dictionaries: the latest state,
the mode, the received plans, the :class:`Maneuver` being executed and the attitude held after it.
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

Laws per mode: IDLE commands nothing; MAGNETORQUER_PD the PD-like law of Bruni & Celani
(:mod:`.magnetorquer`); SAFE rate damping through the wheels (τ = −k_d ω); PLAN_TRACKING the plan's
feedforward plus quaternion PD feedback (:mod:`.tracking`) for the plan's duration plus a settle
time, then a hold of its final attitude.

The feedback's ``min_cone_margin`` covers the plan's cones and zones at their true positions now:
a :class:`~att_planner.zones.FittedZones` of the plan, built once when it starts, on the controller's
``sky`` (:class:`att_sim.models.ephemeris.Ephemeris` at the scenario epoch, whose time is sim time), evaluated
straight from the ephemeris at the current state's time (one evaluation per feedback). The truth
does not depend on the plan's epoch: a plan made for another start instant shows the margins it
really has. Without a ``sky`` (a scenario with no epoch) the moving zones are left out: the margin
is that of the cones and inertial zones only.
"""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from att_msgs_py import signing
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
from att_planner.control import momentum, tracking
from att_planner.control.magnetorquer import dipole_command
from att_planner.control.measured_state import MeasuredState
from att_planner.control.plan_cache import PlanCache
from att_planner.control.plan_checks import PlanContext, check_start
from att_planner.control.pointing import handover_law, pointing_torque
from att_planner.control.state_gate import GateConfig, StateGate
from att_planner.guidance import reference as guidance_reference
from att_planner.guidance.laws import PointingGeometry
from att_planner.guidance.modes import law_of
from att_planner.zones import FittedZones, zones_from_cones
from att_sim.models import rotations as rot
from att_sim.models.dynamics import Spacecraft
from att_sim.models.ephemeris import Ephemeris


@dataclass(frozen=True)
class ControllerConfig:
    """Gains and timing (the controller node's parameters)."""

    control_period: float = 0.1        # s of sim time between commands
    settle_time: float = 20.0          # s held on the final attitude after the plan ends
    tracking_kp: float = 0.4           # N m / rad, attitude feedback around the plan reference
    tracking_kd: float = 10.0          # N m s / rad
    kp: float = 2e5                    # magnetorquer PD-like law (Bruni & Celani)
    kd: float = 1e8
    m_max: float = math.inf            # A m² per coil (default: the spacecraft's dipole limit)
    safe_kd: float = 10.0              # N m s / rad, rate damping of the safe mode
    feedback_period: float = 0.5       # s of sim time between action feedbacks
    max_cached_plans: int = 50
    max_cache_bytes: int = 64 * 1024 * 1024   # serialized plans kept
    safe_rate_threshold: float = 0.005  # rad/s: found rotating faster at start, the controller damps (safe mode)
    dumping: bool = False              # magnetorquer momentum dumping (issue 15)
    dumping_gain: float = 1e-3         # 1/s: k of m = k (Δh × B)/|B|²
    null_space_gain: float = 0.05      # 1/s: wheel speeds' null-space component to its bias (more than 3 wheels)
    null_space_speed: float = 0.0      # rad/s: that bias, along each null-space direction
    safe_sun_axis: tuple = (0.0, 0.0, 1.0)   # body axis the safe mode points at the Sun once the rates are damped
    handover_blend: float = 60.0       # s: a plan ending at rest enters a moving pointing reference this smoothly

    @property
    def feedback_every(self) -> int:
        """Control steps between action feedbacks."""
        return max(1, round(self.feedback_period / self.control_period))


@dataclass
class Maneuver:
    """The plan being executed, from sim time ``t0``, its zones (:meth:`Controller.start`) and the
    pointing law it hands over to at its end (None: hold its final attitude after a settle time)."""

    plan: Plan
    t0: float
    zones: FittedZones | None = None
    ticks: int = 0
    after: object = None


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


ZONE_FIT_WINDOW = 1.0                          # s: a FittedZones needs a window; the controller uses its truth only


USABLE = (Health.CONVERGED, Health.PROPAGATING)   # estimates the attitude laws may fly on


class Controller:
    def __init__(self, context: PlanContext, config: ControllerConfig = ControllerConfig(),
                 mode: int = ControlMode.IDLE, body_frame_id: str = "body", gate: GateConfig | None = None,
                 sky: Ephemeris | None = None, measured: MeasuredState | None = None, friction=None,
                 guidance_sky: PointingGeometry | None = None):
        """``measured``: fly on attitude estimates (:meth:`accept_estimate`) with measured wheel
        speeds and field, blanking the magnetometer; None: on truth states (:meth:`accept_state`).
        ``friction``: the wheel drives' expected friction torque at relative speeds ν (a callable,
        :meth:`att_sim.models.actuator_specs.WheelDriveSpec.friction`), compensated in every wheel command.
        ``guidance_sky``: the onboard orbit, Sun and Earth the pointing laws look at (issue 15)."""
        self.context, self.config, self.mode, self.body_frame_id = context, config, mode, body_frame_id
        self.measured, self.friction = measured, friction
        self.estimate_health: Health | None = None     # of the latest accepted estimate
        self.sky = sky                                 # the scenario's (time: sim time), None without an epoch
        self.gate = StateGate(context.spacecraft, context.frame_id, body_frame_id, gate or GateConfig())
        self.next_control = -math.inf
        self.maneuver: Maneuver | None = None
        self.hold_q: np.ndarray | None = None          # final attitude held after a maneuver
        self.cache = PlanCache(context, config.max_cached_plans, config.max_cache_bytes)
        self.references = tracking.ReferenceMemo()     # the plan's reference (shared by lockstep runs)
        self.prepared: tuple | None = None             # (state, reference, wheel torques) of the law, done ahead
        self.guidance_sky = guidance_sky
        self.pointing = None                           # the pointing law of MODE_POINTING (guidance.laws)
        self.safe_law = None                           # the safe mode's Sun pointing, built when first used
        self.dumping = config.dumping
        self.mode_key = None                           # Ed25519 public key mode requests must verify against
        self.mode_sequence = 0                         # sequence of the last authenticated mode request

    @property
    def spacecraft(self) -> Spacecraft:
        return self.context.spacecraft

    @property
    def state(self) -> State | None:
        return self.gate.last

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
            if self.maneuver is not None:
                out.ended = self.abort(f"aborted: {out.note}")
            self.next_control = -math.inf
        if first and self.mode == ControlMode.IDLE:
            rate = float(np.linalg.norm(admission.state.omega))
            if rate > self.config.safe_rate_threshold:
                self.mode = ControlMode.SAFE
                out.note = (f"the spacecraft rotates at {rate:.4g} rad/s (above safe_rate_threshold "
                            f"{self.config.safe_rate_threshold:g} rad/s): rate damping (safe mode)")
        return out

    def accept_estimate(self, estimate: AttitudeEstimate, wall: float = 0.0,
                        source: bytes | None = None) -> StateOutcome:
        """Fly on ``estimate`` (with the measured wheel speeds and field) if the state it makes passes
        the gate; an estimate that cannot be flown (initialising, diverged) ends a maneuver and the
        attitude modes in safe mode (rate damping on the gyro's rate)."""
        try:
            state = self.measured.compose(estimate)
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
            self.mode, self.hold_q, self.pointing = ControlMode.SAFE, None, None
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
        if self.mode_key is None:
            return None
        why = signing.check(payload, signature, signer, self.mode_key, "the mode request")
        if why is None and sequence <= self.mode_sequence:
            why = f"sequence {sequence} is not above the last accepted {self.mode_sequence} (a replayed request)"
        if why is not None:
            return RequestError(ErrorCode.MODE_NOT_AUTHENTIC, why)
        self.mode_sequence = sequence
        return None

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
        314 for a bad field or no attitude)."""
        if self.state is None:
            raise RequestError(ErrorCode.NO_STATE, "no spacecraft state received yet")
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
            zones = self.zone_sky(plan)
        except ValueError as err:
            return RequestError(ErrorCode.INVALID_PLAN, f"plan '{plan.plan_id}': its zones cannot be placed in the "
                                                        f"sky now: {err}")
        self.maneuver = Maneuver(plan, self.state.t, zones, after=law)
        self.mode, self.pointing = ControlMode.PLAN_TRACKING, None
        return None

    def zone_sky(self, plan: Plan) -> FittedZones | None:
        """The plan's cones and zones on :attr:`sky` (moving zones left out without one); None
        when there are none. Only its truth is used (any time): the fit is over a short window."""
        zones = zones_from_cones(plan.cones, plan.sensor_axis) + [z for z in plan.zones
                                                                  if self.sky is not None or z.body == "inertial"]
        if not zones:
            return None
        moving = any(z.body != "inertial" for z in zones)
        return FittedZones(zones, self.sky if moving else None, window=ZONE_FIT_WINDOW)

    def abort(self, message: str) -> ManeuverResult:
        """End the running maneuver unsuccessfully (cancelled, or safe mode); safe mode follows."""
        return self._end(False, ErrorCode.ABORTED, message)

    # -- the control loop -------------------------------------------------------------------------
    def due(self) -> bool:
        """Whether the latest state is at or after the next control instant (then it becomes the
        current one)."""
        if self.state is None or self.state.t < self.next_control - 1e-9:
            return False
        self.next_control = self.state.t + self.config.control_period
        return True

    def step(self, cancel_requested: bool = False) -> StepOutput:
        """Command and status for the latest state; ``cancel_requested`` aborts a running maneuver."""
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
            self._track(out, cancel_requested)
        elif self.mode == ControlMode.PLAN_TRACKING and self.hold_q is not None:
            cmd.wheel_torques = self._wheel_command(tracking.Reference(self.hold_q, np.zeros(3), np.zeros(3)))
            status.message = "holding the final attitude of the last maneuver"
            status.reference_q, status.attitude_error = self.hold_q, float(rot.angle_between(s.q, self.hold_q))
        status.dumping = self.dumping
        if self.measured is not None:
            self.measured.dipoles.record(s.t, cmd.dipole)
        return out

    def stale_command(self) -> tuple[Command, ControllerStatus]:
        """What the watchdog sends when no state arrives: zero wheel torques in safe mode."""
        t = self.state.t if self.state is not None else 0.0
        return (Command(mode=ControlMode.SAFE, wheel_torques=np.zeros(self.spacecraft.n_wheels), t=t,
                        frame_id=self.body_frame_id),
                ControllerStatus(mode=self.mode, t=t, state_stale=True, message="no state (wall clock)",
                                 frame_id=self.body_frame_id))

    def _wheels(self, body_torque: np.ndarray, wheel_speed: np.ndarray | None = None) -> np.ndarray:
        """Motor torques that put ``body_torque`` on the body, the expected drive friction compensated
        (``wheel_speed``: the inertial spin rates the gyroscopic term uses; default the state's), and
        with more than three wheels the null-space control of their speeds (no body torque)."""
        s, sc, c = self.state, self.spacecraft, self.config
        extra = momentum.null_space_torques(sc, s.wheel_speeds, c.null_space_speed, c.null_space_gain)
        if self.friction is not None:
            extra = extra + self.friction(s.wheel_speeds - sc.wheel_axes.T @ s.omega)
        return tracking.wheel_torques(sc, body_torque, s.omega, s.wheel_speeds if wheel_speed is None else wheel_speed,
                                      extra)

    def _point(self, out: StepOutput, law) -> None:
        """Track ``law``'s reference (feedforward + PD) through the wheels, dumping momentum with the
        magnetorquers when that is on (their torque fed forward to the wheels)."""
        s, sc, c = self.state, self.spacecraft, self.config
        ref = guidance_reference(law.attitude, s.t)
        tau = pointing_torque(sc, s.q, s.omega, ref, c.tracking_kp, c.tracking_kd)
        blank = self.measured is not None and self.measured.blank(s.t, c.control_period)
        if self.dumping and not blank and sc.n_wheels:
            h_wheels = sc.wheel_axes @ (sc.wheel_inertia * s.wheel_speeds)
            out.command.dipole = momentum.desaturation_dipole(h_wheels, np.zeros(3), s.field_body, c.dumping_gain,
                                                              self.m_max)
        out.command.wheel_torques = self._wheels(tau - rot.cross(out.command.dipole, s.field_body))
        st = out.status
        st.guidance, st.reference_q, st.reference_rate = law.name, ref.q_RN, ref.omega_RN_R
        st.attitude_error = float(rot.angle_between(s.q, ref.q_RN))
        if law.degenerate:
            st.message = f"pointing {law.name}: the directions are parallel now; holding the last attitude"

    def _safe(self, out: StepOutput) -> None:
        """Rate damping (τ = −k_d ω); once the rates are below ``safe_rate_threshold``, with a Sun to
        see and an attitude to trust, the safe Sun pointing (``safe_sun_axis`` on the Sun, the orbit
        normal as secondary)."""
        s, c = self.state, self.config
        sun_ok = self.guidance_sky is not None and self.guidance_sky.sun_N is not None and \
            (self.measured is None or self.estimate_health in USABLE)
        if not sun_ok or float(np.linalg.norm(s.omega)) > c.safe_rate_threshold:
            out.command.wheel_torques = self._wheels(-c.safe_kd * s.omega)
            return
        if self.safe_law is None:
            axis = np.asarray(c.safe_sun_axis, float)
            mode = PointingMode("sun", primary_axis=axis, secondary_axis=rot.orthonormal_basis(axis)[0],
                                secondary="orbit_normal")
            try:
                self.safe_law = law_of(mode, self.guidance_sky, s.t, s.q)
            except RequestError:
                out.command.wheel_torques = self._wheels(-c.safe_kd * s.omega)
                return
        self._point(out, self.safe_law)

    def _wheel_command(self, ref: tracking.Reference) -> np.ndarray:
        """Wheel torques of the tracking law about a body-torque reference (the ones :meth:`prepare`
        was given for this state and reference, when it was)."""
        prepared, self.prepared = self.prepared, None
        s, c = self.state, self.config
        if prepared is not None and prepared[0] is s and prepared[1] is ref:
            return prepared[2]
        return self._wheels(tracking.tracking_torque(s.q, s.omega, ref, c.tracking_kp, c.tracking_kd))

    def prepare(self, reference: tracking.Reference, wheel_torques: np.ndarray) -> None:
        """Give the next :meth:`step` the tracking law's wheel torques about ``reference`` for the
        latest state, computed elsewhere (:func:`att_planner.control.lockstep.track_together`)."""
        self.prepared = (self.state, reference, wheel_torques)

    def _track(self, out: StepOutput, cancel_requested: bool) -> None:
        """One plan-tracking step: command, feedback every ``feedback_period``, the end."""
        s, m, sc = self.state, self.maneuver, self.spacecraft
        plan = m.plan
        elapsed = s.t - m.t0
        ref = self.references(plan, elapsed)
        if plan.control_kind == ControlKind.WHEEL_TORQUE:
            # the plan's wheel torques as feedforward, PD feedback about its reference states
            fb = tracking.tracking_torque(s.q, s.omega, tracking.Reference(ref.q, ref.omega, np.zeros(3)),
                                          self.config.tracking_kp, self.config.tracking_kd)
            u = ref.torque + self._wheels(fb, np.zeros(sc.n_wheels))
            u = np.clip(u, -sc.wheel_torque_max, sc.wheel_torque_max)
        else:
            u = self._wheel_command(ref)
        out.command.wheel_torques = u
        out.command.plan_id = out.status.plan_id = plan.plan_id
        m.ticks += 1
        if m.ticks % self.config.feedback_every == 0:
            span = max(plan.duration + self.config.settle_time, 1e-9)
            out.feedback = ManeuverFeedback(
                elapsed=float(elapsed), progress=float(min(1.0, elapsed / span)),
                attitude_error=float(rot.angle_between(s.q, ref.q)),
                min_cone_margin=float(m.zones.margins(s.t, s.q, true=True).min()) if m.zones else math.inf)
        if cancel_requested:
            out.result = self.abort("cancelled")
            return
        out.status.plan_progress = float(min(1.0, elapsed / max(plan.duration, 1e-9)))
        out.status.reference_q, out.status.reference_rate = ref.q, ref.omega
        out.status.attitude_error = float(rot.angle_between(s.q, ref.q))
        if m.after is not None and elapsed >= plan.duration:
            law = handover_law(m.after, plan, s.t, self.config.handover_blend)
            out.result = self._end(True, ErrorCode.OK, f"maneuver complete; pointing {law.name}")
            self.mode, self.pointing, self.hold_q = ControlMode.POINTING, law, None
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
        self.hold_q = plan.q[-1] if success else None
        self.maneuver = None
        if code == ErrorCode.ABORTED:
            self.mode = ControlMode.SAFE
        return result
