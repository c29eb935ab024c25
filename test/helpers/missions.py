"""A mission written to files and flown through the nodes (the ROS mission tests)."""
from __future__ import annotations

import math

import yaml

from att_planner.mission import config as mission_config
from att_planner.mission.targets import load as load_targets
from att_planner.tools.mission import fly_mission

# the short observatory day the ROS mission tests fly: 2400 s of leo_observatory's sky at 2.5 Hz, --rtf max
SHORT_DAY = {"sensor_axis": [0, 1, 0], "horizon_s": 2400, "start_lead_s": 120, "time_budget_s": 5, "rate_Hz": 2.5}


def fly_written(out, target_list: dict, mission: dict, rtf: float | None = None):
    """Write ``target_list`` and ``mission`` (its ``targets`` key set to that list) under ``out`` and
    fly it (``rtf``: as ``att-mission --rtf``, 0 for max): (the loaded mission, the MCAP's path, the
    day's report)."""
    (out / "targets.yaml").write_text(yaml.safe_dump(target_list))
    (out / "mission.yaml").write_text(yaml.safe_dump({**mission, "targets": str(out / "targets.yaml")}))
    loaded = mission_config.load(str(out / "mission.yaml"))
    mcap, report = fly_mission(loaded, out, log=print, rtf=rtf)
    return loaded, mcap, report


def fly_observatory_sources(out, dwells: dict, mission: dict = SHORT_DAY, rtf: float | None = 0.0):
    """Fly sources of ``config/targets/observatory.yaml`` (name -> dwell s) as an inertial target list
    of leo_observatory through ``mission``: :func:`fly_written`'s answer."""
    observatory = {t.name: t for t in load_targets("observatory").targets}
    targets = [{"name": n, "ra_deg": math.degrees(math.atan2(d[1], d[0])) % 360.0,
                "dec_deg": math.degrees(math.asin(d[2])), "dwell_s": dwell}
               for n, dwell in dwells.items() for d in [observatory[n].direction]]
    return fly_written(out, {"kind": "inertial", "scenario": "leo_observatory", "targets": targets}, mission, rtf)
