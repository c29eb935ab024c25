"""Is the sky closed? A conservative test that the zones leave a sensor no way from its start
direction to its goal direction (no ROS).

The boresight can be steered along any path of directions (a rotation about the boresight then
reaches any attitude), so a maneuver exists exactly when the start and goal directions lie in one
connected piece of the free sky. The test samples the sphere with a Fibonacci lattice of
:data:`LATTICE_POINTS` points whose covering radius ``h`` (every direction lies within ``h`` of a
lattice point) is computed exactly from its Delaunay triangles. A lattice point counts as free
when its cone margin exceeds ``-h`` (it is within ``h`` of a free direction, or could be), and free
points closer than :data:`REACH` ``h`` are neighbours. Every point of a free path has a free
lattice point within ``h``, and the nearest lattice points of two nearby path points are within
``2 h`` of each other, so a feasible request is never refused: :func:`closed_sky` only reports
start and goal in different pieces of this slightly fattened sky. Cones that do not overlap
cannot close anything (the complement of disjoint caps is connected) and cost nothing.

Zones are tested sensor by sensor (the zones sharing one sensor axis; a keep-in zone
is free inside its cap). A moving zone is replaced by a fixed cap about its axis at t = 0 holding
every direction that is free at some time of the zone window (:func:`relaxed_caps`: keep-out
caps shrunk, keep-in caps grown by the zone's motion), so a path that is free at each of its own
times lies in the relaxed sky and the test still never refuses a feasible request whose maneuver
fits in the window. Fixed zones (and the keep-out cones) are their caps at t = 0 exactly.
"""
from __future__ import annotations

import functools
import math
from dataclasses import dataclass

import numpy as np
from scipy.sparse import coo_matrix
from scipy.sparse.csgraph import connected_components
from scipy.spatial import ConvexHull, cKDTree

from att_planner.cones import boresight
from att_planner.zones import FittedZones

LATTICE_POINTS = 20_000
SLACK = 1.1            # free: margin > -SLACK h (h: the lattice's covering radius)
REACH = 2.2            # neighbours: closer than REACH · SLACK · h


@dataclass(frozen=True)
class Lattice:
    points: np.ndarray      # (n, 3) unit vectors
    h: float                # rad: free-margin threshold (covering radius times SLACK)
    tree: cKDTree
    pairs: np.ndarray       # (m, 2) indices of neighbouring points


def _chord(angle: float) -> float:
    return 2.0 * math.sin(angle / 2.0)


@functools.cache
def lattice() -> Lattice:
    """The Fibonacci lattice, its covering radius and neighbour pairs (built once, ~0.1 s)."""
    i = np.arange(LATTICE_POINTS) + 0.5
    z = 1.0 - 2.0 * i / LATTICE_POINTS
    phi = math.pi * (1.0 + math.sqrt(5.0)) * i
    r = np.sqrt(1.0 - z * z)
    points = np.column_stack([r * np.cos(phi), r * np.sin(phi), z])
    # each hull facet is a Delaunay triangle; its plane offset is the cosine of its empty cap's radius
    covering = float(np.arccos(np.clip(-ConvexHull(points).equations[:, 3], -1.0, 1.0)).max())
    h = SLACK * covering
    tree = cKDTree(points)
    return Lattice(points, h, tree, tree.query_pairs(_chord(REACH * h), output_type="ndarray"))


MOTION_SAMPLES = 257   # times over the zone window at which moving zones are sampled


@dataclass(frozen=True)
class Cap:
    """A zone of one sensor as a fixed spherical cap: keep-out (the boresight stays outside) or
    keep-in (inside)."""

    direction: np.ndarray
    half_angle: float
    keep_in: bool


