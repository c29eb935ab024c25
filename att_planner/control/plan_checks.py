"""What the controller checks before it keeps or flies a plan (no ROS).

:func:`check_plan` looks at every field of a received plan (cached from ``/planner/plans`` or
inline in an ``ExecuteManeuver`` goal), and :func:`check_message` at the message's ``duration``
before conversion: sizes and lengths against each other, finiteness, unit
quaternions, times from 0 strictly increasing and bounded, controls within the spacecraft's
limits, known vocabularies, bounded strings, its zones (:func:`att_msgs_py.validation.zone`: known
body, unit axes, half-angle range, an inertial zone's direction) and its epoch (within
:mod:`att_sim.models.epoch`'s span; needed by a zone that moves); then its context: made for this spacecraft
configuration (name and :attr:`~att_sim.models.dynamics.Spacecraft.digest`) and signed by the configured
key (:mod:`att_msgs_py.signing`). :func:`check_start` compares a plan's first sample with the
current state, and the epoch of a plan with moving zones with the current instant (the scenario's
epoch + sim time; UTC arithmetic, a leap second in between is a second off); :func:`plan_start`
when a plan onto a moving goal starts (its own clock). Each returns ``None`` (:func:`plan_start`: the
start's sim time) or a :class:`RequestError` (code and sentence).
"""
from __future__ import annotations

import math
from dataclasses import dataclass
from datetime import datetime, timedelta

import numpy as np

from att_msgs_py import signing, validation
from att_msgs_py.errors import ErrorCode, RequestError
from att_msgs_py.limits import MAX_CONES, MAX_ZONES
from att_msgs_py.types import POINTING_KINDS, ControlKind, Interpolation, Plan, State, Status
from att_msgs_py.validation import UNIX_EPOCH
from att_planner.control import pd
from att_sim.models import epoch as epochs
from att_sim.models import rotations as rot
from att_sim.models.dynamics import Spacecraft

LIMIT_TOLERANCE = 1e-6       # relative: plan controls may touch their limit, not exceed it
MAX_PLAN_RATE = 10.0         # rad/s, any body axis: beyond it a plan is not a slew
DURATION_TOLERANCE = 1e-9   # relative: a plan's stated duration against the span of its times


@dataclass(frozen=True)
class PlanContext:
    """What a plan must match: the controller's spacecraft, frames and key, and the start tolerances."""

    spacecraft: Spacecraft
    spacecraft_name: str
    frame_id: str
    public_key: object                      # Ed25519PublicKey
    max_start_attitude_error: float = math.radians(5.0)   # rad
    max_start_rate_error: float = 0.01                    # rad/s
    epoch: datetime | None = None           # the scenario's (sim time zero); None: no sky to check against
    max_start_epoch_error: float = 10.0     # s: a LEO Earth limb moves 0.7 deg in it (orbit rate)


