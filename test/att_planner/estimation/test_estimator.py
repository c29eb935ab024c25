"""The estimator core (no ROS): late measurements applied at their instant, initialisation from a
tracker or from QUEST on the sun and field, health, blanking, and every hostile input refused with
its code while the filter carries on."""
from __future__ import annotations

import math
from dataclasses import replace

import numpy as np
import pytest

from att_msgs_py.errors import ErrorCode, RequestError
from att_msgs_py.types import (
    GyroMeasurement,
    Health,
    MagnetometerMeasurement,
    StarTrackerMeasurement,
    SunSensorMeasurement,
)
from att_planner.estimation.estimator import Estimator, EstimatorConfig, replay
from att_planner.estimation.inputs import Sources
from att_sim.models import rotations as rot
from att_sim.models.sensor_specs import (
    ARCSEC,
    DEG,
    HOUR,
    GyroSpec,
    MagnetometerSpec,
    SensorSpecs,
    StarTrackerSpec,
    SunSensorSpec,
)
from att_sim.models.world import Bodies

MOUNT = rot.from_axis_angle([0, 1, 0], 0.5)
GYRO = GyroSpec(rate=20.0, arw=0.01 * DEG / math.sqrt(HOUR), rrw=0.01 * DEG / HOUR / math.sqrt(HOUR),
                initial_bias=1 * DEG / HOUR, range=math.radians(5.0))
SPECS = SensorSpecs(gyro=GYRO, star_trackers=(StarTrackerSpec(name="st", mounting=MOUNT, cross_boresight=5 * ARCSEC,
                                                              about_boresight=30 * ARCSEC),),
                    magnetometer=MagnetometerSpec(rate=2.0, noise=50e-9), sun_sensors=SunSensorSpec())
SUN_N = np.array([0.6, 0.8, 0.0])
FIELD_N = np.array([1e-5, -2e-5, 2.5e-5])


class FixedEnvironment:
    """A fixed sun and field: the onboard models the estimator asks."""

    def bodies(self, t):
        return Bodies(np.array([7e6, 0, 0]), FIELD_N, np.array([-1.0, 0, 0]), 1.1, SUN_N, None, 1.0)


def estimator(**config) -> Estimator:
    base = dict(publish_period=0.05, arw=GYRO.arw, rrw=GYRO.rrw, initial_bias_sigma=GYRO.initial_bias)
    return Estimator(SPECS, EstimatorConfig(**{**base, **config}), FixedEnvironment(), "eci", "body")


def gyro(t, omega=(0.0, 0.0, 0.0)) -> GyroMeasurement:
    return GyroMeasurement(t, np.asarray(omega, float), np.eye(3) * 1e-12, "body")


def tracker(t, q_body, valid=True, name="st", frame="eci") -> StarTrackerMeasurement:
    return StarTrackerMeasurement(t, name, rot.multiply(q_body, MOUNT), np.eye(3) * 1e-10, valid=valid,
                                  frame_id=frame)


Q = rot.from_axis_angle([1, 2, 3], 1.0)
OMEGA = np.array([0.02, -0.01, 0.015])


def truth(t):
    return rot.propagate_constant_rate(Q, OMEGA, t)


def test_a_late_tracker_measurement_is_applied_at_its_instant():
    """Measurements arriving 0.15 s late give the same filter as the same ones in order, to rounding."""
    late, in_order = estimator(), estimator()
    queue = []
    for k in range(101):
        t = 0.05 * k
        if k % 4 == 0:
            in_order.on_star_tracker(tracker(t, truth(t)))
            queue.append((t + 0.15, tracker(t, truth(t))))
        in_order.on_gyro(gyro(t, OMEGA))
        for _, m in [item for item in queue if item[0] <= t + 1e-9]:
            late.on_star_tracker(m)
        queue = [item for item in queue if item[0] > t + 1e-9]
        late.on_gyro(gyro(t, OMEGA))
    # the late filter has not yet seen the last measurement (it is still on its way): replay it now
    for _, m in queue:
        late.on_star_tracker(m)
    a, b = late.state, in_order.state
    assert rot.angle_between(a.q_BN, b.q_BN) < 1e-12 and np.allclose(a.P, b.P, rtol=1e-9, atol=1e-30)
    assert rot.angle_between(a.q_BN, truth(5.0)) < 1e-9 and late.health(5.0) == Health.CONVERGED


