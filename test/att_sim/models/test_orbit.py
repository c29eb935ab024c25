"""Orbits of the real sky (att_sim.models.orbit): circular, Kepler + J2, TLE/SGP4 to GCRS."""
import importlib.resources
import math

import numpy as np
import pytest
from sgp4.api import Satrec
from skyfield.sgp4lib import TEME

from att_sim.models import environment as env
from att_sim.models import orbit as ob
from att_sim.models.epoch import skyfield_times

EPOCH = "2026-12-21T00:00:00Z"
LINE1 = "1 28485U          26355.00000000  .00000000  00000-0  20000-4 0    07"   # a 580 km, 20.56° LEO
LINE2 = "2 28485  20.5600  60.0000 0005000  90.0000  10.0000 14.95764766    08"


def fix_checksum(line: str) -> str:
    return line[:68] + str(ob.tle_checksum(line))


@pytest.fixture(scope="module")
def leo_orbit():
    return ob.TLEOrbit(EPOCH, LINE1, LINE2)


# ---------------------------------------------------------------- circular
def test_circular_is_environment_position_exactly():
    p = env.OrbitParams(altitude=450e3, inclination=math.radians(87.0), raan=0.4, arg0=0.3)
    o = ob.CircularOrbit(p)
    t = np.linspace(-100.0, 3 * p.period, 777)
    assert np.array_equal(o.position(t), env.position(p, t))
    assert np.array_equal(o.state(t)[0], env.position(p, t))
    assert np.array_equal(o.position(12.5), env.position(p, 12.5))
    assert np.array_equal(o.state(12.5)[0], env.position(p, 12.5))
    h = 1e-3
    np.testing.assert_allclose(o.state(t)[1], (env.position(p, t + h) - env.position(p, t - h)) / (2 * h), atol=1e-5)
    assert o.period == p.period and o.epoch is None


# ---------------------------------------------------------------- Kepler + J2
def test_sun_synchronous_raan_rate_is_one_turn_a_year():
    a, e = env.EARTH_RADIUS + 700e3, 0.001
    n, p = math.sqrt(env.EARTH_MU / a**3), a * (1 - e * e)
    target = 2 * math.pi / (365.2422 * 86400)                  # 0.9856 deg/day
    i = math.acos(-target / (1.5 * n * ob.J2 * (env.EARTH_RADIUS / p) ** 2))
    assert math.degrees(i) == pytest.approx(98.19, abs=0.02)   # the textbook SSO inclination at 700 km
    o = ob.KeplerOrbit(EPOCH, a, e, i, 0.3, 0.5, 0.1)
    assert math.degrees(o.raan_rate) * 86400 == pytest.approx(0.9856, abs=1e-4)
    # the node of r × v, a day later, moved by that rate
    r, v = o.state(np.array([0.0, 86400.0]))
    h = np.cross(r, v)
    node = np.arctan2(h[:, 0], -h[:, 1])
    assert math.degrees(node[1] - node[0]) == pytest.approx(0.9856, abs=2e-3)


def test_j2_rates_hand_formula_and_critical_inclination():
    a, e, i = 7000e3, 0.01, math.radians(63.4349488)
    o = ob.KeplerOrbit(EPOCH, a, e, i, 0.0, 0.0, 0.0)
    assert abs(o.argp_rate) < 1e-12                              # 4 − 5 sin² i = 0
    n, k = math.sqrt(env.EARTH_MU / a**3), ob.J2 * (env.EARTH_RADIUS / (a * (1 - e * e))) ** 2
    assert o.raan_rate == pytest.approx(-1.5 * n * k * math.cos(i), rel=1e-12)
    assert o.mean_motion == pytest.approx(n * (1 + 0.75 * k * math.sqrt(1 - e * e) * (2 - 3 * math.sin(i) ** 2)))
    # ISS-like: Ω̇ ≈ −5.0 deg/day at 51.6°, 400 km (a well-known figure)
    iss = ob.KeplerOrbit(EPOCH, env.EARTH_RADIUS + 400e3, 0.0, math.radians(51.6), 0, 0, 0)
    assert math.degrees(iss.raan_rate) * 86400 == pytest.approx(-5.0, abs=0.1)


