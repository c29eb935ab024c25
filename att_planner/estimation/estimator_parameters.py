"""The estimator node's parameters, declared once (read by the node and by the in-process closed loop).

The filter's tuning is in datasheet units; the defaults are the core's (:class:`EstimatorConfig`, and
:meth:`Estimator.default_config` for those it finds from the scenario's sensor datasheets).
"""
from __future__ import annotations

from att_msgs_py.parameters import Parameter, ParameterTable
from att_planner.estimation.estimator import EstimatorConfig
from att_sim.models.sensor_specs import DEG, NANOTESLA

_E = EstimatorConfig()
_DATASHEET = "from the gyro's datasheet (Estimator.default_config)"

ESTIMATOR = ParameterTable("estimator", (
    Parameter("publish_rate_Hz", float, None, "rate of the estimates, in sim time", "Hz", 0.0, float("inf"),
              low_open=True, default_rule="the gyro's rate", high_rule="the gyro's rate"),
    Parameter("arw_deg_per_sqrt_h", float, None, "angle random walk of the gyro model", "deg/sqrt(h)", 0.0, 100.0,
              low_open=True, default_rule=_DATASHEET),
    Parameter("rrw_deg_per_h_per_sqrt_h", float, None, "bias random walk of the gyro model", "deg/h/sqrt(h)",
              0.0, 1e4, low_open=True, default_rule=_DATASHEET + ", covering its bias instability"),
    Parameter("initial_bias_sigma_deg_per_h", float, None, "1-sigma of the gyro bias prior", "deg/h", 0.0, 1e5,
              low_open=True, default_rule="3 x the gyro's turn-on bias, at least its bias instability"),
    Parameter("consider_scale_factor_ppm", float, None, "1-sigma of the gyro scale factors, considered (Schmidt)",
              "ppm", 0.0, 1e5, default_rule=_DATASHEET),
    Parameter("consider_misalignment_arcsec", float, None, "1-sigma of the gyro misalignments, considered (Schmidt)",
              "arcsec", 0.0, 3600.0, default_rule=_DATASHEET),
    Parameter("gate_probability", float, _E.gate_probability, "chi-square gate probability of every measurement",
              "", 0.5, 1.0 - 1e-12),
    Parameter("converged_attitude_sigma_arcsec", float, None, "largest 3-sigma attitude error of a CONVERGED "
                                                              "estimate", "arcsec", 0.0, 648000.0, low_open=True,
              default_rule="10 x the best star tracker's about-boresight error"),
    Parameter("propagate_timeout_s", float, _E.propagate_timeout, "time without an accepted attitude measurement "
                                                                "after which the estimate is PROPAGATING", "s",
              0.0, 3600.0, low_open=True),
    Parameter("history_s", float, _E.history, "span of samples kept to apply late measurements", "s", 0.0, 60.0,
              low_open=True),
    Parameter("lost_after", int, _E.lost_after, "tracker measurements rejected in a row after which the estimate is "
                                                "DIVERGED", "", 1, 1000),
    Parameter("vector_fallback_after_s", float, _E.vector_fallback_after, "time without a tracker update after which "
                                                                        "vector measurements update the attitude", "s",
              0.0, 3600.0),
    Parameter("magnetometer_sigma_nT", float, _E.magnetometer_sigma / NANOTESLA, "magnetometer noise and field-model "
                                                                                 "error per axis", "nT", 0.0, 1e5,
              low_open=True),
    Parameter("sun_sigma_deg", float, _E.sun_sigma / DEG, "coarse Sun vector error per axis", "deg", 0.0, 90.0,
              low_open=True),
    Parameter("sun_threshold", float, _E.sun_threshold, "sun sensor output above which a detector is lit", "",
              0.0, 1.0),
    Parameter("pair_window_s", float, _E.pair_window, "largest time between the two vectors of a QUEST "
                                                    "initialisation", "s", 0.0, 60.0),
    Parameter("max_gyro_gap_s", float, _E.max_gyro_gap, "a gyro sample (or a measurement) further ahead of the last "
                                                      "gyro sample is refused", "s", 0.0, 3600.0, low_open=True),
    Parameter("resync_timeout_s", float, _E.resync_timeout, "wall time without a gyro sample after which the next "
                                                          "starts a new timeline", "s", 0.0, 3600.0, low_open=True),
    Parameter("fault_table", str, "", "fault table whose sensor detectors the estimator runs, excluding a sensor "
                                      "isolated (docs/fdir.md): a name of config/faults or a file's path; empty: "
                                      "none"),
    Parameter("wait_for_subscribers", int, 0, "subscribers to the estimate that must listen before the estimator "
                                              "takes its inputs", "", 0, 1000),
    Parameter("start_timeout_s", float, 60.0, "wall time waited for those subscribers before taking inputs anyway",
              "s", 0.0, 3600.0, low_open=True),
), "the attitude estimator: a multiplicative extended Kalman filter (MEKF) on the gyro",
    renamed={"publish_rate": "publish_rate_Hz", "resync_timeout": "resync_timeout_s",
             "start_timeout": "start_timeout_s", "propagate_timeout": "propagate_timeout_s", "history": "history_s",
             "vector_fallback_after": "vector_fallback_after_s", "pair_window": "pair_window_s",
             "max_gyro_gap": "max_gyro_gap_s"})