@pytest.mark.parametrize("trackers", [2, 0], ids=["two trackers", "vectors alone"])
def test_measurements_kept_between_gyro_samples_are_applied_by_one_replay_as_if_each_at_once(monkeypatch, trackers):
    """The measurements of a gyro interval (two trackers, one of them once wrong; or a field sample and
    a sun vector, without trackers), arriving 0.1–0.2 s late: kept (``take_*``), they change nothing
    until the next gyro sample, whose one replay leaves every estimate bit for bit as applying each
    measurement when it came (``on_*``), the gate's decisions included."""
    spec = StarTrackerSpec(name="a", mounting=MOUNT, cross_boresight=5 * ARCSEC, about_boresight=30 * ARCSEC)
    specs = replace(SPECS, star_trackers=(spec, replace(spec, name="b"))[:trackers])
    config = EstimatorConfig(publish_period=0.05, arw=GYRO.arw, rrw=GYRO.rrw, initial_bias_sigma=GYRO.initial_bias)
    at_once, kept = (Estimator(specs, config, FixedEnvironment(), "eci", "body") for _ in range(2))
    replays = []
    monkeypatch.setattr(Estimator, "reprocess", lambda self, start: replays.append(self) or replay([(self, start)]))
    rng = np.random.default_rng(7)
    wrong = rot.multiply(rot.from_axis_angle([1, 0, 0], 0.2), Q)
    for k in range(60):
        t = 0.05 * k
        arriving = []
        if k >= 4:
            taken = t - 0.05 * rng.integers(2, 5)
            if trackers:
                arriving = [tracker(taken, wrong if k == 30 else truth(taken), name="b"),
                            tracker(taken, truth(taken), name="a")]
            else:
                arriving = [MagnetometerMeasurement(taken, rot.dcm_BN(truth(taken)) @ FIELD_N, np.eye(3), "body"),
                            SunSensorMeasurement(taken, np.clip(SPECS.sun_sensors.normals @ rot.dcm_BN(truth(taken))
                                                                @ SUN_N, 0.0, None), 0.0, "body")]
        before = kept.state
        for m in arriving:
            kind = {StarTrackerMeasurement: "star_tracker", MagnetometerMeasurement: "magnetometer",
                    SunSensorMeasurement: "sun_sensors"}[type(m)]
            getattr(at_once, f"on_{kind}")(m)
            getattr(kept, f"take_{kind}")(m)
        assert kept.state is before
        del replays[:]
        a, b = at_once.on_gyro(gyro(t, OMEGA)), kept.on_gyro(gyro(t, OMEGA))
        assert replays == [at_once, kept]
        for x, y in ((a.q, b.q), (a.attitude_covariance, b.attitude_covariance), (a.gyro_bias, b.gyro_bias)):
            assert np.array_equal(x, y), k
        assert (a.rejected, a.health, a.time_since_update) == (b.rejected, b.health, b.time_since_update)
    assert b.health == (Health.CONVERGED if trackers else Health.PROPAGATING) and b.rejected == trackers // 2
    assert rot.angle_between(kept.state.q_BN, truth(t)) < (1e-7 if trackers else 1e-3)


@pytest.mark.parametrize("kind, history, fix", [("magnetometer", 2.0, 3.5), ("sun_sensors", 2.0, 3.5),
                                                ("magnetometer", 1.0, 2.5), ("sun_sensors", 1.0, 2.5)],
                         ids=["field after the fallback", "sun after the fallback",
                              "field within the fallback, the last tracker forgotten",
                              "sun within the fallback, the last tracker forgotten"])
