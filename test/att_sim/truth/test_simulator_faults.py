"""Fault injection through the simulator node: a wheel seized over ``/simulator/inject_fault`` on a
running leo_pyramid simulator (alone, free-running at its real-time factor) is published on
``/simulator/faults`` and freezes that wheel's measured speed while the healthy wheels spin down by
their friction; a request naming a wheel the spacecraft does not have is refused with its code and
the simulator keeps publishing."""
from __future__ import annotations

import numpy as np
import pytest
import rclpy
from sensor_msgs.msg import JointState

from att_msgs.msg import FaultEvent
from att_msgs.srv import InjectFault, ResetSimulator
from att_msgs_py import convert, qos, topics
from att_msgs_py.errors import ErrorCode
from helpers.waiting import wait_until

SPEED0 = 100.0               # rad/s: every wheel's speed after the reset


def call(node, client, request, timeout: float = 20.0):
    future = client.call_async(request)
    rclpy.spin_until_future_complete(node, future, timeout_sec=timeout)
    assert future.done(), f"no answer from {client.srv_name} within {timeout} s"
    return future.result()


def slope(samples: list[tuple[float, float]]) -> float:
    """Least-squares rate of change of (t, value) samples."""
    t, v = np.array(samples).T
    return float(np.polyfit(t - t[0], v, 1)[0])


@pytest.mark.ros
def test_a_wheel_seized_through_the_service_is_published_and_freezes_its_speed(ros_suite):
    with ros_suite("leo_pyramid", nodes=("simulator",), params={"simulator": {"real_time_factor": 8.0}},
                   name="sim_faults") as s:
        node = s.client
        speeds, events = [], []
        node.create_subscription(JointState, topics.WHEEL_SPEEDS,
                                 lambda m: speeds.append(convert.wheel_speeds_from_msg(m)), qos.STREAM_QOS)
        node.create_subscription(FaultEvent, topics.SIM_FAULTS,
                                 lambda m: events.append(convert.fault_event_from_msg(m)), qos.MISSION_QOS)
        inject = node.create_client(InjectFault, topics.INJECT_FAULT)
        reset = node.create_client(ResetSimulator, topics.RESET_SIMULATOR)
        assert inject.wait_for_service(timeout_sec=60) and reset.wait_for_service(timeout_sec=60)
        wait_until(lambda: len(speeds) > 0, 60, "wheel speeds from the simulator", node=node)

        r = call(node, reset, ResetSimulator.Request(attitude=convert.quaternion([0.0, 0.0, 0.0, 1.0]),
                                                     wheel_speeds=[SPEED0] * 4))
        assert r.success, r.message
        r = call(node, inject, InjectFault.Request(component="wheel", index=0, kind="seized", t_s=0.0))
        assert r.success and r.error_code == 0, r.message
        wait_until(lambda: events, 30, "the fault on /simulator/faults", node=node)
        [event] = events
        assert (event.component, event.index, event.kind, event.source) == ("wheel", 0, "seized", "service")
        onset = event.t

        def after(margin: float):
            return [m for m in speeds if m.t > onset + margin]
        wait_until(lambda: len(after(0.2)) >= 80, 60, "4 s of wheel speeds after the onset", node=node)
        late = after(0.2)
        seized = [(m.t, m.speeds[0]) for m in late]
        healthy = [(m.t, m.speeds[1]) for m in late]
        assert abs(seized[0][1] - SPEED0) < 1.0           # seized near the speed of the reset
        # frozen: within the tachometer's noise (0.01 rad/s, 0.005 quantum) while the healthy wheel
        # spins down by its friction, (0.005 N m + 2e-5 N m s x 100 rad/s) / 0.2 kg m^2 = 0.035 rad/s^2
        assert np.ptp([v for _, v in seized]) < 0.08 and abs(slope(seized)) < 0.005
        assert slope(healthy) == pytest.approx(-0.035, rel=0.25)

        r = call(node, inject, InjectFault.Request(component="wheel", index=9, kind="off", t_s=0.0))
        assert not r.success and r.error_code == ErrorCode.INVALID_FAULT, r.message
        assert "index: expected below 4 (the spacecraft has 4 wheels); found 9" in r.message
        count = len(speeds)
        wait_until(lambda: len(speeds) > count + 20, 30, "wheel speeds after the refused request", node=node)
        assert len(events) == 1 and all(s.suite.alive().values())
        assert "fault injection rejected [403 INVALID_FAULT]" in s.suite.log_text("simulator")
