"""One control instant (no ROS): the law of the controller's mode applied to its latest state.

Given a :class:`~.controller.Controller` (its mode, the maneuver it flies, the attitude it holds), a
step computes the command of the control instant, its status and, in plan tracking, the action's
feedback; it tells the controller when a maneuver ends (:meth:`~.controller.Controller.complete`,
:meth:`~.controller.Controller.abort`), which changes the mode.

Laws per mode, each a pure function of its module: IDLE commands nothing; MAGNETORQUER_PD the
PD-like law of Bruni & Celani (:mod:`.magnetorquer`); SAFE rate damping, then Sun pointing
(:mod:`.safe`), or what is left when the healthy wheels or the gyro no longer do; POINTING a
guidance law's reference (:mod:`.pointing`), dumping momentum with the magnetorquers when that is
on (:mod:`.momentum`); PLAN_TRACKING the plan's feedforward plus the PD law (:mod:`.tracking`) for
the plan's duration plus a settle time, then a hold of its final attitude, or the hand-over to a
pointing law at its end. The wheel laws share one PD law (:mod:`.pd`) and one realisation by the
wheels (:mod:`.wheels`). While a law or a plan is followed, the active checks add their patterns:
the coils' dipole with its torque fed forward to the wheels (:mod:`.coil_check`) and the wheels'
null-space excitation (:mod:`.wheel_check`).

:func:`step_controllers` steps several controllers at once (the runs of a Monte Carlo task): the
tracking law of those flying it through the wheels is evaluated as rows of runs, one evaluation per
group of one :func:`tracking_law`; :meth:`Controller.step <.controller.Controller.step>` is that
step of one controller.
"""
from __future__ import annotations

import math
from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np

from att_msgs_py.errors import RequestError
from att_msgs_py.types import (
    Command,
    ControlKind,
    ControllerStatus,
    ControlMode,
    Health,
    ManeuverFeedback,
    ManeuverResult,
    State,
)
from att_planner.control import momentum, safe, tracking, wheels
from att_planner.control.coil_check import feedforward
from att_planner.control.magnetorquer import dipole_command
from att_planner.control.pointing import handover_law, law_reference, pointing_torque
from att_planner.control.wheel_check import excite
from att_planner.guidance import Reference, at_rest, stack
from att_planner.guidance.modes import law_of
from att_sim.models import rotations as rot

if TYPE_CHECKING:
    from att_planner.control.controller import Controller


@dataclass
class StepOutput:
    """What one control instant produces."""

    command: Command
    status: ControllerStatus
    feedback: ManeuverFeedback | None = None
    result: ManeuverResult | None = None       # the maneuver that ended at this step


USABLE = (Health.CONVERGED, Health.PROPAGATING)   # estimates the attitude laws may fly on


def step_controllers(controllers: list[Controller], cancel_requested: list[bool] | None = None) -> list[StepOutput]:
    """Step each controller (at its latest state; ``cancel_requested``: per controller, default
    none) as it steps alone; the tracking law of those flying it through the wheels is evaluated
    as rows, one evaluation per group of controllers of one :func:`tracking_law`
    (the runs of a Monte Carlo task: one nominal model, the same gains)."""
    cancel = [False] * len(controllers) if cancel_requested is None else cancel_requested
    refs = [tracking_reference(c) for c in controllers]
    tracked: list[np.ndarray | None] = [None] * len(controllers)
    waiting = [i for i, (c, ref) in enumerate(zip(controllers, refs)) if ref is not None and tracks_body_torque(c)]
    while waiting:
        first = controllers[waiting[0]]
        law = tracking_law(first)
        group = [i for i in waiting if tracking_law(controllers[i]) == law]
        rows = tracking_command(first, [controllers[i].state for i in group], stack([refs[i] for i in group]))
        for i, row in zip(group, rows):
            tracked[i] = row
        waiting = [i for i in waiting if tracked[i] is None]
    return [step_with(c, k, ref, u) for c, k, ref, u in zip(controllers, cancel, refs, tracked)]


