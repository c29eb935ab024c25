"""Message <-> numpy conversions and the rosbag2 message definitions written to logs."""
import numpy as np

from att_msgs.msg import ManeuverPlan as PlanMsg
from att_msgs_py import convert
from att_msgs_py.mcap_log import SEPARATOR, message_definition
from att_planner.cones import Cone
from att_planner.problem import ManeuverPlan
from att_planner.verify import Verification
from att_sim import rotations as rot


def test_quaternion_vector_time_round_trip():
    q = rot.from_axis_angle([1, 2, 3], 0.8)
    assert np.array_equal(convert.from_quaternion(convert.quaternion(q)), q)
    msg = convert.quaternion(q)
    assert (msg.x, msg.y, msg.z, msg.w) == tuple(q)          # geometry_msgs order = numpy order
    assert np.array_equal(convert.from_vector3(convert.vector3([1.5, -2, 3])), [1.5, -2, 3])
    for t in (0.0, 1.25, 12345.999999999):
        assert abs(convert.from_time(convert.time_msg(t)) - t) < 1e-9


def test_state_round_trip():
    x = np.concatenate([rot.from_axis_angle([0, 1, 0], 0.3), [0.1, -0.2, 0.3], [10.0, 20.0, -30.0]])
    msg = convert.state_msg(12.5, x, frame_id="eci", body_frame_id="body", wheel_torques=[0.01, 0, 0],
                            field_body=[1e-5, 2e-5, 3e-5], dipole=[1, 2, 3], applied_torque=[0, 0, 1e-3],
                            position=[7e6, 0, 0], command_timeout=True)
    a = convert.state_arrays(msg)
    assert a["t"] == 12.5 and np.allclose(a["q"], x[:4]) and np.allclose(a["omega"], x[4:7])
    assert np.allclose(a["wheel_speeds"], x[7:]) and np.allclose(a["dipole"], [1, 2, 3])
    assert msg.header.frame_id == "eci" and msg.body_frame_id == "body" and msg.command_timeout


def test_plan_round_trip():
    k = 5
    t = np.linspace(0, 4, k)
    q = rot.from_axis_angle(np.tile([0, 0, 1.0], (k, 1)), np.linspace(0, 1, k))
    plan = ManeuverPlan("m", t, np.arange(3 * k, dtype=float).reshape(k, 3), q, np.ones((k, 3)), "linear", "optimal")
    cones = [Cone([0, 0, 1], 0.3, "sun")]
    ver = Verification(1e-4, 1e-5, 0.2, [0.2], 0.9, 0.0, 0.1, 4.0, 100)
    msg = convert.plan_msg(plan, plan_id="abc", frame_id="eci", spacecraft="swift_demo", sensor_axis=[1, 0, 0],
                           cones=cones, verification=ver)
    assert isinstance(msg, PlanMsg) and msg.verification.min_cone_margin == 0.2
    back = convert.plan_arrays(msg)
    assert back["plan_id"] == "abc" and back["interpolation"] == "linear" and back["duration"] == 4.0
    for key in ("t", "q", "omega", "torque"):
        assert np.allclose(back[key], getattr(plan, key))
    assert back["cones"][0].name == "sun" and np.isclose(back["cones"][0].half_angle, 0.3)


def test_message_definition_has_every_dependency_once():
    text = message_definition("att_msgs/msg/ManeuverPlan")
    deps = [line[5:] for line in text.splitlines() if line.startswith("MSG: ")]
    assert set(deps) == {"std_msgs/msg/Header", "builtin_interfaces/msg/Time", "geometry_msgs/msg/Quaternion",
                         "geometry_msgs/msg/Vector3", "att_msgs/msg/KeepOutCone", "att_msgs/msg/PlanVerification"}
    assert len(deps) == len(set(deps)) and text.count(SEPARATOR) == len(deps)
