"""Sensor models against their statistics: the gyro's Allan deviation recovers its ARW and
bias instability, the star tracker's noise its σ about each sensor axis, exclusions blind it; the
magnetometer, sun sensors and tachometers as their datasheets say; every stream reproducible from
the seed."""
from __future__ import annotations

import math
from dataclasses import replace

import numpy as np
import pytest

from att_msgs_py.types import TrackerStatus
from att_sim.models import rotations as rot
from att_sim.models.sensor_specs import (
    ARCSEC,
    DEG,
    HOUR,
    Exclusion,
    GyroSpec,
    MagnetometerSpec,
    SensorSpecs,
    StarTrackerSpec,
    SunSensorSpec,
    TachometerSpec,
    sensors_from_params,
)
from att_sim.models.world import Bodies
from att_sim.truth.sensors import SensorSuite
from att_sim.truth.sensors.gyro import Gyro, Gyros
from att_sim.truth.sensors.magnetometer import Magnetometer
from att_sim.truth.sensors.star_tracker import StarTracker
from att_sim.truth.sensors.sun_sensors import SunSensors
from att_sim.truth.sensors.tachometer import Tachometer
from att_sim.truth.sensors.tachometer import measure as measure_tachometers

ARW = 0.01 * DEG / math.sqrt(HOUR)           # 0.01 deg/sqrt(h)
BIAS_INSTABILITY = 0.05 * DEG / HOUR          # 0.05 deg/h
FLOOR = math.sqrt(2 * math.log(2) / math.pi)  # Allan deviation of flicker noise / B (0.664)


def allan_deviation(rate: np.ndarray, dt: float, taus) -> np.ndarray:
    """Overlapping Allan deviation of a rate record (IEEE Std 952-1997, eq. C.6), per axis: (len(taus), 3)."""
    theta = np.vstack([np.zeros(rate.shape[1]), np.cumsum(rate, axis=0) * dt])
    out = []
    for tau in taus:
        m = int(round(tau / dt))
        d = theta[2 * m:] - 2 * theta[m:-m] + theta[:-2 * m]
        out.append(np.sqrt(np.mean(d**2, axis=0) / (2 * tau**2)))
    return np.array(out)


EARTH_RADIUS_ANGLE = math.radians(66.0)       # seen from 7000 km


def bodies(sun=None, moon=None, nadir=(0.0, 0.0, -1.0), earth_radius=EARTH_RADIUS_ANGLE, shadow=1.0) -> Bodies:
    n = np.asarray(nadir, float)
    return Bodies(-7e6 * n, np.array([2e-5, 0.0, 1e-5]), n, earth_radius,
                  None if sun is None else np.asarray(sun, float) / np.linalg.norm(sun),
                  None if moon is None else np.asarray(moon, float) / np.linalg.norm(moon), shadow)


def test_gyro_allan_deviation_recovers_arw_and_bias_instability():
    spec = GyroSpec(rate=10.0, arw=ARW, bias_instability=BIAS_INSTABILITY,
                    rrw=0.002 * DEG / HOUR / math.sqrt(HOUR))
    # ARW: the -1/2 slope at tau = 1 s (sampled at 10 Hz, 20 000 s at rest)
    gyro = Gyro(spec, np.random.default_rng(1))
    fast = gyro.measure(np.zeros((200_000, 3)), 0.1)
    arw = allan_deviation(fast, 0.1, [1.0])[0]            # sigma(1 s) = N
    assert np.all(np.abs(arw / ARW - 1.0) < 0.10), arw / ARW
    # bias instability: the flat floor 0.664 B, at 5000..20000 s (10 s samples over 10^7 s)
    gyro = Gyro(spec, np.random.default_rng(2))
    slow = gyro.measure(np.zeros((1_000_000, 3)), 10.0)
    floor = allan_deviation(slow, 10.0, [5e3, 1e4, 2e4])
    estimate = np.median(floor, axis=0) / FLOOR
    assert np.all(np.abs(estimate / BIAS_INSTABILITY - 1.0) < 0.10), estimate / BIAS_INSTABILITY
    # and the ARW line really is the short-term behaviour: sigma(10 s) sqrt(10) = N as well
    assert np.all(np.abs(allan_deviation(fast, 0.1, [10.0])[0] * math.sqrt(10) / ARW - 1) < 0.1)


