"""Hardware faults of the truth: each model against an independent recomputation (the law it states,
or the same run without the fault, whose random streams it shares), a fault per run in a batch."""
import math

import numpy as np
import pytest

from att_msgs_py.errors import ErrorCode
from att_msgs_py.types import Command, ControlMode, FaultSource
from att_sim.models import dynamics as dyn
from att_sim.models import rotations as rot
from att_sim.models.actuator_specs import ActuatorSpecs, WheelDriveSpec
from att_sim.models.config_faults import spec
from att_sim.models.environment import OrbitParams
from att_sim.models.sensor_specs import GyroSpec, MagnetometerSpec, SensorSpecs, StarTrackerSpec, TachometerSpec
from att_sim.truth.batch import SimulationBatch
from att_sim.truth.simulation import Simulation

SC = dyn.Spacecraft(inertia=np.diag([100.0, 100.0, 100.0]), wheel_inertia=0.01, wheel_torque_max=0.12,
                    wheel_speed_max=630.0, dipole_max=10.0)
FRICTION = WheelDriveSpec(coulomb_friction=0.002, viscous_friction=1e-5, friction_speed=0.5)
SENSORS = SensorSpecs(seed=5, gyro=GyroSpec(rate=20.0, arw=1e-5, initial_bias=1e-5),
                      star_trackers=(StarTrackerSpec(name="st", rate=5.0),),
                      magnetometer=MagnetometerSpec(rate=10.0, noise=50e-9), tachometer=TachometerSpec(rate=20.0,
                                                                                                     noise=0.01))
STEP = 0.05


def simulation(wheel_speed0=(300.0, 0.0, 0.0), drive=FRICTION, sensors=None, faults=(), omega0=(0, 0, 0)):
    return Simulation(SC, OrbitParams(), omega0=omega0, wheel_speed0=wheel_speed0,
                      actuators=ActuatorSpecs(wheels=drive), sensors=sensors, seed=3, faults=tuple(faults))


def command(wheel=(0.0, 0.0, 0.0), dipole=(0.0, 0.0, 0.0)) -> Command:
    return Command(mode=ControlMode.PLAN_TRACKING, wheel_torques=np.asarray(wheel, float),
                   dipole=np.asarray(dipole, float), body_torque=np.zeros(3))


def fly(sim, seconds, readings=None):
    for _ in range(int(round(seconds / STEP))):
        sim.advance(STEP)
        if readings is not None:
            readings.append(sim.sense())


def test_a_seized_wheel_keeps_its_speed_and_gives_the_body_no_torque():
    """Only wheel 0 commanded, the others at rest: after the seizure nothing moves (without it the
    body would turn by the reaction of 0.05 N m)."""
    sim = simulation(faults=[spec("wheel", 0, "seized", t_s=0.5)])
    sim.set_command(command([0.05, 0.0, 0.0]))
    fly(sim, 0.5)
    speed, omega = sim.x[7].copy(), sim.x[4:7].copy()
    assert abs(omega[0]) > 1e-5                         # before the onset the motor acted
    fly(sim, 5.0)
    assert sim.x[7] == speed                            # the wheel's inertial spin held exactly
    assert np.array_equal(sim.x[4:7], omega)            # no torque on the body from it
    assert sim.applied.wheel_torque[0] == 0.0 and np.allclose(sim.applied.body_torque, 0.0, atol=1e-15)
    [event] = sim.faults.take_events()
    assert (event.t, event.component, event.index, event.kind, event.source) == \
        (pytest.approx(0.5), "wheel", 0, "seized", FaultSource.SCENARIO)
    assert sim.faults.take_events() == []


def test_a_wheel_off_spins_down_by_its_friction_law_whatever_its_command():
    sim = simulation(faults=[spec("wheel", 0, "off", t_s=0.0)])
    sim.set_command(command([0.1, 0.0, 0.0]))           # would speed the wheel up by 100 rad/s in 10 s
    speed0 = dyn.relative_wheel_speed(SC, sim.x[7:], sim.x[4:7])[0]
    fly(sim, 10.0)
    speed = dyn.relative_wheel_speed(SC, sim.x[7:], sim.x[4:7])[0]
    # |Δν| ≈ ∫ f(ν) dt / I_w = 10 s × (0.002 + 1e-5 ν) / 0.01 (the body's share is J_w/J = 1e-4)
    assert speed0 - speed == pytest.approx(10.0 * (0.002 + 1e-5 * speed0) / 0.01, rel=0.02)
    assert sim.applied.wheel_torque[0] == 0.0


