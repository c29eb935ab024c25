"""The tracking law on rows of runs: each row gets what the controller computes alone — the PD about
the reference, the null-space torques, the drive friction compensated, the wheels' distribution and
its scaling to the torque limit — and controllers stepped together (:func:`step_controllers`)
command what each commands alone."""
import numpy as np
import pytest

from att_msgs_py.types import ControlMode
from att_planner.control import momentum, tracking, wheels
from att_planner.control.controller import Controller, ControllerConfig, step_controllers
from att_planner.guidance import Reference
from att_planner.methods.eigenaxis import plan_eigenaxis_smooth
from att_planner.problem import ManeuverProblem
from att_sim.models import rotations as rot
from att_sim.models import scenario
from att_sim.truth.simulation import Simulation
from helpers.signed_plans import context, issue

RELATIVE = 1e-12       # a row computed among others against the same row alone


def same(a, b) -> bool:
    return np.allclose(a, b, rtol=RELATIVE, atol=RELATIVE * max(float(np.abs(b).max(initial=0.0)), 1e-300))


@pytest.mark.parametrize("name", ["swift_demo", "leo_momentum"])     # 3 wheels; 4 (a null space)
def test_the_law_on_rows_gives_each_run_what_it_gets_alone(name):
    s = scenario.load(name)
    sc, rng, runs = s.spacecraft, np.random.default_rng(16), 40
    wheel_drives = s.actuators.wheels if s.actuators is not None else None
    friction = wheel_drives.friction if wheel_drives is not None else (lambda v: 0.01 * np.tanh(v))
    size = np.where(np.arange(runs) % 2, 1.0, 1e-3)[:, None]       # every other run within the torque limit
    q = rot.normalize(rng.standard_normal((runs, 4)))
    ref_q = rot.normalize(q + size * 0.05 * rng.standard_normal((runs, 4)))
    omega, ref_omega = size * 0.02 * rng.standard_normal((runs, 3)), size * 0.02 * rng.standard_normal((runs, 3))
    ref_torque = size * 0.05 * rng.standard_normal((runs, 3))
    speeds = 0.5 * sc.wheel_speed_max * rng.standard_normal((runs, sc.n_wheels))
    gains = (1.0, 16.0)
    body = tracking.tracking_torque(q, omega, Reference(ref_q, ref_omega, np.zeros((runs, 3)), ref_torque), *gains)
    extra = momentum.null_space_torques(sc, speeds, 3.0, 0.05) + \
        friction(speeds - wheels.matvec_rows(sc.wheel_axes.T, omega))
    rows = wheels.wheel_torques(sc, body, omega, speeds, extra)
    assert rows.tobytes() == wheels.wheel_command(sc, body, omega, speeds, 3.0, 0.05, friction).tobytes()
    scaled = 0
    for i in range(runs):
        ref = Reference(ref_q[i], ref_omega[i], np.zeros(3), ref_torque[i])
        tau = tracking.tracking_torque(q[i], omega[i], ref, *gains)
        alone_extra = momentum.null_space_torques(sc, speeds[i], 3.0, 0.05) + \
            friction(speeds[i] - sc.wheel_axes.T @ omega[i])
        alone = wheels.wheel_torques(sc, tau[None], omega[i][None], speeds[i][None], alone_extra[None])[0]
        assert same(body[i], tau) and extra[i].tobytes() == alone_extra.tobytes()
        assert same(rows[i], alone), i
        one_row = wheels.wheel_torques(sc, body[i][None], omega[i][None], speeds[i][None], extra[i][None])[0]
        assert rows[i].tobytes() == one_row.tobytes(), i                  # the distribution: each row's own bits
        demand = tau + rot.cross(omega[i], sc.wheel_axes @ (sc.wheel_inertia * speeds[i]))
        scaled += bool(np.abs(sc.wheel_axes_pinv @ demand).max() > sc.wheel_torque_max)
    assert 0 < scaled < runs


def _tracking(start_error_deg: float, ctx):
    """A swift_demo controller (of the plan context ``ctx``: controllers of one model share theirs)
    flying an eigenaxis plan, on a simulation started off its start."""
    s = scenario.load("swift_demo")
    q0 = rot.from_axis_angle([1.0, 0.2, -0.3], np.radians(start_error_deg))
    sim = Simulation(s.spacecraft, s.orbit, q0=q0, omega0=np.array([1e-3, -2e-3, 5e-4]))
    plan, payload = issue(plan_eigenaxis_smooth(ManeuverProblem(s.spacecraft, rot.IDENTITY,
                                                                rot.from_axis_angle([0, 0, 1], 1.0))), ctx)
    config = ControllerConfig(control_period=0.05, tracking_kp=1.0, tracking_kd=16.0)
    core = Controller(ctx, config, body_frame_id="body")
    assert core.receive_plan(plan, payload) is None and core.accept_state(sim.state("eci", "body")).refused is None
    assert core.start(core.resolve("p1")[0]) is None and core.mode == ControlMode.PLAN_TRACKING
    sim.advance(0.05)
    return sim, core


def test_controllers_stepped_as_a_batch_command_what_each_commands_alone():
    """Three controllers stepped together and the same three stepped alone (built alike) command
    the same torques at every step (to 1e-12 relative); a controller in another mode, stepped among
    them, commands what it commands alone."""
    ctx = context()
    together, alone = ([_tracking(e, ctx) for e in (0.0, 0.05, 0.2)] for _ in range(2))
    for _ in range(40):
        for sim, core in together + alone:
            assert core.accept_state(sim.state("eci", "body"), wall=sim.t).refused is None and core.due()
        outs = step_controllers([core for _, core in together])
        for (sim, _), out, (sim_alone, core_alone) in zip(together, outs, alone):
            out_alone = core_alone.step()
            command = out_alone.command
            assert same(out.command.wheel_torques, command.wheel_torques)
            assert out.status.attitude_error == pytest.approx(out_alone.status.attitude_error, rel=1e-9, abs=1e-15)
            for s, c in ((sim, out.command), (sim_alone, command)):
                assert s.set_command(c) is None
                s.advance(0.05)
    (sim, core), (sim_alone, core_alone) = together[0], alone[0]
    core.mode = core_alone.mode = ControlMode.SAFE
    for s, c in ((sim, core), (sim_alone, core_alone)):
        c.accept_state(s.state("eci", "body"), wall=s.t)
    outs = step_controllers([core] + [c for _, c in together[1:]])
    assert outs[0].command.mode == ControlMode.SAFE
    assert same(outs[0].command.wheel_torques, core_alone.step().command.wheel_torques)