def _fields(plan: Plan, sc: Spacecraft, frame_id: str) -> Plan:
    """The plan with checked arrays (quaternions normalised); raises RequestError."""
    code = ErrorCode.INVALID_PLAN
    for name, value, limit in (("plan_id", plan.plan_id, validation.MAX_NAME_LENGTH),
                               ("method", plan.method, validation.MAX_NAME_LENGTH),
                               ("spacecraft", plan.spacecraft, validation.MAX_NAME_LENGTH),
                               ("header.frame_id", plan.frame_id, validation.MAX_NAME_LENGTH),
                               ("message", plan.message, validation.MAX_TEXT_LENGTH)):
        validation.text(value, f"plan.{name}", max_length=limit)
    if not plan.plan_id:
        raise RequestError(code, "plan.plan_id is empty")
    if plan.frame_id != frame_id:
        raise RequestError(ErrorCode.INVALID_FRAME,
                           f"plan.header.frame_id '{plan.frame_id}' is not the controller's frame '{frame_id}'")
    if plan.status not in tuple(Status) or plan.status == Status.FAILED:
        raise RequestError(code, f"plan.status '{plan.status}' is not one a plan can be flown with "
                                 f"({', '.join(s for s in Status if s != Status.FAILED)})")
    if plan.control_kind not in tuple(ControlKind):
        raise RequestError(code, f"plan.control_kind '{plan.control_kind}' is not one of {', '.join(ControlKind)}")
    if plan.interpolation not in tuple(Interpolation):
        raise RequestError(code, f"plan.interpolation '{plan.interpolation}' is not one of {', '.join(Interpolation)}")
    k = len(plan.t)
    if k > validation.MAX_PLAN_SAMPLES:
        raise RequestError(ErrorCode.SIZE_LIMIT, f"plan.times has {k} samples; at most {validation.MAX_PLAN_SAMPLES}")
    if k < 2:
        raise RequestError(code, f"plan.times has {k} samples; a plan needs at least 2")
    for name, a in (("attitudes", plan.q), ("rates", plan.omega), ("torques", plan.torque)):
        if len(a) != k:
            raise RequestError(code, f"plan.{name} has {len(a)} entries for {k} times")
    validation.number(plan.wall_time, "plan.solve_seconds", code, 0.0)
    t = validation.finite_array(plan.t, "plan.times", code, (-1,))
    if t[0] != 0.0:
        raise RequestError(code, f"plan.times[0] = {t[0]!r}; a plan starts at 0")
    step = np.diff(t)
    if np.any(step <= 0):
        i = int(np.flatnonzero(step <= 0)[0])
        raise RequestError(code, f"plan.times do not increase at index {i + 1} ({t[i]!r} then {t[i + 1]!r})")
    if t[-1] > validation.MAX_PLAN_DURATION:
        raise RequestError(code, f"plan duration {t[-1]:.6g} s is above {validation.MAX_PLAN_DURATION:g} s")
    q = validation.unit_quaternions(plan.q, "plan.attitudes", code)
    omega = validation.finite_array(plan.omega, "plan.rates", code, (-1, 3))
    if np.max(np.abs(omega)) > MAX_PLAN_RATE:
        raise RequestError(code, f"plan.rates reach {np.max(np.abs(omega)):.6g} rad/s; at most {MAX_PLAN_RATE} rad/s")
    torque = validation.finite_array(plan.torque, "plan.torques", code, (-1, 3))
    if plan.control_kind == ControlKind.WHEEL_TORQUE:
        if sc.n_wheels != 3:
            raise RequestError(code, f"a wheel_torque plan carries 3 wheels; this spacecraft has {sc.n_wheels}")
        limit, what = sc.wheel_torque_max, "wheel_torque_max"
    else:
        limit, what = sc.body_torque_max, "torque_max"
    peak = float(np.max(np.abs(torque)))
    if peak > limit * (1 + LIMIT_TOLERANCE):
        raise RequestError(code, f"plan.torques reach {peak:.6g} N m, above the spacecraft's {what} {limit:.6g} N m")
    axis = validation.unit_vector(plan.sensor_axis, "plan.sensor_axis", code)
    if len(plan.cones) > MAX_CONES:
        raise RequestError(ErrorCode.SIZE_LIMIT, f"plan.cones has {len(plan.cones)} cones; at most {MAX_CONES}")
    for i, c in enumerate(plan.cones):
        validation.text(c.name, f"plan.cones[{i}].name")
        validation.unit_vector(c.direction, f"plan.cones[{i}].direction", code)
        if not (math.isfinite(c.half_angle) and 0.0 < c.half_angle < math.pi / 2):
            raise RequestError(code, f"plan.cones[{i}].half_angle = {c.half_angle!r} rad is outside (0, pi/2)")
    goal = "" if plan.verification is None else plan.verification.goal
    validation.text(goal, "plan.verification.goal", max_length=validation.MAX_NAME_LENGTH)
    if goal not in ("", "moving", *POINTING_KINDS):
        raise RequestError(code, f"plan.verification.goal '{goal}' is not a pointing kind "
                                 f"({', '.join(POINTING_KINDS)}), 'moving' or empty")
    plan.zones, plan.epoch = _zones(plan)
    plan.t, plan.q, plan.omega, plan.torque, plan.sensor_axis = t, q, omega, torque, axis
    return plan


def _zones(plan: Plan) -> tuple[list, datetime | None]:
    """The plan's zones checked and normalised, and its epoch (None, or a UTC ``datetime`` within
    the ephemeris span; a moving zone needs one)."""
    code = ErrorCode.INVALID_PLAN
    if len(plan.zones) > MAX_ZONES:
        raise RequestError(ErrorCode.SIZE_LIMIT, f"plan.zones has {len(plan.zones)} zones; at most {MAX_ZONES}")
    zones = [validation.zone(z, f"plan.zones[{i}]", code) for i, z in enumerate(plan.zones)]
    epoch = plan.epoch
    if epoch is not None:
        if not isinstance(epoch, datetime):
            raise RequestError(code, f"plan.epoch must be a UTC datetime or none, got {type(epoch).__name__}")
        try:
            epoch = epochs.parse_epoch(epoch, "plan.epoch")
        except ValueError as err:
            raise RequestError(code, str(err)) from None
    moving = next((i for i, z in enumerate(zones) if z.body != "inertial"), None)
    if moving is not None and epoch is None:
        raise RequestError(code, f"plan.zones[{moving}] ('{zones[moving].name}') moves with the sky (body "
                                 f"{zones[moving].body}) but plan.epoch is zero: a moving zone needs the epoch")
    return zones, epoch


def check_message(msg) -> RequestError | None:
    """Why a ``ManeuverPlan`` message (published or inline) contradicts itself in a field that
    :class:`~att_msgs_py.types.Plan` does not carry: its ``duration`` must be finite and equal to
    ``times[-1] - times[0]`` (relative tolerance :data:`DURATION_TOLERANCE`). Checked before the
    message is converted; :func:`check_plan` checks the rest."""
    times = msg.times
    if not 0 < len(times) <= validation.MAX_PLAN_SAMPLES:
        return None                                   # check_plan refuses the sample count
    span = float(times[-1]) - float(times[0])
    stated = float(msg.duration)
    if not (math.isfinite(stated) and math.isfinite(span)
            and abs(stated - span) <= DURATION_TOLERANCE * max(1.0, abs(span))):
        return RequestError(ErrorCode.INVALID_PLAN,
                            f"plan.duration = {stated!r} s contradicts plan.times, which span {span!r} s "
                            f"(from {float(times[0])!r} to {float(times[-1])!r})")
    return None


