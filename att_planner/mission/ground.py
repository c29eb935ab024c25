"""Ground sites of a mission: when a site can be observed and the attitude that tracks it.

A site is observed with the controller's ``ground`` pointing mode: the sensor axis on the
line of sight to the site, carried by the Earth's rotation, a secondary body axis as close as
possible to a named direction (:mod:`att_planner.guidance.laws`). :class:`GroundTrack` gives, over
an array of times (s past the scenario's epoch):

* the site's **elevation**: ``sin e = û · (r − s) / |r − s|`` with ``r`` the spacecraft's and ``s``
  the site's position and ``û`` the site's geodetic up (GCRS, through the field's GCRS→ITRS table,
  as the controller's law);
* the **attitude** of the pointing law, exactly the one the controller flies;
* the **torque** tracking it takes: the larger, per body axis, of the body torque ``J ω̇ + ω × J ω``
  (what the planners bound) and ``J ω̇`` (what the wheels give with the total momentum near zero),
  from the law's rate and acceleration (:func:`att_planner.guidance.reference`).

A site is *trackable* at a time when it stands ``min_elevation`` above its horizon and that torque
stays within ``torque_share`` of the planning limit (the rest is the feedback's): passes nearly
overhead turn the line of sight faster than a large spacecraft can follow.

A strip (:class:`StripTrack`) is scanned from the slew's arrival: its law depends on that instant
(:meth:`StripTrack.mode_at`). An arrival ``A`` can scan it when the spacecraft stands ``min_elevation``
above the strip's start at ``A`` and above its end at ``A + duration``, and the scan's body torque
(:func:`att_planner.guidance.strip.tracking_demand`) stays within the same share; its attitudes at ``A``
are the strip's first point at the scan's rate (:func:`att_planner.guidance.strip.strip_start_goal`).
"""
from __future__ import annotations

import numpy as np

from att_msgs_py.types import PointingMode
from att_planner.guidance import reference
from att_planner.guidance.ground_arrival import elevation_sines
from att_planner.guidance.laws import WGS84_A, WGS84_E2, WGS84_F, PointingGeometry, geodetic_to_itrs
from att_planner.guidance.modes import law_of, strip_mode
from att_planner.guidance.strip import StripLaw, strip_start_goal, tracking_demand
from att_sim.models import rotations as rot
from att_sim.models import world

TORQUE_SHARE = 0.8             # of the planning torque limit a site's tracking may take


def elevation_above(environment, t, p_itrs, up_itrs) -> np.ndarray:
    """The elevation (rad) of the spacecraft on ``environment``'s orbit above the horizon of the ITRS
    point ``p_itrs`` (its unit up ``up_itrs``) at each time of ``t``: ``sin e = û · (r − s) / |r − s|``,
    GCRS to ITRS through the field's table, as the controller's ground law."""
    t = np.atleast_1d(np.asarray(t, float))
    R = environment.field.itrs_rotation(t)                                 # GCRS -> ITRS, (K, 3, 3)
    r = np.asarray(environment.orbit.position(t), float).reshape(-1, 3)    # GCRS, as the law's
    sines = elevation_sines(np.einsum("kij,kj->ki", R, r), p_itrs, up_itrs)[0]
    return np.arcsin(np.clip(sines, -1.0, 1.0))


def site_track(scenario, site, sensor_axis, secondary_axis, secondary: str, min_elevation: float):
    """The track of target list site ``site``: a :class:`StripTrack` for a strip, else a
    :class:`GroundTrack` of its :func:`site_mode`."""
    if site.strip is not None:
        return StripTrack(scenario, site, sensor_axis, secondary_axis, min_elevation)
    return GroundTrack(scenario, site, site_mode(site, sensor_axis, secondary_axis, secondary), min_elevation)


def site_mode(site, sensor_axis, secondary_axis, secondary: str) -> PointingMode:
    """The ``ground`` pointing mode that tracks ``site`` (a :class:`~att_planner.mission.targets.Site`)."""
    return PointingMode("ground", primary_axis=np.asarray(sensor_axis, float),
                        secondary_axis=np.asarray(secondary_axis, float), secondary=secondary,
                        latitude=site.latitude, longitude=site.longitude, altitude=site.altitude)


def geodetic_up(latitude, longitude) -> np.ndarray:
    """The unit normal of the WGS-84 ellipsoid at geodetic latitudes and longitudes (rad), ITRS,
    shape ``latitude.shape + (3,)``."""
    lat, lon = np.asarray(latitude, float), np.asarray(longitude, float)
    return np.stack([np.cos(lat) * np.cos(lon), np.cos(lat) * np.sin(lon), np.sin(lat)], axis=-1)