def test_whether_a_vector_is_used_depends_on_the_trackers_before_it_not_on_a_later_one_that_came_first(
        kind, history, fix):
    """Trackers until t = 1 s, then none until a fix at ``fix``; a vector taken 0.05 s before the fix
    and arriving after it (0.1 s late) is used or not as if it had come in time order: by the newest
    tracker measurement before its instant (the one at 1 s, which a 1 s history has forgotten), not
    by the fix. With ``vector_fallback_after`` = 2 s it is used after a 3.5 s fix, not after a 2.5 s one."""
    def vector(t):
        if kind == "magnetometer":
            return MagnetometerMeasurement(t, rot.dcm_BN(truth(t)) @ FIELD_N, np.eye(3), "body")
        return SunSensorMeasurement(t, np.clip(SPECS.sun_sensors.normals @ rot.dcm_BN(truth(t)) @ SUN_N, 0.0, None),
                                    0.0, "body")

    in_order, late, without = (estimator(history=history) for _ in range(3))
    for est in (in_order, late, without):
        converged(est, until=1.0)
    taken = fix - 0.05
    for k in range(21, int(round(fix / 0.05)) + 5):
        t = 0.05 * k
        if abs(t - taken) < 1e-9:
            getattr(in_order, f"on_{kind}")(vector(taken))
        if abs(t - fix) < 1e-9:
            for est in (in_order, late, without):
                est.on_star_tracker(tracker(fix, truth(fix)))
        if abs(t - taken - 0.1) < 1e-9:
            getattr(late, f"on_{kind}")(vector(taken))
        for est in (in_order, late, without):
            est.on_gyro(gyro(t, OMEGA))
    a, b = in_order.state, late.state
    for name in ("t", "q_BN", "bias_B", "P"):
        np.testing.assert_array_equal(getattr(a, name), getattr(b, name))
    assert np.array_equal(a.P, without.state.P) == (taken - 1.0 <= 2.0)     # used only after the fallback


def test_initialisation_from_the_first_tracker_or_from_quest_on_sun_and_field():
    est = estimator()
    assert est.on_gyro(gyro(0.0)).health == Health.INITIALISING
    est.on_star_tracker(tracker(0.05, Q))
    e = est.on_gyro(gyro(0.05))
    assert e.health == Health.CONVERGED and rot.angle_between(e.q, Q) < 1e-9
    # without a tracker: a sun vector and a field sample within the pair window
    est = estimator()
    est.on_gyro(gyro(0.0))
    sun_B, field_B = rot.dcm_BN(Q) @ SUN_N, rot.dcm_BN(Q) @ FIELD_N
    values = np.maximum(np.vstack([np.eye(3), -np.eye(3)]) @ sun_B, 0.0)
    est.on_sun_sensors(SunSensorMeasurement(0.05, values, 0.0, "body"))
    est.on_magnetometer(MagnetometerMeasurement(0.05, field_B, np.eye(3), "body"))
    e = est.on_gyro(gyro(0.05))
    assert rot.angle_between(e.q, Q) < 1e-6
    # ...but with a tracker on board the vectors alone do not make the estimate converged
    assert e.health == Health.PROPAGATING and math.sqrt(np.trace(e.attitude_covariance)) < math.radians(5)


def test_the_covariance_grows_while_blind_and_the_filter_reconverges():
    est = estimator(converged_attitude_sigma=60 * ARCSEC, vector_fallback_after=math.inf)
    sigma = []
    for k in range(1201):
        t = 0.05 * k
        if k % 4 == 0:
            est.on_star_tracker(tracker(t, truth(t), valid=not 10.0 <= t < 40.0))
        e = est.on_gyro(gyro(t, OMEGA))
        sigma.append((t, math.sqrt(np.trace(e.attitude_covariance)), e.health))
    at = {round(t, 2): (s, h) for t, s, h in sigma}
    assert at[9.95][1] == Health.CONVERGED and at[39.95][1] == Health.PROPAGATING
    assert at[39.95][0] > 3 * at[9.95][0]                    # grew on the gyro alone
    assert at[60.0][1] == Health.CONVERGED and at[60.0][0] < 1.5 * at[9.95][0]


