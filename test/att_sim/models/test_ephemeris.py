"""The sky seen from the spacecraft (att_sim.models.ephemeris): DE421 Sun and Moon, shadow."""
import math
import pickle

import numpy as np
import pytest

from att_sim.models import environment as env
from att_sim.models import ephemeris as eph
from att_sim.models import orbit as ob

EPOCH = "2026-12-21T00:00:00Z"
LINE1 = "1 28485U          26355.00000000  .00000000  00000-0  20000-4 0    07"
LINE2 = "2 28485  20.5600  60.0000 0005000  90.0000  10.0000 14.95764766    08"
AU = 1.495978707e11
SOLSTICE = 20 * 3600.0 + 50 * 60.0         # 2026-12-21T20:50Z, the December solstice (USNO)


@pytest.fixture(scope="module")
def sky():
    return eph.Ephemeris(EPOCH, ob.TLEOrbit(EPOCH, LINE1, LINE2))


def _angle(u, v):
    u, v = eph._unit(np.asarray(u, float)), eph._unit(np.asarray(v, float))
    return np.arctan2(np.linalg.norm(np.cross(u, v), axis=-1), np.sum(u * v, -1))


def test_sun_at_the_december_solstice(sky):
    sun = sky.sun(SOLSTICE)
    assert math.degrees(math.asin(sun[2] / np.linalg.norm(sun))) == pytest.approx(-23.44, abs=0.01)
    assert np.linalg.norm(sun) / AU == pytest.approx(0.9838, abs=0.001)
    # geocentric vs from the spacecraft: at most |r|/AU apart
    assert _angle(sky.sun_direction(SOLSTICE), sun) <= np.linalg.norm(sky.position(SOLSTICE)) / AU * 1.01
    assert eph.de421() is eph.de421()


def test_moon_parallax_from_leo_is_about_a_degree(sky):
    t = np.linspace(0.0, sky.orbit.period, 400)
    parallax = np.degrees(_angle(sky.moon_direction(t), sky.moon(t)))
    moon_distance = np.linalg.norm(sky.moon(0.0))
    assert 356e6 < moon_distance < 407e6
    bound = math.degrees(math.asin(np.max(np.linalg.norm(sky.position(t), axis=-1)) / moon_distance))
    assert 0.95 < np.max(parallax) <= bound * 1.001 and bound == pytest.approx(1.08, abs=0.03)


def test_tables_match_direct_evaluation(sky):
    t = np.random.default_rng(2).uniform(-3600.0, 2 * 86400.0, 300)
    for table, direct in ((sky.sun, sky.direct_sun), (sky.moon, sky.direct_moon)):
        a, b = table(t), direct(t)
        assert np.max(np.linalg.norm(a - b, axis=-1)) < 1.0            # measured: 1e-4 m (Sun), 2e-5 m (Moon)
        assert np.max(_angle(a, b)) < 1e-7                             # measured: < 1e-13 rad
        np.testing.assert_allclose(table(float(t[7])), a[7], rtol=1e-15, atol=1e-6)


def test_earth_directions_and_angular_radius(sky):
    t = np.array([0.0, 1234.5])
    r = sky.position(t)
    np.testing.assert_allclose(sky.nadir(t), -r / np.linalg.norm(r, axis=-1, keepdims=True))
    rho = sky.earth_angular_radius(t)
    np.testing.assert_allclose(np.sin(rho), env.EARTH_RADIUS / np.linalg.norm(r, axis=-1))
    assert math.degrees(float(np.mean(rho))) == pytest.approx(66.4, abs=0.6)   # a ~66° limb at 580 km
    np.testing.assert_allclose(sky.velocity(t), sky.orbit.state(t)[1])


def test_sky_epoch_may_differ_from_the_orbits():
    orbit = ob.TLEOrbit(EPOCH, LINE1, LINE2)
    later = eph.Ephemeris("2026-12-21T00:10:00Z", orbit)
    assert later.orbit_offset == pytest.approx(600.0, abs=1e-6)
    np.testing.assert_allclose(later.position(5.0), orbit.position(605.0), atol=1e-6)
    np.testing.assert_allclose(later.sun(0.0), eph.Ephemeris(EPOCH, orbit).sun(600.0), rtol=1e-14)
    circular = eph.Ephemeris(EPOCH, ob.CircularOrbit(env.OrbitParams()))       # epoch-free: starts at the sky's epoch
    assert circular.orbit_offset == 0.0
    np.testing.assert_array_equal(circular.position(10.0), env.position(env.OrbitParams(), 10.0))