def check_plan(plan: Plan, payload: bytes, ctx: PlanContext) -> RequestError | None:
    """Why ``plan`` (whose signed bytes are ``payload``) may not be kept or flown; None when it may.
    On success the plan's arrays are the checked ones (quaternions normalised)."""
    if len(payload) > validation.MAX_PLAN_BYTES:
        return RequestError(ErrorCode.SIZE_LIMIT, f"the plan message has {len(payload)} bytes; at most "
                                                  f"{validation.MAX_PLAN_BYTES}")
    try:
        _fields(plan, ctx.spacecraft, ctx.frame_id)
    except RequestError as err:
        return err.with_traceback(None)          # its frames hold the refused plan's arrays
    if plan.spacecraft != ctx.spacecraft_name or plan.spacecraft_digest != ctx.spacecraft.digest:
        which = "name" if plan.spacecraft != ctx.spacecraft_name else "physical parameters (digest)"
        return RequestError(ErrorCode.WRONG_SPACECRAFT,
                            f"plan '{plan.plan_id}' was made for spacecraft '{plan.spacecraft}', not for this "
                            f"controller's '{ctx.spacecraft_name}' (the {which} differ)")
    why = signing.check(payload, plan.signature, plan.key_id, ctx.public_key)
    if why is not None:
        return RequestError(ErrorCode.PLAN_NOT_AUTHENTIC, f"plan '{plan.plan_id}': {why}")
    return None


def check_start(plan: Plan, state: State, ctx: PlanContext) -> RequestError | None:
    """Why ``plan`` cannot start from ``state`` (its first attitude or rate, in the plan's reference axes, too far
    away)."""
    angle = rot.angle_between(state.q, plan.q[0])
    if angle > ctx.max_start_attitude_error:
        return RequestError(ErrorCode.PLAN_CONTEXT,
                            f"plan '{plan.plan_id}' starts {math.degrees(angle):.2f} deg from the current attitude "
                            f"(at most {math.degrees(ctx.max_start_attitude_error):.2f} deg, parameter "
                            "max_start_attitude_error_deg)")
    q_BR = pd.relative_attitude(state.q, plan.q[0])          # the rate error ω_BN_B − [BR] ω_RN_R
    rate_error = float(np.linalg.norm(state.omega - pd.to_body(q_BR, plan.omega[0])))
    if rate_error > ctx.max_start_rate_error:
        return RequestError(ErrorCode.PLAN_CONTEXT,
                            f"plan '{plan.plan_id}' starts at a rate {rate_error:.4g} rad/s from the current one "
                            f"(at most {ctx.max_start_rate_error:g} rad/s, parameter max_start_rate_error_rad_s)")
    moving = any(z.body != "inertial" for z in plan.zones)
    if moving and ctx.epoch is not None and plan.epoch is not None:
        now = ctx.epoch + timedelta(seconds=float(state.t))
        lag = (now - plan.epoch).total_seconds()
        if abs(lag) > ctx.max_start_epoch_error:
            when = f"{abs(lag):.1f} s {'later' if lag > 0 else 'earlier'}"
            return RequestError(ErrorCode.PLAN_CONTEXT,
                                f"plan '{plan.plan_id}' avoids moving zones as they are from "
                                f"{epochs.format_epoch(plan.epoch)}, but it would start at {epochs.format_epoch(now)}, "
                                f"{when} (at most {ctx.max_start_epoch_error:g} s, "
                                "parameter max_start_epoch_error_s): request it with the start epoch")
    return None


def plan_start(plan: Plan, state: State, ctx: PlanContext) -> float | RequestError:
    """The sim time ``plan`` starts from when it starts at ``state``: now, or for a plan onto a moving
    goal (``verification.goal``), which meets it at its planned instant only, that instant (its
    epoch; sim time 0 without one): such a plan runs on its own clock, the steps between that instant
    and now flown from then (before it, its first attitude is held). Why not, when that instant is
    more than ``max_start_epoch_error`` s from now."""
    goal = plan.verification.goal if plan.verification is not None else ""
    if not goal:
        return float(state.t)
    t0 = 0.0 if plan.epoch is None else (plan.epoch - (ctx.epoch or UNIX_EPOCH)).total_seconds()
    lag = float(state.t) - t0
    if abs(lag) > ctx.max_start_epoch_error:
        return RequestError(ErrorCode.PLAN_CONTEXT,
                            f"plan '{plan.plan_id}' ends on a moving {goal} goal at its planned instant, sim time "
                            f"{t0:.3f} s; it would start {abs(lag):.1f} s {'later' if lag > 0 else 'earlier'} (at "
                            f"most {ctx.max_start_epoch_error:g} s, parameter max_start_epoch_error_s)")
    return t0