def test_a_saturated_gyro_grows_the_attitude_covariance_at_its_range():
    est = estimator()
    est.on_star_tracker(tracker(0.0, Q))
    est.on_gyro(gyro(0.0))
    before = np.trace(est.state.P[:3, :3])
    est.on_gyro(gyro(0.05, [math.radians(5.0), 0, 0]))       # at the range: the true rate may be anything above
    assert np.trace(est.state.P[:3, :3]) - before > (math.radians(5.0) * 0.05) ** 2 * 2
    assert any("saturated" in n for n in est.take_report().notes)


def test_trackers_rejected_in_a_row_lose_the_estimate_which_reinitialises():
    est = estimator(lost_after=3)
    est.on_star_tracker(tracker(0.0, Q))
    est.on_gyro(gyro(0.0))
    wrong = rot.multiply(Q, rot.from_axis_angle([1, 0, 0], 0.2))      # 11 deg away: gated out
    for k in range(1, 4):
        est.on_star_tracker(tracker(0.05 * k, wrong))
        e = est.on_gyro(gyro(0.05 * k))
    assert e.health == Health.DIVERGED and est.monitor.rejected == 3
    est.on_star_tracker(tracker(0.25, wrong))
    e = est.on_gyro(gyro(0.25))
    assert e.health == Health.CONVERGED and rot.angle_between(e.q, wrong) < 1e-9     # the tracker it trusts now


def test_a_magnetometer_sample_taken_while_torquing_is_not_used():
    est = estimator(vector_fallback_after=0.0)
    est.on_star_tracker(tracker(0.0, Q))
    est.on_gyro(gyro(0.0))
    est.on_dipole_command(0.0, np.array([0.0, 5.0, 0.0]))
    est.on_magnetometer(MagnetometerMeasurement(0.05, np.array([1e-5, 0, 0]), np.eye(3), "body"))
    assert not [r for r in est.history.records if r.kind == "magnetometer"]
    est.on_dipole_command(0.05, np.zeros(3))
    est.on_magnetometer(MagnetometerMeasurement(0.1, np.array([1e-5, 0, 0]), np.eye(3), "body"))
    assert [r for r in est.history.records if r.kind == "magnetometer"]


GOOD_GYRO = dict(t=1.0, omega=np.zeros(3), covariance=np.eye(3), frame_id="body")


@pytest.mark.parametrize("make, code", [
    (lambda: gyro(math.nan), ErrorCode.INVALID_MEASUREMENT),
    (lambda: GyroMeasurement(1.0, np.array([math.nan, 0, 0]), np.eye(3), "body"), ErrorCode.INVALID_MEASUREMENT),
    (lambda: GyroMeasurement(1.0, np.array([1e3, 0, 0]), np.eye(3), "body"), ErrorCode.INVALID_MEASUREMENT),
    (lambda: GyroMeasurement(1.0, np.zeros(2), np.eye(3), "body"), ErrorCode.INVALID_MEASUREMENT),
    (lambda: GyroMeasurement(1.0, np.zeros(3), np.eye(3), "sensor"), ErrorCode.INVALID_MEASUREMENT),
    (lambda: gyro(0.5), ErrorCode.STALE_MEASUREMENT),                  # before the last sample (1.0)
    (lambda: gyro(1.0), ErrorCode.STALE_MEASUREMENT),                  # the same stamp again
])
def test_hostile_gyro_samples_are_refused_and_change_nothing(make, code):
    est = estimator()
    est.on_star_tracker(tracker(0.9, Q))
    est.on_gyro(gyro(1.0))
    before = est.state
    with pytest.raises(RequestError) as err:
        est.on_gyro(make())
    assert err.value.code == code and est.state is before
    assert est.on_gyro(gyro(1.05)).health == Health.CONVERGED        # and it carries on


