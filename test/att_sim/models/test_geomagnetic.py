"""IGRF-14 field, Earth rotation table and field track of att_sim.models.geomagnetic."""
import math
import time
from datetime import UTC, datetime

import numpy as np
import pytest

from att_sim.models import environment as env
from att_sim.models import geomagnetic as gm

# Reference values computed by IAGA's own Fortran synthesis program igrf14syn (geocentric input),
# as published with the test suite of SatelliteToolboxGeomagneticField.jl (JuliaSpace,
# test/IGRF14_test_geocentric.txt): decimal year, r (km), colatitude (deg), east longitude (deg),
# X north, Y east, Z down, F (nT). Rows chosen to span 1900..2033, the poles, the equator, the
# 2025-2030 secular variation and the 2030-2035 extrapolation.
IGRF14SYN = """
1900.0 6610.46 68.00 165.11  27405.59329   3074.66838  17132.54518  32466.04740
1971.9 6750.33  4.23 244.39  -1045.63966    128.93455  48340.11401  48351.59366
1991.7 7895.51 34.52 186.99   9961.03296   1855.53539  25360.82131  27310.00635
2012.2 6455.32  4.81 190.69    716.25521    404.85533  54898.32179  54904.48675
1956.4 7498.84 53.01 334.96  14106.28273  -4195.64922  22882.02175  27206.20525
1985.4 7610.26 89.19 131.52  21665.00649    807.74391  -6604.88493  22663.83598
2022.1 7207.24 46.47 114.85  17343.43338  -1717.75319  33139.75721  37443.14177
2027.9 6518.00 45.06 138.29  23401.96250  -4296.86589  42525.97951  48729.59920
2027.0 6480.13 68.54 277.27  24526.15584  -2284.08774  29399.38466  38354.57202
2033.2 7190.36 23.95  32.66   8342.29093   1792.93586  37807.77776  38758.69575
1985.1 7386.16  0.05   0.32    664.68242  -1268.46751  37518.62935  37545.94999
1949.3 6738.43 89.92  55.30  28321.59739  -1639.20107  -9689.29713  29978.03092
2019.6 7239.98 41.70  23.47  14510.71642   1050.50604  30315.14930  33625.47741
"""
# Same source, geodetic input (test/IGRF14_test_geodetic.txt): year, height above WGS-84 (km),
# geodetic colatitude (deg), east longitude (deg), X, Y, Z (nT) in the geodetic local frame.
IGRF14SYN_GEODETIC = """
1977.5  611.63 18.90  12.59   8387.94253   -721.95950  40461.24224
1982.4 1261.94 23.56 319.36   5513.70089  -3010.23939  32217.22119
2027.9  139.86 45.06 138.29  23759.41728  -4335.97718  42511.80742
2033.2  812.22 23.95  32.66   8521.38373   1820.76747  38032.79714
"""
EPOCH = "2026-12-21T00:00:00Z"


def _ecef(r, colat, lon):
    th, ph = np.radians(colat), np.radians(lon)
    return np.asarray(r)[..., None] * np.stack(np.broadcast_arrays(np.sin(th) * np.cos(ph), np.sin(th) * np.sin(ph),
                                                                   np.cos(th)), -1)


def _xyz(b, r_itrs):
    """North, east, down components of ``b`` at ``r_itrs`` (geocentric local axes)."""
    up = r_itrs / np.linalg.norm(r_itrs, axis=-1, keepdims=True)
    east = np.cross([0.0, 0.0, 1.0], up)
    east /= np.linalg.norm(east, axis=-1, keepdims=True)
    north = np.cross(up, east)
    return np.stack([np.sum(b * north, -1), np.sum(b * east, -1), -np.sum(b * up, -1)], -1)


def test_matches_igrf14syn_reference_values():
    rows = np.array([line.split() for line in IGRF14SYN.split("\n") if line.strip()], float)
    year, r, colat, lon, ref = rows[:, 0], rows[:, 1] * 1e3, rows[:, 2], rows[:, 3], rows[:, 4:7]
    r_itrs = _ecef(r, colat, lon)
    got = _xyz(gm.igrf_field_geocentric(r_itrs, year), r_itrs) * 1e9      # per-point years
    np.testing.assert_allclose(got, ref, atol=0.05)                        # nT (≤ 0.014 on all 2000 rows)
    np.testing.assert_allclose(np.linalg.norm(got, axis=1), rows[:, 7], atol=0.05)
    for k in (0, 7, 10):                                                   # scalar path, same numbers
        one = _xyz(gm.igrf_field_geocentric(r_itrs[k], year[k]), r_itrs[k]) * 1e9
        np.testing.assert_allclose(one, got[k], atol=1e-9)