def test_gyro_scale_factor_misalignment_saturation_and_quantisation():
    spec = GyroSpec(rate=10.0, scale_factor=1e-3, misalignment=1e-3, quantization=1.0 * ARCSEC,
                    range=math.radians(5.0))
    gyro = Gyro(spec, np.random.default_rng(3))
    assert not np.allclose(gyro.transfer, np.eye(3))
    omega = np.array([0.02, -0.01, 0.03])
    rates = gyro.measure(np.tile(omega * 0.1, (1000, 1)), 0.1)
    # quantised increments: the summed output angle stays within one count of the true transferred angle
    assert np.all(np.abs(rates.sum(axis=0) * 0.1 - 100 * gyro.transfer @ omega) <= spec.quantization + 1e-12)
    assert np.allclose(np.round(rates * 0.1 / spec.quantization), rates * 0.1 / spec.quantization)
    fast = gyro.measure(np.array([1.0, 0.0, -1.0]) * 0.1, 0.1)      # 1 rad/s: beyond the 5 deg/s range
    assert abs(fast[0]) <= spec.range + spec.quantization / 0.1 and abs(fast[0]) > 0.9 * spec.range


def test_star_tracker_noise_matches_its_sigma_about_each_sensor_axis():
    spec = StarTrackerSpec(name="st", mounting=rot.from_axis_angle([1, 2, 3], 0.8), cross_boresight=5 * ARCSEC,
                           about_boresight=40 * ARCSEC)
    tracker = StarTracker(spec, np.random.default_rng(4))
    q = rot.from_axis_angle([0.3, -1, 0.2], 2.0)
    q_S = rot.multiply(q, spec.mounting)
    errors = np.array([rot.log_map(rot.multiply(rot.conjugate(q_S), tracker.measure(0.0, q, np.zeros(3),
                                                                                     bodies()).q))
                       for _ in range(5000)])
    sigma = errors.std(axis=0)
    expected = np.array([spec.cross_boresight, spec.cross_boresight, spec.about_boresight])
    assert np.all(np.abs(sigma / expected - 1.0) < 0.05), sigma / expected
    assert np.all(np.abs(errors.mean(axis=0)) < 4 * expected / math.sqrt(5000))


@pytest.mark.parametrize("exclusion, sky, inside, status", [
    (Exclusion("sun", math.radians(30)), dict(sun=[math.cos(0.4), 0, math.sin(0.4)]), True, TrackerStatus.SUN),
    (Exclusion("sun", math.radians(30)), dict(sun=[math.cos(0.6), 0, math.sin(0.6)]), False, TrackerStatus.OK),
    (Exclusion("moon", math.radians(10)), dict(moon=[math.cos(0.15), math.sin(0.15), 0]), True, TrackerStatus.MOON),
    (Exclusion("moon", math.radians(10)), dict(moon=[math.cos(0.2), math.sin(0.2), 0]), False, TrackerStatus.OK),
    # the Earth counts from its limb: nadir 80 deg from the boresight, radius 66 deg, +20 deg exclusion
    (Exclusion("earth_limb", math.radians(20)), dict(nadir=[math.cos(1.396), 0, -math.sin(1.396)]), True,
     TrackerStatus.EARTH),
    (Exclusion("earth_limb", math.radians(10)), dict(nadir=[math.cos(1.396), 0, -math.sin(1.396)]), False,
     TrackerStatus.OK),
    (Exclusion("inertial", math.radians(5), np.array([1.0, 0.0, 0.0])), {}, True, TrackerStatus.EXCLUDED),
])
def test_star_tracker_reports_invalid_inside_an_exclusion_never_a_wrong_attitude(exclusion, sky, inside, status):
    # boresight (sensor +z) along inertial +x: the sensor frame's z axis turned onto x
    spec = StarTrackerSpec(name="st", mounting=rot.from_axis_angle([0, 1, 0], math.pi / 2), exclusions=(exclusion,))
    m = StarTracker(spec, np.random.default_rng(5)).measure(1.0, rot.IDENTITY, np.zeros(3), bodies(**sky))
    assert m.valid is (not inside) and m.status == status


