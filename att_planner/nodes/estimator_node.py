"""Estimator node: a thin ROS adapter around :class:`att_planner.estimation.estimator.Estimator`.

Subscribes ``/sensors/imu`` (sensor_msgs/Imu: its angular velocity), ``/sensors/star_tracker``,
``/sensors/magnetometer``, ``/sensors/sun_sensors`` and ``/actuator/command`` (the magnetorquer
commands, for the magnetometer's blanking); publishes ``/estimator/attitude``
(att_msgs/AttitudeEstimate) at ``publish_rate_Hz`` of sim time, on gyro samples. The filter's
datasheets are the scenario's ``sensors`` group (nominal mountings and noise, never the errors the
simulator drew); its tuning is this node's parameters, defaulting to values derived from them.

Nothing received is trusted: a message above its size caps (:mod:`att_msgs_py.limits`, 132
SIZE_LIMIT) is refused before it is read; a refused measurement (320 INVALID_MEASUREMENT, 321
STALE_MEASUREMENT; a second publisher of an input while the held one is in the ROS graph, too:
:class:`att_planner.estimation.inputs.Sources`) changes nothing
and is logged at most once a second per kind with the running count, as are measurements rejected
by the innovation gate and the filter's notes (initialised, diverged, gyro saturated).

With ``fault_table`` (a name of ``config/faults`` or a file's path; empty, the default: off) it runs
that table's sensor detectors on its accepted inputs (:class:`att_planner.fdir.onboard.Onboard`: a
stuck gyro axis or magnetometer, a silent tracker, the trackers' and the gyro's innovations), excludes
a sensor isolated (re-admitting it where its detector allows) and publishes each report on the latched
``/estimator/faults`` (att_msgs/FaultStatus), which the controller hears for the responses that are
its own (safe mode on a gyro fault).
"""
from __future__ import annotations

import math
import time

from sensor_msgs.msg import Imu, MagneticField

from att_msgs.msg import ActuatorCommand, AttitudeEstimate, CoarseSunSensors, FaultStatus, StarTracker
from att_msgs_py import convert, limits, memory, qos, topics
from att_msgs_py.errors import RequestError, clip
from att_msgs_py.node_runner import (
    ParameterReader,
    RefusalLog,
    live_publishers,
    publisher_of,
    read_scenario,
    run_node,
    subscribe_when_heard,
)
from att_msgs_py.suite_node import SuiteNode
from att_planner.estimation.estimator_from_scenario import estimator_from_scenario
from att_planner.estimation.estimator_parameters import ESTIMATOR
from att_planner.estimation.inputs import Sources
from att_planner.fdir.onboard import Onboard, load_table
from att_sim.models import scenario as scen
from att_sim.models.sensor_specs import DEG, HOUR

INPUTS = {"gyro sample": topics.IMU, "star tracker measurement": topics.STAR_TRACKER,
          "magnetometer measurement": topics.MAGNETOMETER, "sun sensor measurement": topics.SUN_SENSORS,
          "actuator command": topics.COMMAND}      # each input's topic, by the name its refusals give