class GroundTrack:
    """Site ``site`` tracked with ``mode`` (:func:`site_mode`) from ``scenario``'s spacecraft and orbit."""

    def __init__(self, scenario, site, mode: PointingMode, min_elevation: float, torque_share: float = TORQUE_SHARE):
        self.site, self.mode, self.min_elevation = site, mode, float(min_elevation)
        self.environment = world.Environment.from_scenario(scenario)
        self.law = law_of(mode, PointingGeometry.of(self.environment), 0.0, np.array([0.0, 0.0, 0.0, 1.0]))
        self.spacecraft = scenario.spacecraft
        self.torque_limit = torque_share * self.spacecraft.body_torque_max
        self.r_itrs = geodetic_to_itrs(site.latitude, site.longitude, site.altitude)
        self.up_itrs = geodetic_up(site.latitude, site.longitude)

    def elevation(self, t) -> np.ndarray:
        """The spacecraft's elevation (rad) above the site's horizon at each time of ``t``."""
        return elevation_above(self.environment, t, self.r_itrs, self.up_itrs)

    def attitudes(self, t) -> np.ndarray:
        """The law's attitude (body-to-inertial) at each time of ``t``, (K, 4)."""
        return np.array([self.law.attitude(float(x)) for x in np.atleast_1d(t)])

    def line_of_sight(self, t) -> np.ndarray:
        """The unit line of sight from the spacecraft to the site at each time of ``t``, (K, 3)."""
        return np.array([self.law.primary_N(float(x)) for x in np.atleast_1d(t)])

    def torque(self, t) -> np.ndarray:
        """The largest per-axis torque (N m) tracking the site takes at each time of ``t`` (module docstring)."""
        J = self.spacecraft.inertia
        out = []
        for x in np.atleast_1d(t):
            ref = reference(self.law.attitude, float(x))
            wheel = J @ ref.omega_dot_RN_R
            out.append(max(np.abs(wheel).max(), np.abs(wheel + np.cross(ref.omega_RN_R, J @ ref.omega_RN_R)).max()))
        return np.array(out)

    def trackable(self, t) -> np.ndarray:
        """Whether the site is above ``min_elevation`` and its tracking within the torque share, at each time."""
        t = np.atleast_1d(np.asarray(t, float))
        ok = self.elevation(t) >= self.min_elevation
        if ok.any():
            ok[ok] = self.torque(t[ok]) <= self.torque_limit
        return ok

    def mode_at(self, arrival: float) -> PointingMode:
        """The pointing mode a slew arriving at ``arrival`` hands over to: the site's, whenever."""
        return self.mode


class StripTrack:
    """Strip ``site.strip`` scanned from a slew's arrival by ``scenario``'s spacecraft, boresight
    ``sensor_axis`` and the detector's along-track axis ``secondary_axis`` (body axes): the
    :class:`GroundTrack` interface, whose times are arrivals (module docstring)."""

    def __init__(self, scenario, site, sensor_axis, secondary_axis, min_elevation: float,
                 torque_share: float = TORQUE_SHARE):
        self.site, self.strip, self.min_elevation = site, site.strip, float(min_elevation)
        self.primary_B, self.secondary_B = np.asarray(sensor_axis, float), np.asarray(secondary_axis, float)
        self.environment = world.Environment.from_scenario(scenario)
        self.geometry = PointingGeometry.of(self.environment)
        self.spacecraft = scenario.spacecraft
        self.torque_limit = torque_share * self.spacecraft.body_torque_max
        self.start_goal = strip_start_goal(self.geometry, self.strip, self.primary_B, self.secondary_B)
        ends = [self.strip.point(self.strip.theta_of(s))[0] for s in (0.0, self.strip.length_m)]
        self.ends_itrs = np.array(ends)
        self.ups_itrs = np.array([geodetic_up(*geodetic_of(p)[:2])[0] for p in ends])

    @property
    def duration(self) -> float:
        """The scan's duration (s): the strip's length at its scan speed."""
        return self.strip.duration_s

    def mode_at(self, arrival: float) -> PointingMode:
        """The strip's pointing mode scanned from ``arrival`` (s past the epoch)."""
        return strip_mode(self.strip, self.primary_B, self.secondary_B, arrival)

    def elevation(self, t, end: int = 0) -> np.ndarray:
        """The spacecraft's elevation (rad) above the strip's start (``end`` 1: its end) at each time of ``t``."""
        return elevation_above(self.environment, t, self.ends_itrs[end], self.ups_itrs[end])

    def attitudes(self, t) -> np.ndarray:
        """The attitude on the strip's first point, a scan starting there, at each time of ``t``, (K, 4)."""
        return np.array([self.start_goal(float(x))[0] for x in np.atleast_1d(t)])

    def scan_attitudes(self, arrivals, fraction: float) -> np.ndarray:
        """The attitude ``fraction`` of the way through the scan started at each of ``arrivals``, (K, 4)."""
        law = [StripLaw(self.geometry, self.strip, self.primary_B, self.secondary_B, float(a))
               for a in np.atleast_1d(arrivals)]
        return np.array([x.attitude(x.t_start + fraction * self.duration) for x in law])

    def line_of_sight(self, t) -> np.ndarray:
        """The unit line of sight from the spacecraft to the strip's start at each time of ``t``, (K, 3)."""
        return np.array([rot.dcm_NB(q) @ self.primary_B for q in self.attitudes(t)])

    def trackable(self, t) -> np.ndarray:
        """Whether a scan from each arrival of ``t`` sees the strip's start and end ``min_elevation`` high
        and asks a body torque within the share."""
        t = np.atleast_1d(np.asarray(t, float))
        ok = (self.elevation(t) >= self.min_elevation) & (self.elevation(t + self.duration, 1) >= self.min_elevation)
        for k in np.flatnonzero(ok):
            _, torque = tracking_demand(self.spacecraft, self.geometry, self.strip, self.primary_B, self.secondary_B,
                                        float(t[k]), samples=3)
            ok[k] = torque <= self.torque_limit
        return ok


