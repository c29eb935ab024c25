"""Controllers of lockstep Monte Carlo runs stepping together (no ROS).

At a control instant the runs of a Monte Carlo task each step their controller. Those tracking a
plan's body-torque reference compute the same law — the quaternion PD about the reference and its
realisation by the wheels (:meth:`Controller._wheel_command
<att_planner.control.controller.Controller._wheel_command>`) — on their own state.
:func:`track_together` computes it for the controllers of one law (one nominal model, the same
gains: :func:`law`) as rows of runs, each row to the bits the controller computes alone, and hands
each its wheel torques (:meth:`Controller.prepare
<att_planner.control.controller.Controller.prepare>`); the controllers then step as they would alone.
"""
from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np

from att_msgs_py.types import ControlKind, ControlMode
from att_planner.control import momentum, tracking

if TYPE_CHECKING:
    from att_planner.control.controller import Controller


def tracked_reference(c: Controller) -> tracking.Reference | None:
    """The reference ``c``'s next step feeds to its tracking law (:meth:`Controller._wheel_command
    <att_planner.control.controller.Controller._wheel_command>`: a plan of body torques being
    flown), None when it does not."""
    m = c.maneuver
    if c.mode != ControlMode.PLAN_TRACKING or m is None or m.plan.control_kind == ControlKind.WHEEL_TORQUE:
        return None
    return c.references(m.plan, c.state.t - m.t0)


def law(c: Controller) -> tuple:
    """What ``c``'s tracking law depends on besides the state and the reference: its model (the
    object), gains and friction compensation. Controllers of one law compute it as rows."""
    k = c.config
    return id(c.spacecraft), k.tracking_kp, k.tracking_kd, k.null_space_speed, k.null_space_gain, c.friction


def track_together(controllers: list[Controller]) -> None:
    """Prepare the tracking law's wheel torques of the controllers about to step that track a plan
    and share the first one's :func:`law` (the others compute theirs alone, as does a group of one)."""
    tracking_now = [(c, ref) for c in controllers if (ref := tracked_reference(c)) is not None]
    if not tracking_now:
        return
    first_law = law(tracking_now[0][0])
    group = [(c, ref) for c, ref in tracking_now if law(c) == first_law]
    if len(group) < 2 or not group[0][0].spacecraft.n_wheels:
        return
    first, states = group[0][0], [c.state for c, _ in group]
    sc, config = first.spacecraft, first.config
    omega = np.array([s.omega for s in states])
    speeds = np.array([s.wheel_speeds for s in states])
    refs = [ref for _, ref in group]
    stacked = tracking.Reference(np.array([r.q for r in refs]), np.array([r.omega for r in refs]),
                                 np.array([r.torque for r in refs]))
    body = tracking.tracking_torque(np.array([s.q for s in states]), omega, stacked, config.tracking_kp,
                                    config.tracking_kd)
    extra = momentum.null_space_torques(sc, speeds, config.null_space_speed, config.null_space_gain)
    if first.friction is not None:
        extra = extra + first.friction(speeds - tracking.matvec_rows(sc.wheel_axes.T, omega))
    torques = tracking.wheel_torques_of_runs(sc, body, omega, speeds, extra)
    for (c, ref), u in zip(group, torques):
        c.prepare(ref, u)
