"""What the 3D view shows, without ROS: the zones as cones where they are now, the
sensor boresights, the Sun, Moon and Earth directions, and a plan's boresight path, as plain
:class:`att_msgs_py.types.Shape` (:mod:`att_msgs_py.markers` makes the messages).

The view is centred on the spacecraft: the body frame's origin is the inertial frame's, so a cone's
apex (the spacecraft) is the origin and a direction is a point ``length`` m along it. Zones: ``θ``
the half-angle and ``a_N`` the unit inertial axis now (:func:`zone_views`, as
:mod:`att_planner.zones` defines them); the rim is the circle of the points at angle ``θ`` from
``a_N``, ``length`` m from the apex. Keep-out red, keep-in green.
"""
from __future__ import annotations

import math
from typing import NamedTuple

import numpy as np

from att_msgs_py.types import Shape, ShapeKind, Zone
from att_sim.models import rotations as rot
from att_sim.models.world import Bodies

LENGTH = 2.0              # m: cone side, arrow and path radius in the view
RIM_POINTS = 48           # points on a cone's rim
KEEP_OUT_RGBA = (0.9, 0.1, 0.1, 0.35)
KEEP_IN_RGBA = (0.1, 0.8, 0.2, 0.35)
BORESIGHT_RGBA = (1.0, 1.0, 1.0, 1.0)
PATH_RGBA = (0.2, 0.6, 1.0, 1.0)
BODY_RGBA = {"sun": (1.0, 0.85, 0.1, 1.0), "moon": (0.75, 0.75, 0.8, 1.0), "earth": (0.2, 0.4, 1.0, 1.0)}


class ZoneView(NamedTuple):
    """A zone at one time: unit inertial axis ``axis_N`` and half-angle (rad)."""

    name: str
    keep_in: bool
    axis_N: np.ndarray
    half_angle: float


EARTH_FIXED_FRAME = "itrs"          # /tf child of the inertial frame in the scenarios with an epoch


def earth_fixed(environment, t: float, r_N) -> tuple[np.ndarray, np.ndarray]:
    """The Earth-fixed frame (ITRS) in the inertial frame of a view centred on the spacecraft at
    ``r_N`` (m): ``(q_EN, origin_N)``, the rotation with ``p_N = R(q_EN) p_E`` (the transpose of
    the field's GCRS → ITRS rotation, IAU 2006 by skyfield) and the Earth's centre at ``−r_N``."""
    R_EN = environment.field.itrs_rotation(np.asarray(t, float))        # r_E = R r_N
    return rot.from_dcm_NB(R_EN.T), -np.asarray(r_N, float)


def zone_views(zones: list[Zone], bodies: Bodies) -> list[ZoneView]:
    """Every zone where it is at the time of ``bodies`` (a Sun or Moon zone without a sky is left out)."""
    out = []
    for z in zones:
        half_angle = z.half_angle
        if z.body == "inertial":
            axis_N = z.direction
        elif z.body == "earth_limb":
            axis_N, half_angle = bodies.nadir, bodies.earth_radius + z.half_angle
        else:
            axis_N = bodies.sun if z.body == "sun" else bodies.moon
        if axis_N is not None:
            out.append(ZoneView(z.name, z.keep_in, np.asarray(axis_N, float), float(half_angle)))
    return out


def zone_margins(zones: list[Zone], views: list[ZoneView], q_BN) -> np.ndarray:
    """Margin of each zone (rad, >= 0 clear) at attitude ``q_BN``: ``γ − θ`` keep-out, ``θ − γ``
    keep-in, ``γ`` the angle of the boresight ``R(q_BN) s_B`` from the zone's axis ``a_N``
    (``views`` are :func:`zone_views` of ``zones``, in the same order)."""
    if not views:
        return np.zeros(0)
    s_B = np.array([z.sensor_axis / np.linalg.norm(z.sensor_axis) for z in zones])
    b_N = s_B @ rot.dcm_BN(np.asarray(q_BN, float))
    a_N = np.array([v.axis_N for v in views])
    gamma = np.arctan2(np.linalg.norm(np.cross(b_N, a_N), axis=1), np.einsum("ij,ij->i", b_N, a_N))
    theta = np.array([v.half_angle for v in views])
    return np.where([v.keep_in for v in views], theta - gamma, gamma - theta)