class EstimatorNode(SuiteNode):
    def __init__(self):
        super().__init__("estimator")
        s = scen.load_checked(read_scenario(self))
        param = ParameterReader(self, ESTIMATOR, s.node_params.get("estimator", {}), str(s.node_params_path))
        self._core = estimator_from_scenario(param, s)
        wait_for_subscribers = param("wait_for_subscribers")
        start_timeout = param("start_timeout_s")
        fault_table = load_table(param("fault_table"))
        param.refuse_unknown()
        self._fdir = None if fault_table is None else Onboard(fault_table, s, None, self._core)
        self._refusals = RefusalLog(self.get_logger())
        self._sources = Sources({what: live_publishers(self, topic) for what, topic in INPUTS.items()})
        self._pub = self.create_publisher(AttitudeEstimate, topics.ESTIMATE, qos.STREAM_QOS)
        if self._fdir is not None:
            self._fault_pub = self.create_publisher(FaultStatus, topics.ESTIMATOR_FAULTS, qos.MISSION_QOS)
        subscribe_when_heard(self, self._pub, wait_for_subscribers, start_timeout, self._subscribe_sensors)
        c = self._core.config
        self.get_logger().info(
            f"scenario '{s.name}': MEKF on {len(s.sensors.star_trackers)} star tracker(s), "
            f"magnetometer {'yes' if s.sensors.magnetometer else 'no'}, sun sensors "
            f"{'yes' if s.sensors.sun_sensors else 'no'}; ARW {c.arw * math.sqrt(HOUR) / DEG:.4g} deg/sqrt(h), "
            f"bias walk {c.rrw * HOUR * math.sqrt(HOUR) / DEG:.4g} deg/h/sqrt(h), gate p = {c.gate_probability}; "
            f"fault table {'off' if self._fdir is None else 'on'}")

    def _subscribe_sensors(self) -> None:
        self.create_subscription(Imu, topics.IMU, self.on_imu, qos.STREAM_QOS)
        self.create_subscription(StarTracker, topics.STAR_TRACKER, self.on_star_tracker, qos.STREAM_QOS)
        self.create_subscription(MagneticField, topics.MAGNETOMETER, self.on_magnetometer, qos.STREAM_QOS)
        self.create_subscription(CoarseSunSensors, topics.SUN_SENSORS, self.on_sun_sensors, qos.STREAM_QOS)
        self.create_subscription(ActuatorCommand, topics.COMMAND, self.on_command, qos.STREAM_QOS)

    def _guarded(self, what: str, info: dict, call, *args, watch: tuple | None = None):
        """Run ``call(*args)`` (a core input) if its publisher is the one of ``what``, logging a
        refusal; its result otherwise (and then the fault monitor fed ``watch``: (topic, message))."""
        try:
            out = self._sources.guarded(what, publisher_of(info), call, *args)
        except RequestError as err:
            self._refusals(what, err)
            return None
        if watch is not None and self._fdir is not None:
            topic, message = watch
            self._report(self._fdir.feed(topic, message.t, message))
        return out

    def _report(self, reports: list) -> None:
        """Publish and log the monitor's reports; act on the responses (the estimator's exclusions)."""
        for report in reports:
            self._fault_pub.publish(convert.fault_status_msg(report))
            log = self.get_logger().warning if report.active else self.get_logger().info
            log(clip(f"fault {report.fault_id} on {report.component} {report.index} "
                     f"{'declared' if report.active else 'cleared'} at t = {report.t:.2f} s ({report.detector}: "
                     f"{report.evidence}); response {report.response}"))
        if reports:
            self._fdir.respond()

    # -- callbacks: translate messages to Estimator calls -------------------------------------------
    # (``info`` has no default: rclpy passes the message info only to two-argument callbacks)
    def _oversized(self, msg, caps: dict, what: str, name: str) -> bool:
        """Whether ``msg`` (its fields named ``name.field``) is above its size caps
        (:mod:`att_msgs_py.limits`): refused as ``what`` before it is read."""
        err = limits.issue(msg, caps, name)
        if err is not None:
            self._refusals(what, err)
        return err is not None

    def on_imu(self, msg: Imu, info: dict):
        if self._oversized(msg, limits.HEADER_ONLY, "gyro sample", "imu"):
            return
        gyro = convert.gyro_from_msg(msg)
        estimate = self._guarded("gyro sample", info, self._core.on_gyro, gyro, time.monotonic(),
                                 watch=(topics.IMU, gyro))
        if self._fdir is not None:
            self._report(self._fdir.innovations())
        report = self._core.take_report()
        for note in report.notes:
            self.get_logger().info(clip(note), throttle_duration_sec=1.0)
        if estimate is not None:
            self._pub.publish(convert.estimate_msg(estimate))

    def on_star_tracker(self, msg: StarTracker, info: dict):
        if self._oversized(msg, limits.STAR_TRACKER, "star tracker measurement", "star_tracker"):
            return
        measurement = convert.star_tracker_from_msg(msg)
        self._guarded("star tracker measurement", info, self._core.take_star_tracker, measurement,
                      watch=(topics.STAR_TRACKER, measurement))

    def on_magnetometer(self, msg: MagneticField, info: dict):
        if self._oversized(msg, limits.HEADER_ONLY, "magnetometer measurement", "magnetometer"):
            return
        measurement = convert.magnetometer_from_msg(msg)
        self._guarded("magnetometer measurement", info, self._core.take_magnetometer, measurement,
                      watch=(topics.MAGNETOMETER, measurement))

    def on_sun_sensors(self, msg: CoarseSunSensors, info: dict):
        if self._oversized(msg, limits.SUN_SENSORS, "sun sensor measurement", "sun_sensors"):
            return
        self._guarded("sun sensor measurement", info, self._core.take_sun_sensors, convert.sun_sensors_from_msg(msg))

    def on_command(self, msg: ActuatorCommand, info: dict):
        if self._oversized(msg, limits.ACTUATOR_COMMAND, "actuator command", "command"):
            return
        command = convert.command_from_msg(msg)
        if math.isfinite(command.t) and all(math.isfinite(v) for v in command.dipole):   # else: blanks nothing
            self._guarded("actuator command", info, self._core.on_dipole_command, command.t, command.dipole)


def main(args=None):
    memory.reexec_with_c_allocator()
    run_node(EstimatorNode, args)


if __name__ == "__main__":
    main()