@pytest.mark.parametrize("make, code", [
    (lambda: StarTrackerMeasurement(1.0, "st", np.array([0, 0, 0, 1.1]), np.eye(3), frame_id="eci"),
     ErrorCode.INVALID_MEASUREMENT),                                   # non-unit quaternion
    (lambda: StarTrackerMeasurement(1.0, "st", np.array([0, 0, 0, math.nan]), np.eye(3), frame_id="eci"),
     ErrorCode.INVALID_MEASUREMENT),
    (lambda: StarTrackerMeasurement(1.0, "st", np.zeros(4), np.eye(3), frame_id="eci"), ErrorCode.INVALID_MEASUREMENT),
    (lambda: StarTrackerMeasurement(1.0, "st", rot.IDENTITY, np.full((3, 3), math.inf), frame_id="eci"),
     ErrorCode.INVALID_MEASUREMENT),
    (lambda: tracker(1.0, Q, name="other"), ErrorCode.INVALID_MEASUREMENT),
    (lambda: tracker(1.0, Q, frame="gcrs"), ErrorCode.INVALID_MEASUREMENT),
    (lambda: tracker(-1.0, Q), ErrorCode.INVALID_MEASUREMENT),
    (lambda: tracker(0.2, Q), ErrorCode.STALE_MEASUREMENT),           # older than the filter's 2 s history
    (lambda: MagnetometerMeasurement(1.0, np.array([1.0, 0, 0]), np.eye(3), "body"), ErrorCode.INVALID_MEASUREMENT),
    (lambda: MagnetometerMeasurement(1.0, np.zeros(3), np.eye(3), "body"), ErrorCode.INVALID_MEASUREMENT),
    (lambda: SunSensorMeasurement(1.0, np.full(6, -0.5), 0.0, "body"), ErrorCode.INVALID_MEASUREMENT),
    (lambda: SunSensorMeasurement(1.0, np.zeros(5), 0.0, "body"), ErrorCode.INVALID_MEASUREMENT),
])
def test_hostile_measurements_are_refused_and_the_filter_carries_on(make, code):
    est = estimator()
    for k in range(61):
        if k % 4 == 0:
            est.on_star_tracker(tracker(0.05 * k, truth(0.05 * k)))
        est.on_gyro(gyro(0.05 * k, OMEGA))
    m = make()
    call = {StarTrackerMeasurement: est.on_star_tracker, MagnetometerMeasurement: est.on_magnetometer,
            SunSensorMeasurement: est.on_sun_sensors}[type(m)]
    records = list(est.history.records)
    with pytest.raises(RequestError) as err:
        call(m)
    assert err.value.code == code and est.history.records == records
    e = est.on_gyro(gyro(3.05, OMEGA))
    assert e.health == Health.CONVERGED and rot.angle_between(e.q, truth(3.05)) < 1e-6


def test_an_invalid_tracker_measurement_only_says_it_is_blind():
    est = estimator()
    est.on_star_tracker(tracker(0.0, Q))
    est.on_gyro(gyro(0.0))
    est.on_star_tracker(StarTrackerMeasurement(0.05, "st", rot.IDENTITY, np.full((3, 3), -1.0), valid=False,
                                               frame_id="eci"))
    assert rot.angle_between(est.on_gyro(gyro(0.05)).q, Q) < 1e-9


def test_no_single_gyro_sample_can_steer_the_filters_clock_but_a_restarted_timeline_is_followed():
    est = estimator()
    est.on_star_tracker(tracker(0.0, Q))
    est.on_gyro(gyro(0.0), wall=100.0)
    with pytest.raises(RequestError) as err:                          # 1e6 s ahead, while the gyro is alive
        est.on_gyro(gyro(1e6), wall=100.01)
    assert err.value.code == ErrorCode.STALE_MEASUREMENT
    assert est.on_gyro(gyro(0.05), wall=100.05).health == Health.CONVERGED
    with pytest.raises(RequestError):                                 # a tracker far ahead of the gyro
        est.on_star_tracker(tracker(50.0, Q))
    # the gyro silent for more than resync_timeout: a new timeline (a restarted simulator) starts afresh
    e = est.on_gyro(gyro(3.0), wall=102.0)
    assert e.health == Health.INITIALISING and any("restarted" in n for n in est.take_report().notes)
    est.on_star_tracker(tracker(3.05, Q))
    assert est.on_gyro(gyro(3.05), wall=102.05).health == Health.CONVERGED


