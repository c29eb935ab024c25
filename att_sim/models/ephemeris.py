"""The sky seen from the spacecraft: Sun, Moon, Earth and the Earth's shadow.

* Sun and Moon: geometric geocentric positions from JPL DE421 (Folkner, Williams & Boggs, IPN Progress
  Report 42-178, 2009) through skyfield, opened offline from the ``de421.bsp`` packaged by
  ``skyfield-data``. Light time and aberration are ignored (≤ 20.5″ ≈ 1e-4 rad for the Sun, 0.7″ for
  the Moon); axes ICRF, i.e. GCRS's. Positions are tabulated every 600 s (1-day chunks, built as t
  reaches them) and interpolated by :class:`att_sim.models.orbit.HermiteTable` (quintic Hermite on 8th-order
  differences): against direct evaluation ≤ 1e-4 m, i.e. rounding (≤ 1e-13 rad in direction; the
  bound required is 1e-7 rad), measured in test/att_sim/models/test_ephemeris.py.
* Directions from the spacecraft ``r`` (not the Earth's centre): ``ŝ = (r_sun − r)/|r_sun − r|``; the
  lunar parallax in LEO is up to ~1°.
* Earth: nadir ``−r̂``, angular radius ``asin(R_E/|r|)`` (sphere of the WGS-84 equatorial radius).
* Shadow: conical model with penumbra, Montenbruck & Gill, *Satellite Orbits* (2000) §3.4.2,
  eqs. 3.85–3.87: apparent radii ``a = asin(R_☉/|s|)``, ``b = asin(R_E/|r|)``, separation
  ``c = acos(−rᵀs/(|r||s|))`` with ``s = r_sun − r``; the visible fraction is 1 for ``c ≥ a + b``,
  0 (umbra) or ``1 − b²/a²`` (annular) for ``c ≤ |a − b|``, else ``1 − A/(π a²)`` with
  ``x = (c² + a² − b²)/(2c)``, ``y = sqrt(a² − x²)``, ``A = a² acos(x/a) + b² acos((c − x)/b) − c y``.
"""
from __future__ import annotations

import math
from functools import lru_cache
from importlib import resources

import numpy as np

from att_sim.models.environment import EARTH_RADIUS
from att_sim.models.epoch import parse_epoch, skyfield_times, timescale
from att_sim.models.orbit import HermiteTable, Orbit

SUN_RADIUS = 696.0e6        # m (Montenbruck & Gill 2000 §3.4.2)
BODY_STEP = 600.0           # s, node spacing of the Sun/Moon tables
BODY_CHUNK = 144            # intervals per chunk (1 day)

__all__ = ["EARTH_RADIUS", "SUN_RADIUS", "Ephemeris", "de421", "shadow_function"]


@lru_cache(maxsize=1)
def de421():
    """The DE421 ephemeris packaged by skyfield-data, opened offline once."""
    from skyfield.api import load_file

    return load_file(str(resources.files("skyfield_data") / "data" / "de421.bsp"))


def _unit(v) -> np.ndarray:
    return v / np.linalg.norm(v, axis=-1, keepdims=True)


def shadow_function(r_sat, r_sun) -> np.ndarray:
    """Fraction of the solar disc visible from ``r_sat`` (m, geocentric) with the Sun at ``r_sun``:
    conical Earth shadow with penumbra (Montenbruck & Gill 2000 §3.4.2); vectorised over ``...``."""
    if np.ndim(r_sat) == 1 and np.ndim(r_sun) == 1:
        return _shadow_scalar(*(float(x) for x in r_sat), *(float(x) for x in r_sun))
    r, s = np.broadcast_arrays(np.asarray(r_sat, float), np.asarray(r_sun, float) - np.asarray(r_sat, float))
    rn, sn = np.linalg.norm(r, axis=-1), np.linalg.norm(s, axis=-1)
    a = np.arcsin(np.minimum(SUN_RADIUS / sn, 1.0))
    b = np.arcsin(np.minimum(EARTH_RADIUS / rn, 1.0))
    c = np.arccos(np.clip(-np.einsum("...i,...i", r, s) / (rn * sn), -1.0, 1.0))
    with np.errstate(invalid="ignore", divide="ignore"):
        x = (c * c + a * a - b * b) / (2.0 * c)
        y = np.sqrt(np.maximum(a * a - x * x, 0.0))
        area = a * a * np.arccos(np.clip(x / a, -1.0, 1.0)) + b * b * np.arccos(np.clip((c - x) / b, -1.0, 1.0)) - c * y
        partial = 1.0 - area / (math.pi * a * a)
    inner = np.where(a < b, 0.0, 1.0 - (b * b) / (a * a))
    nu = np.where(c >= a + b, 1.0, np.where(c <= np.abs(a - b), inner, partial))
    return np.clip(nu, 0.0, 1.0)


