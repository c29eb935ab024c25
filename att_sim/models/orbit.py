"""Orbits of the real sky: circular (Bruni–Celani), Kepler with J2 secular rates, TLE/SGP4.

Every orbit gives ``state(t) -> (r, v)`` (m, m/s) in GCRS (Earth-centred, ICRF axes), ``t`` in SI
seconds past its ``epoch`` (sim time zero), scalar or array (leading shape kept, trailing 3).

* :class:`CircularOrbit` wraps :mod:`att_sim.models.environment` (position identical to
  ``environment.position``). It has no epoch: its frame is the suite's old ECI, whose axes are read as
  GCRS's when it is combined with an epoch (the old model never tied them to the sky).
* :class:`KeplerOrbit`: two-body ellipse whose Ω, ω, M drift at the J2 secular rates
  (Vallado, *Fundamentals of Astrodynamics and Applications*, 4th ed. 2013, §9.6, eq. 9-41)::

      p = a(1 − e²),  k = J2 (R_E/p)²,  n = sqrt(μ/a³)
      Ω̇ = −(3/2) n k cos i,   ω̇ = (3/4) n k (4 − 5 sin² i),   Ṁ = n [1 + (3/4) k sqrt(1 − e²)(2 − 3 sin² i)]

  Kepler's equation ``E − e sin E = M`` by Newton's method (vectorised, to 1e-15 rad).
  ``v`` is the exact time derivative of that position (the frame's drift included).
* :class:`TLEOrbit`: SGP4/SDP4 (Vallado, Crawford, Hujsak & Kelso, "Revisiting Spacetrack Report #3",
  AIAA 2006-6753) through ``sgp4`` and skyfield's ``EarthSatellite``, which rotates TEME into GCRS
  (IAU 2000B-class precession–nutation and the equation of the equinoxes; polar motion ignored). The
  TLE is checked column by column and by its checksum (mod-10 sum of the digits, '-' = 1, of columns
  1–68; ``Satrec.twoline2rv`` checks neither). skyfield costs ~0.1 ms a call, so positions are tabulated
  every 60 s in 3-h chunks built as ``t`` reaches them and interpolated by :class:`HermiteTable`
  (quintic Hermite on 8th-order central differences): position within 1e-5 m of direct evaluation in
  LEO (7e-4 m at the perigee of a 0.7-eccentric orbit), ``v`` the interpolant's derivative, within
  2e-4 m/s of dr/dt. SGP4's own velocity is not dr/dt (5 cm/s off in LEO, up to ~3 m/s in eccentric
  orbits), so it is not used. Where SGP4 fails (decay) ``state`` raises ``ValueError``.

:func:`check_altitude` uses the spherical altitude ``|r| − R_E`` (R_E the WGS-84 equatorial radius),
a lower bound of the geodetic altitude, sampled every ≤ 30 s.
"""
from __future__ import annotations

import functools
import math
from datetime import UTC, datetime, timedelta

import numpy as np

from att_sim.models import environment as env
from att_sim.models.epoch import format_epoch, parse_epoch, skyfield_times, timescale

J2 = 1.08262668e-3          # EGM-96 / Vallado 2013 Table D-1, with R_E = 6378.137 km
TLE_STEP = 60.0             # s, node spacing of the TLE table
TLE_CHUNK = 180             # intervals per chunk (3 h)
ALTITUDE_STEP = 30.0        # s, largest sample spacing of check_altitude


class Orbit:
    """Protocol of every orbit: ``state``, ``position``, ``period`` (s), ``epoch``, ``frame``."""

    frame = "GCRS"
    epoch: datetime | None = None
    period: float

    def state(self, t) -> tuple[np.ndarray, np.ndarray]:
        raise NotImplementedError

    def position(self, t) -> np.ndarray:
        return self.state(t)[0]

    def velocity(self, t) -> np.ndarray:
        return self.state(t)[1]

    def unchecked_position(self, t) -> np.ndarray:
        """Position, NaN where the propagator fails instead of an error (for :func:`check_altitude`)."""
        return self.position(t)


