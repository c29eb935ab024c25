"""Truth dynamics: conservation laws, quaternion norm, momentum exchange with wheels."""
import numpy as np
import pytest

from att_sim.models import dynamics as dyn
from att_sim.models import rotations as rot
from att_sim.models.environment import OrbitParams

ORBIT_PERIOD = OrbitParams().period


def test_torque_free_conserves_energy_and_momentum_over_ten_orbits():
    sc = dyn.Spacecraft(inertia=np.diag([27.0, 17.0, 25.0]))
    x = dyn.initial_state(sc, rot.from_axis_angle([1, 2, 3], 0.7), [0.01, -0.02, 0.015])
    e0, h0 = dyn.kinetic_energy(sc, x), dyn.angular_momentum_N(sc, x)
    dt = 1.0
    steps = int(10 * ORBIT_PERIOD / dt)
    inputs = dyn.Inputs()
    for _ in range(steps):
        x = dyn.step(sc, x, inputs, dt)
    assert abs(dyn.kinetic_energy(sc, x) - e0) / e0 < 1e-9
    assert np.linalg.norm(dyn.angular_momentum_N(sc, x) - h0) / np.linalg.norm(h0) < 1e-9
    assert abs(np.linalg.norm(x[:4]) - 1.0) < 1e-12


def test_spinning_wheels_torque_free_conserve_energy_and_momentum():
    sc = dyn.Spacecraft(inertia=np.diag([10.0, 12.0, 14.0]), wheel_inertia=0.05)
    x = dyn.initial_state(sc, rot.IDENTITY, [0.01, -0.02, 0.03], wheel_speed=[100.0, -50.0, 20.0])
    e0, h0 = dyn.kinetic_energy(sc, x), dyn.angular_momentum_N(sc, x)
    for _ in range(5000):
        x = dyn.step(sc, x, dyn.Inputs(wheel_torque=np.zeros(3)), 0.05)
    assert abs(dyn.kinetic_energy(sc, x) - e0) / e0 < 1e-9
    assert np.linalg.norm(dyn.angular_momentum_N(sc, x) - h0) / np.linalg.norm(h0) < 1e-9


def test_wheels_exchange_momentum_without_changing_the_total():
    sc = dyn.Spacecraft(inertia=np.diag([10.0, 12.0, 14.0]), wheel_inertia=0.02, wheel_torque_max=0.5)
    x = dyn.initial_state(sc, rot.IDENTITY, [0.01, 0.0, -0.01])
    h0 = dyn.angular_momentum_N(sc, x)
    for k in range(2000):
        u = 0.05 * np.array([np.sin(0.01 * k), np.cos(0.02 * k), 0.3])
        x = dyn.step(sc, x, dyn.Inputs(wheel_torque=u), 0.05)
    assert np.linalg.norm(dyn.angular_momentum_N(sc, x) - h0) < 1e-10 * 1e3


def test_wheel_only_slew_turns_the_body_by_the_momentum_exchange_angle():
    """Spin the z wheel up then down (zero total momentum): the body turns by −I_w ∫Ω dt / J_z."""
    jz, iw = 20.0, 0.05
    sc = dyn.Spacecraft(inertia=np.diag([15.0, 18.0, jz]), wheel_inertia=iw, wheel_torque_max=1.0)
    x = dyn.initial_state(sc)
    dt, integral = 0.01, 0.0
    for k in range(2000):
        u = np.array([0.0, 0.0, 0.2 if k < 1000 else -0.2])
        x_new = dyn.step(sc, x, dyn.Inputs(wheel_torque=u), dt)
        integral += 0.5 * (x[9] + x_new[9]) * dt
        x = x_new
    expected = -iw * integral / jz
    axis, angle = rot.to_axis_angle(x[:4])
    assert abs(x[9]) < 1e-9 and np.linalg.norm(x[4:7]) < 1e-12
    assert axis[2] * angle == pytest.approx(expected, rel=1e-6)
    assert abs(expected) > 0.5           # a real slew, not a rounding error


def test_saturated_wheel_cannot_accelerate_further():
    sc = dyn.Spacecraft(inertia=np.eye(3) * 5, wheel_inertia=0.01, wheel_torque_max=0.1, wheel_speed_max=100.0)
    x = dyn.initial_state(sc, wheel_speed=[0.0, 0.0, 100.0])
    u = dyn.effective_wheel_torque(sc, x[7:], [0.1, 0.1, 0.1], x[4:7])
    assert u.tolist() == [0.1, 0.1, 0.0]
    assert dyn.effective_wheel_torque(sc, x[7:], [0, 0, -0.1], x[4:7])[2] == -0.1


def test_bang_bang_eigenaxis_profile_reaches_the_goal():
    sc = dyn.Spacecraft(inertia=np.eye(3), body_torque_max=1.0)
    half = np.sqrt(np.pi)
    traj = dyn.simulate_profile(sc, dyn.initial_state(sc), [0, half, 2 * half], [[0, 0, 1], [0, 0, -1], [0, 0, 0]])
    assert rot.angle_between(traj.q_BN[-1], rot.from_axis_angle([0, 0, 1], np.pi)) < 1e-5
    assert np.linalg.norm(traj.omega_BN_B[-1]) < 1e-12