def test_equatorial_circular_kepler_by_hand():
    a = 7000e3
    o = ob.KeplerOrbit(EPOCH, a, 0.0, 0.0, 0.2, 0.3, 0.4)
    rate = o.mean_motion + o.argp_rate + o.raan_rate
    t = np.linspace(0.0, 20000.0, 41)
    u = 0.9 + rate * t
    np.testing.assert_allclose(o.position(t), a * np.stack([np.cos(u), np.sin(u), 0 * u], -1), atol=1e-6)
    np.testing.assert_allclose(o.state(t)[1], a * rate * np.stack([-np.sin(u), np.cos(u), 0 * u], -1), atol=1e-9)


def test_kepler_velocity_is_derivative_scalar_equals_vector_and_kepler_solved():
    o = ob.KeplerOrbit(EPOCH, 26600e3, 0.74, math.radians(63.4), 1.0, 4.7, 0.2)    # Molniya
    t = np.linspace(0.0, 2 * o.period, 1001)
    h = 1e-2
    num = (o.position(t + h) - o.position(t - h)) / (2 * h)
    np.testing.assert_allclose(o.state(t)[1], num, atol=2e-4)
    for x in t[::97]:
        rs, vs = o.state(float(x))
        rv, vv = o.state(np.array([x]))
        np.testing.assert_allclose(rs, rv[0], atol=1e-6)
        np.testing.assert_allclose(vs, vv[0], atol=1e-9)
    m = np.linspace(-10, 10, 2001)
    for e in (0.0, 0.3, 0.95):
        big = ob.solve_kepler(m, e)
        np.testing.assert_allclose(big - e * np.sin(big), np.remainder(m + math.pi, 2 * math.pi) - math.pi, atol=1e-13)


@pytest.mark.parametrize("args, words", [
    ((6000e3, 0.0, 0.1, 0, 0, 0), "semi_major_axis"),
    ((7000e3, 1.0, 0.1, 0, 0, 0), "eccentricity"),
    ((7000e3, -0.1, 0.1, 0, 0, 0), "eccentricity"),
    ((7000e3, 0.0, 3.2, 0, 0, 0), "inclination"),
    ((7000e3, 0.0, 0.1, math.nan, 0, 0), "raan"),
    ((7000e3, 0.0, 0.1, 0, True, 0), "arg_perigee"),
])
def test_kepler_bad_elements(args, words):
    with pytest.raises(ValueError, match=words):
        ob.KeplerOrbit(EPOCH, *args)


# ---------------------------------------------------------------- TLE text
def test_leo_tle_parses_and_flies_at_580_km(leo_orbit):
    o = leo_orbit
    assert o.tle_epoch.isoformat() == "2026-12-21T00:00:00+00:00" and o.frame == "GCRS"
    t = np.linspace(0.0, o.period, 200)
    r = np.linalg.norm(o.position(t), axis=-1)
    assert np.mean(r) - env.EARTH_RADIUS == pytest.approx(580e3, abs=10e3)
    assert math.degrees(np.mean(np.arcsin(env.EARTH_RADIUS / r))) == pytest.approx(66.4, abs=0.5)   # limb zone
    assert o.period == pytest.approx(86400 / 14.95764766)
    ob.check_altitude(o, 0.0, 6000.0)


def test_sgp4_ver_tles_pass_the_checks_but_the_three_bad_checksums():
    text = (importlib.resources.files("sgp4") / "SGP4-VER.TLE").read_text()
    lines = [x[:69] for x in text.splitlines() if x and not x.startswith("#")]
    bad = []
    for l1, l2 in zip(lines[::2], lines[1::2]):
        try:
            ob.check_tle(l1, l2)
        except ValueError as err:
            assert "checksum" in str(err)
            bad.append(l1[2:7])
    assert bad == ["33333", "33334", "33335"]


def _replace(line, col, text):           # 1-based column, checksum recomputed
    return fix_checksum(line[:col - 1] + text + line[col - 1 + len(text):])


