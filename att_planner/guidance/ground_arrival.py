"""The attitude and body rate that look at a ground site at one instant, from the line of sight's derivative.

A slew that ends on a ground site must reach, at its final time ``t_f``, the attitude of the
``ground`` pointing law (:mod:`.laws`) and that law's body rate, so that tracking takes over without
a jump. :func:`ground_motion` gives both in closed form on the onboard
:class:`~.laws.PointingGeometry` (docs: ``ground-arrival.md``):

* the **site** ``s_E`` (ITRS, :func:`~.laws.geodetic_to_itrs` on WGS-84) in the inertial frame:
  ``s_N = [EN]ᵀ s_E`` with ``[EN](t)`` the Earth rotation model of the geometry (skyfield's
  GCRS→ITRS through the field's table with an epoch, ``R_3(ω_E t)`` without), and its velocity
  ``ṡ_N = ω_E k_N × s_N``, ``k_N = [EN]ᵀ ẑ`` the Earth's axis (precession and nutation move it by
  less than 1e-11 rad/s);
* the **line of sight** ``d = s_N − r_N``, ``P = d/|d|`` and its derivative
  ``Ṗ = (ḋ − P (P·ḋ))/|d|`` with ``ḋ = ṡ_N − v_N`` (``r_N, v_N`` the orbit's state);
* the **secondary direction** ``S`` (:func:`~.laws.directions`: along-track ``velocity``, the
  ``ground_velocity`` ``v_N − ω_E k_N × r_N`` of the spacecraft over the turning Earth, ...) and
  its derivative by a central difference over :data:`SECONDARY_STEP` (it turns at the orbit's rate,
  so the difference is exact to 1e-12 rad/s);
* the **target attitude**: the two-vector triad ``(P, C, P × C)``, ``C = (P × S)/|P × S|``, matched to
  the body triad of the primary and secondary axes (:func:`~.laws.two_vector_attitude`), then the
  mode's yaw about the primary axis;
* its **rate**: with ``Ċ = (I − C Cᵀ)(Ṗ × S + P × Ṡ)/|P × S|`` and ``(P × C)˙ = Ṗ × C + P × Ċ``,
  the inertial rate of an orthonormal triad ``(e_1, e_2, e_3)`` is ``ω_N = ½ Σ e_i × ė_i``
  (Schaub & Junkins, *Analytical Mechanics of Space Systems*, §3.2: ``[ω×] = Ṙ Rᵀ``), and the
  body rate of the target frame is ``ω_RN_R = [RN] ω_N``.

The terminal condition of a slew is then ``q(t_f) = ±q_RN(t_f)`` and ``ω(t_f) = ω_RN_R(t_f)``
(:class:`att_planner.problem.MovingGoal`).
"""
from __future__ import annotations

import math
from collections.abc import Callable

import numpy as np

from att_planner.guidance.laws import (
    WGS84_A,
    WGS84_E2,
    WGS84_F,
    PointingGeometry,
    geodetic_to_itrs,
    two_vector_attitude,
)
from att_sim.models import rotations as rot
from att_sim.models.geomagnetic import EARTH_ROTATION_RATE

MIN_ELEVATION_DEG = math.degrees(math.atan2(800.0, 500.0))   # an imager's default minimum elevation: bsk-rl's, 58.0 deg
SECONDARY_STEP = 0.5          # s: the central difference of the secondary direction


def earth_axis_N(geometry: PointingGeometry, t: float) -> np.ndarray:
    """The Earth's rotation axis in inertial axes, ``[EN]ᵀ ẑ`` (unit)."""
    return np.asarray(geometry.dcm_EN(t))[2]


def site_state_N(geometry: PointingGeometry, site_E: np.ndarray, t: float) -> tuple[np.ndarray, np.ndarray]:
    """The inertial position and velocity of an Earth-fixed point.

    Parameters
    ----------
    geometry : PointingGeometry
        The onboard geometry (its ``dcm_EN``: the Earth rotation model).
    site_E : ndarray, shape (3,)
        The point in ITRS (m).
    t : float
        Time (s past the scenario's epoch).

    Returns
    -------
    s_N, s_dot_N : ndarray, shape (3,)
        Position (m) and velocity (m/s) in inertial axes, ``s_dot_N = ω_E k_N × s_N``.
    """
    s_N = np.asarray(geometry.dcm_EN(t)).T @ site_E
    return s_N, EARTH_ROTATION_RATE * rot.cross(earth_axis_N(geometry, t), s_N)


