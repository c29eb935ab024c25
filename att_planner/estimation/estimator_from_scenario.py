"""The estimator core of a scenario, built from its sensors' datasheets and the estimator's parameters
(no ROS): the node and the in-process closed loop build the same filter."""
from __future__ import annotations

import math

from att_msgs_py.errors import ConfigError, ErrorCode
from att_planner.estimation.estimator import Estimator, EstimatorConfig
from att_sim.models import world
from att_sim.models.scenario import Scenario
from att_sim.models.sensor_specs import ARCSEC, DEG, HOUR, NANOTESLA


def estimator_config(param, s: Scenario) -> EstimatorConfig:
    """The filter's tuning from the parameters of
    :data:`~att_planner.estimation.estimator_parameters.ESTIMATOR` (datasheet units), defaulting to
    :meth:`Estimator.default_config`."""
    d = Estimator.default_config(s.sensors, 1.0 / s.sensors.gyro.rate)
    rate = param("publish_rate_Hz", 1.0 / d.publish_period, high=s.sensors.gyro.rate)
    return EstimatorConfig(
        publish_period=1.0 / rate,
        arw=param("arw_deg_per_sqrt_h", d.arw * math.sqrt(HOUR) / DEG) * DEG / math.sqrt(HOUR),
        rrw=param("rrw_deg_per_h_per_sqrt_h", d.rrw * HOUR * math.sqrt(HOUR) / DEG) * DEG / HOUR / math.sqrt(HOUR),
        initial_bias_sigma=param("initial_bias_sigma_deg_per_h", d.initial_bias_sigma * HOUR / DEG) * DEG / HOUR,
        scale_factor_sigma=param("consider_scale_factor_ppm", d.scale_factor_sigma * 1e6) * 1e-6,
        misalignment_sigma=param("consider_misalignment_arcsec", d.misalignment_sigma / ARCSEC) * ARCSEC,
        gate_probability=param("gate_probability"),
        converged_attitude_sigma=param("converged_attitude_sigma_arcsec", d.converged_attitude_sigma / ARCSEC)
        * ARCSEC,
        propagate_timeout=param("propagate_timeout_s"), history=param("history_s"), lost_after=param("lost_after"),
        vector_fallback_after=param("vector_fallback_after_s"),
        magnetometer_sigma=param("magnetometer_sigma_nT") * NANOTESLA, sun_sigma=param("sun_sigma_deg") * DEG,
        sun_threshold=param("sun_threshold"), pair_window=param("pair_window_s"), max_gyro_gap=param("max_gyro_gap_s"),
        resync_timeout=param("resync_timeout_s"))


def estimator_from_scenario(param, s: Scenario) -> Estimator:
    """The estimator of ``s`` (its sensors' datasheets, its onboard field and Sun models) with its
    parameters; ConfigError for a scenario without a gyro."""
    if s.sensors.gyro is None:
        raise ConfigError(ErrorCode.INVALID_CONFIG, f"scenario '{s.name}' has no gyro (sensors.gyro): the "
                                                    "estimator propagates on it")
    environment = world.Environment.from_scenario(s) if (s.sensors.magnetometer or s.sensors.sun_sensors) else None
    return Estimator(s.sensors, estimator_config(param, s), environment, s.frame_id, s.body_frame_id)