def cone_rim(axis_N, half_angle: float, length: float = LENGTH, n: int = RIM_POINTS) -> np.ndarray:
    """(n + 1, 3) closed circle of the points at ``half_angle`` from ``axis_N``, ``length`` from the apex."""
    a = np.asarray(axis_N, float) / np.linalg.norm(axis_N)
    e1, e2 = rot.orthonormal_basis(a)
    phi = np.linspace(0.0, 2.0 * math.pi, n + 1)[:, None]
    ring = np.cos(phi) * e1 + np.sin(phi) * e2
    return length * (math.cos(half_angle) * a + math.sin(half_angle) * ring)


def cone_triangles(rim: np.ndarray) -> np.ndarray:
    """(3n, 3) triangle list of the cone's side: apex (origin), rim point k, rim point k + 1."""
    n = len(rim) - 1
    out = np.zeros((3 * n, 3))
    out[1::3], out[2::3] = rim[:-1], rim[1:]
    return out


def boresight_path(q_BN, sensor_axis_B, length: float = LENGTH) -> np.ndarray:
    """(K, 3) inertial boresight ``length R(q_BN) s_B / |s_B|`` along the attitudes ``q_BN`` (K, 4)."""
    s_B = np.asarray(sensor_axis_B, float) / np.linalg.norm(sensor_axis_B)
    return length * np.einsum("kij,j->ki", rot.dcm_NB(np.asarray(q_BN, float).reshape(-1, 4)), s_B)


def zone_shapes(views: list[ZoneView], frame_N: str, length: float = LENGTH) -> list[Shape]:
    """Each zone's cone (a triangle list) and rim (a line), ids in zone order."""
    out = []
    for k, v in enumerate(views):
        rim = cone_rim(v.axis_N, v.half_angle, length)
        rgba = KEEP_IN_RGBA if v.keep_in else KEEP_OUT_RGBA
        out.append(Shape("zones", k, frame_N, ShapeKind.TRIANGLES, cone_triangles(rim), rgba))
        out.append(Shape("zone_rims", k, frame_N, ShapeKind.LINE, rim, rgba[:3] + (1.0,)))
    return out


def sky_shapes(zones: list[Zone], bodies: Bodies, frame_N: str, frame_B: str, length: float = LENGTH) -> list[Shape]:
    """The simulator's view at one time: the zones' cones, an arrow along each distinct sensor
    axis of the zones (body frame), and arrows to the Sun, Moon (with a sky) and Earth (nadir)."""
    out = zone_shapes(zone_views(zones, bodies), frame_N, length)
    axes: list[np.ndarray] = []
    for z in zones:
        s_B = z.sensor_axis / np.linalg.norm(z.sensor_axis)
        if not any(np.allclose(s_B, a, atol=1e-12) for a in axes):
            axes.append(s_B)
    out += [Shape("boresight", k, frame_B, ShapeKind.ARROW, np.array([np.zeros(3), 1.25 * length * s_B]),
                  BORESIGHT_RGBA, 0.05) for k, s_B in enumerate(axes)]
    directions = {"sun": bodies.sun, "moon": bodies.moon, "earth": bodies.nadir}
    out += [Shape("bodies", k, frame_N, ShapeKind.ARROW, np.array([np.zeros(3), 1.5 * length * np.asarray(u)]),
                  BODY_RGBA[name], 0.04) for k, (name, u) in enumerate(directions.items()) if u is not None]
    return out


def plan_shapes(q_BN, sensor_axis_B, frame_N: str, length: float = LENGTH) -> list[Shape]:
    """A plan's boresight path (a line through its reference attitudes, inertial frame)."""
    return [Shape("plan_path", 0, frame_N, ShapeKind.LINE, boresight_path(q_BN, sensor_axis_B, length), PATH_RGBA)]