@pytest.mark.parametrize("line1, line2, words", [
    (LINE1[:68] + "8", LINE2, "line 1 checksum"),
    (LINE1, LINE2[:68] + "0", "line 2 checksum"),
    (LINE1, LINE2.replace("20.5600", "20.5601"), "line 2 checksum"),      # one digit off
    (LINE1[:68] + "x", LINE2, "line 1 checksum"),
    (LINE2, LINE1, "line 1 must start with its line number '1'"),
    (LINE1, _replace(LINE2, 3, "28486"), "satellite numbers differ"),
    (LINE1[:60], LINE2, "line 1 must have 69 characters, got 60"),
    (LINE1, LINE2 + " 7", "line 2 must have 69 characters"),
    (LINE1, _replace(LINE2, 9, " 2X.5600"), "line 2 inclination \\(columns 9-16\\) is malformed"),
    (_replace(LINE1, 19, "2a"), LINE2, "line 1 epoch year"),
    (_replace(LINE1, 54, " 2000-4 "), LINE2, "line 1 B\\* drag term"),
    (LINE1, _replace(LINE2, 27, "000 000"), "line 2 eccentricity"),
    (_replace(LINE1, 33, "."), LINE2, "line 1 column 33 must be a blank"),
    (_replace(LINE1, 21, "400.00000000"), LINE2, "epoch day"),
    (LINE1, _replace(LINE2, 9, "190.0000"), "line 2 inclination"),
    (LINE1, _replace(LINE2, 53, " 0.00000000"), "mean motion"),
    ("1 28485U é" + LINE1[10:], LINE2, "ASCII"),
    (None, LINE2, "line 1 must be ASCII text"),
])
def test_bad_tle_is_a_value_error_naming_line_and_fault(line1, line2, words):
    with pytest.raises(ValueError, match=words):
        ob.TLEOrbit(EPOCH, line1, line2)


def test_trailing_blanks_and_checksum_of_minus_signs():
    o = ob.TLEOrbit(EPOCH, LINE1 + "  ", LINE2 + "\n")
    assert o.line1 == LINE1 and o.line2 == LINE2
    assert ob.tle_checksum("1 -----" + " " * 62) == 6


# ---------------------------------------------------------------- SGP4 against its verification vectors
def _verification():
    files = importlib.resources.files("sgp4")
    lines = [x for x in (files / "SGP4-VER.TLE").read_text().splitlines() if x and not x.startswith("#")]
    tles = {a[2:7].lstrip("0"): (a[:69], b[:69]) for a, b in zip(lines[::2], lines[1::2])}
    ref, cur = {}, None
    for row in (files / "tcppver.out").read_text().splitlines():
        if "xx" in row:
            cur = row.split()[0]
            ref[cur] = []
        else:
            ref[cur].append([float(x) for x in row.split()[:7]])
    return tles, {k: np.array(v) for k, v in ref.items()}


@pytest.mark.parametrize("sat", ["5", "6251", "8195", "28057"])   # eccentric LEO, drag, Molniya (SDP4), SSO
def test_sgp4_teme_matches_tcppver_and_tle_orbit_rotates_it_to_gcrs(sat):
    tles, ref = _verification()
    line1, line2 = tles[sat]
    rows = ref[sat]
    satrec = Satrec.twoline2rv(line1, line2)
    for row in rows:                                  # the published TEME vectors, printed to 1e-8 km
        err, r, v = satrec.sgp4_tsince(row[0])
        assert err == 0
        np.testing.assert_allclose(r, row[1:4], atol=2e-8)
        np.testing.assert_allclose(v, row[4:7], atol=2e-11)
    # TLEOrbit with sim time zero at the TLE epoch: its GCRS, rotated back to TEME, is the same
    probe = ob.TLEOrbit("2000-01-01T00:00:00Z", line1, line2)
    o = ob.TLEOrbit(probe.tle_epoch, line1, line2)
    t = rows[:, 0] * 60.0
    r_gcrs = o.direct_state(t)[0]
    near = np.abs(t) <= 43200.0                                    # the table over the first 12 h (time)
    np.testing.assert_allclose(o.position(t[near]), r_gcrs[near], atol=1e-3)
    rot = TEME.rotation_at(skyfield_times(o.epoch, t))             # GCRS -> TEME, (3, 3, N)
    r_teme = np.einsum("ijn,nj->ni", rot, r_gcrs)
    np.testing.assert_allclose(r_teme / 1e3, rows[:, 1:4], atol=1e-5)     # 1 cm: the epoch is kept to 1 µs
    angle = np.arccos(np.clip(np.sum(r_teme * r_gcrs, -1) / np.linalg.norm(r_gcrs, axis=-1) ** 2, -1, 1))
    assert np.all(angle < math.radians(0.1))        # epochs 2000-2006: little precession yet


