"""The tracking law on rows of runs (att_planner.control.lockstep): each row gets the bits the
controller computes alone — the PD about the reference, the null-space torques, the drive friction
compensated, the wheels' distribution and its scaling to the torque limit."""
import numpy as np
import pytest

from att_planner.control import momentum, tracking
from att_sim import rotations as rot
from att_sim import scenario


@pytest.mark.parametrize("name", ["swift_demo", "leo_momentum"])     # 3 wheels; 4 (a null space)
def test_the_law_on_rows_gives_each_run_the_bits_it_gets_alone(name):
    s = scenario.load(name)
    sc, rng, runs = s.spacecraft, np.random.default_rng(16), 40
    wheels = s.actuators.wheels if s.actuators is not None else None
    friction = wheels.friction if wheels is not None else (lambda v: 0.01 * np.tanh(v))
    size = np.where(np.arange(runs) % 2, 1.0, 1e-3)[:, None]       # every other run within the torque limit
    q = rot.normalize(rng.standard_normal((runs, 4)))
    ref_q = rot.normalize(q + size * 0.05 * rng.standard_normal((runs, 4)))
    omega, ref_omega = size * 0.02 * rng.standard_normal((runs, 3)), size * 0.02 * rng.standard_normal((runs, 3))
    ref_torque = size * 0.05 * rng.standard_normal((runs, 3))
    speeds = 0.5 * sc.wheel_speed_max * rng.standard_normal((runs, sc.n_wheels))
    gains = (1.0, 16.0)
    body = tracking.tracking_torques_of_runs(q, omega, ref_q, ref_omega, ref_torque, *gains)
    extra = momentum.null_space_torques(sc, speeds, 3.0, 0.05) + \
        friction(speeds - tracking.matvec_rows(sc.wheel_axes.T, omega))
    rows = tracking.wheel_torques_of_runs(sc, body, omega, speeds, extra)
    scaled = 0
    for i in range(runs):
        ref = tracking.Reference(ref_q[i], ref_omega[i], ref_torque[i])
        tau = tracking.tracking_torque(q[i], omega[i], ref, *gains)
        alone_extra = momentum.null_space_torques(sc, speeds[i], 3.0, 0.05) + \
            friction(speeds[i] - sc.wheel_axes.T @ omega[i])
        alone = tracking.wheel_torques(sc, tau, omega[i], speeds[i], alone_extra)
        assert body[i].tobytes() == tau.tobytes() and extra[i].tobytes() == alone_extra.tobytes()
        assert rows[i].tobytes() == alone.tobytes(), i
        demand = tau + rot.cross(omega[i], sc.wheel_axes @ (sc.wheel_inertia * speeds[i]))
        scaled += bool(np.abs(sc.wheel_axes_pinv @ demand).max() > sc.wheel_torque_max)
    assert 0 < scaled < runs