class CircularOrbit(Orbit):
    """The circular orbit of Bruni & Celani (:class:`att_sim.models.environment.OrbitParams`); no epoch needed."""

    def __init__(self, params: env.OrbitParams):
        self.params = params
        self.period = params.period
        self._plane = params.plane_matrix().tolist()

    def position(self, t) -> np.ndarray:
        return env.position(self.params, t)

    def state(self, t):
        """``r`` is computed as :func:`att_sim.models.environment.position` does (equal to it); ``v = ṙ``."""
        p = self.params
        u = env.argument_of_latitude(p, t)
        one = u.ndim == 0                       # one time (the simulator's): on Python floats
        cu, su = (math.cos(u), math.sin(u)) if one else (np.cos(u), np.sin(u))
        stack = np.array if one else functools.partial(np.stack, axis=-1)
        return (p.radius * stack(env.direction(p, cu, su, self._plane)),
                (p.radius * p.mean_motion) * stack(env.direction(p, -su, cu, self._plane)))


def _rotation(raan, i, argp):
    """Inertial P̂, Q̂ (perifocal x, y axes) of ``R_z(Ω) R_x(i) R_z(ω)``, each ``(..., 3)``."""
    co, so, ci, si, cw, sw = np.cos(raan), np.sin(raan), np.cos(i), np.sin(i), np.cos(argp), np.sin(argp)
    si, ci = np.broadcast_to(si, co.shape), np.broadcast_to(ci, co.shape)
    p = np.stack([co * cw - so * sw * ci, so * cw + co * sw * ci, sw * si], -1)
    q = np.stack([-co * sw - so * cw * ci, -so * sw + co * cw * ci, cw * si], -1)
    return p, q


def solve_kepler(mean_anomaly, e: float, tol: float = 1e-15) -> np.ndarray:
    """Eccentric anomaly E of ``E − e sin E = M`` (Newton from E = M + e sin M; vectorised)."""
    m = np.remainder(np.asarray(mean_anomaly, float) + math.pi, 2.0 * math.pi) - math.pi
    big = m + e * np.sin(m)
    for _ in range(30):
        step = (big - e * np.sin(big) - m) / (1.0 - e * np.cos(big))
        big = big - step
        if np.all(np.abs(step) <= tol):
            break
    return big