def relaxed_caps(zone_sky: FittedZones, zones: np.ndarray) -> list[Cap]:
    """Zones ``zones`` (indices) of ``zone_sky`` as fixed caps about their axes at t = 0 that contain
    every direction free at some time of the window: a moving keep-out zone shrunk by how far its
    axis strays from a(0) (and its half-angle drops), a keep-in zone grown likewise; ``δ``, the
    largest step between samples of the axis and the half-angle, bounds the motion between them.
    Fixed zones are the caps themselves. A keep-out zone that shrinks to nothing is dropped."""
    t = np.linspace(0.0, zone_sky.window, MOTION_SAMPLES) if zone_sky.moving else np.zeros(1)
    axes, half = zone_sky.true_axes(t)[:, zones], zone_sky.true_half_angles(t)[:, zones]
    axes = axes / np.linalg.norm(axes, axis=-1, keepdims=True)
    stray = np.arccos(np.clip(np.einsum("kzj,zj->kz", axes, axes[0]), -1.0, 1.0))
    step = (np.arccos(np.clip(np.einsum("kzj,kzj->kz", axes[1:], axes[:-1]), -1.0, 1.0)).max(axis=0)
            + np.abs(np.diff(half, axis=0)).max(axis=0)) if len(t) > 1 else np.zeros(len(zones))
    caps = []
    for j, z in enumerate(zones):
        if zone_sky.keep_in[z]:
            caps.append(Cap(axes[0, j], float(min((half[:, j] + stray[:, j]).max() + step[j], math.pi)), True))
        else:
            shrunk = float((half[:, j] - stray[:, j]).min() - step[j])
            if shrunk > 0.0:
                caps.append(Cap(axes[0, j], shrunk, False))
    return caps


def _overlapping(caps: list[Cap]) -> bool:
    """Whether two keep-out caps overlap (only then can they enclose part of the sky)."""
    for a in range(len(caps)):
        for b in range(a + 1, len(caps)):
            gap = math.acos(float(np.clip(caps[a].direction @ caps[b].direction, -1.0, 1.0)))
            if gap < caps[a].half_angle + caps[b].half_angle:
                return True
    return False


def separated(caps: list[Cap], start: np.ndarray, goal: np.ndarray) -> bool:
    """True when the caps certainly separate the unit directions ``start`` and ``goal`` of one
    sensor (the lattice test of the module docstring); False when a path may exist."""
    out = [c for c in caps if not c.keep_in]
    if not any(c.keep_in for c in caps) and (len(out) < 2 or not _overlapping(out)):
        return False
    lat = lattice()
    W = np.stack([c.direction for c in caps])
    theta = np.array([c.half_angle for c in caps])
    keep_in = np.array([c.keep_in for c in caps])
    cos = lat.points @ W.T
    shrunk = theta - lat.h
    # keep-out: margin > -h  <=>  angle to the axis > half-angle - h  <=>  p·w < cos(half-angle - h)
    clear_out = (cos < np.cos(np.maximum(shrunk, 0.0))) | (shrunk <= 0.0)
    # keep-in: margin > -h  <=>  angle to the axis < half-angle + h
    clear_in = cos > np.cos(np.minimum(theta + lat.h, math.pi))
    free = np.all(np.where(keep_in, clear_in, clear_out), axis=1)
    keep = free[lat.pairs[:, 0]] & free[lat.pairs[:, 1]]
    a, b = lat.pairs[keep].T
    n = len(lat.points)
    _, label = connected_components(coo_matrix((np.ones(len(a), bool), (a, b)), shape=(n, n)), directed=False)
    pieces = []
    for direction in (start, goal):
        near = lat.tree.query_ball_point(direction / np.linalg.norm(direction), _chord(lat.h))
        pieces.append({int(label[k]) for k in near if free[k]})
    return not (pieces[0] & pieces[1])


def closed_sky(zone_sky: FittedZones, q_initial, q_final, sensor_axis, sensor_target=None) -> np.ndarray | None:
    """The sensor axis whose zones certainly separate its start direction from its goal direction
    (for ``sensor_axis`` with a semi-free goal: from ``sensor_target``), or None when a path may
    exist for every sensor. Zones are taken as :func:`relaxed_caps` over the window; with a
    semi-free goal the other sensors' goal directions are free and are not tested. Ends inside a
    zone are refused before this."""
    axes = zone_sky.sensor_axes / np.linalg.norm(zone_sky.sensor_axes, axis=-1, keepdims=True)
    groups: dict[bytes, list[int]] = {}
    for i, s in enumerate(axes):
        groups.setdefault(np.round(s, 12).tobytes(), []).append(i)
    r = np.asarray(sensor_axis, float) / np.linalg.norm(sensor_axis)
    for members in groups.values():
        s = axes[members[0]]
        main = np.allclose(s, r, atol=1e-12)
        if sensor_target is not None and not main:
            continue
        goal = np.asarray(sensor_target, float) if sensor_target is not None else boresight(q_final, s)
        if separated(relaxed_caps(zone_sky, np.array(members)), boresight(q_initial, s), goal):
            return s
    return None
