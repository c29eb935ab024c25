"""day: a day in orbit flown by the nodes, its targets, margins and wheels.

``att-bench day [--mission NAME] [--out DIR] --json PATH`` flies a mission file (default
``config/missions/observatory_day.yaml``: the observatory's 16 sources from ``leo_observatory``
over 6 h of sim time) exactly as ``att-mission`` does — recorder, simulator, estimator, controller
and planner as ROS nodes — and reports what the log shows (:func:`att_planner.mission.day.day_report`):
per target its dwell (UTC), whether it was observed and the truth pointing error, the missed ones
with why, the zones and their smallest margins at their true positions, the wheels' peak speed
against the limit, the MCAP's path, the wall time and the real-time factor.
"""
from __future__ import annotations

from pathlib import Path

from att_planner.tools.mission import fly_mission, mission_and_env, real_time_factor


def configure(parser) -> None:
    parser.add_argument("--mission", default="observatory_day",
                        help="a mission file (config/missions/NAME.yaml or a path)")
    parser.add_argument("--out", default="runs", help="directory for the MCAP and the node logs")
    parser.add_argument("--rtf", type=real_time_factor, default=None,
                        help="'max' or a real-time factor: sim time held while the planner plans (att-mission --rtf)")


def run(args) -> dict:
    try:
        mission, env = mission_and_env(args.mission)
    except ValueError as err:
        raise SystemExit(f"att-bench day: {err}") from None
    _, report = fly_mission(mission, Path(args.out), rtf=args.rtf, env=env)
    report["mission"] = mission.path.stem
    report["rtf_mode"] = "paced by the planner's budget" if args.rtf is None else (
        "max, sim time held while planning" if args.rtf == 0 else f"at most {args.rtf:g}, held while planning")
    print(f"{'target':14s} {'observed':8s} {'start (UTC)':32s} {'pointing error':>14s}  why")
    for x in report["targets"]:
        err = f"{x['pointing_error_deg']:.4f} deg" if x["pointing_error_deg"] is not None else "-"
        print(f"{x['name']:14s} {str(x['observed']):8s} {x['start'] or '-':32s} {err:>14s}  {x.get('why', '')}")
    print(f"observed {report['observed']}, missed {report['missed']}; minimum zone margin "
          f"{report['min_margin_deg']:.3f} deg; peak wheel speed {report['peak_wheel_ratio']:.3f} of the limit; "
          f"{report['sim_seconds']:.0f} s of sim time in {report['wall_seconds']:.0f} s (RTF {report['rtf']:.1f})")
    return report