def tracking_reference(ctl: Controller) -> Reference | None:
    """The reference ``ctl``'s next step's plan tracking flies about (the plan's now, its torque the
    mean over the control period the command is held for; or the held attitude), None when it
    flies none."""
    if ctl.mode != ControlMode.PLAN_TRACKING:
        return None
    if ctl.maneuver is not None:
        return ctl.references(ctl.maneuver.plan, ctl.state.t - ctl.maneuver.t0, ctl.config.control_period)
    return at_rest(ctl.hold_q_RN) if ctl.hold_q_RN is not None else None


def tracks_body_torque(ctl: Controller) -> bool:
    """Whether ``ctl``'s next command is the tracking law realised by the wheels (a plan of body
    torques, or the hold after a maneuver; a plan of wheel torques feeds its torques forward)."""
    m = ctl.maneuver
    return m is None or m.plan.control_kind != ControlKind.WHEEL_TORQUE


def tracking_law(ctl: Controller) -> tuple:
    """What ``ctl``'s tracking law depends on besides the state and the reference: the model (the
    object), gains, null-space control and friction compensation. Controllers of one law
    evaluate it as rows (:func:`step_controllers`)."""
    k = ctl.config
    return (id(ctl.spacecraft), k.tracking_kp, k.tracking_kd, k.null_space_speed, k.null_space_gain, ctl.friction,
            ctl.healthy)


def tracking_command(ctl: Controller, states: list[State], ref: Reference) -> np.ndarray:
    """Wheel torques (rows) of ``ctl``'s tracking law for rows of ``states`` about the rows of
    ``ref``: :func:`~.tracking.tracking_torque` through :func:`~.wheels.wheel_command`."""
    sc, c = ctl.spacecraft, ctl.config
    omega_BN_B = np.array([s.omega for s in states])
    torque_B = tracking.tracking_torque(np.array([s.q for s in states]), omega_BN_B, ref, c.tracking_kp,
                                        c.tracking_kd)
    return wheels.wheel_command(sc, torque_B, omega_BN_B, np.array([s.wheel_speeds for s in states]),
                                c.null_space_speed, c.null_space_gain, ctl.friction, healthy=ctl.healthy)


def step_with(ctl: Controller, cancel_requested: bool, ref: Reference | None,
              tracked: np.ndarray | None) -> StepOutput:
    """The step of :func:`step_controllers` once the tracking law is evaluated: ``ref`` from
    :func:`tracking_reference`, ``tracked`` its wheel torques (when :func:`tracks_body_torque`)."""
    s = ctl.state
    cmd = Command(mode=ctl.mode, wheel_torques=np.zeros(ctl.spacecraft.n_wheels), t=s.t,
                  frame_id=ctl.body_frame_id)
    status = ControllerStatus(mode=ctl.mode, t=s.t, frame_id=ctl.body_frame_id)
    out = StepOutput(cmd, status)
    if ctl.mode == ControlMode.MAGNETORQUER_PD:
        blank = ctl.measured is not None and ctl.measured.blank(s.t, ctl.config.control_period)
        if not blank:
            cmd.dipole = dipole_command(s.q, s.omega, s.field_body, ctl.config.kp, ctl.config.kd, ctl.m_max)
    elif ctl.mode == ControlMode.SAFE:
        _safe(ctl, out)
    elif ctl.mode == ControlMode.POINTING and ctl.pointing is not None:
        _point(ctl, out, ctl.pointing)
    elif ctl.mode == ControlMode.PLAN_TRACKING and ctl.maneuver is not None:
        _track(ctl, out, cancel_requested, ref, tracked)
    elif ctl.mode == ControlMode.PLAN_TRACKING and ctl.hold_q_RN is not None:
        cmd.wheel_torques = tracked
        status.message = "holding the final attitude of the last maneuver"
        status.reference_q, status.attitude_error = ctl.hold_q_RN, float(rot.angle_between(s.q, ctl.hold_q_RN))
    # the active checks run while a law or a plan (or its final attitude) is followed
    following = (ctl.mode == ControlMode.POINTING and ctl.pointing is not None
                 or ctl.mode == ControlMode.PLAN_TRACKING
                 and (ctl.maneuver is not None or ctl.hold_q_RN is not None))
    if following and ctl.coil_check is not None and ctl.measured is not None:
        _check_coils(ctl, cmd)
    if following and ctl.wheel_check is not None:
        _check_wheels(ctl, cmd)
    status.dumping = ctl.dumping
    if ctl.measured is not None:
        ctl.measured.dipoles.record(s.t, cmd.dipole)
        ctl.measured.record_command(s.t, cmd.wheel_torques, cmd.dipole)
    return out