def test_matches_igrf14syn_geodetic_values_through_wgs84():
    rows = np.array([line.split() for line in IGRF14SYN_GEODETIC.split("\n") if line.strip()], float)
    lat, lon, h = np.radians(90.0 - rows[:, 2]), np.radians(rows[:, 3]), rows[:, 1] * 1e3
    a, f = 6378137.0, 1 / 298.257223563
    e2 = f * (2 - f)
    n = a / np.sqrt(1 - e2 * np.sin(lat) ** 2)
    r_itrs = np.stack([(n + h) * np.cos(lat) * np.cos(lon), (n + h) * np.cos(lat) * np.sin(lon),
                       (n * (1 - e2) + h) * np.sin(lat)], -1)
    b = gm.igrf_field_geocentric(r_itrs, rows[:, 0]) * 1e9
    up = np.stack([np.cos(lat) * np.cos(lon), np.cos(lat) * np.sin(lon), np.sin(lat)], -1)   # ellipsoid normal
    east = np.stack([-np.sin(lon), np.cos(lon), 0.0 * lon], -1)
    north = np.cross(up, east)
    got = np.stack([np.sum(b * north, -1), np.sum(b * east, -1), -np.sum(b * up, -1)], -1)
    np.testing.assert_allclose(got, rows[:, 4:7], atol=0.1)              # nT (observed ≤ 0.08 on 2000 rows)


def test_matches_ppigrf_geocentric_at_model_epochs():
    import ppigrf

    colat, lon, r = np.array([30.0, 90.0, 120.0, 170.0]), np.array([10.0, -75.0, 140.0, 300.0]), 6900.0
    for year in (1965, 2020, 2025, 2030):
        br, bt, bp = (c[0] for c in ppigrf.igrf_gc(r, colat, lon, datetime(year, 1, 1)))
        r_itrs = _ecef(r * 1e3, colat, lon)
        got = _xyz(gm.igrf_field_geocentric(r_itrs, float(year)), r_itrs) * 1e9
        np.testing.assert_allclose(got, np.stack([-bt, bp, -br], -1), atol=0.1)


def test_coefficients_and_secular_variation_of_igrf14():
    years, g, h = gm.igrf14_coefficients()
    assert years[0] == 1900.0 and years[-1] == 2030.0 and g.shape == (27, 104)
    k10, k11 = gm._TERMS.index((1, 0)), gm._TERMS.index((1, 1))
    assert g[-2, k10] == -29350.0 and g[-2, k11] == -1410.3 and h[-2, k11] == 4545.5   # IGRF-14 2025
    # 2025-2030: g10 moves by its published SV, 12.6 nT/yr; after 2030 the same rate continues
    c = [gm._coefficients(y)[k10] for y in (2025.0, 2026.0, 2031.0)]
    assert c[1] - c[0] == pytest.approx(12.6) and c[2] - c[0] == pytest.approx(6 * 12.6)


def test_field_magnitude_at_the_surface_is_earth_like():
    lon = np.linspace(0.0, 350.0, 36)
    equator = np.linalg.norm(gm.igrf_field_geocentric(_ecef(6371.2e3, 90.0, lon), 2026.9), axis=-1)
    assert 25e-6 < equator.min() and equator.max() < 45e-6                # 30 µT class (27 .. 43 µT)
    poles = np.linalg.norm(gm.igrf_field_geocentric(_ecef(6371.2e3, np.array([0.0, 180.0]), 0.0), 2026.9),
                           axis=-1)
    assert np.all((50e-6 < poles) & (poles < 68e-6))                      # 60 µT class
    assert np.all(np.isfinite(poles))


def test_dipole_mode_is_environment_field():
    orbit = env.OrbitParams(altitude=450e3, inclination=math.radians(87.0), raan=0.3, arg0=0.2)
    t = np.linspace(0.0, 2 * orbit.period, 41)
    field = gm.GeomagneticField("dipole")
    np.testing.assert_allclose(field.field_inertial(t, env.position(orbit, t)), env.field_inertial(orbit, t),
                               rtol=1e-13, atol=1e-22)
    np.testing.assert_allclose(field.field_inertial(t[3], env.position(orbit, t[3])),
                               env.field_inertial(orbit, t[3]), rtol=1e-13, atol=1e-22)


