"""Estimator node: a thin ROS adapter around :class:`att_planner.estimation.estimator.Estimator`.

Subscribes ``/sensors/imu`` (sensor_msgs/Imu: its angular velocity), ``/sensors/star_tracker``,
``/sensors/magnetometer``, ``/sensors/sun_sensors`` and ``/actuator/command`` (the magnetorquer
commands, for the magnetometer's blanking); publishes ``/estimator/attitude``
(att_msgs/AttitudeEstimate) at ``publish_rate`` Hz of sim time, on gyro samples. The filter's
datasheets are the scenario's ``sensors`` group (nominal mountings and noise, never the errors the
simulator drew); its tuning is this node's parameters, defaulting to values derived from them.

Nothing received is trusted: a refused measurement (320 INVALID_MEASUREMENT, 321
STALE_MEASUREMENT) changes nothing and is logged at most once a second per kind with the running
count, as are measurements rejected by the innovation gate and the filter's notes (initialised,
diverged, gyro saturated).
"""
from __future__ import annotations

import math
from collections import Counter

from rclpy.node import Node
from sensor_msgs.msg import Imu, MagneticField

from att_msgs.msg import ActuatorCommand, AttitudeEstimate, CoarseSunSensors, StarTracker
from att_msgs_py import convert, qos, topics
from att_msgs_py.errors import ConfigError, ErrorCode, RequestError, clip
from att_msgs_py.node_runner import parameter_reader, run_node
from att_planner.estimation.estimator import Estimator, EstimatorConfig
from att_sim import scenario as scen
from att_sim import world
from att_sim.sensors.specs import ARCSEC, DEG, HOUR, NANOTESLA