def test_star_tracker_loses_its_stars_above_its_rate_limit():
    spec = StarTrackerSpec(name="st", max_rate=math.radians(2.0))
    tracker = StarTracker(spec, np.random.default_rng(6))
    assert tracker.measure(0.0, rot.IDENTITY, np.array([0.0, 0.03, 0.0]), bodies()).valid
    slow = tracker.measure(0.0, rot.IDENTITY, np.array([0.0, 0.04, 0.0]), bodies())
    assert not slow.valid and slow.status == TrackerStatus.RATE


def test_magnetometer_noise_bias_misalignment_and_coupling():
    spec = MagnetometerSpec(noise=50e-9, bias=100e-9, misalignment=math.radians(0.2), dipole_coupling=200e-9)
    mag = Magnetometer(spec, np.random.default_rng(7))
    field = np.array([2e-5, -1e-5, 3e-5])
    clean = np.array([mag.measure(0.0, field, np.zeros(3)).field for _ in range(4000)])
    assert np.allclose(clean.mean(axis=0), mag.transfer @ field + mag.bias, atol=4 * 50e-9 / math.sqrt(4000))
    assert np.all(np.abs(clean.std(axis=0) / 50e-9 - 1) < 0.05)
    torquing = np.array([mag.measure(0.0, field, np.array([0.0, 0.0, 5.0])).field for _ in range(4000)])
    assert (torquing - clean).mean(axis=0)[2] == pytest.approx(5.0 * 200e-9, rel=0.02)


def test_sun_sensors_follow_the_cosine_law_their_field_of_view_and_the_shadow():
    spec = SunSensorSpec(fov=math.radians(60.0))
    css = SunSensors(spec, np.random.default_rng(8))
    sun = np.array([math.cos(0.5), 0.0, math.sin(0.5)])          # 28.6 deg from +x, 61.4 deg from +z
    values = css.measure(0.0, rot.IDENTITY, bodies(sun=sun)).values
    assert values == pytest.approx([math.cos(0.5), 0, 0, 0, 0, 0])   # +z sees it at 61.4 deg > 60: dark
    dark = css.measure(0.0, rot.IDENTITY, bodies(sun=sun, shadow=0.0)).values
    assert np.all(dark == 0.0)
    half = css.measure(0.0, rot.IDENTITY, bodies(sun=sun, shadow=0.5)).values
    assert half[0] == pytest.approx(0.5 * math.cos(0.5))


def test_tachometer_noise_and_quantisation():
    tach = Tachometer(TachometerSpec(noise=0.01, quantization=0.005), np.random.default_rng(9))
    speeds = np.array([measure_tachometers([tach], np.array([[100.0, -3.0, 0.0]]))[0] for _ in range(4000)])
    assert np.allclose(np.round(speeds / 0.005) * 0.005, speeds)
    assert np.allclose(speeds.mean(axis=0), [100.0, -3.0, 0.0], atol=0.002)
    assert np.all(np.abs(speeds.std(axis=0) / math.hypot(0.01, 0.005 / math.sqrt(12)) - 1) < 0.08)


def _suite_specs(latency: float = 0.1) -> SensorSpecs:
    return SensorSpecs(seed=1, gyro=GyroSpec(rate=20.0, arw=ARW, initial_bias=1e-5),
                       star_trackers=(StarTrackerSpec(name="st", rate=5.0, latency=latency),),
                       magnetometer=MagnetometerSpec(rate=2.0, noise=50e-9), tachometer=TachometerSpec(rate=10.0))