def test_gcrs_differs_from_teme_by_precession_since_j2000(leo_orbit):
    t = np.linspace(0.0, 6000.0, 7)
    rot = TEME.rotation_at(skyfield_times(EPOCH, t))
    angle = np.degrees(np.arccos((np.trace(rot) - 1.0) / 2.0))
    # general precession 50.29"/yr × 26.97 yr = 0.377° (nutation adds at most ~0.005°)
    assert angle == pytest.approx(np.full(7, 0.377), abs=0.01)
    e, r, _ = leo_orbit.satrec.sgp4_array(np.full(7, leo_orbit.satrec.jdsatepoch), t / 86400.0)
    r_gcrs = leo_orbit.position(t)
    np.testing.assert_allclose(np.einsum("ijn,nj->ni", rot, r_gcrs) / 1e3, r, atol=1e-5)
    between = np.degrees(np.arccos(np.sum(r * 1e3 * r_gcrs, -1) / np.linalg.norm(r_gcrs, axis=-1) ** 2))
    assert np.all(between < 0.39) and np.max(between) > 0.1


# ---------------------------------------------------------------- tabulation
def test_table_matches_direct_evaluation(leo_orbit):
    o = leo_orbit
    t = np.random.default_rng(1).uniform(-3000.0, 12000.0, 400)
    r, v = o.state(t)
    r_direct, v_sgp4 = o.direct_state(t)
    assert np.max(np.linalg.norm(r - r_direct, axis=-1)) < 1e-3                 # ≤ 1 mm (measured ~1e-5 m)
    h = 0.25
    num = (o.direct_state(t + h)[0] - o.direct_state(t - h)[0]) / (2 * h)
    assert np.max(np.linalg.norm(v - num, axis=-1)) < 1e-3                      # v = dr/dt of SGP4's r
    assert np.max(np.linalg.norm(v - v_sgp4, axis=-1)) < 0.1                    # SGP4's own v: ~5 cm/s off
    rs, vs = o.state(float(t[3]))
    np.testing.assert_allclose(rs, r[3], atol=1e-6)
    np.testing.assert_allclose(vs, v[3], atol=1e-9)
    assert o.state(t.reshape(20, 20))[0].shape == (20, 20, 3)


def test_scalar_calls_agree_with_one_call_on_2000_times(leo_orbit):
    """Each orbit model answers a scalar time as it answers that time in a vector of 2000."""
    orbits = [leo_orbit, ob.KeplerOrbit(EPOCH, 7000e3, 0.01, 1.7, 0.3, 0.5, 0.1),
              ob.CircularOrbit(env.OrbitParams())]
    t = np.linspace(0.0, 9000.0, 2000)
    for o in orbits:
        r, v = o.state(t)
        scalar = [o.state(x) for x in t[:300].tolist()]
        np.testing.assert_allclose([rs for rs, _ in scalar], r[:300], rtol=1e-12, atol=1e-6, err_msg=type(o).__name__)
        np.testing.assert_allclose([vs for _, vs in scalar], v[:300], rtol=1e-12, atol=1e-9, err_msg=type(o).__name__)


# ---------------------------------------------------------------- altitude and decay
def test_check_altitude_low_perigee_and_decay():
    low = ob.KeplerOrbit(EPOCH, env.EARTH_RADIUS + 400e3, 0.02, 1.0, 0.0, 0.0, math.pi)   # perigee ≈ 253 km
    ob.check_altitude(low, 0.0, 6000.0, minimum=150e3)
    with pytest.raises(ValueError, match="below the minimum 300 km at t = 2"):
        ob.check_altitude(low, 0.0, 6000.0, minimum=300e3)
    with pytest.raises(ValueError, match="below the minimum 150 km"):
        ob.check_altitude(ob.CircularOrbit(env.OrbitParams(altitude=120e3)), 0.0, 10.0)
    # a heavy-drag TLE decays within hours: the altitude crosses 150 km, then SGP4 fails
    decay = ob.TLEOrbit(EPOCH, fix_checksum(LINE1.replace(" 20000-4", " 99999-1")),
                        fix_checksum(LINE2.replace("14.95764766", "16.05764766")))
    ob.check_altitude(decay, 0.0, 3600.0)
    with pytest.raises(ValueError, match="below the minimum 150 km"):
        ob.check_altitude(decay, 0.0, 86400.0)
    with pytest.raises(ValueError, match="SGP4 cannot propagate"):
        ob.check_altitude(decay, 0.0, 86400.0, minimum=0.0)
    with pytest.raises(ValueError, match="SGP4 cannot propagate the TLE from t = 1"):
        decay.state(86400.0)
    with pytest.raises(ValueError, match="t0 <= t1"):
        ob.check_altitude(low, 10.0, 0.0)


