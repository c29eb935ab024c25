"""The planner node's parameters, declared once (read by the node and by the in-process planning of
:func:`att_planner.tools.closed_loop.plan`)."""
from __future__ import annotations

import math

from att_msgs_py.parameters import Parameter, ParameterTable
from att_planner import methods
from att_planner.service.imaging import MAX_SCAN_SPEED_M_S, MIN_ELEVATION_DEG
from att_planner.service.requests import MAX_TIME_BUDGET
from att_planner.verification import TOLERANCES

PLANNER = ParameterTable("planner", (
    Parameter("default_method", str, "", "planning method of a request that names none ('': the best available)",
              choices=("", *methods.METHODS),
              refusal=f"expected '' (the best) or one of {', '.join(methods.METHODS)}"),
    Parameter("time_budget_s", float, 20.0, "wall-time budget of a request whose time_budget is 0", "s",
              0.0, MAX_TIME_BUDGET, low_open=True),
    Parameter("accept_attitude_error_deg", float, math.degrees(TOLERANCES.attitude), "largest final attitude error "
                                                                                     "of an accepted plan", "deg",
              0.0, 180.0, low_open=True),
    Parameter("accept_final_rate_rad_s", float, TOLERANCES.rate, "largest final body rate of an accepted plan",
              "rad/s", 0.0, 10.0, low_open=True),
    Parameter("accept_cone_penetration_deg", float, math.degrees(TOLERANCES.cone_penetration),
              "largest penetration of a keep-out cone an accepted plan may have", "deg", 0.0, 10.0),
    Parameter("cone_padding_deg", float, 1.0, "cones widened by this for planning (a tracking margin); plans are "
                                              "verified against the cones unpadded", "deg", 0.0, 10.0),
    Parameter("schedule_rate_max_rad_s", float, math.inf, "body rate bound of a schedule's slews (.inf: none)",
              "rad/s", 0.0, low_open=True, refusal="expected a body-rate bound > 0 rad/s (.inf: none)", allow_inf=True),
    Parameter("image_min_elevation_deg", float, MIN_ELEVATION_DEG, "the instrument's minimum elevation of an "
              "imaged site above its horizon (image_target, image_strip)", "deg", 0.0, 90.0),
    Parameter("strip_scan_speed_m_s", float, 0.0, "ground speed of a strip's scan when a request gives none (0: the "
              "sub-satellite point's ground speed at the slew's start)", "m/s", 0.0, MAX_SCAN_SPEED_M_S),
    Parameter("signing_key", str, None, "Ed25519 private key file the plans are signed with",
              default_rule="plan_signing.key in the suite's key directory ($ATT_KEY_DIR, see att-keygen)"),
    Parameter("max_parallel_solves", int, 2, "plans solved at once (worker processes)", "", 1, 64),
    Parameter("plan_markers", bool, True, "publish each plan's boresight path on /planner/plan_markers (the 3D view)"),
    Parameter("warm_up_scenarios", str, None, "comma-separated scenarios whose demo maneuvers every worker "
                                              "plans before the node serves ('': none)", default_rule="the scenario"),
), "the maneuver planner: the plan_maneuver, plan_schedule, image_target and image_strip services",
    renamed={"time_budget": "time_budget_s", "accept_final_rate": "accept_final_rate_rad_s",
             "schedule_rate_max": "schedule_rate_max_rad_s"})