# ---------------------------------------------------------------- shadow
R_SUN = np.array([AU, 0.0, 0.0])


def _grid_fraction(a, b, c, n=801):
    """Visible fraction of a disc of radius a at distance c from an occulting disc of radius b (grid)."""
    x, y = np.meshgrid(np.linspace(-a, a, n), np.linspace(-a, a, n))
    inside = x * x + y * y <= a * a
    visible = (x + c) ** 2 + y * y > b * b
    return np.sum(inside & visible) / np.sum(inside)


def test_shadow_full_sun_umbra_annular():
    assert eph.shadow_function([7000e3, 0, 0], R_SUN) == 1.0                  # sunward
    assert eph.shadow_function([0, 7000e3, 0], R_SUN) == 1.0                  # over the terminator, 1000 km up
    assert eph.shadow_function([-7000e3, 0, 0], R_SUN) == 0.0                 # behind the Earth: umbra
    far = np.array([-3e9, 0.0, 0.0])                                         # beyond the umbra's apex (1.4e9 m)
    a = math.asin(eph.SUN_RADIUS / (AU + 3e9))
    b = math.asin(env.EARTH_RADIUS / 3e9)
    assert eph.shadow_function(far, R_SUN) == pytest.approx(1 - b * b / (a * a), rel=1e-12)   # annular


def test_shadow_penumbra_matches_a_grid_integration():
    rn = 7000e3
    b = math.asin(env.EARTH_RADIUS / rn)
    a = math.asin(eph.SUN_RADIUS / AU)
    values = []
    for frac in np.linspace(-0.9, 0.9, 7):                 # Sun centre from inside to outside the limb
        c = b + frac * a
        # spacecraft such that the Earth centre and the Sun are c apart (Sun along +x, far away)
        r = rn * np.array([-math.cos(c), math.sin(c), 0.0])
        r_sun = r + np.array([AU, 0.0, 0.0])
        nu = float(eph.shadow_function(r, r_sun))
        values.append(nu)
        a_seen = math.asin(eph.SUN_RADIUS / AU)
        assert nu == pytest.approx(_grid_fraction(a_seen, b, c), abs=3e-3)
    assert np.all(np.diff(values) > 0) and 0.4 < values[3] < 0.6
    # vectorised equals scalar, and a LEO orbit sees umbra, penumbra and sunlight
    r = np.array([[7000e3, 0, 0], [-7000e3, 0, 0], [-7000e3 * math.cos(b), 7000e3 * math.sin(b), 0]])
    vec = eph.shadow_function(r, R_SUN)
    assert [float(eph.shadow_function(x, R_SUN)) for x in r] == pytest.approx(vec.tolist(), abs=1e-12)


def test_shadow_along_the_issue_orbit(sky):
    t = np.linspace(0.0, sky.orbit.period, 3000)
    nu = sky.shadow(t)
    assert 0.3 < np.mean(nu < 0.5) < 0.42                   # ~37 % of a 580 km orbit in the Earth's shadow
    assert np.any((nu > 0.01) & (nu < 0.99))                # penumbra crossings (~8 s each)
    assert sky.shadow(float(t[100])) == pytest.approx(nu[100], abs=1e-9)


def test_scalar_calls_agree_with_one_call_on_2000_times(sky):
    """Each of the sky's functions answers a scalar time as it answers that time in a vector of 2000
    (to 1e-9, as the shadow test above: in the penumbra the two differ by ~6e-12)."""
    t = np.linspace(0.0, 9000.0, 2000)
    for name in ("sun_direction", "moon_direction", "shadow", "earth_angular_radius", "nadir"):
        f = getattr(sky, name)
        vector = np.asarray(f(t))
        scalar = np.array([f(x) for x in t[:300].tolist()])
        np.testing.assert_allclose(scalar, vector[:300], rtol=1e-12, atol=1e-9, err_msg=name)


def test_sky_and_tle_orbit_pickle_as_their_recipe(sky):
    copy = pickle.loads(pickle.dumps(sky))
    assert copy.epoch == sky.epoch and copy.orbit.line1 == LINE1 and copy.orbit.epoch == sky.orbit.epoch
    np.testing.assert_array_equal(copy.sun_direction(100.0), sky.sun_direction(100.0))
    np.testing.assert_allclose(sky.sun_vector(100.0), sky.sun(100.0) - sky.position(100.0))