def _drive(suite: SensorSuite, duration: float, step: float = 0.05):
    out, q, omega = [], rot.IDENTITY, np.array([0.0, 0.01, 0.0])
    for k in range(int(round(duration / step)) + 1):
        t = k * step
        out.append((t, suite.sample(t, q, omega, np.zeros(3), np.array([2e-5, 0, 0]), np.zeros(3), bodies)))
        q = rot.propagate_constant_rate(q, omega, step)
    return out


def test_suite_samples_each_sensor_at_its_rate_and_releases_trackers_after_their_latency():
    samples = _drive(SensorSuite(_suite_specs(), seed=1), 10.0)
    count = {k: sum(getattr(r, k) is not None for _, r in samples) for k in ("gyro", "magnetometer", "wheel_speeds")}
    assert count == {"gyro": 201, "magnetometer": 21, "wheel_speeds": 101}
    released = [(t, m.t) for t, r in samples for m in r.star_trackers]
    assert len(released) == 50 and all(t - measured == pytest.approx(0.1) for t, measured in released)
    # the gyro measures the rotation between its samples, 0.01 rad/s about y (within its 1e-5 rad/s bias)
    rates = np.array([r.gyro.omega for _, r in samples if r.gyro is not None])
    assert np.allclose(rates.mean(axis=0), [0, 0.01, 0], atol=5e-5)


def test_every_stream_is_reproduced_by_its_seed_alone():
    first = _drive(SensorSuite(_suite_specs(), seed=42), 3.0)
    again = _drive(SensorSuite(_suite_specs(), seed=42), 3.0)
    other = _drive(SensorSuite(_suite_specs(), seed=43), 3.0)

    def gyro(run):
        return np.array([r.gyro.omega for _, r in run if r.gyro is not None])
    assert np.array_equal(gyro(first), gyro(again)) and not np.array_equal(gyro(first), gyro(other))
    # a sensor added to the datasheet leaves the others' streams alone
    more = replace(_suite_specs(), sun_sensors=None, tachometer=TachometerSpec(rate=10.0, noise=0.1))
    assert np.array_equal(gyro(_drive(SensorSuite(more, seed=42), 3.0)), gyro(first))


@pytest.mark.parametrize("values, field", [
    ({"gyro": {"arw_deg_per_sqrt_h": -1.0}}, "sensors.gyro.arw_deg_per_sqrt_h"),
    ({"gyro": {"arw_deg_per_sqrt_h": "fast"}}, "sensors.gyro.arw_deg_per_sqrt_h"),
    ({"gyro": {"rate_Hz": 0.0}}, "sensors.gyro.rate_Hz"),
    ({"gyro": {"arw": 0.1}}, "sensors.gyro.arw: expected one of the keys"),
    ({"star_trackers": [{"name": "a", "mounting": [0, 0, 0, 2]}]}, "sensors.star_trackers[0].mounting"),
    ({"star_trackers": [{"name": "a"}, {"name": "a"}]}, "sensors.star_trackers: expected distinct star tracker names"),
    ({"star_trackers": [{"name": "a", "exclusions": [{"body": "sun", "half_angle_deg": 30}]}]},
     "sensors.star_trackers[0].exclusions[0].body sun needs the scenario's epoch"),
    ({"star_trackers": [{"name": "a", "exclusions": [{"body": "inertial", "half_angle_deg": 30}]}]},
     "sensors.star_trackers[0].exclusions[0]: expected direction (a unit inertial vector) for body inertial"),
    ({"star_trackers": [{"name": "a", "exclusions": [{"body": "pluto", "half_angle_deg": 30}]}]},
     "sensors.star_trackers[0].exclusions[0].body: expected 'inertial', 'sun', 'moon' or 'earth_limb'"),
    ({"sun_sensors": {"normals": [1, 0, 0]}}, "sensors.sun_sensors needs the scenario's epoch"),
    ({"magnetometer": {"noise_nT": float("nan")}}, "sensors.magnetometer.noise_nT"),
    ({"seed": -1}, "sensors.seed: expected greater than or equal to 0"),
    ({"seed": 1.5}, "sensors.seed: expected a valid integer"),
    ({"lidar": {}}, "sensors.lidar: expected one of the keys"),
    ([1, 2], "sensors: expected a valid dictionary"),
])
def test_a_bad_sensor_datasheet_is_refused_naming_the_field(values, field):
    with pytest.raises(ValueError, match=None) as err:
        sensors_from_params(values, epoch_known=False)
    assert field in str(err.value)