def _wheels(ctl: Controller, torque_B: np.ndarray, gyroscopic_speeds: np.ndarray | None = None) -> np.ndarray:
    """Motor torques that put ``torque_B`` on the body at ``ctl``'s latest state (:func:`~.wheels.wheel_command`
    of one row; ``gyroscopic_speeds``: the spin rates the gyroscopic term uses, default the state's)."""
    s, c = ctl.state, ctl.config
    return wheels.wheel_command(ctl.spacecraft, np.asarray(torque_B, float)[None], s.omega[None],
                                s.wheel_speeds[None], c.null_space_speed, c.null_space_gain, ctl.friction,
                                None if gyroscopic_speeds is None else gyroscopic_speeds[None],
                                healthy=ctl.healthy)[0]


def _check_coils(ctl: Controller, cmd: Command) -> None:
    """The active coil check's dipole (:mod:`.coil_check`) in place of the command's, when a check
    sample follows within its dwell: the difference of their magnetic torques fed forward to the
    healthy wheels (clipped at their limit)."""
    s, sc = ctl.state, ctl.spacecraft
    m = ctl.coil_check.dipole(s.t, ctl.config.control_period, ctl.m_max)
    if m is None or not np.any(s.field_body) or not sc.n_wheels:
        return
    A = sc.wheel_axes_pinv if ctl.healthy is None else wheels.healthy_allocation(sc.wheel_axes, ctl.healthy)
    u = np.asarray(cmd.wheel_torques, float) + feedforward(m - np.asarray(cmd.dipole, float), s.field_body, A)
    u = np.clip(u, -sc.wheel_torque_max, sc.wheel_torque_max)
    cmd.wheel_torques = u if ctl.healthy is None else u * np.asarray(ctl.healthy, bool)
    cmd.dipole = m


def _check_wheels(ctl: Controller, cmd: Command) -> None:
    """The active wheel check's null-space torques (:mod:`.wheel_check`) added to the command, scaled
    to the headroom under the wheels' limit; nothing without a null space on the healthy wheels."""
    sc = ctl.spacecraft
    if sc.n_wheels < 4 or cmd.wheel_torques is None:
        return
    delta = ctl.wheel_check.torques(ctl.state.t, sc.wheel_axes, ctl.healthy)
    if delta is not None:
        cmd.wheel_torques = excite(cmd.wheel_torques, delta, sc.wheel_torque_max)


def _point(ctl: Controller, out: StepOutput, law) -> None:
    """Track ``law``'s reference (:func:`~.pointing.pointing_torque`) through the wheels, dumping
    momentum with the magnetorquers when that is on (their torque fed forward to the wheels)."""
    s, sc, c = ctl.state, ctl.spacecraft, ctl.config
    ref = law_reference(law, s.t)
    tau = pointing_torque(sc, s.q, s.omega, ref, c.tracking_kp, c.tracking_kd)
    blank = ctl.measured is not None and ctl.measured.blank(s.t, c.control_period)
    if ctl.dumping and not blank and sc.n_wheels:
        h_wheels_B = sc.wheel_axes @ (sc.wheel_inertia * s.wheel_speeds)
        out.command.dipole = momentum.desaturation_dipole(h_wheels_B, np.zeros(3), s.field_body, c.dumping_gain,
                                                          ctl.m_max)
    out.command.wheel_torques = _wheels(ctl, tau - rot.cross(out.command.dipole, s.field_body))
    st = out.status
    st.guidance, st.reference_q, st.reference_rate = law.name, ref.q_RN, ref.omega_RN_R
    st.attitude_error = float(rot.angle_between(s.q, ref.q_RN))
    if law.degenerate:
        st.message = f"pointing {law.name}: the directions are parallel now; holding the last attitude"