def test_a_second_publisher_of_an_input_is_refused_while_the_first_is_in_the_graph_however_long_it_is_silent():
    gyros, trackers = {b"a", b"b"}, {b"b"}
    sources = Sources({"gyro sample": lambda: gyros, "star tracker measurement": lambda: trackers})
    taken = []
    assert sources.guarded("gyro sample", b"a", taken.append, 1) is None and taken == [1]
    for _ in range(1000):                                             # the first one paused, another floods
        with pytest.raises(RequestError) as err:
            sources.guarded("gyro sample", b"b", taken.append, 2)
        assert err.value.code == ErrorCode.INVALID_MEASUREMENT and "second publisher" in err.value.message
    assert taken == [1]
    sources.guarded("star tracker measurement", b"b", taken.append, 3)   # another input: its own publisher
    gyros.discard(b"a")                                               # the first one left the graph: taken over
    sources.guarded("gyro sample", b"b", taken.append, 4)
    gyros.add(b"a")
    with pytest.raises(RequestError):
        sources.guarded("gyro sample", b"a", taken.append, 5)
    assert taken == [1, 3, 4]


def test_a_publisher_whose_message_the_estimator_refuses_never_takes_an_input():
    est = estimator()
    sources = Sources({"gyro sample": lambda: {b"intruder", b"real"}})
    with pytest.raises(RequestError):                                 # the intruder came first, with a NaN rate
        sources.guarded("gyro sample", b"intruder", est.on_gyro, gyro(0.0, omega=np.array([np.nan, 0, 0])))
    assert sources.hold("gyro sample").held is None
    sources.guarded("gyro sample", b"real", est.on_gyro, gyro(0.0))
    assert sources.hold("gyro sample").held == b"real"


def test_a_covariance_that_stops_being_positive_definite_loses_the_estimate_which_reinitialises():
    est = estimator()
    est.on_star_tracker(tracker(0.0, Q))
    est.on_gyro(gyro(0.0))
    t, x = est.history.snapshots[-1]
    broken = np.array(x.P)
    broken[0, 0] = -1e-6                                             # e.g. rounding gone wrong
    est.history.snapshots[-1] = (t, replace(x, P=broken))
    e = est.on_gyro(gyro(0.05))
    assert e.health == Health.DIVERGED and any("positive definite" in n for n in est.take_report().notes)
    assert np.allclose(e.attitude_covariance, np.eye(3) * math.pi**2)   # published as lost, not as known
    est.on_star_tracker(tracker(0.1, Q))
    assert est.on_gyro(gyro(0.1)).health == Health.CONVERGED


def test_estimators_replayed_as_a_batch_reach_the_states_they_reach_alone():
    """replay of a batch (the Monte Carlo's) is each estimator's own reprocessing: late
    trackers, a run whose trackers are wrong until it loses its estimate and reinitialises, a blind
    run, and one of another tuning (propagated on its own) end bit for bit where they end alone."""
    wrong = rot.multiply(Q, rot.from_axis_angle([1, 0, 0], 0.2))

    def streams():
        return [(estimator(), lambda t: truth(t), True), (estimator(lost_after=3), lambda t: wrong, True),
                (estimator(), lambda t: truth(t), False), (estimator(arw=2 * GYRO.arw), lambda t: truth(t), True)]

    alone, batch = streams(), streams()
    for k in range(60):
        t = 0.05 * k
        late = [tracker(t - 0.1, q(t - 0.1), valid=valid) for _, q, valid in alone] if k >= 2 and k % 4 == 2 else None
        for i, (est, _, _) in enumerate(alone):
            if late:
                est.on_star_tracker(late[i])
            est.on_gyro(gyro(t, OMEGA))
        if late:
            replay([(est, est.take_star_tracker(m)) for (est, _, _), m in zip(batch, late)])
        rates = [est.take_gyro(gyro(t, OMEGA)) for est, _, _ in batch]
        replay([(est, est.newest) for est, _, _ in batch])
        for (est, _, _), omega in zip(batch, rates):
            est.publish(t, omega)
    assert alone[1][0].monitor.rejected >= 3 and alone[2][0].state is None
    for (a, _, _), (b, _, _) in zip(alone, batch):
        assert (a.state is None) == (b.state is None) and a.monitor.rejected == b.monitor.rejected
        assert a.monitor.lost_at == b.monitor.lost_at
        if a.state is not None:
            for name in ("t", "q_BN", "bias_B", "P", "C"):
                np.testing.assert_array_equal(getattr(a.state, name), getattr(b.state, name))