class EstimatorNode(Node):
    def __init__(self):
        super().__init__("estimator")
        s = self._scenario = scen.load_checked(parameter_reader(self, {})("scenario", "swift_demo"))
        if s.sensors.gyro is None:
            raise ConfigError(ErrorCode.INVALID_CONFIG, f"scenario '{s.name}' has no gyro (sensors.gyro): the "
                                                        "estimator propagates on it")
        param = parameter_reader(self, s.node_params.get("estimator", {}), str(s.path))
        environment = world.Environment.from_scenario(s) if (s.sensors.magnetometer or s.sensors.sun_sensors) else None
        self._core = Estimator(s.sensors, self._config(param), environment, s.frame_id, s.body_frame_id)
        param.refuse_unknown()
        self._refused = Counter()
        self._pub = self.create_publisher(AttitudeEstimate, topics.ESTIMATE, qos.STREAM_QOS)
        self.create_subscription(Imu, topics.IMU, self.on_imu, qos.STREAM_QOS)
        self.create_subscription(StarTracker, topics.STAR_TRACKER, self.on_star_tracker, qos.STREAM_QOS)
        self.create_subscription(MagneticField, topics.MAGNETOMETER, self.on_magnetometer, qos.STREAM_QOS)
        self.create_subscription(CoarseSunSensors, topics.SUN_SENSORS, self.on_sun_sensors, qos.STREAM_QOS)
        self.create_subscription(ActuatorCommand, topics.COMMAND, self.on_command, qos.STREAM_QOS)
        c = self._core.config
        self.get_logger().info(
            f"scenario '{s.name}': MEKF on {len(s.sensors.star_trackers)} star tracker(s), "
            f"magnetometer {'yes' if s.sensors.magnetometer else 'no'}, sun sensors "
            f"{'yes' if s.sensors.sun_sensors else 'no'}; ARW {c.arw * math.sqrt(HOUR) / DEG:.4g} deg/sqrt(h), "
            f"bias walk {c.rrw * HOUR * math.sqrt(HOUR) / DEG:.4g} deg/h/sqrt(h), gate p = {c.gate_probability}")

    def _config(self, param) -> EstimatorConfig:
        s = self._scenario
        d = Estimator.default_config(s.sensors, 1.0 / s.sensors.gyro.rate)
        rate = param("publish_rate", 1.0 / d.publish_period, 0.0, s.sensors.gyro.rate, low_open=True)
        return EstimatorConfig(
            publish_period=1.0 / rate,
            arw=param("arw_deg_per_sqrt_h", d.arw * math.sqrt(HOUR) / DEG, 0.0, 100.0, low_open=True)
            * DEG / math.sqrt(HOUR),
            rrw=param("rrw_deg_per_h_per_sqrt_h", d.rrw * HOUR * math.sqrt(HOUR) / DEG, 0.0, 1e4, low_open=True)
            * DEG / HOUR / math.sqrt(HOUR),
            initial_bias_sigma=param("initial_bias_sigma_deg_per_h", d.initial_bias_sigma * HOUR / DEG, 0.0, 1e5,
                                     low_open=True) * DEG / HOUR,
            gate_probability=param("gate_probability", d.gate_probability, 0.5, 1.0 - 1e-12),
            converged_attitude_sigma=param("converged_attitude_sigma_arcsec", d.converged_attitude_sigma / ARCSEC,
                                           0.0, 648000.0, low_open=True) * ARCSEC,
            propagate_timeout=param("propagate_timeout", d.propagate_timeout, 0.0, 3600.0, low_open=True),
            history=param("history", d.history, 0.0, 60.0, low_open=True),
            lost_after=param("lost_after", d.lost_after, 1, 1000),
            vector_fallback_after=param("vector_fallback_after", d.vector_fallback_after, 0.0, 3600.0),
            magnetometer_sigma=param("magnetometer_sigma_nT", d.magnetometer_sigma / NANOTESLA, 0.0, 1e5,
                                     low_open=True) * NANOTESLA,
            sun_sigma=param("sun_sigma_deg", d.sun_sigma / DEG, 0.0, 90.0, low_open=True) * DEG,
            sun_threshold=param("sun_threshold", d.sun_threshold, 0.0, 1.0),
            pair_window=param("pair_window", d.pair_window, 0.0, 60.0),
            max_gyro_gap=param("max_gyro_gap", d.max_gyro_gap, 0.0, 3600.0, low_open=True))

    def _report_refusal(self, what: str, err: RequestError) -> None:
        self._refused[what] += 1
        self.get_logger().warning(clip(f"{what} refused ({self._refused[what]} so far) [{int(err.code)} "
                                       f"{err.code.name}]: {err.message}"), throttle_duration_sec=1.0)

    def _guarded(self, what: str, call, msg):
        """Run ``call(msg)`` (a core input), logging a refusal; its result otherwise."""
        try:
            return call(msg)
        except RequestError as err:
            self._report_refusal(what, err)
            return None

    # -- callbacks: translate messages to Estimator calls -------------------------------------------
    def on_imu(self, msg: Imu):
        estimate = self._guarded("gyro sample", self._core.on_gyro, convert.gyro_from_msg(msg))
        report = self._core.take_report()
        for note in report.notes:
            self.get_logger().info(clip(note), throttle_duration_sec=1.0)
        if estimate is not None:
            self._pub.publish(convert.estimate_msg(estimate))

    def on_star_tracker(self, msg: StarTracker):
        self._guarded("star tracker measurement", self._core.on_star_tracker, convert.star_tracker_from_msg(msg))

    def on_magnetometer(self, msg: MagneticField):
        self._guarded("magnetometer measurement", self._core.on_magnetometer, convert.magnetometer_from_msg(msg))

    def on_sun_sensors(self, msg: CoarseSunSensors):
        self._guarded("sun sensor measurement", self._core.on_sun_sensors, convert.sun_sensors_from_msg(msg))

    def on_command(self, msg: ActuatorCommand):
        command = convert.command_from_msg(msg)
        if math.isfinite(command.t) and all(math.isfinite(v) for v in command.dipole):
            self._core.on_dipole_command(command.t, command.dipole)   # a malformed one blanks nothing


def main(args=None):
    run_node(EstimatorNode, args)


if __name__ == "__main__":
    main()
