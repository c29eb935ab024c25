"""Independent verification of a plan: integrate its controls through the truth dynamics.

Every plan the planner returns carries these figures; nothing is taken from the planner's own
model. The integration is :func:`att_sim.dynamics.simulate_profile` (RK4, inputs switched exactly
at the knots for zero-order hold), from the request's initial attitude at rest.
"""
from __future__ import annotations

from dataclasses import asdict, dataclass

import numpy as np

from att_planner.cones import Cone, margins
from att_sim import dynamics as dyn
from att_sim import rotations as rot


@dataclass
class Verification:
    final_attitude_error: float      # rad, angle between reached and goal attitude
    final_rate: float                # rad/s, ‖ω(t_f)‖
    min_cone_margin: float           # rad over the dense grid (+inf without cones)
    cone_margins: list               # rad, minimum per cone
    torque_ratio: float              # max |u_j| / limit over the samples
    wheel_speed_ratio: float         # max |Ω_j| / limit over the dense grid (0 without wheels)
    rate_max: float                  # rad/s, max ‖ω‖ over the dense grid
    duration: float                  # s
    dense_samples: int

    def as_dict(self) -> dict:
        return asdict(self)

    def passes(self, attitude_tol: float, rate_tol: float, margin_tol: float = 0.0,
               ratio_tol: float = 1.0 + 1e-9) -> bool:
        return (self.final_attitude_error <= attitude_tol and self.final_rate <= rate_tol
                and self.min_cone_margin >= -margin_tol and self.torque_ratio <= ratio_tol
                and self.wheel_speed_ratio <= ratio_tol)


def verify_profile(
    sc: dyn.Spacecraft,
    q0: np.ndarray,
    q_goal: np.ndarray,
    t: np.ndarray,
    controls: np.ndarray,
    *,
    kind: str = "body_torque",
    interpolation: str = "zoh",
    sensor_axis: np.ndarray = (1.0, 0.0, 0.0),
    cones: list[Cone] = (),
    torque_limit: float | None = None,
    dense_step: float | None = None,
    omega0=(0.0, 0.0, 0.0),
    wheel_speed0=None,
) -> tuple[Verification, dyn.Trajectory]:
    """Integrate ``controls`` sampled at ``t`` and measure the plan against its request.

    ``torque_limit`` defaults to the spacecraft's limit for the control kind.
    """
    t = np.asarray(t, float)
    controls = np.asarray(controls, float).reshape(len(t), -1)
    x0 = dyn.initial_state(sc, q0, omega0, wheel_speed0)
    traj = dyn.simulate_profile(sc, x0, t, controls, kind=kind, interpolation=interpolation, max_step=dense_step)
    if torque_limit is None:
        torque_limit = sc.body_torque_max if kind == "body_torque" else sc.wheel_torque_max
    # For ZOH the last sample is never applied (it holds over an empty interval).
    applied = controls[:-1] if interpolation == "zoh" and len(controls) > 1 else controls
    torque_ratio = float(np.abs(applied).max() / torque_limit) if np.isfinite(torque_limit) and applied.size else 0.0
    m = margins(traj.q, sensor_axis, list(cones))
    wheel_ratio = 0.0
    if traj.wheel_speed.size and np.isfinite(sc.wheel_speed_max):
        wheel_ratio = float(np.abs(traj.wheel_speed).max() / sc.wheel_speed_max)
    ver = Verification(
        final_attitude_error=float(rot.angle_between(traj.q[-1], q_goal)),
        final_rate=float(np.linalg.norm(traj.omega[-1])),
        min_cone_margin=float(m.min()) if m.size else float("inf"),
        cone_margins=[float(v) for v in m.min(axis=0)] if m.size else [],
        torque_ratio=torque_ratio,
        wheel_speed_ratio=wheel_ratio,
        rate_max=float(np.linalg.norm(traj.omega, axis=1).max()),
        duration=float(t[-1] - t[0]),
        dense_samples=len(traj.t),
    )
    return ver, traj
