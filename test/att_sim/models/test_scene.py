"""The 3D view's geometry: cones at their zones' half-angles about the zones' current
axes (the planner's definition), boresights and paths through the attitude convention, frames."""
import math

import numpy as np
import pytest
from scipy.spatial.transform import Rotation

from att_msgs_py import markers
from att_msgs_py.types import ShapeKind, Zone
from att_planner.zones import FittedZones
from att_sim.models import rotations as rot
from att_sim.models import scenario as scen
from att_sim.models import scene
from att_sim.models.ephemeris import Ephemeris
from att_sim.models.world import Environment


def angles_deg(points, axis):
    p = np.asarray(points, float)
    return np.degrees(np.arccos(np.clip(p @ axis / np.linalg.norm(p, axis=1) / np.linalg.norm(axis), -1, 1)))


@pytest.mark.parametrize("axis, half_deg", [([0, 0, 1], 30.0), ([1, 2, -3], 5.0), ([0.9, 0.1, 0], 120.0),
                                            ([1, 0, 0], 89.0)])
def test_cone_rim_is_at_the_half_angle_and_the_side_joins_apex_to_rim(axis, half_deg):
    rim = scene.cone_rim(axis, math.radians(half_deg), length=3.0)
    assert rim.shape == (scene.RIM_POINTS + 1, 3) and np.allclose(rim[0], rim[-1])      # a closed circle
    assert np.allclose(angles_deg(rim, axis), half_deg, atol=1e-9)
    assert np.allclose(np.linalg.norm(rim, axis=1), 3.0)
    steps = np.linalg.norm(np.diff(rim, axis=0), axis=1)
    assert np.allclose(steps, steps[0])                                                   # evenly around
    tri = scene.cone_triangles(rim)
    assert tri.shape == (3 * scene.RIM_POINTS, 3) and not tri[0::3].any()
    assert np.array_equal(tri[1::3], rim[:-1]) and np.array_equal(tri[2::3], rim[1:])


def test_the_tf_transform_rotates_body_vectors_into_the_inertial_frame_as_the_state_does():
    q_BN = rot.from_axis_angle([0.3, -1.0, 0.5], 2.1)
    msg = markers.transform_msg(12.5, "gcrs", "body", q_BN)
    assert msg.header.frame_id == "gcrs" and msg.child_frame_id == "body"
    assert msg.header.stamp.sec == 12 and msg.header.stamp.nanosec == 500_000_000
    r = msg.transform.rotation
    as_tf = Rotation.from_quat([r.x, r.y, r.z, r.w])          # tf: v_parent = R v_child, scalar last
    v_B = np.array([[1.0, 0, 0], [0, 1.0, 0], [0.2, -0.4, 0.9]])
    assert np.allclose(as_tf.apply(v_B), (rot.dcm_NB(q_BN) @ v_B.T).T, atol=1e-12)
    t = msg.transform.translation
    assert (t.x, t.y, t.z) == (0.0, 0.0, 0.0)                 # the view is centred on the spacecraft
    # the boresight arrow drawn in the body frame lands where the plan path (inertial) puts it
    s_B = np.array([0.0, 1.0, 0.0])
    assert np.allclose(as_tf.apply(scene.LENGTH * s_B), scene.boresight_path([q_BN], s_B)[0], atol=1e-12)


def test_a_plan_path_follows_the_boresight_through_the_attitudes():
    q = rot.slerp(rot.from_axis_angle([0, 0, 1], 0.0), rot.from_axis_angle([0, 0, 1], math.pi / 2),
                  np.linspace(0, 1, 11))
    path = scene.boresight_path(q, [2.0, 0.0, 0.0], length=1.5)
    assert np.allclose(np.linalg.norm(path, axis=1), 1.5)
    assert np.allclose(path[0], [1.5, 0, 0]) and np.allclose(path[-1], [0, 1.5, 0], atol=1e-12)
    assert np.allclose(np.degrees(np.arctan2(path[:, 1], path[:, 0])), np.linspace(0, 90, 11))
    (shape,) = scene.plan_shapes(q, [1, 0, 0], "eci")
    assert shape.kind is ShapeKind.LINE and shape.frame_id == "eci" and len(shape.points) == 11


