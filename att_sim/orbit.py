"""Orbits of the real sky (issue 13): circular (Bruni–Celani), Kepler with J2 secular rates, TLE/SGP4.

Every orbit gives ``state(t) -> (r, v)`` (m, m/s) in GCRS (Earth-centred, ICRF axes), ``t`` in SI
seconds past its ``epoch`` (sim time zero), scalar or array (leading shape kept, trailing 3).

* :class:`CircularOrbit` wraps :mod:`att_sim.environment` (position identical to
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
  1–68; ``Satrec.twoline2rv`` checks neither). skyfield costs ~0.1 ms a call, so r and v are tabulated
  every 60 s in chunks built as ``t`` reaches them and interpolated by cubic Hermite (r and v at the
  nodes): position error ≤ 1 mm, velocity ≤ 0.1 mm/s, measured in LEO against direct evaluation
  (test/att_sim/test_orbit.py; the error bound h⁴|r⁗|/384 ≈ 0.3 mm at 60 s, 580 km).

:func:`check_altitude` uses the spherical altitude ``|r| − R_E`` (R_E the WGS-84 equatorial radius),
a lower bound of the geodetic altitude, sampled every ≤ 30 s.
"""
from __future__ import annotations

import math
from dataclasses import fields
from datetime import datetime

import numpy as np

from att_sim import environment as env
from att_sim.epoch import parse_epoch, skyfield_times, timescale

J2 = 1.08262668e-3          # EGM-96 / Vallado 2013 Table D-1, with R_E = 6378.137 km
TLE_STEP = 60.0             # s, node spacing of the TLE table
TLE_CHUNK = 720             # intervals per chunk (12 h)
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


class CircularOrbit(Orbit):
    """Today's circular orbit (:class:`att_sim.environment.OrbitParams`); no epoch needed."""

    def __init__(self, params: env.OrbitParams):
        self.params = params
        self.period = params.period

    def position(self, t) -> np.ndarray:
        return env.position(self.params, t)

    def state(self, t):
        p = self.params
        u = env.argument_of_latitude(p, t)
        r = p.radius * np.stack(env.direction(p, np.cos(u), np.sin(u)), -1)
        v = p.radius * p.mean_motion * np.stack(env.direction(p, -np.sin(u), np.cos(u)), -1)
        return r, v


def _rotation(raan, i, argp):
    """Columns P̂, Q̂, Ŵ of ``R_z(Ω) R_x(i) R_z(ω)`` (perifocal to inertial), shape ``(..., 3, 3)``."""
    co, so, ci, si, cw, sw = np.cos(raan), np.sin(raan), np.cos(i), np.sin(i), np.cos(argp), np.sin(argp)
    si, ci = np.broadcast_to(si, co.shape), np.broadcast_to(ci, co.shape)
    p = np.stack([co * cw - so * sw * ci, so * cw + co * sw * ci, sw * si], -1)
    q = np.stack([-co * sw - so * cw * ci, -so * sw + co * cw * ci, cw * si], -1)
    w = np.stack([so * si, -co * si, ci], -1)
    return p, q, w


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
        t = np.asarray(t, float)
        a, e = self.a, self.e
        big = solve_kepler(self.m0 + self.mean_motion * t, e)
        ce, se = np.cos(big), np.sin(big)
        b = a * math.sqrt(1.0 - e * e)
        e_dot = self.mean_motion / (1.0 - e * ce)
        p, q, w = _rotation(self.raan0 + self.raan_rate * t, np.float64(self.i), self.argp0 + self.argp_rate * t)
        x, y = (a * (ce - e))[..., None], (b * se)[..., None]
        r = x * p + y * q
        v = (-a * se * e_dot)[..., None] * p + (b * ce * e_dot)[..., None] * q
        v = v + self.argp_rate * np.cross(w, r) + self.raan_rate * np.cross([0.0, 0.0, 1.0], r)
        return r, v


