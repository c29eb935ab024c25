"""The simulator node's parameters, declared once (read by the node and by the in-process closed loop)."""
from __future__ import annotations

from att_msgs_py.parameters import Parameter, ParameterTable
from att_sim.truth.simulation import DEFAULT_STEP

PER_STEP = " (at most 1/step_s: one per integration step)"
PER_STEP_OR_OFF = " (at most 1/step_s: one per integration step; 0: off)"
INF = float("inf")

SIMULATOR = ParameterTable("simulator", (
    Parameter("step_s", float, DEFAULT_STEP, "integration step (RK4, inputs held over a step)", "s",
              0.0, 1.0, low_open=True),
    Parameter("publish_rate_Hz", float, None, "rate of the state (and sensor) messages, in sim time", "Hz",
              0.0, INF, low_open=True, default_rule="min(10, 1/step_s)", high_rule="1/step_s", hint=PER_STEP),
    Parameter("clock_rate_Hz", float, None, "rate of /clock, in sim time", "Hz", 0.0, INF, low_open=True,
              default_rule="min(50, 1/step_s)", high_rule="1/step_s", hint=PER_STEP),
    Parameter("tf_rate_Hz", float, None, "rate of /tf and /simulator/zone_margins, in sim time (0: off)", "Hz",
              0.0, INF, default_rule="publish_rate_Hz", high_rule="1/step_s", hint=PER_STEP_OR_OFF),
    Parameter("marker_rate_Hz", float, None, "rate of /simulator/markers (the 3D view), in sim time (0: off)", "Hz",
              0.0, INF, default_rule="min(1, 1/step_s)", high_rule="1/step_s", hint=PER_STEP_OR_OFF),
    Parameter("real_time_factor", float, 1.0, "sim time per wall time (0: as fast as possible)", "", 0.0, INF),
    Parameter("max_hold_s", float, 600.0, "wall time a /simulator/hold stops sim time at most (then released)", "s",
              0.0, INF, low_open=True),
    Parameter("command_timeout_s", float, 1.0, "sim time without a valid command after which the actuator "
                                               "inputs are zeroed; also the largest age of a command's stamp", "s",
              0.0, INF, low_open=True),
    Parameter("end_time_s", float, 0.0, "sim time at which the simulator stops (0: run until stopped)", "s", 0.0, INF),
    Parameter("wait_for_subscribers", int, 0, "listeners that must be there before sim time starts: "
                                              "subscriptions to the state, plus nodes that hear only the sensors",
              "", 0, 1000),
    Parameter("start_timeout_s", float, 60.0, "wall time waited for those subscribers before starting anyway", "s",
              0.0, INF, low_open=True),
    Parameter("lockstep", bool, True, "wait for the command that answers each state (the loop stays closed at any "
                                      "speed and under CPU load)"),
    Parameter("lockstep_timeout_s", float, 0.5, "wall time waited for that command (then: free-run, inputs zeroed)",
              "s", 0.0, INF, low_open=True),
    Parameter("command_limit_factor", float, 2.0, "a command beyond this multiple of an actuator limit is refused "
                                                  "(within it: saturated)", "", 1.0, INF),
    Parameter("max_reset_rate_rad_s", float, 1.0, "largest body rate norm a /simulator/reset (or "
                                                  "initial_rate_rad_s) may set", "rad/s", 0.0, INF, low_open=True),
    Parameter("gravity_gradient", bool, None, "apply the gravity-gradient torque",
              default_rule="the scenario's environment.gravity_gradient (false without it)"),
    Parameter("initial_attitude", list, (0.0, 0.0, 0.0, 1.0), "initial attitude q_BN [x, y, z, w] (unit norm within "
                                                              "1e-3)", "", -INF, INF, length=4),
    Parameter("initial_rate_rad_s", list, (0.0, 0.0, 0.0), "initial body rate omega_BN_B (norm at most "
                                                                 "max_reset_rate_rad_s)", "rad/s", -INF, INF, length=3),
    Parameter("seed", int, None, "seed of every random stream of the sensors and actuators", "", 0, 2**63 - 1,
              default_rule="the scenario's sensors.seed"),
    Parameter("campaign", str, "", "Monte Carlo campaign file whose run run_seed is flown (dispersed truth; with "
                                   "run_seed)"),
    Parameter("run_seed", int, -1, "run seed of that campaign (-1: none; with campaign)", "", -1, 2**32 - 1),
), "the truth simulation: dynamics, environment, sensors and actuators",
    renamed={"step": "step_s", "publish_rate": "publish_rate_Hz", "command_timeout": "command_timeout_s",
             "clock_rate": "clock_rate_Hz", "tf_rate": "tf_rate_Hz", "marker_rate": "marker_rate_Hz",
             "lockstep_timeout": "lockstep_timeout_s", "end_time": "end_time_s",
             "max_reset_rate": "max_reset_rate_rad_s", "start_timeout": "start_timeout_s",
             "initial_rate": "initial_rate_rad_s"})
