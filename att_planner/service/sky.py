"""Is the sky closed? A conservative test that the keep-out cones leave the sensor no way from its
start direction to its goal direction (no ROS).

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
"""
from __future__ import annotations

import functools
import math
from dataclasses import dataclass

import numpy as np
from scipy.sparse import coo_matrix
from scipy.sparse.csgraph import connected_components
from scipy.spatial import ConvexHull, cKDTree

from att_msgs_py.types import Cone
from att_planner.cones import endpoint_directions

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


def _overlapping(cones: list[Cone]) -> bool:
    """Whether two cones overlap (only then can they enclose part of the sky)."""
    for a in range(len(cones)):
        for b in range(a + 1, len(cones)):
            gap = math.acos(float(np.clip(cones[a].direction @ cones[b].direction, -1.0, 1.0)))
            if gap < cones[a].half_angle + cones[b].half_angle:
                return True
    return False


def closed_sky(q_initial, q_final, sensor_axis, cones: list[Cone], sensor_target=None) -> bool:
    """True when the cones certainly separate the start sensor direction from the goal one (or
    sensor_target); False when a path may exist. Ends inside a cone are refused before this."""
    if len(cones) < 2 or not _overlapping(cones):
        return False
    lat = lattice()
    W = np.stack([c.direction for c in cones])
    shrunk = np.array([c.half_angle for c in cones]) - lat.h
    # margin > -h  <=>  angle to the axis > half-angle - h  <=>  p·w < cos(half-angle - h)
    free = np.all((lat.points @ W.T < np.cos(np.maximum(shrunk, 0.0))) | (shrunk <= 0.0), axis=1)
    keep = free[lat.pairs[:, 0]] & free[lat.pairs[:, 1]]
    a, b = lat.pairs[keep].T
    n = len(lat.points)
    _, label = connected_components(coo_matrix((np.ones(len(a), bool), (a, b)), shape=(n, n)), directed=False)
    pieces = []
    for direction in endpoint_directions(q_initial, q_final, sensor_axis, sensor_target).values():
        near = lat.tree.query_ball_point(direction / np.linalg.norm(direction), _chord(lat.h))
        pieces.append({int(label[k]) for k in near if free[k]})
    return not (pieces[0] & pieces[1])