def test_datasheet_units_are_converted_once():
    specs = sensors_from_params({"gyro": {"arw_deg_per_sqrt_h": 0.01, "bias_instability_deg_per_h": 0.05,
                                          "rrw_deg_per_h_per_sqrt_h": 0.002, "scale_factor_ppm": 50,
                                          "misalignment_arcsec": 20, "range_deg_per_s": 10},
                                 "star_trackers": [{"name": "st", "cross_boresight_arcsec": 3}],
                                 "magnetometer": {"noise_nT": 50}}, epoch_known=True)
    g = specs.gyro
    assert g.arw == pytest.approx(math.radians(0.01) / 60.0) and g.bias_instability == pytest.approx(
        math.radians(0.05) / 3600.0)
    assert g.rrw == pytest.approx(math.radians(0.002) / 3600.0 / 60.0) and g.scale_factor == pytest.approx(5e-5)
    assert g.misalignment == pytest.approx(math.radians(20 / 3600)) and g.range == pytest.approx(math.radians(10))
    assert specs.star_trackers[0].cross_boresight == pytest.approx(math.radians(3 / 3600))
    assert specs.magnetometer.noise == pytest.approx(50e-9)


def _gyro_spec(quantization: float = 0.0) -> GyroSpec:
    return GyroSpec(rate=20.0, arw=ARW, bias_instability=BIAS_INSTABILITY, rrw=1e-9, initial_bias=1e-5,
                    scale_factor=1e-4, misalignment=1e-4, quantization=quantization, range=0.2)


def test_gyros_on_rows_give_each_unit_its_own_rates():
    """Three unlike gyros measured on rows (a batch's) against each one alone from the same stream,
    over intervals of their own; the noise state each one keeps goes on alike."""
    specs = [_gyro_spec(), _gyro_spec(1e-7), replace(_gyro_spec(), bias_instability=0.0)]
    rows = Gyros([Gyro(s, np.random.default_rng(k)) for k, s in enumerate(specs)])
    alone = [Gyro(s, np.random.default_rng(k)) for k, s in enumerate(specs)]
    rng = np.random.default_rng(4)
    for _ in range(5):
        rotation, dts = rng.normal(0, 1e-3, (3, 3)), (0.05, 0.1, 0.05)
        rates = rows.measure(rotation[:, None, :], dts)[:, 0]
        for g, r, dt, got, unit in zip(alone, rotation, dts, rates, rows.gyros):
            np.testing.assert_allclose(got, g.measure(r, dt), rtol=1e-12, atol=1e-18)
            np.testing.assert_allclose(unit.bias, g.bias, rtol=1e-12, atol=1e-20)


def test_a_gyro_measures_many_intervals_at_once_as_one_after_the_other():
    """k consecutive intervals in one call give the rates of k single calls, to rounding: the errors
    drawn once (turn-on bias, scale factor, misalignment), saturation and the quantiser's carried
    remainder (the noise streams are drawn in another order, so the noise is off here)."""
    spec = replace(_gyro_spec(1e-6), arw=0.0, bias_instability=0.0, rrw=0.0)
    batch, single = Gyro(spec, np.random.default_rng(8)), Gyro(spec, np.random.default_rng(8))
    rotation = np.random.default_rng(9).normal(0, 1e-3, (50, 3))
    rotation[7] = [0.05, 0.0, 0.0]                  # 1 rad/s: saturated
    together = batch.measure(rotation, 0.05)
    one_by_one = np.array([single.measure(r, 0.05) for r in rotation])
    np.testing.assert_allclose(together, one_by_one, rtol=1e-9, atol=1e-15)
    np.testing.assert_allclose(batch.carry, single.carry, rtol=0, atol=1e-15)
    assert together[7, 0] == pytest.approx(0.2, abs=1e-6 / 0.05) and np.any(single.carry != 0)