def geodetic_of(p_itrs) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Geodetic latitude, longitude (rad) and altitude (m) on WGS-84 of ITRS points ``p_itrs`` (K, 3)
    (Bowring's closed form, a few mm below 1000 km); NaN for NaN rows."""
    p = np.asarray(p_itrs, float).reshape(-1, 3)
    x, y, z = p[:, 0], p[:, 1], p[:, 2]
    b = WGS84_A * (1.0 - WGS84_F)
    ep2 = (WGS84_A ** 2 - b ** 2) / b ** 2
    rho = np.hypot(x, y)
    beta = np.arctan2(WGS84_A * z, b * rho)
    lat = np.arctan2(z + ep2 * b * np.sin(beta) ** 3, rho - WGS84_E2 * WGS84_A * np.cos(beta) ** 3)
    n = WGS84_A / np.sqrt(1.0 - WGS84_E2 * np.sin(lat) ** 2)
    alt = rho * np.cos(lat) + (z + WGS84_E2 * n * np.sin(lat)) * np.sin(lat) - n
    return lat, np.arctan2(y, x), alt


def ground_points(r_itrs, d_itrs) -> np.ndarray:
    """Where the lines of sight ``d_itrs`` (K, 3) from the spacecraft at ``r_itrs`` (K, 3, m, ITRS) first
    meet the WGS-84 ellipsoid: ITRS points (K, 3), NaN where a line misses the Earth (or looks away)."""
    scale = np.array([1.0, 1.0, 1.0 / (1.0 - WGS84_F)]) / WGS84_A      # the ellipsoid as the unit sphere
    r = np.asarray(r_itrs, float).reshape(-1, 3)
    d = np.asarray(d_itrs, float).reshape(-1, 3)
    rs, ds = r * scale, d * scale
    a, b, c = (np.einsum("ki,ki->k", ds, ds), np.einsum("ki,ki->k", rs, ds), np.einsum("ki,ki->k", rs, rs) - 1.0)
    disc = b * b - a * c
    with np.errstate(invalid="ignore"):
        s = (-b - np.sqrt(disc)) / a
    s = np.where((disc >= 0.0) & (s > 0.0), s, np.nan)
    return r + s[:, None] * d


def ground_fixes(dcm_EN, r_N, q_BN, sensor_axis_B) -> dict:
    """The sub-satellite point (``sub_lat``, ``sub_lon`` deg, ``sub_alt`` m: the spacecraft's altitude) and
    the boresight's ground point (``bore_lat``, ``bore_lon`` deg; NaN where the sensor axis misses the
    Earth) of spacecraft at GCRS positions ``r_N`` (K, 3, m) with attitudes ``q_BN`` (K, 4), the GCRS to
    ITRS rotations ``dcm_EN`` (K, 3, 3)."""
    R = np.asarray(dcm_EN, float).reshape(-1, 3, 3)
    r = np.einsum("kij,kj->ki", R, np.asarray(r_N, float).reshape(-1, 3))
    d_N = np.einsum("kij,j->ki", rot.dcm_NB(np.asarray(q_BN, float).reshape(-1, 4)), np.asarray(sensor_axis_B, float))
    sub_lat, sub_lon, sub_alt = geodetic_of(r)
    bore_lat, bore_lon, _ = geodetic_of(ground_points(r, np.einsum("kij,kj->ki", R, d_N)))
    return {"sub_lat": np.degrees(sub_lat), "sub_lon": np.degrees(sub_lon), "sub_alt": sub_alt,
            "bore_lat": np.degrees(bore_lat), "bore_lon": np.degrees(bore_lon)}


def ground_track(environment, t, q_BN, sensor_axis_B) -> dict:
    """:func:`ground_fixes` at times ``t`` (s past the epoch) with the attitudes ``q_BN`` (K, 4), the
    spacecraft on ``environment``'s orbit (GCRS to ITRS by its field's table, as the controller's ground
    law)."""
    t = np.atleast_1d(np.asarray(t, float))
    return ground_fixes(environment.field.itrs_rotation(t), np.asarray(environment.orbit.position(t), float),
                        q_BN, sensor_axis_B)