def _safe(ctl: Controller, out: StepOutput) -> None:
    """The safe-mode law (:mod:`.safe`): rate damping; once the rates are below
    ``safe_rate_threshold``, with a Sun to see and an attitude to trust, the safe Sun pointing
    (``safe_sun_axis`` on the Sun, the orbit normal as secondary)."""
    s, c = ctl.state, ctl.config
    act = ctl.safe_actuation(s) if ctl.safe_actuation is not None else None
    if act is not None:             # the healthy wheels or the gyro no longer do: what is left
        if act.on_wheels:
            out.command.wheel_torques = _wheels(ctl, act.torque_B)
        else:
            out.command.dipole = act.dipole_B
        out.status.message = f"safe mode on what is left ({act.law})"
        return
    sun_ok = ctl.guidance_sky is not None and ctl.guidance_sky.sun_N is not None and \
        (ctl.measured is None or ctl.estimate_health in USABLE)
    if not sun_ok or not safe.damped(s.omega, c.safe_rate_threshold):
        out.command.wheel_torques = _wheels(ctl, safe.damping_torque(s.omega, c.safe_kd))
        return
    if ctl.safe_law is None:
        try:
            ctl.safe_law = law_of(safe.sun_mode(c.safe_sun_axis), ctl.guidance_sky, s.t, s.q)
        except RequestError:
            out.command.wheel_torques = _wheels(ctl, safe.damping_torque(s.omega, c.safe_kd))
            return
    _point(ctl, out, ctl.safe_law)


def _track(ctl: Controller, out: StepOutput, cancel_requested: bool, ref: Reference,
           tracked: np.ndarray | None) -> None:
    """One plan-tracking step about ``ref`` (``tracked``: the tracking law's wheel torques):
    command, feedback every ``feedback_period``, the end."""
    s, m, sc = ctl.state, ctl.maneuver, ctl.spacecraft
    plan = m.plan
    elapsed = s.t - m.t0
    if plan.control_kind == ControlKind.WHEEL_TORQUE:
        # the plan's wheel torques as feedforward, PD feedback about its reference states
        fb = tracking.tracking_torque(s.q, s.omega, ref, ctl.config.tracking_kp, ctl.config.tracking_kd,
                                      feedforward=False)
        u = ref.torque_R + _wheels(ctl, fb, np.zeros(sc.n_wheels))
        u = np.clip(u, -sc.wheel_torque_max, sc.wheel_torque_max)
        if ctl.healthy is not None:
            u = u * np.asarray(ctl.healthy, bool)
    else:
        u = tracked
    out.command.wheel_torques = u
    out.command.plan_id = out.status.plan_id = plan.plan_id
    m.ticks += 1
    if m.ticks % ctl.config.feedback_every == 0:
        span = max(plan.duration + ctl.config.settle_time, 1e-9)
        out.feedback = ManeuverFeedback(
            elapsed=float(elapsed), progress=float(min(1.0, max(0.0, elapsed) / span)),
            attitude_error=float(rot.angle_between(s.q, ref.q_RN)),
            min_cone_margin=float(m.zones.margins(s.t, s.q, true=True).min()) if m.zones else math.inf)
    if cancel_requested:
        out.result = ctl.abort("cancelled")
        return
    out.status.plan_progress = float(min(1.0, max(0.0, elapsed) / max(plan.duration, 1e-9)))
    out.status.reference_q, out.status.reference_rate = ref.q_RN, ref.omega_RN_R
    out.status.attitude_error = float(rot.angle_between(s.q, ref.q_RN))
    if m.after is not None and elapsed >= plan.duration:
        # the law takes over at this step: its reference, not the plan's held past its end
        law = handover_law(m.after, plan, m.t0 + plan.duration, s.t, ctl.config.handover_blend)
        out.result = ctl.complete(f"maneuver complete; pointing {law.name}", law)
        out.command.mode = out.status.mode = ControlMode.POINTING
        _point(ctl, out, law)
        out.status.message = f"maneuver complete; pointing {law.name}"
        return
    if elapsed >= plan.duration + ctl.config.settle_time:
        out.result = ctl.complete("maneuver complete")
        out.status.message = "maneuver complete; holding the final attitude"
