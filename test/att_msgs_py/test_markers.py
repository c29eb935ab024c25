"""Messages of the 3D view: marker arrays that replace rather than accumulate, shapes
that survive the wire, and /tf and markers that the recorder can describe in a log."""
import numpy as np
from rclpy.serialization import deserialize_message, serialize_message
from tf2_msgs.msg import TFMessage
from visualization_msgs.msg import Marker, MarkerArray

from att_msgs_py import markers, topics
from att_msgs_py.log.definitions import message_definition
from att_msgs_py.types import Shape, ShapeKind
from att_sim.models import rotations as rot

SHAPES = [Shape("zones", 0, "eci", ShapeKind.TRIANGLES, np.arange(9.0).reshape(3, 3), (1.0, 0.0, 0.0, 0.3)),
          Shape("zone_rims", 0, "eci", ShapeKind.LINE, np.ones((4, 3)), (1.0, 0.0, 0.0, 1.0), 0.02),
          Shape("boresight", 0, "body", ShapeKind.ARROW, np.array([[0.0, 0, 0], [0, 2.5, 0]]), (1, 1, 1, 1), 0.05)]


def test_a_marker_array_clears_then_draws_every_shape_and_survives_the_wire():
    array = deserialize_message(serialize_message(markers.marker_array(SHAPES, 7.25, "eci")), MarkerArray)
    clear, *drawn = array.markers
    assert clear.action == Marker.DELETEALL and clear.header.frame_id == "eci"
    assert [m.action for m in drawn] == [Marker.ADD] * 3
    assert [m.type for m in drawn] == [Marker.TRIANGLE_LIST, Marker.LINE_STRIP, Marker.ARROW]
    assert [(m.ns, m.id, m.header.frame_id) for m in drawn] == [("zones", 0, "eci"), ("zone_rims", 0, "eci"),
                                                                 ("boresight", 0, "body")]
    assert all(m.header.stamp.sec == 7 and m.header.stamp.nanosec == 250_000_000 for m in array.markers)
    assert all(m.pose.orientation.w == 1.0 and m.lifetime.sec == 0 and m.frame_locked for m in drawn)
    line, arrow = drawn[1], drawn[2]
    assert line.scale.x == 0.02                              # a line's width
    assert arrow.scale.x == 0.05 and arrow.scale.y > arrow.scale.x and arrow.scale.z > 0     # shaft, head
    for shape, msg in zip(SHAPES, drawn, strict=True):
        back = markers.shape_from_marker(msg)
        assert (back.ns, back.id, back.frame_id, back.kind) == (shape.ns, shape.id, shape.frame_id, shape.kind)
        assert np.array_equal(back.points, shape.points) and np.allclose(back.rgba, shape.rgba)


def test_tf_message_carries_the_attitude_and_frames():
    q_BN = rot.from_axis_angle([1, 1, 0], 0.7)
    tf = deserialize_message(serialize_message(markers.tf_msg([markers.transform_msg(3.0, "eci", "body", q_BN)])),
                             TFMessage)
    (t,) = tf.transforms
    r = t.transform.rotation
    assert (t.header.frame_id, t.child_frame_id) == ("eci", "body")
    assert np.array_equal([r.x, r.y, r.z, r.w], q_BN)


def test_the_view_topics_are_recorded_with_complete_definitions():
    assert topics.RECORDED[topics.TF] == "tf2_msgs/msg/TFMessage"
    assert topics.RECORDED[topics.SIM_MARKERS] == topics.RECORDED[topics.PLAN_MARKERS] == \
        "visualization_msgs/msg/MarkerArray"
    tf = message_definition("tf2_msgs/msg/TFMessage")
    assert tf.startswith("geometry_msgs/TransformStamped[] transforms") and "MSG: geometry_msgs/msg/Quaternion" in tf
    array = message_definition("visualization_msgs/msg/MarkerArray")
    assert "MSG: visualization_msgs/msg/Marker" in array and "MSG: std_msgs/msg/ColorRGBA" in array
