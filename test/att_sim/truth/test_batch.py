"""SimulationBatch: simulations advanced as one batch reach, run by run, what each reaches alone (to
1e-12 relative: the same operations on rows, the last bit free to differ where numpy's kernels do),
and a run is reproduced from its seed alone."""
import functools
from pathlib import Path

import numpy as np
import pytest

from att_msgs_py.types import Command, ControlMode
from att_sim.models import scenario as scen
from att_sim.truth import dispersions as disp
from att_sim.truth.batch import SimulationBatch
from att_sim.truth.simulation import Simulation

CAMPAIGN = Path(__file__).resolve().parents[3] / "campaigns" / "swift_demo.yaml"


@functools.cache
def campaign() -> tuple[disp.Campaign, scen.Scenario]:
    c = disp.load_campaign(CAMPAIGN)
    return c, scen.load(c.scenario)


def dispersed_pair(seed: int) -> tuple[Simulation, Simulation]:
    """Two simulations of the swift_demo campaign's run of ``seed`` (own spacecraft, drives,
    seed; one orbit: the runs' environments share their time-only part)."""
    truth, _ = disp.seed_truth(*campaign(), seed, omega0=(0.01, -0.02, 0.015))
    return tuple(Simulation.for_scenario(truth.scenario, q0=truth.q0, omega0=truth.omega0, seed=truth.seed)
                 for _ in range(2))


def disturbed_pair(seed: int) -> tuple[Simulation, Simulation]:
    """Two identical simulations of the real-sky scenario: TLE orbit, IGRF, every disturbance torque."""
    s = scen.load("leo_observatory")
    rng = np.random.default_rng(seed)
    q0, omega0 = rng.normal(size=4), rng.normal(0, 0.01, 3)
    return tuple(Simulation.for_scenario(s, q0=q0 / np.linalg.norm(q0), omega0=omega0, seed=seed) for _ in range(2))


def commands(sim: Simulation, rng: np.random.Generator) -> Command:
    sc = sim.sc
    return Command(mode=ControlMode.PLAN_TRACKING, t=sim.t,
                   wheel_torques=rng.uniform(-1.5, 1.5, sc.n_wheels) * sc.wheel_torque_max,
                   dipole=rng.uniform(-1.2, 1.2, 3) * min(sc.dipole_max, 10.0))


def fly(pairs, steps: int, dt: float = 0.05, before_step=None):
    """Advance the first of each pair alone and the second ones in one batch, commanding both alike
    (``before_step(k, pairs)`` before step k)."""
    alone = [a for a, _ in pairs]
    together = [b for _, b in pairs]
    batch = SimulationBatch(together)
    rng_a, rng_b = np.random.default_rng(7), np.random.default_rng(7)
    for k in range(steps):
        if before_step is not None:
            before_step(k, pairs)
        if k % 3 == 0:
            for a, b in pairs:
                assert a.set_command(commands(a, rng_a)) is None
                assert b.set_command(commands(b, rng_b)) is None
        assert_same_readings([a.sense() for a in alone], batch.sense())
        for a in alone:
            a.advance(dt)
        batch.advance(dt)
    return alone, together


RTOL = 1e-12


def close(a, b):
    """``a`` equals ``b`` to 1e-12 relative (of the larger magnitude of the vector)."""
    a, b = np.asarray(a, float), np.asarray(b, float)
    assert a.shape == b.shape
    np.testing.assert_allclose(a, b, rtol=0, atol=RTOL * max(np.abs(b).max(initial=0.0), 1e-300))


def assert_same_readings(alone, together):
    """The sensors' outputs of one instant, alone and in a batch (the gyros measure on rows)."""
    for a, b in zip(alone, together):
        assert (a.gyro is None) == (b.gyro is None) and len(a.star_trackers) == len(b.star_trackers)
        assert (a.wheel_speeds is None) == (b.wheel_speeds is None)
        if a.gyro is not None:
            close(a.gyro.omega, b.gyro.omega)
            close(a.truth.gyro_bias, b.truth.gyro_bias)
        for m, n in zip(a.star_trackers, b.star_trackers):
            close(m.q, n.q)
        if a.wheel_speeds is not None:
            close(a.wheel_speeds.speeds, b.wheel_speeds.speeds)


def assert_same(alone, together):
    for a, b in zip(alone, together):
        assert a.t == b.t
        for part in (slice(0, 4), slice(4, 7), slice(7, None)):      # attitude, rate, wheel speeds
            close(a.x[part], b.x[part])
        for name in ("wheel_torque", "dipole", "body_torque"):
            close(getattr(a.applied, name), getattr(b.applied, name))
        close(a.now.field_B, b.now.field_B)
        close(a.now.torque_B, b.now.torque_B)


def test_dispersed_runs_with_imperfect_drives_reach_what_they_reach_alone():
    alone, together = fly([dispersed_pair(seed) for seed in (3, 11, 2024)], steps=60)
    assert_same(alone, together)
    assert len({a.x.tobytes() for a in alone}) == 3      # the runs differ from each other
    assert any(np.any(a.applied.wheel_torque != 0) for a in alone)