class KeplerOrbit(Orbit):
    """Keplerian elements at ``epoch`` (m, rad) with the J2 secular drift of Ω, ω, M."""

    def __init__(self, epoch, a: float, e: float, i: float, raan: float, argp: float, mean_anomaly: float):
        self.epoch = parse_epoch(epoch)
        vals = dict(semi_major_axis=a, eccentricity=e, inclination=i, raan=raan, arg_perigee=argp,
                    mean_anomaly=mean_anomaly)
        for name, x in vals.items():
            if isinstance(x, bool) or not isinstance(x, (int, float)) or not math.isfinite(x):
                raise ValueError(f"orbit.{name} must be a finite number, got {x!r}")
        if a <= env.EARTH_RADIUS:
            raise ValueError(f"orbit.semi_major_axis must exceed the Earth radius {env.EARTH_RADIUS:.0f} m, got {a!r}")
        if not 0.0 <= e < 1.0:
            raise ValueError(f"orbit.eccentricity must be in [0, 1), got {e!r}")
        if not 0.0 <= i <= math.pi:
            raise ValueError(f"orbit.inclination must be in [0, 180] deg, got {math.degrees(i)!r}")
        self.a, self.e, self.i, self.raan0, self.argp0, self.m0 = map(float, (a, e, i, raan, argp, mean_anomaly))
        n = math.sqrt(env.EARTH_MU / a**3)
        k = J2 * (env.EARTH_RADIUS / (a * (1.0 - e * e))) ** 2
        s2 = math.sin(i) ** 2
        self.raan_rate = -1.5 * n * k * math.cos(i)
        self.argp_rate = 0.75 * n * k * (4.0 - 5.0 * s2)
        self.mean_motion = n * (1.0 + 0.75 * k * math.sqrt(1.0 - e * e) * (2.0 - 3.0 * s2))
        self.period = 2.0 * math.pi / self.mean_motion          # anomalistic period

    def state(self, t):
        if isinstance(t, (float, int)) and not isinstance(t, bool):
            return self._state_scalar(float(t))
        t = np.asarray(t, float)
        a, e = self.a, self.e
        big = solve_kepler(self.m0 + self.mean_motion * t, e)
        ce, se = np.cos(big), np.sin(big)
        b = a * math.sqrt(1.0 - e * e)
        e_dot = self.mean_motion / (1.0 - e * ce)
        p, q = _rotation(self.raan0 + self.raan_rate * t, np.float64(self.i), self.argp0 + self.argp_rate * t)
        x, y = a * (ce - e), b * se
        vx, vy = -a * se * e_dot - self.argp_rate * y, b * ce * e_dot + self.argp_rate * x    # ω̇ Ŵ × r
        r = x[..., None] * p + y[..., None] * q
        v = vx[..., None] * p + vy[..., None] * q
        v[..., 0] -= self.raan_rate * r[..., 1]                                              # Ω̇ ẑ × r
        v[..., 1] += self.raan_rate * r[..., 0]
        return r, v

    def _state_scalar(self, t: float):
        """:meth:`state` at one time with math on floats (the per-stage call)."""
        a, e = self.a, self.e
        m = math.remainder(self.m0 + self.mean_motion * t, 2.0 * math.pi)
        big = m + e * math.sin(m)
        for _ in range(30):
            step = (big - e * math.sin(big) - m) / (1.0 - e * math.cos(big))
            big -= step
            if abs(step) <= 1e-15:
                break
        ce, se = math.cos(big), math.sin(big)
        b = a * math.sqrt(1.0 - e * e)
        e_dot = self.mean_motion / (1.0 - e * ce)
        x, y = a * (ce - e), b * se
        vx, vy = -a * se * e_dot - self.argp_rate * y, b * ce * e_dot + self.argp_rate * x
        raan, argp = self.raan0 + self.raan_rate * t, self.argp0 + self.argp_rate * t
        co, so, cw, sw = math.cos(raan), math.sin(raan), math.cos(argp), math.sin(argp)
        ci, si = math.cos(self.i), math.sin(self.i)
        p = (co * cw - so * sw * ci, so * cw + co * sw * ci, sw * si)
        q = (-co * sw - so * cw * ci, -so * sw + co * cw * ci, cw * si)
        r = [x * p[k] + y * q[k] for k in range(3)]
        v = [vx * p[k] + vy * q[k] for k in range(3)]
        v[0] -= self.raan_rate * r[1]
        v[1] += self.raan_rate * r[0]
        return np.array(r), np.array(v)


# 8th-order central differences on 9 nodes (Fornberg 1988, Math. Comp. 51, Table 1)
_D1 = np.array([1 / 280, -4 / 105, 1 / 5, -4 / 5, 0.0, 4 / 5, -1 / 5, 4 / 105, -1 / 280])
_D2 = np.array([-1 / 560, 8 / 315, -1 / 5, 8 / 5, -205 / 72, 8 / 5, -1 / 5, 8 / 315, -1 / 560])
_HALF = 4


def quintic_hermite(y, d1, d2, h: float) -> np.ndarray:
    """Coefficients ``c_k`` (``(n − 1, 6, 3)``) of ``y(s) = Σ c_k s^k`` on each interval of the nodes
    ``y`` (``(n, 3)``) with first and second derivatives ``d1``, ``d2`` (step ``h``, ``s ∈ [0, 1]``)."""
    c0, c1, c2 = y[:-1], h * d1[:-1], 0.5 * h * h * d2[:-1]
    big_d = y[1:] - c0 - c1 - c2
    slope = h * d1[1:] - c1 - 2.0 * c2
    curv = h * h * d2[1:] - 2.0 * c2
    c3 = 10.0 * big_d - 4.0 * slope + 0.5 * curv
    c4 = -15.0 * big_d + 7.0 * slope - curv
    c5 = 6.0 * big_d - 3.0 * slope + 0.5 * curv
    return np.ascontiguousarray(np.stack([c0, c1, c2, c3, c4, c5], 1))