def test_wheel_speed_limit_is_on_the_speed_relative_to_the_body():
    """Ω is the inertial spin rate; the drive limits Ω − Gᵀω (here ω_z = ±0.5 rad/s, Ω_z = 100)."""
    sc = dyn.Spacecraft(inertia=np.eye(3) * 5, wheel_inertia=0.01, wheel_torque_max=0.1, wheel_speed_max=100.0)
    u = [0.0, 0.0, 0.1]
    np.testing.assert_allclose(dyn.relative_wheel_speed(sc, [0, 0, 100.0], [0, 0, 0.5]), [0, 0, 99.5])
    assert dyn.effective_wheel_torque(sc, [0, 0, 100.0], u, [0, 0, 0.5])[2] == 0.1     # 99.5 relative: free
    assert dyn.effective_wheel_torque(sc, [0, 0, 99.8], u, [0, 0, -0.5])[2] == 0.0     # 100.3 relative: cut
    # in the dynamics: the body spins at +0.5 rad/s about z, the wheel is driven from Ω = 99 (98.5
    # relative): it is cut at 100 relative to the body, Ω ≈ 100.5 (an inertial limit would stop it at 100)
    x = dyn.initial_state(sc, omega_BN_B=[0, 0, 0.5], wheel_speed=[0, 0, 99.0])
    for _ in range(400):
        x = dyn.step(sc, x, dyn.Inputs(wheel_torque=np.array(u)), 0.01)
    rel = dyn.relative_wheel_speed(sc, x[7:], x[4:7])[2]
    assert 100.0 <= rel < 100.0 + 0.1 / 0.01 * 0.01 + 1e-9      # overshoot: at most one step's increment
    assert x[9] > 100.4


# ------------------------------------------------------------ environment at every RK4 stage
def _constant_dipole_run(dt: float, per_stage: bool, t_end: float = 120.0) -> np.ndarray:
    """Bruni–Celani spacecraft tumbling at 0.04 rad/s with a constant 8 A m² dipole in the tilted-dipole
    field: the field in body axes from the stage attitude (per_stage) or held over each step."""
    from att_sim.models import environment as env
    orbit = env.OrbitParams(arg0=0.332)
    sc = dyn.Spacecraft(inertia=np.diag([27.0, 17.0, 25.0]), dipole_max=10.0)
    x = dyn.initial_state(sc, rot.IDENTITY, [0.02, 0.02, -0.03])
    inputs = dyn.Inputs(dipole_B=np.array([8.0, -5.0, 6.0]))

    def stage(t, s):
        return env.field_body(orbit, t, s[:4]), None
    n = int(round(t_end / dt))
    for k in range(n):
        t = k * dt
        if per_stage:
            x = dyn.step(sc, x, inputs, dt, stage, t)
        else:
            held = dyn.Inputs(dipole_B=inputs.dipole_B, field_B=env.field_body(orbit, t, x[:4]))
            x = dyn.step(sc, x, held, dt)
    return x


def test_environment_at_every_stage_is_fourth_order_and_the_held_field_first_order():
    reference = _constant_dipole_run(0.25, True)
    errors = {dt: np.linalg.norm(_constant_dipole_run(dt, True) - reference) for dt in (4.0, 2.0, 1.0)}
    ratios = [errors[4.0] / errors[2.0], errors[2.0] / errors[1.0]]
    assert min(ratios) > 12 and max(ratios) < 20, ratios        # ≈ 16: fourth order
    held = {dt: np.linalg.norm(_constant_dipole_run(dt, False) - reference) for dt in (2.0, 1.0)}
    assert 1.7 < held[2.0] / held[1.0] < 2.5                      # ≈ 2: first order
    assert held[1.0] > 100 * errors[1.0]


