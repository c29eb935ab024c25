"""Message <-> numpy conversions and the rosbag2 message definitions written to logs."""
import numpy as np

from att_msgs.msg import ManeuverPlan as PlanMsg
from att_msgs_py import convert
from att_msgs_py.log.definitions import SEPARATOR, message_definition
from att_msgs_py.types import Cone, Interpolation, Plan, State, Status, Verification
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
    msg = convert.state_msg(State(12.5, x[:4], x[4:7], x[7:], wheel_torques=np.array([0.01, 0, 0]),
                                  field_body=np.array([1e-5, 2e-5, 3e-5]), dipole=np.array([1, 2, 3]),
                                  applied_torque=np.array([0, 0, 1e-3]), position=np.array([7e6, 0, 0]),
                                  command_timeout=True, frame_id="eci", body_frame_id="body"))
    a = convert.state_from_msg(msg)
    assert a.t == 12.5 and np.allclose(a.q, x[:4]) and np.allclose(a.omega, x[4:7])
    assert np.allclose(a.wheel_speeds, x[7:]) and np.allclose(a.dipole, [1, 2, 3])
    assert msg.header.frame_id == "eci" and msg.body_frame_id == "body" and msg.command_timeout
    assert a.frame_id == "eci" and a.body_frame_id == "body" and a.command_timeout


def test_plan_round_trip():
    k = 5
    t = np.linspace(0, 4, k)
    q = rot.from_axis_angle(np.tile([0, 0, 1.0], (k, 1)), np.linspace(0, 1, k))
    ver = Verification(1e-4, 1e-5, 0.2, [0.2], 0.9, 0.0, 0.1, 100, duration=4.0)
    plan = Plan(t=t, torque=np.arange(3 * k, dtype=float).reshape(k, 3), q=q, omega=np.ones((k, 3)),
                interpolation=Interpolation.LINEAR, method="m", status=Status.OPTIMAL, plan_id="abc", frame_id="eci",
                spacecraft="swift_demo", sensor_axis=np.array([1.0, 0, 0]), cones=[Cone([0, 0, 1], 0.3, "sun")],
                verification=ver)
    msg = convert.plan_msg(plan)
    assert isinstance(msg, PlanMsg) and msg.verification.min_cone_margin == 0.2
    back = convert.plan_from_msg(msg)
    assert back.plan_id == "abc" and back.interpolation == "linear" and back.duration == 4.0
    assert back.status == Status.OPTIMAL and back.frame_id == "eci" and back.spacecraft == "swift_demo"
    for key in ("t", "q", "omega", "torque"):
        assert np.allclose(getattr(back, key), getattr(plan, key))
    assert back.cones[0].name == "sun" and np.isclose(back.cones[0].half_angle, 0.3)
    assert back.verification.min_cone_margin == 0.2 and back.verification.dense_samples == 100


def test_message_definition_has_every_dependency_once():
    text = message_definition("att_msgs/msg/ManeuverPlan")
    deps = [line[5:] for line in text.splitlines() if line.startswith("MSG: ")]
    assert set(deps) == {"std_msgs/msg/Header", "builtin_interfaces/msg/Time", "geometry_msgs/msg/Quaternion",
                         "geometry_msgs/msg/Vector3", "att_msgs/msg/KeepOutCone", "att_msgs/msg/PlanVerification",
                         "att_msgs/msg/Zone"}
    assert len(deps) == len(set(deps)) and text.count(SEPARATOR) == len(deps)
