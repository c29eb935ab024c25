"""Messages of the 3D view: ``/tf`` transforms, the zones' margins and ``visualization_msgs/MarkerArray``
from the plain :class:`att_msgs_py.types.Shape` (the conversions of :mod:`att_msgs_py.convert`,
for Foxglove's 3D panel and RViz).

A transform's rotation is the attitude quaternion as the suite writes it, body-to-inertial
(x, y, z, w): tf's transform from ``child`` to ``parent`` maps ``v_parent = R(q) v_child``, which is
``v_N = R(q_BN) v_B`` for the body frame under the inertial frame. Every marker array starts with a
DELETEALL, so a viewer replaces the shapes of the previous array (none lingers after its zone or
plan is gone) and nothing accumulates; the shapes keep their ``(ns, id)`` from array to array.
"""
from __future__ import annotations

import math

import numpy as np
from geometry_msgs.msg import Point, Quaternion, Transform, TransformStamped, Vector3
from std_msgs.msg import ColorRGBA, Header
from tf2_msgs.msg import TFMessage
from visualization_msgs.msg import Marker, MarkerArray

from att_msgs.msg import ZoneMargins
from att_msgs_py.convert import quaternion, time_msg, vector3
from att_msgs_py.types import Shape, ShapeKind

KINDS = {ShapeKind.TRIANGLES: Marker.TRIANGLE_LIST, ShapeKind.LINE: Marker.LINE_STRIP,
         ShapeKind.ARROW: Marker.ARROW}
ARROW_HEAD = 2.0          # arrow head diameter and length, in shaft widths


def transform_msg(t: float, parent: str, child: str, q_BN, r_N=(0.0, 0.0, 0.0)) -> TransformStamped:
    """Frame ``child`` (B) in frame ``parent`` (N) at sim time ``t``: rotation ``q_BN``
    (body-to-inertial), origin of B at ``r_N`` (m, parent axes)."""
    return TransformStamped(header=Header(stamp=time_msg(t), frame_id=parent), child_frame_id=child,
                            transform=Transform(translation=vector3(r_N), rotation=quaternion(q_BN)))


def tf_msg(transforms: list[TransformStamped]) -> TFMessage:
    return TFMessage(transforms=list(transforms))


def zone_margins_msg(t: float, frame_id: str, names, keep_in, margins) -> ZoneMargins:
    """The zones' margins (rad) at sim time ``t``; ``min_margin`` inf without zones."""
    values = [float(m) for m in margins]
    return ZoneMargins(header=Header(stamp=time_msg(t), frame_id=frame_id), names=list(names),
                       keep_in=[bool(k) for k in keep_in], margins=values, min_margin=min(values, default=math.inf))


def marker_msg(shape: Shape, t: float) -> Marker:
    """One ADD marker at sim time ``t``, pose identity (the points are in ``shape.frame_id``)."""
    marker = Marker(header=Header(stamp=time_msg(t), frame_id=shape.frame_id), ns=shape.ns, id=int(shape.id),
                    type=KINDS[shape.kind], action=Marker.ADD, frame_locked=True)
    marker.pose.orientation = Quaternion(w=1.0)
    width = float(shape.width)
    marker.scale = (Vector3(x=width, y=ARROW_HEAD * width, z=ARROW_HEAD * width) if shape.kind is ShapeKind.ARROW
                    else Vector3(x=width, y=width, z=width) if shape.kind is ShapeKind.LINE
                    else Vector3(x=1.0, y=1.0, z=1.0))
    r, g, b, a = (float(c) for c in shape.rgba)
    marker.color = ColorRGBA(r=r, g=g, b=b, a=a)
    marker.points = [Point(x=x, y=y, z=z) for x, y, z in np.asarray(shape.points, float).tolist()]
    return marker


def marker_array(shapes: list[Shape], t: float, frame_id: str) -> MarkerArray:
    """A DELETEALL (stamped ``t`` in ``frame_id``), then every shape."""
    clear = Marker(header=Header(stamp=time_msg(t), frame_id=frame_id), action=Marker.DELETEALL)
    return MarkerArray(markers=[clear] + [marker_msg(s, t) for s in shapes])


def shape_from_marker(msg) -> Shape:
    """The :class:`Shape` of an ADD marker (a live message or one decoded from a log)."""
    kind = {v: k for k, v in KINDS.items()}[msg.type]
    c = msg.color
    return Shape(msg.ns, msg.id, msg.header.frame_id, kind, np.array([[p.x, p.y, p.z] for p in msg.points], float),
                 (c.r, c.g, c.b, c.a), msg.scale.x)
