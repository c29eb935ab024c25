"""What each error code means: the cases a service, action, topic or node refuses with it.

One entry per :class:`att_msgs_py.errors.ErrorCode`; the documentation's page of error codes is generated
from this table (``docs/_ext/att_docs``). A refusal's own message names the field and the value found.
"""
from __future__ import annotations

from att_msgs_py.errors import ErrorCode

MEANINGS: dict[ErrorCode, str] = {
    ErrorCode.OK: 'success: the request was served',
    ErrorCode.INVALID_ATTITUDE: (
        'NaN/Inf component, zero quaternion, norm off by more than 1e-3 (within 1e-3 it is normalised); '
        'schedule targets/names mismatched, empty or repeated, two targets that are one attitude (within 1e-6 '
        'rad, `q` and `-q` included; both indices named)'
    ),
    ErrorCode.INVALID_FRAME: (
        "a request's `header.frame_id` is neither empty nor the planner's inertial frame; a plan whose frame "
        "is not the controller's"
    ),
    ErrorCode.INVALID_SENSOR_AXIS: 'sensor axis or semi-free sensor target zero, non-finite or not unit (1e-3)',
    ErrorCode.INVALID_CONE: 'cone direction zero/non-finite/not unit, half-angle outside (0, π/2)',
    ErrorCode.SENSOR_IN_CONE: (
        'start, goal or target boresight inside a cone by more than `BOUNDARY_TOLERANCE` = 1e-6 rad (names '
        'the cone and by how many degrees); one within 1e-6 rad of the boundary, inside or out, is on it and '
        'plannable (boundary ends, on the planning methods page; zones the same, 154)'
    ),
    ErrorCode.INFEASIBLE: (
        'the cones (and zones, sensor by sensor) close the sky between the start and goal boresight (decided '
        'before solving: the closed-sky test of the limits page), or leave no path the method could find'
    ),
    ErrorCode.INVALID_SPACECRAFT: (
        'inertia not symmetric positive definite or violating the triangle inequality; a limit ≤ 0; no wheels '
        'for a schedule; a configuration file that does not load'
    ),
    ErrorCode.UNKNOWN_SPACECRAFT: 'no such configuration (names are letters, digits, `_`, `-`)',
    ErrorCode.UNKNOWN_METHOD: 'a method name that is not in the registry (the message lists the registered ones)',
    ErrorCode.INVALID_OPTION: (
        "option not known to the method, out of its range (the registry's, "
        '`att_planner/methods/__init__.py`), NaN/Inf, not an integer, a combination the method cannot run '
        '(Slepian N·W < 1 or M > 2·N·W, time-optimal max_intervals < intervals), given twice or with an empty '
        'name, lists of different length; `end_pointing` with a method other than time_optimal, '
        'smooth_collocation or graph_smooth, or with '
        "`semi_free`; a `boundary_cone` the request's cones do not have, or whose boundary the start or goal "
        'sensor direction is not on (within 1e-6 rad)'
    ),
    ErrorCode.SIZE_LIMIT: (
        'more than 16 cones, 16 zones (`MAX_ZONES`, besides the cones), 16 options or 20 schedule targets; a '
        "TLE line above 80 characters; a name longer than 128 characters (a plan's message: 1000); a plan of "
        'more than 20 000 samples or a plan message above 4 MiB; more than 16 wheels in a state, command, '
        'reset or wheel speed message, 64 sun sensor cells, a signature above 256 bytes. Every cap is '
        'declared in `att_msgs_py/limits.py` and checked on the message (element counts) before it is read, '
        'by every node'
    ),
    ErrorCode.INVALID_TEXT: (
        'a string with a control, format or unassigned character (U+XXXX and its position named): frames, '
        'method, spacecraft, cone, zone, option and target names, zone bodies, TLE lines, plan ids, plan text'
    ),
    ErrorCode.INVALID_TIME_BUDGET: 'budget negative, non-finite or above 600 s',
    ErrorCode.INVALID_EPOCH: (
        "`epoch.sec` outside int32 or `epoch.nanosec` ≥ 1e9; an epoch (the request's or the scenario's) "
        "outside 1900-01-01 .. 2050-01-01 or the wire's 1901-12-13T20:45:52Z .. 2038-01-19T03:14:07Z, or "
        'exactly 1970-01-01T00:00:00Z (zero means "none"); a moving zone or a TLE with no epoch anywhere'
    ),
    ErrorCode.INVALID_ORBIT: (
        'one TLE line without the other; a line not 69 columns, a field malformed (named with its columns), a '
        'wrong line number or checksum, satellite numbers that differ, elements SGP4 rejects'
    ),
    ErrorCode.ORBIT_TOO_LOW: (
        "the orbit (the request's TLE or the scenario's) below 150 km (`|r| − R_E`, every ≤ 30 s) anywhere in "
        'the zone window from the epoch, or SGP4 failing there (decayed)'
    ),
    ErrorCode.INVALID_ZONE: (
        'unknown `body`; `sensor_axis` or `direction` zero or non-finite (any other length is normalised); '
        '`half_angle` outside (0, π), for `earth_limb` outside [0, π/2); an inertial zone without a '
        'direction, or a direction on a Sun, Moon or Earth-limb zone'
    ),
    ErrorCode.ZONE_AT_END: (
        'the start violates a zone at t = 0 (keep-out entered, keep-in left); the goal violates a fixed zone, '
        'or a moving zone at every arrival time of the window; a schedule target inside a fixed zone'
    ),
    ErrorCode.CONTRADICTORY_ZONES: (
        'at t = 0, for one sensor: a keep-in zone entirely inside a keep-out zone, or two keep-in zones that '
        'do not meet (pairs only)'
    ),
    ErrorCode.INVALID_WHEEL_SPEEDS: (
        "`wheel_speeds` with a number of values other than the spacecraft's wheels (or none), NaN/Inf, or a "
        'speed beyond `wheel_speed_max`'
    ),
    ErrorCode.INVALID_OBSERVATION: (
        "a `PlanSchedule`'s `dwell_times`, `window_opens` or `window_closes` with a number of values other "
        "than the targets' (or none); opens without closes or the reverse; a dwell NaN/Inf, negative or above "
        'a day; a window opening NaN/Inf, negative or more than a week after the start; a window closing NaN '
        "or before its opening plus the target's dwell"
    ),
    ErrorCode.INVALID_SITE: (
        "an `ImageTarget` or `ImageStrip` field NaN/Inf or out of its range: a latitude outside [-90, 90] deg, a "
        "longitude outside [-180, 180] deg, an altitude outside [-500 m, 100 km], a negative or over-a-day dwell, "
        "a strip shorter than 1 m or longer than 2000 km, a scan speed negative or above 20 km/s, or a scan "
        "whose tracking asks more body rate or torque than the spacecraft has"
    ),
    ErrorCode.SITE_NOT_VISIBLE: (
        "the site (a strip: its first point) never rises above the instrument's minimum elevation within the "
        "planning window, or the slew arrives, or the dwell or scan runs, where it is below it"
    ),
    ErrorCode.INVALID_WHEEL_SET: (
        "a `PlanManeuver`'s `healthy_wheels` with a number of values other than the spacecraft's wheels (or "
        "none), or healthy wheels whose axes do not span the body (the attitude cannot be controlled on them)"
    ),
    ErrorCode.SOLVER_FAILED: 'the method failed (or its process died) and no safe fallback exists',
    ErrorCode.VERIFICATION_FAILED: (
        'the plan did not survive integration through the dynamics and no safe fallback exists'
    ),
    ErrorCode.WHEEL_SATURATION: (
        'no plan keeps every wheel within its speed limit: the momentum stored at the start saturates a wheel '
        'on the path at any speed, the plan would have to fly more than 20 times slower, or a plan that '
        'cannot be slowed (a wheel-torque plan, one ending on `end_pointing`) saturates one'
    ),
    ErrorCode.UNKNOWN_PLAN: '`ExecuteManeuver` for a plan id the controller never received',
    ErrorCode.INVALID_PLAN: (
        'a plan (inline or published) whose times do not start at 0, do not strictly increase, exceed a day '
        'or disagree in number with its attitudes, rates or torques; fewer than 2 samples; NaN/Inf anywhere; '
        "attitudes off unit norm by more than 1e-3; rates above 10 rad/s; torques above the spacecraft's "
        'limit (body `torque_max`, or `wheel_torque_max` for a wheel-torque plan); an unknown or empty '
        'control kind, interpolation or status, status `failed`; a bad sensor axis, cone or zone (the checks '
        'of 153); an epoch outside 1900..2050, or none for a zone that moves'
    ),
    ErrorCode.BUSY: 'a maneuver is executing: mode changes other than MODE_SAFE (abort) are refused',
    ErrorCode.INVALID_MODE: 'unknown mode, or plan tracking requested through `set_mode`',
    ErrorCode.NO_STATE: 'the controller has not accepted a state yet',
    ErrorCode.ABORTED: (
        'the maneuver was cancelled, stopped by safe mode or by a new state timeline, or (client side) its '
        'controller fell silent'
    ),
    ErrorCode.PLAN_NOT_AUTHENTIC: (
        'a plan without a signature, signed with another key, or whose signature does not verify (altered '
        'after signing)'
    ),
    ErrorCode.PLAN_ID_REUSED: 'a plan whose id the controller already knows for a different plan',
    ErrorCode.WRONG_SPACECRAFT: 'a plan made for another spacecraft configuration (name or physical parameters)',
    ErrorCode.PLAN_CONTEXT: (
        'a plan whose first attitude or rate is too far from the current state, or (moving zones, or a moving '
        'goal at its end) whose epoch is more than `max_start_epoch_error_s` from the scenario epoch + sim time'
    ),
    ErrorCode.INVALID_STATE: (
        '(logged) a state with a bad field, the wrong frames, or from a second publisher while the held one '
        'is in the ROS graph'
    ),
    ErrorCode.STATE_TIME_JUMP: (
        '(logged) a state whose stamp goes backward, repeats, jumps forward too far or is far from the sim '
        'clock'
    ),
    ErrorCode.MODE_NOT_AUTHENTIC: (
        'with `require_signed_modes`: a `set_mode` request unsigned, signed with another key, altered, or '
        'whose `sequence` is not above the last accepted one (a replay)'
    ),
    ErrorCode.ESTIMATE_UNHEALTHY: (
        '`state_source: estimate`: a maneuver or a magnetorquer mode asked for while the attitude estimate is '
        'not CONVERGED'
    ),
    ErrorCode.INVALID_POINTING: (
        'a pointing mode (`set_mode`, `pointing_after`, `end_pointing`) with an unknown kind or secondary, an '
        'axis zero or non-finite, parallel primary and secondary axes, a latitude, longitude, yaw or altitude '
        'out of range, `sun` without an epoch, or no attitude now (primary and secondary directions '
        'parallel); MODE_POINTING without a pointing mode'
    ),
    ErrorCode.INVALID_MEASUREMENT: (
        '(logged) a sensor message or estimate input with a bad field: NaN/Inf, wrong size or frame, a '
        'tracker quaternion off unit norm by more than 1e-3, an unknown tracker, a rate above 100 rad/s or a '
        'field above 1e-3 T, sun sensor outputs outside [0, 2], wheel speeds beyond twice the limit; a second '
        'publisher of the same input while the held one is in the ROS graph'
    ),
    ErrorCode.STALE_MEASUREMENT: (
        '(logged) a gyro stamp that does not move forward or jumps more than `max_gyro_gap_s` ahead (unless the '
        "gyro was silent for `resync_timeout_s`); a measurement older than the filter's history or more than "
        '`max_gyro_gap_s` ahead of the gyro'
    ),
    ErrorCode.INVALID_FAULT_REPORT: (
        "(logged) a `FaultStatus` on `/estimator/faults` whose fault id the controller's fault table does not "
        "declare, whose component or response is not that entry's, or whose index is below -1; a second "
        "publisher of them while the held one is in the ROS graph"
    ),
    ErrorCode.INVALID_RESET: (
        '`/simulator/reset` with a non-finite field; an attitude whose norm is off 1 by more than 1e-3; the '
        'wrong number of wheel speeds (empty: zeros) or one beyond `wheel_speed_max` relative to the body (`Ω '
        '− Gᵀω`); a non-zero `orbit_phase` on a kepler or tle orbit (only a circular orbit takes a phase); '
        '‖body_rate‖ above `max_reset_rate_rad_s`; |orbit_phase| above 1e6 rad'
    ),
    ErrorCode.INVALID_COMMAND: (
        '(logged) an actuator command with an unknown mode, the wrong number of wheel torques (empty is '
        'allowed), NaN/Inf, a stamp more than one step ahead of the simulation or older than '
        '`command_timeout`, a frame other than "" or the body frame, or from a second publisher while the '
        'held one (the controller) is in the ROS graph'
    ),
    ErrorCode.COMMAND_LIMIT: (
        '(logged) an actuator command beyond `command_limit_factor` (2) × its limit (wheel torque, dipole, '
        'body torque; any mode). Within the factor the command is saturated'
    ),
    ErrorCode.INVALID_FAULT: (
        '`/simulator/inject_fault`: an unknown component or a kind it cannot have, an index beyond the '
        "spacecraft's hardware (wheels, star trackers, gyro or coil axes, the one magnetometer), a missing "
        'sensor, a NaN/Inf or out-of-range `factor`, `bias_rad` or `bias_rad_s`, a parameter given to a kind '
        'that takes none, a negative or non-finite `t_s`'
    ),
    ErrorCode.FAULT_INJECTION_DISABLED: (
        '`/simulator/inject_fault` to a simulator whose scenario does not set `allow_fault_injection: true`'
    ),
    ErrorCode.INVALID_PARAMETER: 'a node parameter of the wrong type, out of range, or unknown (a typo)',
    ErrorCode.INVALID_CONFIG: (
        'an unknown scenario, a YAML that is not a scenario, a missing or unparsable `--params-file`, a '
        'missing key file'
    ),
    ErrorCode.VERSION_MISMATCH: (
        '`att-mc --scheduler`: a Dask worker runs another suite version (distribution version and digest '
        'of the sources) than the client; the message names the worker and both versions'
    ),
}