class HermiteTable:
    """Lazily built table of a smooth vector function y(t), quintic-Hermite interpolated.

    ``sample(times) -> (N, 3)`` is called for one chunk of nodes spaced ``step`` (plus four on each
    side) when a requested ``t`` first falls in it. The node derivatives ẏ, ÿ are 8th-order central
    differences of the samples (error ≈ (ωh)⁸|y|ω/630 for a motion of rate ω), so the interpolant is
    consistent with y itself; on each interval y is the quintic matching y, ẏ, ÿ at both ends
    (error ≤ h⁶|y⁽⁶⁾|/46080). ``__call__(t)`` returns ``(y, ẏ)``, ẏ the interpolant's derivative.
    """

    def __init__(self, sample, step: float, chunk: int):
        self._sample, self.step, self.chunk = sample, float(step), int(chunk)
        self._chunks: dict[int, np.ndarray] = {}

    def _get(self, c: int) -> np.ndarray:
        got = self._chunks.get(c)
        if got is None:
            times = (c * self.chunk + np.arange(-_HALF, self.chunk + 1 + _HALF)) * self.step
            y = np.asarray(self._sample(times), float)
            n = self.chunk + 1
            windows = np.stack([y[k:k + n] for k in range(2 * _HALF + 1)])       # (9, n, 3)
            d1 = np.tensordot(_D1, windows, 1) / self.step
            d2 = np.tensordot(_D2, windows, 1) / self.step**2
            got = self._chunks[c] = quintic_hermite(y[_HALF:_HALF + n], d1, d2, self.step)
        return got

    def __call__(self, t):
        if isinstance(t, (float, int)) and not isinstance(t, bool):
            return self._scalar(float(t))
        t = np.asarray(t, float)
        flat = t.reshape(-1)
        if not np.all(np.isfinite(flat)):
            raise ValueError("time t must be finite")
        k = np.floor(flat / self.step).astype(np.int64)
        c, j = np.divmod(k, self.chunk)
        s = flat / self.step - k
        powers = s[:, None] ** np.arange(6)
        slopes = np.arange(1, 6) * powers[:, :5] / self.step
        y = np.empty((flat.size, 3))
        dy = np.empty((flat.size, 3))
        for ci in np.unique(c):
            m = c == ci
            coef = self._get(int(ci))[j[m]]
            y[m] = np.einsum("nk,nkd->nd", powers[m], coef)
            dy[m] = np.einsum("nk,nkd->nd", slopes[m], coef[:, 1:])
        return y.reshape(t.shape + (3,)), dy.reshape(t.shape + (3,))

    def _scalar(self, t: float):
        if not math.isfinite(t):
            raise ValueError("time t must be finite")
        x = t / self.step
        k = math.floor(x)
        c, j = divmod(k, self.chunk)
        coef = self._get(c)[j]
        s = x - k
        s2 = s * s
        s3, s4 = s2 * s, s2 * s2
        g = 1.0 / self.step
        return (np.dot((1.0, s, s2, s3, s4, s4 * s), coef),
                np.dot((g, 2.0 * s * g, 3.0 * s2 * g, 4.0 * s3 * g, 5.0 * s4 * g), coef[1:]))