@pytest.mark.parametrize("factor", [0.5, 4.0])
def test_friction_times_k_slows_a_free_wheel_k_times_as_fast(factor):
    sim = simulation(faults=[spec("wheel", 0, "friction", factor=factor, t_s=0.0)])
    speed0 = sim.x[7]
    fly(sim, 10.0)
    expected = factor * 10.0 * (0.002 + 1e-5 * speed0) / 0.01
    assert speed0 - dyn.relative_wheel_speed(SC, sim.x[7:], sim.x[4:7])[0] == pytest.approx(expected, rel=0.03)


def test_a_stuck_tachometer_reads_its_last_value_and_the_others_keep_measuring():
    sim = simulation(sensors=SENSORS, faults=[spec("wheel", 1, "tachometer_stuck", t_s=1.0)])
    sim.set_command(command([0.0, 0.05, 0.0]))          # wheel 1 speeds up by 5 rad/s a second
    readings = []
    fly(sim, 3.0, readings)
    speeds = [(r.wheel_speeds.t, r.wheel_speeds.speeds.copy()) for r in readings if r.wheel_speeds is not None]
    before = [s for t, s in speeds if t < 1.0 - 1e-9]
    after = [s for t, s in speeds if t >= 1.0 - 1e-9]
    assert len(after) > 30 and all(s[1] == before[-1][1] for s in after)
    assert after[-1][0] != after[-2][0]                  # wheel 0's tachometer is not stuck (noise)
    truth = dyn.relative_wheel_speed(SC, sim.x[7:], sim.x[4:7])[1]
    assert truth - before[-1][1] > 9.0                   # the wheel itself went on speeding up


def _runs(sensors, faults, seconds=2.0, omega0=(0.0, 0.01, 0.0)):
    """The readings of a run with ``faults`` and of the same run without them (the same streams)."""
    out = []
    for fs in (faults, ()):
        sim = simulation(sensors=sensors, faults=fs, omega0=omega0)
        readings = []
        fly(sim, seconds, readings)
        out.append(readings)
    return out


def test_a_stuck_gyro_axis_reads_a_constant_and_the_other_axes_are_untouched():
    faulted, nominal = _runs(SENSORS, [spec("gyro", 1, "axis_stuck", t_s=1.0)])
    pairs = [(f.gyro, n.gyro) for f, n in zip(faulted, nominal) if f.gyro is not None]
    after = [(f, n) for f, n in pairs if f.t >= 1.0 - 1e-9]
    last_before = [f for f, n in pairs if f.t < 1.0 - 1e-9][-1]
    assert len(after) > 15
    assert all(f.omega[1] == last_before.omega[1] for f, _ in after)
    assert all(np.array_equal(f.omega[[0, 2]], n.omega[[0, 2]]) for f, n in after)
    assert len({n.omega[1] for _, n in after}) > 1                  # the healthy axis would vary


def test_a_gyro_bias_step_adds_its_step_from_the_onset_and_to_the_evaluation_truth():
    step = 2e-3
    faulted, nominal = _runs(SENSORS, [spec("gyro", 2, "bias_step", bias_rad_s=step, t_s=1.0)])
    for f, n in zip(faulted, nominal):
        if f.gyro is None:
            continue
        shift = step if f.gyro.t >= 1.0 - 1e-9 else 0.0
        assert f.gyro.omega == pytest.approx(n.gyro.omega + [0.0, 0.0, shift], abs=1e-15)
        assert f.truth.gyro_bias == pytest.approx(n.truth.gyro_bias + [0.0, 0.0, shift], abs=1e-15)


def test_a_star_tracker_outage_stops_its_measurements():
    faulted, nominal = _runs(SENSORS, [spec("star_tracker", 0, "outage", t_s=1.0)])
    times = [m.t for r in faulted for m in r.star_trackers]
    assert times and max(times) < 1.0
    assert max(m.t for r in nominal for m in r.star_trackers) > 1.5


def test_a_star_tracker_bias_jump_rotates_its_measurement_by_the_bias():
    bias = (1e-3, -2e-3, 5e-4)
    faulted, nominal = _runs(SENSORS, [spec("star_tracker", 0, "bias_jump", bias_rad=bias, t_s=1.0)])
    pairs = [(f, n) for rf, rn in zip(faulted, nominal) for f, n in zip(rf.star_trackers, rn.star_trackers)]
    assert len(pairs) >= 9
    for f, n in pairs:
        expected = rot.multiply(n.q, rot.exp_map(np.array(bias))) if f.t >= 1.0 - 1e-9 else n.q
        assert f.q == pytest.approx(expected, abs=1e-12)
        angle = 2 * math.acos(min(1.0, abs(float(f.q @ n.q))))
        assert angle == pytest.approx(np.linalg.norm(bias) if f.t >= 1.0 - 1e-9 else 0.0, abs=1e-7)