def hermite(y0, y1, d0, d1, s, h):
    """Cubic Hermite on one interval: value and derivative at ``s ∈ [0, 1]`` of step ``h``."""
    s2, s3 = s * s, s * s * s
    h00, h10, h01, h11 = 2 * s3 - 3 * s2 + 1, s3 - 2 * s2 + s, 3 * s2 - 2 * s3, s3 - s2
    g00, g10, g01, g11 = 6 * (s2 - s), 3 * s2 - 4 * s + 1, 6 * (s - s2), 3 * s2 - 2 * s
    return (h00 * y0 + h10 * h * d0 + h01 * y1 + h11 * h * d1,
            (g00 * y0 + g01 * y1) / h + g10 * d0 + g11 * d1)


class HermiteTable:
    """Lazily built table of a smooth vector function and its derivative, cubic-Hermite interpolated.

    ``sample(times) -> (y, dy)`` (arrays ``(N, 3)``) is called for one chunk of ``chunk + 1`` nodes
    spaced ``step`` at a time, when a requested ``t`` first falls in it. ``__call__(t)`` gives the
    interpolated value and derivative.
    """

    def __init__(self, sample, step: float, chunk: int):
        self._sample, self.step, self.chunk = sample, float(step), int(chunk)
        self._chunks: dict[int, tuple[np.ndarray, np.ndarray]] = {}

    def _get(self, c: int):
        got = self._chunks.get(c)
        if got is None:
            times = (c * self.chunk + np.arange(self.chunk + 1)) * self.step
            y, dy = self._sample(times)
            got = self._chunks[c] = (np.ascontiguousarray(y, float), np.ascontiguousarray(dy, float))
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
        y = np.empty((flat.size, 3))
        dy = np.empty((flat.size, 3))
        s = (flat / self.step - k)[:, None]
        for ci in np.unique(c):
            m = c == ci
            ys, ds = self._get(int(ci))
            jm = j[m]
            y[m], dy[m] = hermite(ys[jm], ys[jm + 1], ds[jm], ds[jm + 1], s[m], self.step)
        return y.reshape(t.shape + (3,)), dy.reshape(t.shape + (3,))

    def _scalar(self, t: float):
        if not math.isfinite(t):
            raise ValueError("time t must be finite")
        x = t / self.step
        k = math.floor(x)
        c, j = divmod(k, self.chunk)
        ys, ds = self._get(c)
        return hermite(ys[j], ys[j + 1], ds[j], ds[j + 1], x - k, self.step)


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
        from sgp4.api import Satrec
        from skyfield.api import EarthSatellite

        self.epoch = parse_epoch(epoch)
        self.line1, self.line2 = check_tle(line1, line2)
        self.satrec = Satrec.twoline2rv(self.line1, self.line2)
        if self.satrec.error:
            raise ValueError(f"TLE elements are rejected by SGP4 (error {self.satrec.error})")
        self.satellite = EarthSatellite.from_satrec(self.satrec, timescale())
        self.period = 2.0 * math.pi / (self.satrec.no_kozai / 60.0)
        self._table = HermiteTable(self.direct_state, TLE_STEP, TLE_CHUNK)

    @property
    def tle_epoch(self) -> datetime:
        return self.satellite.epoch.utc_datetime()

    def direct_state(self, t):
        """r, v (m, m/s, GCRS) straight from skyfield (slow: ~0.1 ms a call); NaN where SGP4 fails."""
        at = self.satellite.at(skyfield_times(self.epoch, t))
        r, v = np.moveaxis(at.position.m, 0, -1), np.moveaxis(at.velocity.m_per_s, 0, -1)
        return r, v

    def sgp4_message(self, t) -> str | None:
        """SGP4's error message at time ``t`` (scalar), or None if it propagates."""
        return self.satellite.at(skyfield_times(self.epoch, float(t))).message

    def state(self, t):
        r, v = self._table(t)
        if np.isnan(r[..., 0]).any():
            bad = np.asarray(t, float).reshape(-1)[np.isnan(r[..., 0]).reshape(-1)][0]
            raise ValueError(f"orbit: SGP4 fails near t = {bad:.0f} s past {self.epoch.isoformat()}: "
                             f"{self.sgp4_message(bad) or 'decayed'}")
        return r, v