def test_rotation_table_matches_skyfield_itrs():
    from skyfield.framelib import itrs

    from att_sim.models.epoch import skyfield_times

    field = gm.GeomagneticField("igrf14", EPOCH)
    t = np.concatenate([np.random.default_rng(1).uniform(-3600.0, 2 * 86400.0, 40), [0.0, 86400.0]])
    direct = np.moveaxis(itrs.rotation_at(skyfield_times(field.epoch, t)), -1, 0)
    table = field.itrs_rotation(t)
    angle = [np.linalg.norm(a @ b.T - np.eye(3)) for a, b in zip(table, direct)]
    assert max(angle) < 1e-9                                              # rad (observed 5e-11)
    for k in (0, 5, 40):
        np.testing.assert_allclose(np.reshape(field._rotation.matrix_at(t[k]), (3, 3)), table[k], atol=1e-14)


def test_inertial_field_is_the_rotated_earth_fixed_field():
    field = gm.GeomagneticField("igrf14", datetime(2026, 12, 21, tzinfo=UTC))
    assert field.decimal_year(0.0) == pytest.approx(2026 + 354 / 365)
    orbit = env.OrbitParams(altitude=580e3, inclination=math.radians(20.56))
    t = np.linspace(0.0, 6000.0, 7)
    r = env.position(orbit, t)
    b = field.field_inertial(t, r)
    rot = field.itrs_rotation(t)
    expect = np.einsum("kji,kj->ki", rot, gm.igrf_field_geocentric(np.einsum("kij,kj->ki", rot, r),
                                                                   field.decimal_year(t)))
    np.testing.assert_allclose(b, expect, rtol=1e-12, atol=1e-20)
    np.testing.assert_allclose(field.field_inertial(t[2], r[2]), b[2], rtol=1e-12, atol=1e-20)
    # the Earth turns under the inertial point: one sidereal day later the field repeats (to SV)
    sidereal = 2 * math.pi / gm.EARTH_ROTATION_RATE
    np.testing.assert_allclose(field.field_inertial(sidereal, r[1]), field.field_inertial(0.0, r[1]),
                               atol=2e-9)                                # T; 100 nT/yr × 1 day ≪ 2 nT
    assert not np.allclose(field.field_inertial(sidereal / 4, r[1]), field.field_inertial(0.0, r[1]),
                           atol=2e-7)


def test_field_track_is_accurate_and_fast():
    field = gm.GeomagneticField("igrf14", EPOCH)
    orbit = env.OrbitParams(altitude=400e3, inclination=math.radians(51.6))
    track = field.track(lambda t: env.position(orbit, t), 0.0, 6000.0)
    t = np.random.default_rng(3).uniform(0.0, 6000.0, 200)
    direct = field.field_inertial(t, env.position(orbit, t))
    np.testing.assert_allclose(track(t), direct, atol=1e-12)              # 1e-3 nT
    np.testing.assert_allclose(track(float(t[7])), direct[7], atol=1e-12)
    np.testing.assert_allclose(track(6000.0), field.field_inertial(6000.0, env.position(orbit, 6000.0)),
                               atol=1e-15)
    start = time.perf_counter()
    for tk in t.tolist() * 5:
        track(tk)
    assert (time.perf_counter() - start) / 1000 < 50e-6                   # s per scalar call (observed 3 µs)


def test_bad_input_is_refused():
    with pytest.raises(ValueError, match="field_model must be one of igrf14, dipole"):
        gm.GeomagneticField("wmm")
    with pytest.raises(ValueError, match="needs an epoch"):
        gm.GeomagneticField("igrf14")
    with pytest.raises(ValueError, match="from 1900 to 2035"):
        gm.GeomagneticField("igrf14", "2040-01-01T00:00:00Z")
    for year in (1899.9, 2035.1, math.nan):
        with pytest.raises(ValueError, match="decimal_year must be from 1900 to 2035"):
            gm.igrf_field_geocentric([7e6, 0.0, 0.0], year)
    with pytest.raises(ValueError, match="r_ITRS must be finite with a norm of at least 3480 km"):
        gm.igrf_field_geocentric([1e6, 0.0, 0.0], 2026.0)
    with pytest.raises(ValueError, match="trailing axis of 3"):
        gm.igrf_field_geocentric([7e6, 0.0], 2026.0)
    track = gm.GeomagneticField("dipole").track(lambda t: env.position(env.OrbitParams(), t), 0.0, 100.0)
    for t in (100.5, math.nan, np.array([0.0, -1.0])):
        with pytest.raises(ValueError, match=r"within the field track's span \[0.0, 100.0\]"):
            track(t)
    with pytest.raises(ValueError, match="itrs_rotation needs an epoch: this dipole field has none"):
        gm.GeomagneticField("dipole").itrs_rotation(0.0)
    assert gm.GeomagneticField("dipole", EPOCH).itrs_rotation(0.0).shape == (3, 3)
    with pytest.raises(ValueError, match="t1 > t0"):
        gm.GeomagneticField("dipole").track(lambda t: t, 10.0, 10.0)
