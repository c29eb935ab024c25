"""The tracking law on rows of runs (att_planner.control.lockstep): each row gets the bits the
controller computes alone — the PD about the reference, the null-space torques, the drive friction
compensated, the wheels' distribution and its scaling to the torque limit — and controllers stepping
together command what each commands alone."""
import numpy as np
import pytest

from att_msgs_py.types import ControlMode
from att_planner.control import momentum, tracking
from att_planner.control.controller import Controller, ControllerConfig
from att_planner.control.lockstep import track_together, tracked_reference
from att_planner.methods.eigenaxis import plan_eigenaxis_smooth
from att_planner.problem import ManeuverProblem
from att_sim.models import rotations as rot
from att_sim.models import scenario
from att_sim.truth.simulation import Simulation
from helpers.signed_plans import context, issue


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
    body = tracking.tracking_torque(q, omega, tracking.Reference(ref_q, ref_omega, ref_torque), *gains)
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


def test_controllers_stepping_together_command_what_each_commands_alone():
    """track_together hands each controller the wheel torques its own law gives (bit for bit: the
    step alone, with nothing prepared, commands the same bytes); a prepared command is used only for
    the state and reference it was made for."""
    ctx = context()
    flights = [_tracking(e, ctx) for e in (0.0, 0.05, 0.2)]
    for _ in range(40):
        for sim, core in flights:
            assert core.accept_state(sim.state("eci", "body"), wall=sim.t).refused is None and core.due()
        track_together([core for _, core in flights])
        for sim, core in flights:
            prepared = core.prepared[2].copy()
            core.prepared = None
            command = core.step().command
            assert command.wheel_torques.tobytes() == prepared.tobytes()
            assert sim.set_command(command) is None
            sim.advance(0.05)
    sim, core = flights[0]
    core.accept_state(sim.state("eci", "body"), wall=sim.t)
    core.prepare(tracked_reference(core), np.full(sim.sc.n_wheels, 0.5))
    assert np.all(core.step().command.wheel_torques == 0.5)               # made for this state: used
    core.prepare(tracked_reference(core), np.full(sim.sc.n_wheels, 0.5))
    sim.advance(0.05)
    core.accept_state(sim.state("eci", "body"), wall=sim.t)
    assert not np.any(core.step().command.wheel_torques == 0.5)           # a newer state: computed again