def test_a_stuck_magnetometer_repeats_its_last_field_at_new_stamps():
    faulted, nominal = _runs(SENSORS, [spec("magnetometer", 0, "stuck", t_s=1.0)])
    readings = [(f.magnetometer, n.magnetometer) for f, n in zip(faulted, nominal) if f.magnetometer is not None]
    before = [f for f, _ in readings if f.t < 1.0 - 1e-9]
    after = [(f, n) for f, n in readings if f.t >= 1.0 - 1e-9]
    assert all(np.array_equal(f.field, before[-1].field) for f, _ in after)
    assert len({f.t for f, _ in after}) == len(after) > 5
    assert all(np.array_equal(f.field, n.field) for f, n in zip(before, [n for _, n in readings]))
    assert not np.array_equal(after[-1][1].field, before[-1].field)    # the true field moved on


def test_an_open_coil_produces_no_dipole_on_its_axis():
    sim = simulation(faults=[spec("magnetorquer", 1, "coil_open", t_s=0.2)])
    sim.set_command(command(dipole=[1.0, 2.0, -3.0]))
    fly(sim, 0.2)
    assert sim.applied.dipole.tolist() == [1.0, 2.0, -3.0]
    fly(sim, 0.2)
    assert sim.applied.dipole.tolist() == [1.0, 0.0, -3.0]


def test_a_fault_is_per_run_in_a_batch_and_the_batch_equals_each_run_alone():
    def runs():
        return [simulation(sensors=SENSORS, faults=[spec("wheel", 0, "seized", t_s=0.3),
                                                     spec("gyro", 0, "bias_step", bias_rad_s=1e-3, t_s=0.1)]),
                simulation(sensors=SENSORS),
                simulation(sensors=SENSORS, faults=[spec("wheel", 2, "friction", factor=3.0, t_s=0.0),
                                                     spec("magnetorquer", 0, "coil_open", t_s=0.0)])]
    together, alone = runs(), runs()
    for sims in (together, alone):
        for s in sims:
            s.set_command(command([0.05, 0.02, -0.03], [1.0, 0.5, 0.2]))
    batch = SimulationBatch(together)
    gyro_together, gyro_alone = [], []
    for _ in range(20):
        batch.advance(STEP)
        gyro_together.append([r.gyro for r in batch.sense()])
        for s in alone:
            s.advance(STEP)
        gyro_alone.append([s.sense().gyro for s in alone])
    for a, b in zip(together, alone):
        assert a.x == pytest.approx(b.x, rel=1e-12, abs=1e-14)
    for row_t, row_a in zip(gyro_together, gyro_alone):
        for g_t, g_a in zip(row_t, row_a):
            assert (g_t is None) == (g_a is None) and (g_t is None or np.allclose(g_t.omega, g_a.omega, atol=1e-15))
    assert together[0].x[7] == pytest.approx(300.0 + 0.05 * 0.3 / 0.01, rel=0.02)    # seized at 0.3 s
    assert together[1].x[7] > together[0].x[7] + 2.0                                # the healthy run went on


@pytest.mark.parametrize("fault, words", [
    (spec("wheel", 3, "seized"), "index: expected below 3 (the spacecraft has 3 wheels); found 3"),
    (spec("star_tracker", 1, "outage"), "below 1 (the spacecraft has 1 star trackers)"),
    (spec("gyro", 3, "axis_stuck"), "below 3"),
    (spec("wheel", 0, "friction", factor=-1.0), "factor: expected a friction multiplier"),
    (spec("wheel", 0, "stuck"), "kind: expected one of seized, off, friction, tachometer_stuck"),
    (spec("sun_sensor", 0, "outage"), "component: expected one of"),
    (spec("gyro", 0, "bias_step", bias_rad_s=math.nan), "bias_rad_s"),
    (spec("wheel", 0, "off", t_s=-1.0), "t_s"),
])
def test_a_fault_the_hardware_cannot_have_is_refused_and_nothing_is_scheduled(fault, words):
    sim = simulation(sensors=SENSORS)
    refusal = sim.inject(fault)
    assert refusal.code == ErrorCode.INVALID_FAULT and words in refusal.message
    assert sim.faults.pending == []


def test_a_tachometer_fault_needs_a_tachometer():
    refusal = simulation().inject(spec("wheel", 0, "tachometer_stuck"))
    assert refusal.code == ErrorCode.INVALID_FAULT and "found no wheels with a tachometer" in refusal.message
