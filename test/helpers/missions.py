"""A mission written to files and flown through the nodes (the ROS mission tests)."""
from __future__ import annotations

import yaml

from att_planner.mission import config as mission_config
from att_planner.tools.mission import fly_mission


def fly_written(out, target_list: dict, mission: dict, rtf: float | None = None):
    """Write ``target_list`` and ``mission`` (its ``targets`` key set to that list) under ``out`` and
    fly it (``rtf``: as ``att-mission --rtf``, 0 for max): (the loaded mission, the MCAP's path, the
    day's report)."""
    (out / "targets.yaml").write_text(yaml.safe_dump(target_list))
    (out / "mission.yaml").write_text(yaml.safe_dump({**mission, "targets": str(out / "targets.yaml")}))
    loaded = mission_config.load(str(out / "mission.yaml"))
    mcap, report = fly_mission(loaded, out, log=print, rtf=rtf)
    return loaded, mcap, report
