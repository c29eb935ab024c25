"""Message <-> numpy conversions (epoch and zones too), the signature's coverage of them, and the
rosbag2 message definitions written to logs."""
import copy
import math
from datetime import UTC, datetime

import numpy as np
import pytest
from cryptography.hazmat.primitives.asymmetric.ed25519 import Ed25519PrivateKey

from att_msgs.msg import ManeuverPlan as PlanMsg
from att_msgs.msg import Zone as ZoneMsg
from att_msgs_py import convert, signing, validation
from att_msgs_py.errors import ErrorCode, RequestError
from att_msgs_py.log.definitions import SEPARATOR, message_definition
from att_msgs_py.types import ZONE_BODIES, Cone, Interpolation, Plan, State, Status, Verification, Zone
from att_sim.models import rotations as rot


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


def _zones():
    return [Zone("sun", "sun", np.array([0.0, 1, 0]), math.radians(47)),
            Zone("limb", "earth_limb", np.array([0.0, 1, 0]), math.radians(10)),
            Zone("radiator", "sun", np.array([0.0, 0, -1]), math.pi / 2, keep_in=True),
            Zone("star", "inertial", np.array([1.0, 0, 0]), 0.2, direction=np.array([0.0, 0, 1]))]


def test_zone_round_trip_and_body_constants():
    assert (ZoneMsg.BODY_INERTIAL, ZoneMsg.BODY_SUN, ZoneMsg.BODY_MOON, ZoneMsg.BODY_EARTH_LIMB) == ZONE_BODIES
    for zone in _zones():
        msg = convert.zone_msg(zone)
        back = convert.zone_from_msg(msg)
        assert (back.name, back.body, back.half_angle, back.keep_in) == (zone.name, zone.body, zone.half_angle,
                                                                         zone.keep_in)
        assert np.array_equal(back.sensor_axis, zone.sensor_axis)
        if zone.direction is None:
            assert back.direction is None and convert.from_vector3(msg.direction).tolist() == [0, 0, 0]
        else:
            assert np.array_equal(back.direction, zone.direction)
    odd = convert.zone_msg(_zones()[0])
    odd.direction = convert.vector3([0, 0, 1])       # a direction on a Sun zone is kept for validation to refuse
    assert convert.zone_from_msg(odd).direction is not None


@pytest.mark.parametrize("iso, sec, nanosec", [
    ("2026-12-21T00:00:00Z", 1797811200, 0),
    ("2026-12-21T00:00:00.000123Z", 1797811200, 123_000),
    ("1969-12-31T23:59:59.5Z", -1, 500_000_000),                     # before 1970: negative seconds
    ("1901-12-13T20:45:52Z", -2**31, 0), ("2038-01-19T03:14:07Z", 2**31 - 1, 0),   # the int32 ends
])
def test_epoch_on_the_wire_is_seconds_since_1970(iso, sec, nanosec):
    epoch = datetime.fromisoformat(iso)
    msg = convert.epoch_msg(epoch)
    assert (msg.sec, msg.nanosec) == (sec, nanosec)
    assert convert.from_epoch(msg) == epoch and validation.wire_epoch(sec, nanosec, "epoch") == epoch


def test_zero_time_is_no_epoch_and_wire_epochs_are_checked():
    assert convert.from_epoch(convert.epoch_msg(None)) is None and validation.wire_epoch(0, 0, "epoch") is None
    with pytest.raises(RequestError, match=r"epoch.nanosec = 1000000000 is outside") as err:
        validation.wire_epoch(5, 1_000_000_000, "epoch")
    assert err.value.code == ErrorCode.INVALID_EPOCH
    with pytest.raises(RequestError, match="int32"):
        validation.wire_epoch(2**31, 0, "epoch")
    with pytest.raises(RequestError, match="2038-01-19T03:14:07"):
        validation.sendable_epoch(datetime(2045, 1, 1, tzinfo=UTC), "the scenario's epoch")
    with pytest.raises(RequestError, match="no epoch"):
        validation.sendable_epoch(validation.UNIX_EPOCH, "epoch")