def test_zones_are_drawn_where_the_planner_says_they_are_now():
    sc = scen.load("leo_observatory")
    zones = sc.zones + [Zone("target", "inertial", [0, 1, 0], math.radians(20), True, [0.0, 0.6, 0.8])]
    env = Environment.from_scenario(sc)
    truth = FittedZones(zones, Ephemeris(sc.epoch, sc.orbit_model), window=4000.0)
    for t in (0.0, 1234.5, 3600.0):
        views = scene.zone_views(zones, env.bodies(t))
        assert [v.name for v in views] == ["sun", "moon", "earth", "target"]
        axes, halves = truth.true_axes(np.array(t)), truth.true_half_angles(np.array(t))
        for v, a, h in zip(views, axes, halves, strict=True):
            assert math.degrees(math.acos(min(1.0, v.axis_N @ a / np.linalg.norm(a)))) < 1e-6, v.name
            assert abs(v.half_angle - h) < 1e-9, v.name
            shape = next(s for s in scene.zone_shapes([v], "gcrs") if s.ns == "zone_rims")
            assert np.allclose(angles_deg(shape.points, a), math.degrees(h), atol=1e-6)
    earth = views[2]
    r = np.linalg.norm(env.bodies(3600.0).position)
    assert abs(earth.half_angle - (math.asin(6378.137e3 / r) + math.radians(10.0))) < 1e-12


def test_the_sky_shapes_name_their_frames_and_colours():
    sc = scen.load("leo_observatory")
    zones = sc.zones + [Zone("target", "inertial", [0, 0, 1], math.radians(20), True, [1.0, 0, 0])]
    shapes = scene.sky_shapes(zones, Environment.from_scenario(sc).bodies(10.0), "gcrs", "body")
    by_ns = {}
    for s in shapes:
        by_ns.setdefault(s.ns, []).append(s)
    assert sorted(by_ns) == ["bodies", "boresight", "zone_rims", "zones"]
    assert [s.kind for s in by_ns["zones"]] == [ShapeKind.TRIANGLES] * 4
    assert [s.rgba[:3] for s in by_ns["zones"]] == [scene.KEEP_OUT_RGBA[:3]] * 3 + [scene.KEEP_IN_RGBA[:3]]
    assert all(s.frame_id == "gcrs" for ns in ("zones", "zone_rims", "bodies") for s in by_ns[ns])
    # two distinct sensor axes (+y of the scenario's zones, +z of the target): one body-frame arrow each
    arrows = by_ns["boresight"]
    assert [s.frame_id for s in arrows] == ["body", "body"] and [s.id for s in arrows] == [0, 1]
    heads = np.array([s.points[1] / np.linalg.norm(s.points[1]) for s in arrows])
    assert np.allclose(heads, [[0, 1, 0], [0, 0, 1]])
    assert [s.rgba for s in by_ns["bodies"]] == [scene.BODY_RGBA[k] for k in ("sun", "moon", "earth")]
    for ns, shapes_ in by_ns.items():
        assert len({s.id for s in shapes_}) == len(shapes_), ns         # unique ids: a viewer replaces


def test_without_a_sky_only_the_earth_is_drawn():
    sc = scen.load("swift_demo")
    bodies = Environment.from_scenario(sc).bodies(0.0)
    shapes = scene.sky_shapes([Zone("c", "inertial", [1, 0, 0], 0.5, False, [0, 0, 1])], bodies, "eci", "body")
    assert [(s.ns, s.id) for s in shapes if s.ns == "bodies"] == [("bodies", 2)]      # the Earth keeps its id
    assert scene.zone_views([Zone("s", "sun", [1, 0, 0], 0.5)], bodies) == []


def test_zone_margins_are_the_planners_truth_margins():
    sc = scen.load("leo_observatory")
    zones = sc.zones + [Zone("target", "inertial", [0, 0, 1], math.radians(20), True, [0.0, 0.6, 0.8])]
    env = Environment.from_scenario(sc)
    truth = FittedZones(zones, Ephemeris(sc.epoch, sc.orbit_model), window=4000.0)
    for t, q in ((0.0, rot.IDENTITY), (2000.0, rot.from_axis_angle([1, 2, 3], 2.0))):
        mine = scene.zone_margins(zones, scene.zone_views(zones, env.bodies(t)), q)
        assert np.allclose(mine, truth.margins(np.array([t]), q[None], true=True).reshape(-1), atol=1e-9)
    square = [Zone("out", "inertial", [1, 0, 0], math.radians(30), False, [0, 0, 1]),
              Zone("in", "inertial", [1, 0, 0], math.radians(30), True, [0, 0, 1])]
    views = scene.zone_views(square, None)
    assert np.allclose(np.degrees(scene.zone_margins(square, views, rot.IDENTITY)), [60.0, -60.0])