def test_runs_in_the_real_sky_with_every_disturbance_reach_what_they_reach_alone():
    alone, together = fly([disturbed_pair(seed) for seed in (1, 2)], steps=30)
    assert_same(alone, together)
    assert all(np.any(a.now.torque_B != 0) for a in alone)


def test_runs_whose_watchdog_trips_or_that_have_no_coils_reach_what_they_reach_alone():
    """The inputs of a batch are taken on rows of runs: a tripped watchdog zeroes one run's
    commands (and draws no drive noise); runs with and without coils fly in one batch."""
    def watchdog(k, pairs):                 # run i's watchdog trips over steps 10(i + 1) .. 10(i + 1) + 6
        for i, pair in enumerate(pairs):
            for s in pair:
                s.command_timeout = 10 * (i + 1) <= k < 10 * (i + 1) + 7
    pairs = [dispersed_pair(seed) for seed in (4, 8, 15)]
    alone, together = fly(pairs, steps=50, before_step=watchdog)
    assert_same(alone, together)
    assert len({a.x.tobytes() for a in alone}) == 3
    for a, b in pairs[1:]:
        a.magnetorquers = b.magnetorquers = None
    assert_same(*fly(pairs, steps=20))


def test_a_run_is_reproduced_from_its_seed_alone():
    """Two flights of one seed, each alone, give the same states, readings and applied torques, bit
    for bit; another seed does not."""
    def alone(seed):
        sim, _ = dispersed_pair(seed)
        rng, out = np.random.default_rng(7), []
        for k in range(40):
            if k % 3 == 0:
                assert sim.set_command(commands(sim, rng)) is None
            r = sim.sense()
            sim.advance(0.05)
            out.append(np.concatenate([sim.x, sim.applied.wheel_torque, sim.applied.body_torque,
                                       r.gyro.omega if r.gyro is not None else [],
                                       r.wheel_speeds.speeds if r.wheel_speeds is not None else []]))
        return np.concatenate(out)
    first = alone(21)
    np.testing.assert_array_equal(first, alone(21))
    assert not np.array_equal(first, alone(22))


def test_one_run_is_a_batch_of_one():
    alone, together = fly([dispersed_pair(5)], steps=20)
    assert_same(alone, together)


def test_simulations_of_different_times_or_wheels_are_refused():
    a, b = dispersed_pair(1)
    b.advance(0.05)
    with pytest.raises(ValueError, match="share their time"):
        SimulationBatch([a, b])
    with pytest.raises(ValueError, match="at least one"):
        SimulationBatch([])


def test_a_run_whose_environment_fails_halts_as_it_would_alone_and_the_others_go_on(monkeypatch):
    """One run's orbit stops propagating (as a decayed TLE does) at 0.12 s: that run halts with the
    reason it gets alone; the other run's states stay its own."""
    failing, healthy = disturbed_pair(1), disturbed_pair(2)
    orbit = failing[0].environment.orbit
    assert failing[1].environment.orbit is orbit and healthy[0].environment.orbit is not orbit
    state = orbit.state

    def decayed(t):
        if t > 0.12:
            raise ValueError("the orbit decayed")
        return state(t)
    monkeypatch.setattr(orbit, "state", decayed)
    batch = SimulationBatch([failing[1], healthy[1]])
    for _ in range(4):
        for a in (failing[0], healthy[0]):
            if not a.halted:
                a.advance(0.05)
        batch.advance(0.05)
    alone, together = [failing[0], healthy[0]], [failing[1], healthy[1]]
    assert alone[0].halted and together[0].halted and "the orbit decayed" in together[0].halt_reason
    assert together[0].halt_reason == alone[0].halt_reason and not together[1].halted
    assert_same(alone, together)


def test_a_steps_first_stage_taken_from_the_last_end_sample_changes_no_bit():
    """A step's first environment stage is the previous step's end sample (same time, state and
    environment), computed once: a run stepped so equals, bit for bit, the run whose every stage is
    evaluated afresh; a reset between steps (a new state) is evaluated afresh."""
    reused, fresh = disturbed_pair(5)
    rng_a, rng_b = np.random.default_rng(3), np.random.default_rng(3)
    for k in range(40):
        if k % 3 == 0:
            assert reused.set_command(commands(reused, rng_a)) is None
            assert fresh.set_command(commands(fresh, rng_b)) is None
        if k == 25:
            for s in (reused, fresh):
                assert s.reset([0.0, 0.6, 0.0, 0.8], [0.001, 0.0, -0.002], [], 0.0) is None
        reused.advance(0.05)
        fresh.batch()._last_stage = None
        fresh.advance(0.05)
    np.testing.assert_array_equal(reused.x, fresh.x)
    np.testing.assert_array_equal(reused.now.torque_B, fresh.now.torque_B)
    np.testing.assert_array_equal(reused.applied.body_torque, fresh.applied.body_torque)