def _sky_plan():
    k = 3
    return Plan(t=np.linspace(0, 2, k), torque=np.zeros((k, 3)), q=np.tile(rot.IDENTITY, (k, 1)),
                omega=np.zeros((k, 3)), plan_id="sky", zones=_zones(),
                epoch=datetime(2026, 12, 21, 0, 10, 0, 250_000, tzinfo=UTC))


def test_plan_round_trips_epoch_and_zones_and_old_logs_have_neither():
    plan = _sky_plan()
    back = convert.plan_from_msg(convert.plan_msg(plan))
    assert back.epoch == plan.epoch and [z.name for z in back.zones] == ["sun", "limb", "radiator", "star"]
    assert back.zones[2].keep_in and np.array_equal(back.zones[3].direction, [0, 0, 1])
    assert convert.plan_from_msg(convert.plan_msg(Plan(t=plan.t, torque=plan.torque, q=plan.q,
                                                       omega=plan.omega))).epoch is None

    class OldPlan:                       # a ManeuverPlan decoded from a log recorded without the zone fields
        def __init__(self, msg):
            self._msg = msg

        def __getattr__(self, name):
            if name in ("epoch", "zones", "spacecraft_digest", "key_id", "signature"):
                raise AttributeError(name)
            return getattr(self._msg, name)

    old = convert.plan_from_msg(OldPlan(convert.plan_msg(plan)))
    assert old.epoch is None and old.zones == [] and old.plan_id == "sky"


def test_the_signature_covers_the_epoch_and_every_zone_field():
    key = Ed25519PrivateKey.generate()
    msg = convert.plan_msg(_sky_plan())
    signing.sign(msg, key)
    assert signing.check(signing.payload(msg), msg.signature, msg.key_id, key.public_key()) is None
    changes = {"epoch": lambda m: setattr(m.epoch, "nanosec", m.epoch.nanosec + 1),
               "zone body": lambda m: setattr(m.zones[0], "body", "moon"),
               "zone half-angle": lambda m: setattr(m.zones[1], "half_angle", m.zones[1].half_angle + 1e-12),
               "zone keep-in": lambda m: setattr(m.zones[0], "keep_in", True),
               "zone axis": lambda m: setattr(m.zones[2].sensor_axis, "y", 1e-9),
               "zone direction": lambda m: setattr(m.zones[3].direction, "x", 1e-9),
               "zone name": lambda m: setattr(m.zones[3], "name", "stars"),
               "zone dropped": lambda m: setattr(m, "zones", list(m.zones)[:-1])}
    for what, change in changes.items():
        forged = copy.deepcopy(msg)
        change(forged)
        assert signing.check(signing.payload(forged), forged.signature, forged.key_id, key.public_key()), what


def test_fault_event_and_status_round_trip_and_the_sources_are_the_message_constants():
    from att_msgs.msg import FaultEvent as FaultEventMsg
    from att_msgs_py.types import FaultEvent, FaultSource, FaultStatus

    assert {s.value for s in FaultSource} == {getattr(FaultEventMsg, n) for n in dir(FaultEventMsg)
                                              if n.startswith("SOURCE_")}
    event = FaultEvent(t=12.25, component="star_tracker", index=1, kind="bias_jump", factor=1.0,
                       bias_rad=(1e-3, -2e-3, 0.5), source=FaultSource.SERVICE, frame_id="body")
    back = convert.fault_event_from_msg(convert.fault_event_msg(event))
    assert back == event and isinstance(back.source, FaultSource)
    status = FaultStatus(t=30.5, fault_id="wheel_stall", component="wheel", index=2, detector="wheel_acceleration",
                         evidence="|a_cmd - a_meas| = 3.1 rad/s^2 > 0.5 for 1.0 s", response="reallocate",
                         active=True, detected_at=29.75, frame_id="body")
    assert convert.fault_status_from_msg(convert.fault_status_msg(status)) == status