# ---------------------------------------------------------------- TLE
_SEPARATORS = {1: (2, 9, 18, 33, 44, 53, 62, 64), 2: (2, 8, 17, 26, 34, 43, 52)}
_FIELDS = {   # (name, first column, last column, kind) — columns 1-based as in Spacetrack Report #3
    1: (("satellite number", 3, 7, "satnum"), ("classification", 8, 8, "class"),
        ("epoch year", 19, 20, "int"), ("epoch day", 21, 32, "float"),
        ("first derivative of mean motion", 34, 43, "float"), ("second derivative of mean motion", 45, 52, "exp"),
        ("B* drag term", 54, 61, "exp"), ("ephemeris type", 63, 63, "int?"), ("element set number", 65, 68, "int?")),
    2: (("satellite number", 3, 7, "satnum"), ("inclination", 9, 16, "float"), ("right ascension of the node", 18, 25,
        "float"), ("eccentricity", 27, 33, "digits"), ("argument of perigee", 35, 42, "float"),
        ("mean anomaly", 44, 51, "float"), ("mean motion", 53, 63, "float"), ("revolution number", 64, 68, "int?")),
}


def tle_checksum(line: str) -> int:
    """Mod-10 sum of the digits of columns 1–68, each '-' counting 1 (Spacetrack Report #3)."""
    return sum(int(ch) if ch.isdigit() else ch == "-" for ch in line[:68]) % 10


def _field_ok(text: str, kind: str) -> bool:
    core = text.strip()
    if kind == "satnum":
        return len(text) == 5 and (text.isdigit() or (text[0].isalpha() and text[0] not in "IO" and text[1:].isdigit()))
    if kind == "class":
        return text in "USC "
    if kind == "digits":
        return text.isdigit()
    if kind == "exp":     # ' 12345-6': sign or blank, five digits, signed exponent digit (implied decimal point)
        return len(text) == 8 and text[0] in " +-" and text[1:6].isdigit() and text[6] in "+-" and text[7].isdigit()
    if kind == "int?":
        return core == "" or core.isdigit()
    try:
        value = int(core) if kind == "int" else float(core)
    except ValueError:
        return False
    return math.isfinite(value)


def check_tle(line1, line2) -> tuple[str, str]:
    """The two lines with trailing blanks removed, or ``ValueError`` naming the line and what is wrong."""
    lines = (line1, line2)
    for n, line in enumerate(lines, 1):
        if not isinstance(line, str) or not line.isascii():
            raise ValueError(f"TLE line {n} must be ASCII text, got {line!r}")
    lines = tuple(line.rstrip() for line in lines)
    for n, line in enumerate(lines, 1):
        if len(line) != 69:
            raise ValueError(f"TLE line {n} must have 69 characters, got {len(line)}: {line!r}")
        if line[0] != str(n):
            raise ValueError(f"TLE line {n} must start with its line number '{n}', got {line[0]!r}")
        for col in _SEPARATORS[n]:
            if line[col - 1] != " ":
                raise ValueError(f"TLE line {n} column {col} must be a blank, got {line[col - 1]!r}")
        for name, a, b, kind in _FIELDS[n]:
            if not _field_ok(line[a - 1:b], kind):
                raise ValueError(f"TLE line {n} {name} (columns {a}-{b}) is malformed: {line[a - 1:b]!r}")
        if not line[68].isdigit() or int(line[68]) != tle_checksum(line):
            raise ValueError(f"TLE line {n} checksum (column 69) is {line[68]!r} but the line's sum gives "
                             f"{tle_checksum(line)}")
    if lines[0][2:7] != lines[1][2:7]:
        raise ValueError(f"TLE satellite numbers differ: line 1 has {lines[0][2:7]!r}, line 2 {lines[1][2:7]!r}")
    day = float(lines[0][20:32])
    if not 1.0 <= day < 367.0:
        raise ValueError(f"TLE line 1 epoch day (columns 21-32) must be in [1, 367), got {day!r}")
    if float(lines[1][52:63]) <= 0.0:
        raise ValueError(f"TLE line 2 mean motion (columns 53-63) must be positive, got {lines[1][52:63]!r}")
    if not 0.0 <= float(lines[1][8:16]) <= 180.0:
        raise ValueError(f"TLE line 2 inclination (columns 9-16) must be in [0, 180] deg, got {lines[1][8:16]!r}")
    return lines


