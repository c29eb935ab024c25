"""Zones judged INDEPENDENTLY of the suite, for the checks of the benchmarks' plans (flown by
:mod:`helpers.own_rk4`): nothing of the suite, only numpy and skyfield.

:func:`margins` gives each zone's margin against the true sky: the
spacecraft from the JSON's TLE through skyfield's ``EarthSatellite`` (SGP4, TEME → GCRS), the Sun and
Moon from the ``de421.bsp`` of skyfield-data (geometric, light time ignored: ≤ 0.006° in these
cases), the Earth limb as asin(R_E/|r|) + margin about −r̂ (R_E = 6378.137 km, WGS-84); fixed cones
and inertial zones from their directions.
"""
from __future__ import annotations

from datetime import datetime
from functools import lru_cache
from importlib.resources import files

import numpy as np

from helpers.own_rk4 import dcm_NB

R_EARTH = 6378.137e3          # m, WGS-84 equatorial radius


def attitude_error(q, q_goal) -> float:
    """Angle (rad) between two attitudes (q and −q alike)."""
    return 2.0 * float(np.arccos(min(1.0, abs(float(np.asarray(q) @ np.asarray(q_goal))))))


@lru_cache(maxsize=1)
def _skyfield():
    """skyfield's built-in time scale and the packaged DE421, opened offline once."""
    from skyfield.api import load, load_file

    return load.timescale(builtin=True), load_file(str(files("skyfield_data") / "data" / "de421.bsp"))


def sky(payload, t):
    """(sun, moon, nadir) unit vectors from the spacecraft, (K, 3) each, and asin(R_E/|r|) (K,)."""
    from skyfield.api import EarthSatellite

    ts, eph = _skyfield()
    e = datetime.fromisoformat(payload["epoch"].replace("Z", "+00:00"))
    # UTC seconds = SI seconds: no leap second within a maneuver of these cases
    tt = ts.utc(e.year, e.month, e.day, e.hour, e.minute, e.second + e.microsecond * 1e-6 + np.asarray(t))
    r = EarthSatellite(*payload["tle"], ts=ts).at(tt).position.m.T
    earth = eph["earth"].at(tt).position.m.T

    def unit(v):
        return v / np.linalg.norm(v, axis=1, keepdims=True)
    sun = unit(eph["sun"].at(tt).position.m.T - earth - r)
    moon = unit(eph["moon"].at(tt).position.m.T - earth - r)
    return {"sun": sun, "moon": moon, "earth_limb": unit(-r)}, np.arcsin(R_EARTH / np.linalg.norm(r, axis=1))


def margins(payload, t, q):
    """Per-zone margins (rad, ≥ 0 clear) of attitudes q (K, 4) at times t (K,): the payload's
    ``cones`` (keep-out cones of its ``sensor_axis``) and ``zones`` (against the true sky)."""
    out = {}
    for c in payload.get("cones", []):
        b = dcm_NB(q) @ np.asarray(payload["sensor_axis"], float)
        gamma = np.arccos(np.clip(b @ np.asarray(c["direction"], float) / np.linalg.norm(b, axis=1), -1.0, 1.0))
        out[c["name"]] = gamma - c["half_angle"]
    moving = [z for z in payload.get("zones", []) if z["body"] != "inertial"]
    axes, limb = sky(payload, t) if moving else ({}, None)
    for z in payload.get("zones", []):
        b = dcm_NB(q) @ np.asarray(z["sensor_axis"], float)
        if z["body"] == "inertial":
            a, half = np.broadcast_to(np.asarray(z["direction"], float), b.shape), z["half_angle"]
        elif z["body"] == "earth_limb":
            a, half = axes["earth_limb"], limb + z["margin"]
        else:
            a, half = axes[z["body"]], z["half_angle"]
        gamma = np.arccos(np.clip(np.sum(a * b, axis=1) / np.linalg.norm(b, axis=1), -1.0, 1.0))
        out[z["name"]] = half - gamma if z["keep_in"] else gamma - half
    return out


def site_sight_from(epoch: str, r_N, latitude_deg: float, longitude_deg: float, altitude_m: float, t):
    """Unit lines of sight (K, 3, GCRS) from the spacecraft at the positions ``r_N`` (K, 3, m, GCRS:
    a log's truth states) to a WGS-84 ground site at times ``t`` (s past the UTC ``epoch``):
    skyfield's ``wgs84.latlon`` carried by its own Earth rotation."""
    from skyfield.api import wgs84

    ts, _ = _skyfield()
    e = datetime.fromisoformat(epoch.replace("Z", "+00:00"))
    tt = ts.utc(e.year, e.month, e.day, e.hour, e.minute, e.second + e.microsecond * 1e-6 + np.asarray(t))
    v = wgs84.latlon(latitude_deg, longitude_deg, elevation_m=altitude_m).at(tt).position.m.T - np.asarray(r_N)
    return v / np.linalg.norm(v, axis=1, keepdims=True)


def strip_sight_from(epoch: str, r_N, start_deg: tuple, end_deg: tuple, altitude_m: float, scan_start: float,
                     duration: float, t):
    """Unit lines of sight (K, 3, GCRS) from the spacecraft at ``r_N`` (K, 3, m, GCRS) at times ``t`` (s
    past the UTC ``epoch``) to a strip's aim point, scanned from ``scan_start`` for ``duration`` s:
    the point a fraction ``(t − scan_start) / duration`` of the way from the start to the end
    (geodetic (lat, lon) deg) in latitude and longitude, on skyfield's WGS-84; a strip under 200 km
    is within tens of metres of its great ellipse so."""
    rows = []
    for k, tk in enumerate(np.atleast_1d(t)):
        f = (tk - scan_start) / duration
        lat, lon = (start_deg[i] + f * (end_deg[i] - start_deg[i]) for i in (0, 1))
        rows.append(site_sight_from(epoch, np.asarray(r_N)[k:k + 1], lat, lon, altitude_m, np.array([tk]))[0])
    return np.array(rows)


def site_sight(epoch: str, tle, latitude_deg: float, longitude_deg: float, altitude_m: float, t):
    """Unit lines of sight (K, 3, GCRS) from the spacecraft of ``tle`` to a WGS-84 ground site at
    times ``t`` (s past the UTC ``epoch``): skyfield's ``wgs84.latlon`` and ``EarthSatellite``."""
    from skyfield.api import EarthSatellite, wgs84

    ts, _ = _skyfield()
    e = datetime.fromisoformat(epoch.replace("Z", "+00:00"))
    tt = ts.utc(e.year, e.month, e.day, e.hour, e.minute, e.second + e.microsecond * 1e-6 + np.asarray(t))
    r = EarthSatellite(*tle, ts=ts).at(tt).position.m.T
    site = wgs84.latlon(latitude_deg, longitude_deg, elevation_m=altitude_m).at(tt).position.m.T
    v = site - r
    return v / np.linalg.norm(v, axis=1, keepdims=True)