def converged(est: Estimator, until: float = 2.0) -> None:
    for k in range(int(round(until / 0.05)) + 1):
        t = 0.05 * k
        if k % 4 == 0:
            est.on_star_tracker(tracker(t, truth(t)))
        est.on_gyro(gyro(t, OMEGA))


def test_each_tracker_innovation_is_kept_with_the_rotation_it_measured():
    """A tracker measurement rotated by a known small body rotation from the truth (the estimate
    converged on the truth) has the innovation y ≈ that rotation and d² = yᵀ S⁻¹ y with S ≥ R."""
    est = estimator()
    converged(est)
    assert [i.used for i in est.take_innovations()] == [True] * 10
    delta = np.array([20.0, -10.0, 5.0]) * ARCSEC
    t = 2.05
    est.on_star_tracker(tracker(t, rot.multiply(truth(t), rot.exp_map(delta))))
    est.on_gyro(gyro(t, OMEGA))                                # applied once the gyro reaches its instant
    (inn,) = est.take_innovations()
    assert inn.sensor == "st" and inn.t == t and inn.used
    assert np.allclose(inn.y, delta, atol=2.0 * ARCSEC)
    assert inn.d2 <= float(inn.y @ np.linalg.solve(inn.R, inn.y)) + 1e-9   # S = H P Hᵀ + R ≥ R
    assert est.take_innovations() == []


def test_an_excluded_tracker_is_not_applied_but_its_innovation_is_computed():
    used, excluded, without = estimator(), estimator(), estimator()
    for est in (used, excluded, without):
        converged(est)
    excluded.excluded.add("st")
    jump = rot.exp_map(np.array([0.0, 300.0, 0.0]) * ARCSEC)              # far beyond the gate
    for k in range(41, 201):
        t = 0.05 * k
        if k % 4 == 0:
            for est in (used, excluded):
                est.on_star_tracker(tracker(t, rot.multiply(truth(t), jump)))
        for est in (used, excluded, without):
            est.on_gyro(gyro(t, OMEGA))
    x, w = excluded.state, without.state
    assert rot.angle_between(x.q_BN, w.q_BN) < 1e-12 and np.allclose(x.P, w.P, rtol=1e-12, atol=0)
    inn = [i for i in excluded.take_innovations() if i.t > 2.0]
    assert len(inn) == 40 and not any(i.used for i in inn) and min(i.d2 for i in inn) > 100.0
    assert excluded.monitor.rejected == 0                                  # not gated: not counted
    assert used.monitor.rejected > 0 and any(not i.used or i.d2 > 100 for i in used.take_innovations())
    # re-admitted: the next measurement is applied again
    excluded.excluded.clear()
    excluded.on_star_tracker(tracker(10.0, truth(10.0)))
    excluded.on_gyro(gyro(10.05, OMEGA))
    assert np.trace(excluded.state.P[:3, :3]) < np.trace(without.state.P[:3, :3])


def test_an_excluded_tracker_does_not_initialise_the_filter():
    est = estimator()
    est.excluded.add("st")
    est.on_gyro(gyro(0.0))
    est.on_star_tracker(tracker(0.05, Q))
    assert est.on_gyro(gyro(0.05)).health == Health.INITIALISING
    est.excluded.clear()
    est.on_star_tracker(tracker(0.1, Q))
    assert est.on_gyro(gyro(0.1)).health == Health.CONVERGED


def test_an_excluded_magnetometer_is_not_used_for_the_vector_fallback():
    est = estimator(vector_fallback_after=0.0)
    converged(est)
    est.excluded.add("magnetometer")
    before = est.state.P.copy()
    est.on_magnetometer(MagnetometerMeasurement(2.0, rot.dcm_BN(truth(2.0)) @ FIELD_N, np.eye(3), "body"))
    assert np.array_equal(est.state.P, before)