class TLEOrbit(Orbit):
    """SGP4 propagation of a two-line element set; ``t`` is seconds past ``epoch`` (not the TLE's)."""

    def __init__(self, epoch, line1: str, line2: str):
        from sgp4.api import SGP4_ERRORS, Satrec
        from skyfield.api import EarthSatellite

        self.epoch = parse_epoch(epoch)
        self.line1, self.line2 = check_tle(line1, line2)
        self.satrec = Satrec.twoline2rv(self.line1, self.line2)
        if self.satrec.error:
            raise ValueError(f"TLE elements are rejected by SGP4: {SGP4_ERRORS[self.satrec.error]}")
        self.satellite = EarthSatellite.from_satrec(self.satrec, timescale())
        self.period = 2.0 * math.pi / (self.satrec.no_kozai / 60.0)
        self.failure: tuple[float, str] | None = None       # earliest tabulated SGP4 failure (t, message)
        self._table = HermiteTable(self._sample, TLE_STEP, TLE_CHUNK)

    def __reduce__(self):
        """Pickles as its recipe (skyfield's and SGP4's objects do not pickle); the table is rebuilt."""
        return (TLEOrbit, (self.epoch, self.line1, self.line2))

    @property
    def tle_epoch(self) -> datetime:
        """The element set's epoch (UTC, to the microsecond; skyfield's ``utc_datetime`` loses ~40 µs)."""
        year = self.satrec.epochyr + (2000 if self.satrec.epochyr < 57 else 1900)
        return datetime(year, 1, 1, tzinfo=UTC) + timedelta(days=self.satrec.epochdays - 1.0)

    def direct_state(self, t):
        """r, v (m, m/s, GCRS) straight from skyfield (slow: ~0.1 ms a call); NaN where SGP4 fails."""
        at = self.satellite.at(skyfield_times(self.epoch, t))
        return np.moveaxis(at.position.m, 0, -1), np.moveaxis(at.velocity.m_per_s, 0, -1)

    def _sample(self, times):
        at = self.satellite.at(skyfield_times(self.epoch, times))
        r = np.moveaxis(at.position.m, 0, -1)
        failed = np.array([bool(m) for m in at.message])
        if failed.any():
            r[failed] = np.nan            # an SGP4 error code never passes as a position
            k = int(np.argmax(failed))
            if self.failure is None or times[k] < self.failure[0]:
                self.failure = (float(times[k]), at.message[k])
        return r

    def unchecked_position(self, t) -> np.ndarray:
        return self._table(t)[0]

    def state(self, t):
        r, v = self._table(t)
        if np.isnan(r[..., 0]).any():
            bad = np.asarray(t, float).reshape(-1)[np.isnan(r[..., 0]).reshape(-1)][0]
            when, why = self.failure or (bad, "no position")
            raise ValueError(f"orbit: SGP4 cannot propagate the TLE from t = {when:.0f} s past "
                             f"{format_epoch(self.epoch)} ({why}), needed at t = {bad:.0f} s")
        return r, v


def check_altitude(orbit: Orbit, t0: float, t1: float, minimum: float = 150e3) -> None:
    """``ValueError`` if ``|r| − R_E`` drops below ``minimum`` anywhere in ``[t0, t1]`` (sampled every
    ≤ 30 s, ends included) or if SGP4 fails there (a decayed TLE)."""
    if not (math.isfinite(t0) and math.isfinite(t1)) or t1 < t0:
        raise ValueError(f"altitude check needs finite t0 <= t1, got [{t0!r}, {t1!r}]")
    t = np.linspace(t0, t1, max(2, math.ceil((t1 - t0) / ALTITUDE_STEP) + 1))
    h = np.linalg.norm(orbit.unchecked_position(t), axis=-1) - env.EARTH_RADIUS
    low = np.flatnonzero(h < minimum)
    if low.size:
        raise ValueError(f"orbit altitude |r| - R_E drops below the minimum {minimum / 1e3:.0f} km at t = "
                         f"{t[low[0]]:.0f} s ({h[low[0]] / 1e3:.1f} km)")
    if np.isnan(h).any():
        orbit.position(t)          # raises the propagator's own sentence
