"""The 3D view through the nodes: a real-sky run of the simulator and the planner,
recorded; the log, decoded by rosbags from its own definitions, holds /tf with the body frame under
the inertial one (the state's attitude) and the Earth-fixed frame (skyfield's ITRS, at -r), the
zones' cones where the sky puts them, their margins, and the plan's boresight path."""
import math
from datetime import timedelta

import numpy as np
import pytest
from scipy.spatial.transform import Rotation

from att_msgs_py import topics
from att_msgs_py.log import read_log
from att_planner.nodes.client import maneuver_request
from att_sim.models import rotations as rot
from att_sim.models import scenario as scen
from att_sim.models.world import Environment
from helpers.waiting import wait_until

SCENARIO = "leo_observatory"                    # GCRS, TLE orbit, Sun/Moon/Earth-limb keep-out zones on +y
END = 6.0                                       # s of sim time
PARAMS = {"simulator": {"lockstep": False, "real_time_factor": 0.0, "end_time_s": END, "publish_rate_Hz": 10.0,
                        "tf_rate_Hz": 10.0, "marker_rate_Hz": 2.0}}


def decode(path):
    """Topic -> [message], decoded by rosbags from the log's own definitions."""
    from rosbags.highlevel import AnyReader
    from rosbags.typesys import Stores, get_typestore

    out = {}
    with AnyReader([path], default_typestore=get_typestore(Stores.EMPTY)) as reader:
        for connection, _, raw in reader.messages():
            out.setdefault(connection.topic, []).append(reader.deserialize(raw, connection.msgtype))
        types = {c.topic: c.msgtype for c in reader.connections}
    return out, types


def recorded(path, topic: str) -> bool:
    """Whether the recorder has written a message of ``topic`` to ``path`` (it flushes every 0.5 s;
    read while it writes)."""
    try:
        return bool(len(read_log(path, topics=[topic]).get(topic, ())))
    except (OSError, ValueError):
        return False                # not written yet, or a chunk half written: look again


def stamp(msg) -> float:
    return msg.header.stamp.sec + msg.header.stamp.nanosec * 1e-9