@pytest.mark.parametrize("interpolation", ["zoh", "linear"])
def test_compiled_body_torque_profile_is_the_step_loop(interpolation):
    """simulate_profile's compiled stepper (body torque) against :func:`dyn.step`'s arithmetic step by step:
    a full inertia, spinning wheels (their momentum enters the gyroscopic term), uneven knots, more
    steps than one call of the stepper takes."""
    rng = np.random.default_rng(1)
    sc = dyn.Spacecraft(np.array([[3, 0.2, 0.1], [0.2, 4, 0.3], [0.1, 0.3, 5.0]]), wheel_inertia=0.01)
    x = dyn.initial_state(sc, rot.normalize(rng.normal(size=4)), rng.normal(size=3) * 0.1, rng.normal(size=3) * 3)
    t = np.sort(np.r_[0.0, rng.uniform(0, 10, 300), 10.0])
    torque = rng.normal(size=(len(t), 3)) * 0.3
    traj = dyn.simulate_profile(sc, x, t, torque, interpolation=interpolation, max_step=0.005)
    assert len(traj.t) > dyn.STEPS_PER_CALL
    states = [x]
    for k, (a, b) in enumerate(zip(t[:-1], t[1:])):
        n = max(1, int(np.ceil((b - a) / 0.005 - 1e-9)))
        slope = (torque[k + 1] - torque[k]) / (b - a) if interpolation == "linear" else 0.0
        for i in range(n):
            t0 = a + i * (b - a) / n
            x = dyn.renormalised(dyn.rk4(lambda tt, s, k=k, slope=slope, a=a: dyn.derivative(
                sc, s, dyn.Inputs(torque_B=torque[k] + slope * (tt - a))), t0, x, (b - a) / n))
            states.append(x)
    states = np.array(states)
    np.testing.assert_allclose(traj.q_BN, states[:, :4], rtol=0, atol=1e-13)
    np.testing.assert_allclose(traj.omega_BN_B, states[:, 4:7], rtol=0, atol=1e-13)
    np.testing.assert_array_equal(traj.wheel_speed, states[:, 7:])


def _stack_case():
    """Three unlike spacecraft (inertia, wheel axes, wheel inertia, limits) and a state each, one
    wheel at its speed limit pushed further, one motor torque beyond its limit."""
    rng = np.random.default_rng(5)
    scs = []
    for k in range(3):
        a = rng.normal(size=(3, 3))
        axes = np.eye(3) + 0.05 * rng.normal(size=(3, 3))
        scs.append(dyn.Spacecraft(inertia=np.diag([10.0, 12.0, 14.0]) * (1 + 0.1 * k) + 0.3 * (a + a.T),
                                  wheel_axes=axes / np.linalg.norm(axes, axis=0), wheel_inertia=0.05 * (1 + k),
                                  wheel_torque_max=0.1 + 0.02 * k, wheel_speed_max=300.0 - 10 * k))
    x = np.array([dyn.initial_state(sc, rng.normal(size=4), rng.normal(0, 0.02, 3), rng.uniform(-100, 100, 3))
                  for sc in scs])
    x[0, :4] *= 1.01                                        # a stage's quaternion is off unit norm
    x[1, 7] = scs[1].wheel_speed_max + scs[1].wheel_axes[:, 0] @ x[1, 4:7]     # relative speed at its limit
    u = rng.uniform(-0.08, 0.08, (3, 3))
    u[1, 0] = 0.05                                          # pushes the limited wheel further: cut
    u[2, 1] = 1.0                                           # beyond the torque limit: clipped
    return scs, x, u, rng.normal(0, 1e-3, (3, 3))


def test_rates_of_a_stack_are_each_spacecraft_s_equations():
    """:func:`dyn.rates` on rows of three unlike spacecraft against the equations written out per
    spacecraft with numpy's own products (q̇ = ½ q ⊗ [ω, 0], J ω̇ = τ − G u − ω × (J ω + G I_w Ω),
    I_w Ω̇ = u), and against the derivative of each spacecraft alone."""
    scs, x, u, tau = _stack_case()
    got = dyn.rates(dyn.stack(scs), x, tau, u)
    for sc, xi, ui, ti, row in zip(scs, x, u, tau, got):
        q, w, ws = xi[:4], xi[4:7], xi[7:]
        G = sc.wheel_axes
        nu = ws - G.T @ w
        ui = np.clip(ui, -sc.wheel_torque_max, sc.wheel_torque_max)
        ui = np.where((np.abs(nu) >= sc.wheel_speed_max) & (ui * nu > 0), 0.0, ui)
        h = sc.inertia @ w + G @ (sc.wheel_inertia * ws)
        w_dot = np.linalg.solve(sc.inertia, ti - G @ ui - np.cross(w, h))
        qv, qw = q[:3], q[3]
        q_dot = 0.5 * np.concatenate([qw * w + np.cross(qv, w), [-qv @ w]])
        np.testing.assert_allclose(row, np.concatenate([q_dot, w_dot, ui / sc.wheel_inertia]), rtol=1e-10, atol=1e-15)
        np.testing.assert_allclose(row, dyn.derivative(sc, xi, dyn.Inputs(wheel_torque=ui, torque_B=ti)),
                                   rtol=1e-12, atol=1e-18)
    assert got[1, 7] == 0.0 and got[2, 8] == pytest.approx(scs[2].wheel_torque_max / scs[2].wheel_inertia)
    for i, sc in enumerate(scs):            # one row alone (its quaternion rate on floats): the same bits
        np.testing.assert_array_equal(dyn.rates(sc.stacked, x[i:i + 1], tau[i:i + 1], u[i:i + 1]), got[i:i + 1])


def test_a_stack_refuses_unlike_wheel_counts():
    with pytest.raises(ValueError, match="number of wheels"):
        dyn.stack([dyn.Spacecraft(inertia=np.eye(3)), dyn.Spacecraft(inertia=np.eye(3), wheel_axes=np.eye(3)[:, :2])])