# ---------------------------------------------------------------- scenario group
KEPLER_KEYS = ("semi_major_axis", "eccentricity", "inclination_deg", "raan_deg", "arg_perigee_deg", "mean_anomaly_deg")
CIRCULAR_KEYS = ("altitude", "inclination_deg", "raan_deg", "arg0")
TLE_KEYS = ("line1", "line2")
ORBIT_TYPES = ("circular", "kepler", "tle")


def _number(mapping: dict, key: str) -> float:
    x = mapping[key]
    if isinstance(x, bool) or not isinstance(x, (int, float)) or not math.isfinite(x):
        raise ValueError(f"orbit.{key} must be a finite number, got {x!r}")
    return float(x)


def orbit_from_mapping(mapping: dict, epoch=None) -> Orbit:
    """The scenario's ``orbit`` group as an :class:`Orbit` (``type`` absent: circular, today's keys and
    defaults); ``epoch`` (sim time zero) is required for kepler and tle."""
    if not isinstance(mapping, dict):
        raise ValueError(f"orbit must be a mapping, got {type(mapping).__name__}")
    kind = mapping.get("type", "circular")
    if kind not in ORBIT_TYPES:
        raise ValueError(f"orbit.type must be one of {', '.join(ORBIT_TYPES)}, got {kind!r}")
    keys = {"circular": CIRCULAR_KEYS, "kepler": KEPLER_KEYS, "tle": TLE_KEYS}[kind]
    unknown = sorted(str(k) for k in set(mapping) - set(keys) - {"type"})
    if unknown:
        raise ValueError(f"orbit keys {', '.join(unknown)} are unknown for type {kind} (accepted: {', '.join(keys)})")
    if kind == "circular":
        d = {f.name: f.default for f in fields(env.OrbitParams)}
        vals = {k: _number(mapping, k) for k in mapping if k != "type"}
        if vals.get("altitude", 1.0) <= 0.0:
            raise ValueError(f"orbit.altitude must be positive (m), got {vals['altitude']!r}")
        return CircularOrbit(env.OrbitParams(
            altitude=vals.get("altitude", d["altitude"]),
            inclination=math.radians(vals["inclination_deg"]) if "inclination_deg" in vals else d["inclination"],
            raan=math.radians(vals["raan_deg"]) if "raan_deg" in vals else d["raan"],
            arg0=vals.get("arg0", d["arg0"])))
    missing = [k for k in keys if k not in mapping]
    if missing:
        raise ValueError(f"orbit of type {kind} needs keys {', '.join(missing)}")
    if epoch is None:
        raise ValueError(f"orbit of type {kind} needs an epoch (the scenario's 'epoch')")
    if kind == "tle":
        return TLEOrbit(epoch, mapping["line1"], mapping["line2"])
    v = {k: _number(mapping, k) for k in keys}
    return KeplerOrbit(epoch, v["semi_major_axis"], v["eccentricity"], math.radians(v["inclination_deg"]),
                       math.radians(v["raan_deg"]), math.radians(v["arg_perigee_deg"]),
                       math.radians(v["mean_anomaly_deg"]))


def altitude(orbit: Orbit, t) -> np.ndarray:
    """Spherical altitude ``|r| − R_E`` (m), a lower bound of the geodetic one."""
    return np.linalg.norm(orbit.position(t), axis=-1) - env.EARTH_RADIUS


def check_altitude(orbit: Orbit, t0: float, t1: float, minimum: float = 150e3) -> None:
    """``ValueError`` if ``|r| − R_E`` drops below ``minimum`` anywhere in ``[t0, t1]`` (sampled every
    ≤ 30 s, ends included) or if SGP4 fails (a decayed TLE)."""
    if not (math.isfinite(t0) and math.isfinite(t1)) or t1 < t0:
        raise ValueError(f"altitude check needs finite t0 <= t1, got [{t0!r}, {t1!r}]")
    t = np.linspace(t0, t1, max(2, math.ceil((t1 - t0) / ALTITUDE_STEP) + 1))
    h = altitude(orbit, t)
    k = int(np.argmin(h))
    if h[k] < minimum:
        raise ValueError(f"orbit altitude |r| - R_E is {h[k] / 1e3:.1f} km at t = {t[k]:.0f} s, below the "
                         f"minimum {minimum / 1e3:.0f} km")