@pytest.mark.ros
def test_a_recorded_real_sky_run_holds_tf_markers_and_the_plan_path(ros_suite):
    with ros_suite(SCENARIO, nodes=("recorder", "simulator", "planner"), params=PARAMS, name="scene") as s:
        assert s.client.plan_client.wait_for_service(timeout_sec=60)
        goal = rot.from_axis_angle([1, 0, 0], math.radians(30))
        response = s.client.plan(maneuver_request(rot.IDENTITY, goal, [0, 1, 0], [], method="eigenaxis_smooth",
                                                  time_budget=10.0, frame_id="gcrs"))
        assert response.success, response.message
        assert s.suite.wait_for_output("simulator", "end_time reached", timeout=120)
        # the planner's latched markers reach the recorder whenever its executor gets to them, which
        # under load can be after a fast simulator's end
        wait_until(lambda: recorded(s.mcap, topics.PLAN_MARKERS), 60, "the plan's markers in the log", period=0.2)
        s.stop()
    log, types = decode(s.mcap)
    assert types[topics.TF] == "tf2_msgs/msg/TFMessage"
    assert types[topics.SIM_MARKERS] == types[topics.PLAN_MARKERS] == "visualization_msgs/msg/MarkerArray"

    states = {round(stamp(m), 6): m for m in log[topics.STATE]}
    frames = [t for m in log[topics.TF] for t in m.transforms]
    assert {(t.header.frame_id, t.child_frame_id) for t in frames} == {("gcrs", "body"), ("gcrs", "itrs")}
    tfs = [t for t in frames if t.child_frame_id == "body"]
    assert len(tfs) >= 10 * END and max(stamp(t) for t in tfs) >= END - 1e-6
    # the Earth-fixed frame: skyfield's ITRS rotation at that instant, the Earth's centre at -r
    from skyfield.api import load as sky_load
    from skyfield.framelib import itrs
    timescale = sky_load.timescale(builtin=True)
    epoch = scen.load(SCENARIO).epoch
    earth = [t for t in frames if t.child_frame_id == "itrs"]
    assert len(earth) == len(tfs)
    for t in earth[:: max(1, len(earth) // 5)]:
        state = states[round(stamp(t), 6)]
        utc = timescale.from_datetime(epoch + timedelta(seconds=stamp(t)))
        r = t.transform.rotation
        assert np.allclose(Rotation.from_quat([r.x, r.y, r.z, r.w]).as_matrix(), itrs.rotation_at(utc).T, atol=1e-6)
        origin = t.transform.translation
        assert np.allclose([origin.x, origin.y, origin.z], [-state.position.x, -state.position.y, -state.position.z])
    for t in tfs[:: max(1, len(tfs) // 10)]:
        q = states[round(stamp(t), 6)].attitude               # the state at the transform's time
        r = t.transform.rotation
        assert np.allclose(Rotation.from_quat([r.x, r.y, r.z, r.w]).as_matrix(),
                           rot.dcm_NB(np.array([q.x, q.y, q.z, q.w])), atol=1e-12)

    sc = scen.load(SCENARIO)
    env = Environment.from_scenario(sc)
    arrays = log[topics.SIM_MARKERS]
    assert len(arrays) >= 2 * END
    for array in arrays:
        clear, *drawn = array.markers
        assert clear.action == 3                               # DELETEALL first: replace, never accumulate
        t = stamp(clear)
        zones = [m for m in drawn if m.ns == "zone_rims"]
        assert [m.id for m in zones] == [0, 1, 2] and all(m.header.frame_id == "gcrs" for m in zones)
        bodies = env.bodies(t)
        axes = {"sun": bodies.sun, "moon": bodies.moon, "earth": bodies.nadir}
        for m, z in zip(zones, sc.zones, strict=True):
            p = np.array([[q.x, q.y, q.z] for q in m.points])
            half = z.half_angle + (bodies.earth_radius if z.body == "earth_limb" else 0.0)
            assert np.allclose(np.arccos(p @ axes[z.name] / np.linalg.norm(p, axis=1)), half, atol=1e-9), z.name
        (bore,) = [m for m in drawn if m.ns == "boresight"]
        assert bore.header.frame_id == "body" and bore.points[1].y > 0 and bore.points[1].x == bore.points[1].z == 0

    margins = log[topics.ZONE_MARGINS]
    assert len(margins) == len(log[topics.TF])
    for m in margins[::10]:
        assert list(m.names) == ["sun", "moon", "earth"] and m.min_margin == min(m.margins)
        q = states[round(stamp(m), 6)].attitude
        b_N = rot.dcm_NB(np.array([q.x, q.y, q.z, q.w])) @ [0.0, 1.0, 0.0]        # the zones' sensor +y
        bodies = env.bodies(stamp(m))
        for value, z, axis in zip(m.margins, sc.zones, (bodies.sun, bodies.moon, bodies.nadir), strict=True):
            half = z.half_angle + (bodies.earth_radius if z.body == "earth_limb" else 0.0)
            assert abs(value - (math.acos(np.clip(b_N @ axis, -1, 1)) - half)) < 1e-9, z.name

    (path_array,) = log[topics.PLAN_MARKERS]
    (path,) = path_array.markers[1:]
    plan = response.plan
    assert path.ns == "plan_path" and path.header.frame_id == "gcrs" and len(path.points) == len(plan.attitudes)
    last = plan.attitudes[-1]
    end_boresight = rot.dcm_NB(np.array([last.x, last.y, last.z, last.w])) @ [0, 2.0, 0]
    assert np.allclose([path.points[-1].x, path.points[-1].y, path.points[-1].z], end_boresight, atol=1e-9)