# ---------------------------------------------------------------- scenario orbit group
CRAFT = {"inertia_kg_m2": [1.0, 1.0, 1.0], "wheel_axes": []}


def _scenario_orbit(orbit: dict, epoch=None):
    """The orbit a scenario's ``orbit`` group builds: validated by the schema, built by the scenario reader."""
    from types import SimpleNamespace

    from att_sim.models import config_schema as cs
    from att_sim.models import scenario as scen
    shared = cs.Shared.model_validate({"spacecraft": CRAFT, "orbit": orbit, "epoch": epoch})
    build = scen._Build(SimpleNamespace(shared=shared, lines={}, path="scenario.yaml"))
    return build.orbit(build.epoch())


def test_the_scenario_orbit_group_of_each_type():
    o = _scenario_orbit({})
    assert isinstance(o, ob.CircularOrbit) and o.params == env.OrbitParams()
    o = _scenario_orbit({"type": "circular", "altitude_m": 500e3, "inclination_deg": 45.0, "arg0_rad": 0.5})
    assert o.params == env.OrbitParams(altitude=500e3, inclination=math.radians(45), raan=0.0, arg0=0.5)
    k = _scenario_orbit({"type": "kepler", "semi_major_axis_m": 7e6, "eccentricity": 0.001,
                         "inclination_deg": 98.0, "raan_deg": 10.0, "arg_perigee_deg": 20.0,
                         "mean_anomaly_deg": 30.0}, EPOCH)
    assert isinstance(k, ob.KeplerOrbit) and k.i == pytest.approx(math.radians(98))
    t = _scenario_orbit({"type": "tle", "line1": LINE1, "line2": LINE2}, EPOCH)
    assert isinstance(t, ob.TLEOrbit) and t.epoch.year == 2026


@pytest.mark.parametrize("orbit, epoch, words", [
    ({"type": "sgp8"}, EPOCH, "does not match any of the expected tags: 'circular', 'kepler', 'tle'"),
    ({"type": "tle", "line1": LINE1, "line2": LINE2, "bstar": 1}, EPOCH, "orbit.tle.bstar\n  Extra inputs"),
    ({"altitude_m": 5e5, "semi_major_axis_m": 7e6}, None, "semi_major_axis_m\n  Extra inputs"),
    ({"type": "tle", "line1": LINE1}, EPOCH, "orbit.tle.line2\n  Field required"),
    ({"type": "tle", "line1": LINE1, "line2": LINE2}, None, "an epoch .* for orbit type tle"),
    ({"type": "kepler", "semi_major_axis_m": "7e6", "eccentricity": 0.0, "inclination_deg": 0.0, "raan_deg": 0.0,
      "arg_perigee_deg": 0.0, "mean_anomaly_deg": 0.0}, EPOCH, "semi_major_axis_m\n  Input should be a valid number"),
    ({"altitude_m": -1.0}, None, "altitude_m\n  Input should be greater than 0"),
    ({"inclination_deg": True}, None, "inclination_deg\n  Input should be a valid number"),
    ({"type": "tle", "line1": LINE1, "line2": LINE2}, "2026-12-21", "epoch must carry"),
    ([1, 2], None, "orbit.circular\n  Input should be a valid dictionary"),
])
def test_a_bad_scenario_orbit_group_is_refused(orbit, epoch, words):
    from pydantic import ValidationError
    with pytest.raises(ValidationError, match=words):
        _scenario_orbit(orbit, epoch)


def test_sgp4_error_cases_of_the_verification_file():
    """33334 is refused at initialisation, 33333 fails after ~20 min (checksums fixed: the file's are wrong)."""
    tles, _ = _verification()
    line1, line2 = (fix_checksum(x) for x in tles["33334"])
    with pytest.raises(ValueError, match="rejected by SGP4: perturbed eccentricity"):
        ob.TLEOrbit(EPOCH, line1, line2)
    line1, line2 = (fix_checksum(x) for x in tles["33333"])
    o = ob.TLEOrbit(ob.TLEOrbit(EPOCH, line1, line2).tle_epoch, line1, line2)
    with pytest.raises(ValueError, match="semilatus rectum is less than zero"):
        ob.check_altitude(o, 0.0, 3600.0, minimum=0.0)