def line_of_sight(geometry: PointingGeometry, site_E: np.ndarray, t: float) -> tuple[np.ndarray, np.ndarray]:
    """The unit line of sight from the spacecraft to an Earth-fixed point and its derivative.

    Parameters
    ----------
    geometry : PointingGeometry
        The onboard geometry (orbit state and Earth rotation model).
    site_E : ndarray, shape (3,)
        The point in ITRS (m).
    t : float
        Time (s past the scenario's epoch).

    Returns
    -------
    P, P_dot : ndarray, shape (3,)
        ``P = d/|d|``, ``d = s_N − r_N``, and ``Ṗ = (ḋ − P (P·ḋ))/|d|`` (1/s), inertial axes.
    """
    r_N, v_N = geometry.state_N(t)
    s_N, s_dot_N = site_state_N(geometry, site_E, t)
    d, d_dot = s_N - r_N, s_dot_N - v_N
    rho = math.sqrt(float(d @ d))
    P = d / rho
    return P, (d_dot - P * float(P @ d_dot)) / rho


def triad_rate(frame: np.ndarray, frame_dot: np.ndarray) -> np.ndarray:
    """The inertial angular velocity of an orthonormal triad.

    Parameters
    ----------
    frame, frame_dot : ndarray, shape (3, 3)
        The triad's unit vectors as columns, and their derivatives.

    Returns
    -------
    ndarray, shape (3,)
        ``ω = ½ Σ e_i × ė_i`` (the axial vector of ``Ṙ Rᵀ``; Schaub & Junkins §3.2).
    """
    return 0.5 * sum(rot.cross(frame[:, i], frame_dot[:, i]) for i in range(3))


def two_vector_motion(primary_B, secondary_B, P, P_dot, S, S_dot, yaw_q=None) -> tuple[np.ndarray, np.ndarray]:
    """The two-vector attitude of a primary direction and a secondary one, and its body rate (module docstring).

    Parameters
    ----------
    primary_B, secondary_B : array_like, shape (3,)
        The body axis put on ``P``, and the one kept nearest ``S``.
    P, P_dot : ndarray, shape (3,)
        The unit primary direction (inertial axes) and its derivative (1/s).
    S, S_dot : ndarray, shape (3,)
        The unit secondary direction and its derivative.
    yaw_q : ndarray, shape (4,), optional
        A rotation about the primary axis applied after the alignment (fixed in the body).

    Returns
    -------
    q_RN, omega_RN_R : ndarray
        The attitude ([x, y, z, w]) and the target frame's body rate (rad/s, its own axes); ValueError
        where ``P`` and ``S`` are parallel.
    """
    q_RN = two_vector_attitude(primary_B, secondary_B, P, S)
    n = rot.cross(P, S)
    norm = math.sqrt(float(n @ n))
    C = n / norm
    n_dot = rot.cross(P_dot, S) + rot.cross(P, S_dot)
    C_dot = (n_dot - C * float(C @ n_dot)) / norm
    frame = np.column_stack([P, C, rot.cross(P, C)])
    frame_dot = np.column_stack([P_dot, C_dot, rot.cross(P_dot, C) + rot.cross(P, C_dot)])
    omega_N = triad_rate(frame, frame_dot)
    if yaw_q is not None:
        q_RN = rot.multiply(q_RN, yaw_q)
    return q_RN, rot.dcm_NB(q_RN).T @ omega_N


def ground_motion(geometry: PointingGeometry, latitude: float, longitude: float, altitude: float,
                  primary_B, secondary_B, secondary_N: Callable, yaw: float = 0.0
                  ) -> Callable[[float], tuple[np.ndarray, np.ndarray]]:
    """The attitude and body rate that look at a ground site, as a function of time (module docstring).

    Parameters
    ----------
    geometry : PointingGeometry
        The onboard geometry: orbit state and Earth rotation model.
    latitude, longitude : float
        The site's geodetic latitude and longitude on WGS-84 (rad).
    altitude : float
        Its altitude above the ellipsoid (m).
    primary_B, secondary_B : array_like, shape (3,)
        The body axis put on the line of sight, and the one kept nearest the secondary direction.
    secondary_N : callable
        ``t ↦`` the unit secondary direction (inertial axes), e.g. of :func:`.laws.directions`.
    yaw : float, optional
        Rotation about the primary axis after the alignment (rad).

    Returns
    -------
    callable
        ``t ↦ (q_RN, ω_RN_R)``: the attitude ([x, y, z, w], body to inertial) and the target frame's
        body rate (rad/s, its own axes). It raises ValueError where the line of sight and the
        secondary direction are parallel.
    """
    site_E = geodetic_to_itrs(latitude, longitude, altitude)
    yaw_q = rot.from_axis_angle(np.asarray(primary_B, float), yaw) if yaw else None

    def motion(t: float) -> tuple[np.ndarray, np.ndarray]:
        P, P_dot = line_of_sight(geometry, site_E, t)
        S = np.asarray(secondary_N(t), float)
        S_dot = (np.asarray(secondary_N(t + SECONDARY_STEP), float)
                 - np.asarray(secondary_N(t - SECONDARY_STEP), float)) / (2.0 * SECONDARY_STEP)
        return two_vector_motion(primary_B, secondary_B, P, P_dot, S, S_dot, yaw_q)

    return motion