def _shadow_scalar(rx, ry, rz, sx, sy, sz) -> float:
    """:func:`shadow_function` of one position with math on floats (the per-stage call)."""
    sx, sy, sz = sx - rx, sy - ry, sz - rz
    rn, sn = math.sqrt(rx * rx + ry * ry + rz * rz), math.sqrt(sx * sx + sy * sy + sz * sz)
    a, b = math.asin(min(SUN_RADIUS / sn, 1.0)), math.asin(min(EARTH_RADIUS / rn, 1.0))
    c = math.acos(max(-1.0, min(1.0, -(rx * sx + ry * sy + rz * sz) / (rn * sn))))
    if c >= a + b:
        return 1.0
    if c <= abs(a - b):
        return 0.0 if a < b else 1.0 - (b * b) / (a * a)
    x = (c * c + a * a - b * b) / (2.0 * c)
    y = math.sqrt(max(a * a - x * x, 0.0))
    area = a * a * math.acos(max(-1.0, min(1.0, x / a))) + b * b * math.acos(max(-1.0, min(1.0, (c - x) / b))) - c * y
    return min(1.0, max(0.0, 1.0 - area / (math.pi * a * a)))


class Ephemeris:
    """The ephemeris seen from a spacecraft: the Sun, the Moon and the Earth from the spacecraft of
    ``orbit``, ``t`` in SI seconds past ``epoch``.

    The orbit's own time zero (its ``epoch``) may differ from ``epoch``; an epoch-free orbit
    (:class:`att_sim.models.orbit.CircularOrbit`) is taken to start at ``epoch``.
    """

    def __init__(self, epoch, orbit: Orbit):
        self.epoch = parse_epoch(epoch)
        self.orbit = orbit
        self._last_position = None
        if getattr(orbit, "epoch", None) is None:
            self.orbit_offset = 0.0
        else:
            ts = timescale()
            t_sky, t_orbit = ts.from_datetime(self.epoch), ts.from_datetime(orbit.epoch)
            self.orbit_offset = ((t_sky.whole - t_orbit.whole) + (t_sky.tt_fraction - t_orbit.tt_fraction)) * 86400.0
        eph = de421()
        self._earth, self._sun, self._moon = eph["earth"], eph["sun"], eph["moon"]
        self._tables = {name: HermiteTable(self._direct(body), BODY_STEP, BODY_CHUNK)
                        for name, body in (("sun", self._sun), ("moon", self._moon))}

    def __reduce__(self):
        """Pickles as its recipe (the DE421 handle does not pickle); tables are rebuilt."""
        return (Ephemeris, (self.epoch, self.orbit))

    def sun_vector(self, t) -> np.ndarray:
        """Vector from the spacecraft to the Sun (m): ``sun(t) − position(t)``."""
        return self.sun(t) - self.position(t)

    def _direct(self, body):
        vector = body - self._earth

        def sample(t):
            at = vector.at(skyfield_times(self.epoch, t))
            return np.moveaxis(at.position.m, 0, -1)
        return sample

    def direct_sun(self, t) -> np.ndarray:
        """Geocentric Sun straight from skyfield (slow; for verification)."""
        return self._direct(self._sun)(t)

    def direct_moon(self, t) -> np.ndarray:
        """Geocentric Moon straight from skyfield (slow; for verification)."""
        return self._direct(self._moon)(t)

    def _orbit_time(self, t):
        if self.orbit_offset == 0.0:
            return t
        return t + self.orbit_offset if isinstance(t, (float, int)) else np.asarray(t, float) + self.orbit_offset

    def sun(self, t) -> np.ndarray:
        """Geocentric GCRS position of the Sun (m)."""
        return self._tables["sun"](t)[0]

    def moon(self, t) -> np.ndarray:
        """Geocentric GCRS position of the Moon (m)."""
        return self._tables["moon"](t)[0]

    def position(self, t) -> np.ndarray:
        """Geocentric GCRS position of the spacecraft (m). The last array of times is remembered:
        every direction of a zone sky asks for the same times once per body."""
        if np.ndim(t) == 0:
            return self.orbit.position(self._orbit_time(t))
        times, last = np.asarray(t, float), self._last_position
        if last is None or last[0].shape != times.shape or not np.array_equal(last[0], times):
            last = self._last_position = (times.copy(), self.orbit.position(self._orbit_time(times)))
        return last[1]

    def velocity(self, t) -> np.ndarray:
        return self.orbit.state(self._orbit_time(t))[1]

    def sun_direction(self, t) -> np.ndarray:
        """Unit vector from the spacecraft to the Sun."""
        return _unit(self.sun_vector(t))

    def moon_direction(self, t) -> np.ndarray:
        """Unit vector from the spacecraft to the Moon."""
        return _unit(self.moon(t) - self.position(t))

    def nadir(self, t) -> np.ndarray:
        """``−r̂``, the unit vector from the spacecraft to the Earth's centre."""
        return -_unit(self.position(t))

    def earth_angular_radius(self, t) -> np.ndarray:
        """``asin(R_E/|r|)`` (rad)."""
        return np.arcsin(EARTH_RADIUS / np.linalg.norm(self.position(t), axis=-1))

    def shadow(self, t) -> np.ndarray:
        """Fraction of the solar disc visible, in [0, 1] (conical shadow with penumbra)."""
        return shadow_function(self.position(t), self.sun(t))
