"""The controller node's parameters, declared once (read by the node and by the in-process closed loop).

The defaults of the core's tuning are the core's own (:class:`ControllerConfig`, :class:`PlanContext`,
:class:`GateConfig`), in the parameters' units.
"""
from __future__ import annotations

import dataclasses
import math

from att_msgs_py.parameters import Parameter, ParameterTable
from att_msgs_py.types import ControlMode
from att_planner.control.controller_config import ControllerConfig
from att_planner.control.mode_authentication import MAX_AHEAD
from att_planner.control.plan_checks import PlanContext
from att_planner.control.state_gate import GateConfig

STATE_SOURCES = ("truth", "estimate")
INITIAL_MODES = tuple(int(m) for m in ControlMode if m not in (ControlMode.PLAN_TRACKING, ControlMode.POINTING))
INF = math.inf

_C = ControllerConfig()
_G = GateConfig()
_P = {f.name: f.default for f in dataclasses.fields(PlanContext)}
_KEY_RULE = "plan_signing.pub in the suite's key directory ($ATT_KEY_DIR, see att-keygen)"

CONTROLLER = ParameterTable("controller", (
    Parameter("state_source", str, None, "the state the controller flies on: the simulator's truth or the "
                                         "estimator's estimate (with wheels, estimate needs tachometers)",
              choices=STATE_SOURCES,
              default_rule="estimate when the scenario has a gyro, else truth"),
    Parameter("friction_compensation", bool, None, "add the wheel drives' modelled friction to the wheel commands",
              default_rule="true when the scenario's wheels have friction"),
    Parameter("initial_mode", int, int(ControlMode.IDLE), "control mode at start (" + ", ".join(
        f"{m}: {ControlMode(m).name}" for m in INITIAL_MODES) + ")", choices=INITIAL_MODES),
    Parameter("control_rate_Hz", float, 1.0 / _C.control_period, "rate of the commands, in sim time", "Hz", 0.0,
              1000.0, low_open=True),
    Parameter("settle_time_s", float, _C.settle_time, "time held on the final attitude after a plan ends", "s",
              0.0, 86_400.0),
    Parameter("tracking_kp", float, _C.tracking_kp, "attitude feedback gain around the plan reference", "N m/rad",
              0.0, INF),
    Parameter("tracking_kd", float, _C.tracking_kd, "rate feedback gain around the plan reference", "N m s/rad",
              0.0, INF),
    Parameter("kp", float, _C.kp, "attitude gain of the magnetorquer PD-like law (Bruni & Celani)", "A m^2/T",
              0.0, INF),
    Parameter("kd", float, _C.kd, "rate gain of the magnetorquer PD-like law (Bruni & Celani)", "A m^2 s/(T rad)",
              0.0, INF),
    Parameter("m_max_Am2", float, None, "dipole limit per magnetorquer coil the laws command (capped at the "
                                   "spacecraft's dipole_max_Am2)", "A m^2", 0.0,
              low_open=True, refusal="expected a dipole > 0 A m²", allow_inf=True,
              default_rule="the spacecraft's dipole_max_Am2"),
    Parameter("safe_kd", float, None, "rate damping gain of the safe mode", "N m s/rad", 0.0, INF,
              default_rule="tracking_kd"),
    Parameter("max_cached_plans", int, _C.max_cached_plans, "most plans kept for execution", "", 1, 10_000),
    Parameter("max_cache_MiB", float, _C.max_cache_bytes / 2**20, "largest total size of the plans kept, serialized",
              "MiB", 0.0, 4096.0, low_open=True),
    Parameter("safe_rate_threshold_rad_s", float, _C.safe_rate_threshold, "body rate above which the controller, "
                                                                    "starting, damps it first (safe mode)", "rad/s",
              0.0, 10.0, low_open=True),
    Parameter("momentum_dumping", bool, _C.dumping, "dump wheel momentum with the magnetorquers"),
    Parameter("dumping_gain", float, _C.dumping_gain, "gain k of the dumping law m = k (dh x B)/|B|^2", "1/s",
              0.0, 10.0, low_open=True),
    Parameter("null_space_gain", float, _C.null_space_gain, "gain driving the wheel speeds' null-space component to "
                                                            "null_space_speed_rad_s (more than 3 wheels)", "1/s",
              0.0, 10.0),
    Parameter("null_space_speed_rad_s", float, _C.null_space_speed, "wheel speed bias along each null-space "
                                                                    "direction", "rad/s", -1e4, 1e4),
    Parameter("handover_blend_s", float, _C.handover_blend, "time over which a plan ending at rest blends into a "
                                                          "moving pointing reference", "s", 0.0, 3600.0),
    Parameter("safe_sun_axis", list, _C.safe_sun_axis, "body axis the safe mode points at the Sun once the rates are "
                                                       "damped (a unit vector)", "", -1.0, 1.0, length=3),
    Parameter("fault_table", str, "", "fault table watched and acted on (docs/fdir.md): a name of config/faults or "
                                      "a file's path; empty: no fault handling (needs state_source estimate)"),
    Parameter("plan_public_key", str, None, "Ed25519 public key file plans must be signed with",
              default_rule=_KEY_RULE),
    Parameter("max_start_attitude_error_deg", float, math.degrees(_P["max_start_attitude_error"]),
              "largest attitude error at a plan's start", "deg", 0.0, 180.0, low_open=True),
    Parameter("max_start_rate_error_rad_s", float, _P["max_start_rate_error"], "largest body rate error at a plan's "
                                                                               "start", "rad/s", 0.0, 10.0,
              low_open=True),
    Parameter("max_start_epoch_error_s", float, _P["max_start_epoch_error"], "largest difference between a plan's "
                                                                           "epoch and the scenario's", "s",
              0.0, 86_400.0, low_open=True),
    Parameter("max_state_gap_s", float, _G.max_state_gap, "largest sim time between consecutive accepted states", "s",
              0.0, 3600.0, low_open=True),
    Parameter("max_clock_skew_s", float, _G.max_clock_skew, "largest difference between a state's stamp and the "
                                                          "/clock of the state's publisher", "s", 0.0, 3600.0,
              low_open=True),
    Parameter("resync_timeout_s", float, _G.resync_timeout, "wall time without an accepted state after which the "
                                                          "held publisher's stamps may jump", "s", 0.0, 3600.0,
              low_open=True),
    Parameter("wall_timeout_s", float, 2.0, "wall time without a state after which the command is zero and "
                                          "state_stale is reported", "s", 0.0, 3600.0, low_open=True),
    Parameter("plan_wait_s", float, 5.0, "wall time an execute goal waits for a plan it names that has not been "
                                        "received yet (0: refused at once, UNKNOWN_PLAN; kept below SuiteClient's "
                                        "15 s stall timeout)", "s", 0.0, 10.0),
    Parameter("wait_for_subscribers", int, 0, "subscribers to the commands that must listen before the controller "
                                              "takes its inputs", "", 0, 1000),
    Parameter("start_timeout_s", float, 60.0, "wall time waited for those subscribers before taking inputs anyway",
              "s", 0.0, 3600.0, low_open=True),
    Parameter("require_signed_modes", bool, False, "accept a mode change only as a signed, sequenced command"),
    Parameter("mode_public_key", str, None, "Ed25519 public key file mode commands must be signed with "
                                            "(with require_signed_modes)", default_rule=_KEY_RULE),
    Parameter("mode_sequence_file", str, None, "file keeping the last accepted mode sequence number (with "
                                               "require_signed_modes)",
              default_rule="controller/mode_sequences.json in the state directory ($ATT_STATE_DIR)"),
    Parameter("mode_sequence_ahead_s", float, MAX_AHEAD, "largest lead of a mode sequence over the controller's wall "
                                                       "clock (with require_signed_modes)", "s", 0.0, 86_400.0,
              low_open=True),
), "the attitude controller: plan tracking, pointing, magnetorquer and safe modes",
    renamed={"control_rate": "control_rate_Hz", "settle_time": "settle_time_s", "wall_timeout": "wall_timeout_s",
             "safe_rate_threshold": "safe_rate_threshold_rad_s", "null_space_speed": "null_space_speed_rad_s",
             "handover_blend": "handover_blend_s", "max_start_rate_error": "max_start_rate_error_rad_s",
             "max_start_epoch_error": "max_start_epoch_error_s", "max_state_gap": "max_state_gap_s",
             "max_clock_skew": "max_clock_skew_s", "resync_timeout": "resync_timeout_s",
             "start_timeout": "start_timeout_s", "mode_sequence_ahead": "mode_sequence_ahead_s", "m_max": "m_max_Am2",
             "max_cache_mb": "max_cache_MiB"})