def itrs_to_geodetic(p_E, iterations: int = 6) -> tuple[float, float, float]:
    """Geodetic coordinates on WGS-84 of an ITRS point.

    Parameters
    ----------
    p_E : array_like, shape (3,)
        The point in ITRS (m).
    iterations : int, optional
        Steps of the fixed-point iteration ``tan φ = z / (ρ (1 − e² N/(N + h)))`` (converged to
        1e-12 rad within a few below 100 km).

    Returns
    -------
    latitude, longitude, altitude : float
        rad, rad, m.
    """
    x, y, z = (float(v) for v in p_E)
    rho = math.hypot(x, y)
    lat = math.atan2(z, rho * (1.0 - WGS84_E2))
    for _ in range(iterations):
        n = WGS84_A / math.sqrt(1.0 - WGS84_E2 * math.sin(lat) ** 2)
        alt = rho / math.cos(lat) - n if abs(lat) < math.pi / 4 else z / math.sin(lat) - n * (1.0 - WGS84_E2)
        lat = math.atan2(z, rho * (1.0 - WGS84_E2 * n / (n + alt)))
    n = WGS84_A / math.sqrt(1.0 - WGS84_E2 * math.sin(lat) ** 2)
    alt = rho / math.cos(lat) - n if abs(lat) < math.pi / 4 else z / math.sin(lat) - n * (1.0 - WGS84_E2)
    return lat, math.atan2(y, x), alt


def site_in_view(geometry: PointingGeometry, t: float, off_nadir: float, azimuth: float = 0.0) -> tuple[float, float]:
    """The ground point seen from the spacecraft in a given direction from its nadir.

    Parameters
    ----------
    geometry : PointingGeometry
        The onboard geometry: orbit state and Earth rotation model.
    t : float
        Time (s past the scenario's epoch).
    off_nadir : float
        Angle of the line of sight from the nadir ``−r̂`` (rad).
    azimuth : float, optional
        Its direction about the nadir from the along-track ``v⊥`` (rad): 0 ahead, π behind, π/2
        towards ``−r̂ × v⊥``.

    Returns
    -------
    latitude, longitude : float
        Geodetic, on the WGS-84 ellipsoid (rad).

    Raises
    ------
    ValueError
        When the line of sight misses the Earth.
    """
    r_N, v_N = geometry.state_N(t)
    nadir = -r_N / np.linalg.norm(r_N)
    along = v_N - nadir * float(nadir @ v_N)
    along /= np.linalg.norm(along)
    across = rot.cross(nadir, along)
    d_N = math.cos(off_nadir) * nadir + math.sin(off_nadir) * (math.cos(azimuth) * along + math.sin(azimuth) * across)
    dcm_EN = np.asarray(geometry.dcm_EN(t))
    scale = np.array([1.0, 1.0, 1.0 / (1.0 - WGS84_F)]) / WGS84_A        # the ellipsoid as the unit sphere
    r, d = scale * (dcm_EN @ r_N), scale * (dcm_EN @ d_N)
    a, b, c = float(d @ d), float(r @ d), float(r @ r) - 1.0
    disc = b * b - a * c
    if disc < 0:
        raise ValueError(f"a line of sight {math.degrees(off_nadir):.1f} deg off nadir misses the Earth")
    lat, lon, _ = itrs_to_geodetic(dcm_EN @ (r_N + (-b - math.sqrt(disc)) / a * d_N))
    return lat, lon


def elevation_sines(r_itrs: np.ndarray, sites_itrs: np.ndarray, up_itrs: np.ndarray, pairs: bool = False) -> np.ndarray:
    """``sin e = û · (r − s) / |r − s|``, the elevation of the spacecraft at ``r`` above the horizon of
    the site at ``s`` with geodetic up ``û`` (all ITRS, m), written ``(û·r − û·s) / sqrt(|r|² − 2 s·r + |s|²)``.

    ``r_itrs`` (K, 3) against N sites ``sites_itrs`` and ``up_itrs`` (N, 3): the grid (N, K) in two
    matrix products; ``pairs``: K = N, the k-th position against the k-th site, (K,)."""
    r = np.asarray(r_itrs, float).reshape(-1, 3)
    s = np.asarray(sites_itrs, float).reshape(-1, 3)
    u = np.asarray(up_itrs, float).reshape(-1, 3)

    def rows(a, b):
        return np.einsum("ij,ij->i", a, b)

    cross = rows if pairs else (lambda a, b: a @ b.T)
    column = (lambda x: x) if pairs else (lambda x: x[:, None])
    along = cross(u, r) - column(rows(u, s))
    return along / np.sqrt(rows(r, r) - 2.0 * cross(s, r) + column(rows(s, s)))
