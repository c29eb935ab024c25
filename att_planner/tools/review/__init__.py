"""``att-review LOG.mcap [--out DIR]``: look at a recorded run without ROS running.

Reads the log with :func:`att_msgs_py.log.read_log`, picks the reviewed segment (the last
executed plan, else the last magnetorquer-PD run, else the whole log), and writes into ``DIR``
(default: ``review/`` next to the log):

* ``sky.png`` — the sensor boresight on the celestial sphere (Lambert azimuthal equal-area
  projection centred on the path), every keep-out cone and zone of the recorded ``ManeuverPlan``
  drawn and shaded (a moving zone — Sun, Moon, Earth limb — shaded where it is at the plan's start,
  dashed where it is at its end, with the track of its axis in between; keep-in zones dash-dot;
  zones of other sensors thin, with those sensors' boresights dotted), start and goal marked, the
  closest approach to each zone annotated;
* ``time_histories.png`` — attitude error to goal and to the plan reference, body rates, body
  torque (applied vs planned) and wheel torques (commanded vs applied) with their limits, wheel
  speeds with their limit, magnetorquer dipoles (commanded vs applied) with saturation, cone and
  zone margins (moving zones at their true positions at each recorded time), controller mode;
* ``overview.png`` — a screenshot-sized digest (sky, margins, torque, wheel speeds);
* ``estimation.png`` (a log with the estimator's attitude) — the estimation error per
  body axis with the filter's ±3σ, the gyro bias estimate against the truth, the estimate's health
  and the trackers' invalid samples, the gyro and magnetometer measured against the truth
  (:mod:`.estimation`); the summary gains the estimate's figures (``estimation``);
* ``pointing.png`` (a log with a pointing mode) — the mode timeline with the guidance,
  the pointing error from the reference, each wheel's momentum against its limit, the dipoles
  (:mod:`.pointing`); the summary gains ``pointing``;
* ``mission.png`` and ``mission_sky.png`` (a log of ``att-mission``) — the day's
  timeline (a Gantt row per target: slews, dwells observed or not, parks, misses; the controller's
  mode), the zones' margins, wheel momentum and dipoles over the day, and the sky with the day's
  boresight track, the targets and the Sun, Moon and nadir tracks (:mod:`.mission`); the summary
  gains ``mission``: the table of targets observed (start, dwell, pointing error) and missed (why);
  a mission of ground sites also ``mission_ground.png``: the ground track (sub-satellite point and
  the boresight's ground point, slews and dwells marked), the sites imaged, refused and missed, each
  image's pointing error (the summary's ``mission.sites``);
* with faults (a log with ``/simulator/faults``, ``/controller/faults`` or ``/estimator/faults``):
  each fault injected, its detection (detector, evidence, latency) and the response, and each
  re-plan flown after it, marked on the time histories and listed in the summary (``faults``;
  :mod:`.faults`); the reviewed segment is then the maneuver in flight at the first detection
  through its re-plans;
* ``summary.txt``, ``summary.json`` and ``index.html`` (summary table, figures embedded).

For a maneuver, "executed" is the whole reviewed segment: the maneuver (the plan, t = 0 to its
duration) and the settle and hold on its final attitude after it; the peak body torque is given
against the planning limit ``torque_max`` and the actuator (wheel) limit, and only the latter is
flagged when exceeded (:func:`.summary.notes`).

Limits come from the scenario named by the plan (``att_sim.models.scenario.load(plan.spacecraft)``) or
``--scenario``; so do the epoch and orbit the moving zones are placed with: the simulator's, whose
sim time zero is the scenario's epoch (:func:`.summary.zone_sky_for`; a scenario without an epoch
flew no real sky, and its moving zones are left out with a note). Modules: :mod:`.run` (the
reviewed segment), :mod:`.summary` (the pure :func:`summarize` of a read log), :mod:`.figures`
(matplotlib, Agg, in the ``plot_*`` functions).
"""
from __future__ import annotations

import argparse
import base64
import html
import json
import sys
from dataclasses import dataclass
from pathlib import Path

from att_msgs_py.log import read_log
from att_msgs_py.topics import (
    COMMAND,
    CONTROLLER_FAULTS,
    CONTROLLER_STATUS,
    ESTIMATE,
    ESTIMATOR_FAULTS,
    IMU,
    MAGNETOMETER,
    MISSION_EVENTS,
    PLANS,
    SENSOR_TRUTH,
    SIM_FAULTS,
    STAR_TRACKER,
    STATE,
)

__all__ = ["Review", "extract_run", "format_summary", "main", "review", "settling_time", "summarize"]

# the topics a review reads: the run's, and those of :mod:`.estimation` and :mod:`.mission` (their
# ``TOPICS``); named here so that a log is read, and a damaged one refused, before the figures and
# the models are imported (a second or more on a loaded machine)
REVIEWED_TOPICS = sorted({STATE, COMMAND, PLANS, CONTROLLER_STATUS, ESTIMATE, SENSOR_TRUTH, STAR_TRACKER, IMU,
                          MAGNETOMETER, MISSION_EVENTS, SIM_FAULTS, CONTROLLER_FAULTS, ESTIMATOR_FAULTS})
_LAZY = {"extract_run": "run", "settling_time": "run", "format_summary": "summary", "summarize": "summary"}


def __getattr__(name: str):
    """The package's exports from :mod:`.run` and :mod:`.summary`, imported when first used."""
    if name in _LAZY:
        import importlib

        return getattr(importlib.import_module(f"{__name__}.{_LAZY[name]}"), name)
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")


@dataclass
class Review:
    out_dir: Path
    summary: dict
    text: str
    figures: dict          # name -> png path
    html: Path


def _html(log_path: Path, text: str, remarks: list[str], figures: dict) -> str:
    imgs = "\n".join(
        f'<h2>{html.escape(name)}</h2>\n<img alt="{html.escape(name)}" style="max-width:100%" '
        f'src="data:image/png;base64,{base64.b64encode(Path(p).read_bytes()).decode()}">'
        for name, p in figures.items())
    return ("<!DOCTYPE html>\n<html><head><meta charset=\"utf-8\">"
            f"<title>Review of {html.escape(log_path.name)}</title>"
            "<style>body{font-family:sans-serif;margin:2em}pre{background:#f4f4f4;padding:1em}</style></head><body>\n"
            f"<h1>Review of {html.escape(str(log_path))}</h1>\n<pre>{html.escape(text)}</pre>\n"
            + "".join(f'<p class="note">{html.escape(r)}</p>\n' for r in remarks) + f"{imgs}\n"
            "</body></html>\n")


def _commands(log) -> tuple:
    import numpy as np

    cmd = log.get(COMMAND)
    if cmd is None or not len(cmd):
        return np.zeros(0), np.zeros(0, dtype=str)
    return np.asarray(cmd["header.stamp"], float), np.asarray(cmd["plan_id"], dtype=str)


def _faults(log):
    """The run's faults (:func:`.faults.faults_of`), None without any."""
    from att_planner.tools.review.faults import faults_of

    return faults_of(log, *_commands(log))


def _interrupted(log, faults) -> str | None:
    from att_planner.tools.review.faults import interrupted_plan

    return interrupted_plan(faults, *_commands(log))


def review(log_path: str | Path, out_dir: str | Path | None = None, *, plan_id: str | None = None,
           scenario: str | None = None) -> Review:
    """Read ``log_path`` and write figures, summary and HTML page into ``out_dir``."""
    log_path = Path(log_path)
    log = read_log(log_path, topics=REVIEWED_TOPICS, keep_messages=(PLANS, MISSION_EVENTS))
    from att_planner.tools.review.estimation import estimation_of, estimation_summary, figure_estimation
    from att_planner.tools.review.faults import faults_summary, marks
    from att_planner.tools.review.figures import figure_overview, figure_sky, figure_time_histories
    from att_planner.tools.review.mission import (
        figure_mission,
        figure_mission_ground,
        figure_mission_sky,
        mission_of,
        mission_summary,
    )
    from att_planner.tools.review.pointing import figure_pointing, pointing_of, pointing_summary
    from att_planner.tools.review.run import extract_run
    from att_planner.tools.review.summary import format_summary, notes, scenario_for, summary_of, zone_sky_for

    out = Path(out_dir) if out_dir is not None else log_path.parent / "review"
    faults = _faults(log)
    through = None
    if plan_id is None and faults is not None and faults.replans:      # the maneuver re-planned and its re-plans
        plan_id, through = _interrupted(log, faults), faults.replans[-1]["plan_id"]
    run = extract_run(log, plan_id, through)
    run.marks = marks(faults, run.t0)
    out.mkdir(parents=True, exist_ok=True)
    found = scenario_for(run, scenario)
    sc = found.spacecraft if found is not None else None
    zones, zones_note = zone_sky_for(run, found)
    summary = summary_of(run, sc, zones, zones_note)
    if faults is not None:
        summary["faults"] = faults_summary(faults)
    figures = {"overview": figure_overview(run, sc, out / "overview.png", zones),
               "sky": figure_sky(run, out / "sky.png", zones),
               "time histories": figure_time_histories(run, sc, out / "time_histories.png", zones)}
    estimation = estimation_of(log, run.t0 + run.t[0], run.t0 + run.t[-1])
    if estimation is not None:
        summary["estimation"] = estimation_summary(estimation)
        figures["estimation"] = figure_estimation(estimation, out / "estimation.png", run.t0)
    pointing = pointing_of(log, sc) if sc is not None else None
    if pointing is not None:
        summary["pointing"] = pointing_summary(pointing)
        figures["pointing"] = figure_pointing(pointing, out / "pointing.png")
    mission = mission_of(log, found)
    if mission is not None:
        summary["mission"] = mission_summary(mission)
        figures["mission"] = figure_mission(mission, out / "mission.png")
        figures["mission sky"] = figure_mission_sky(mission, out / "mission_sky.png")
        if mission.ground is not None:
            figures["mission ground track"] = figure_mission_ground(mission, out / "mission_ground.png")
    text = format_summary(summary)
    (out / "summary.txt").write_text(text + "\n")
    (out / "summary.json").write_text(json.dumps(summary, indent=2) + "\n")
    page = out / "index.html"
    page.write_text(_html(log_path, format_summary(summary, with_notes=False), notes(summary), figures))
    return Review(out, summary, text, figures, page)


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(prog="att-review", description=__doc__.splitlines()[0])
    parser.add_argument("log", help="MCAP file written by the suite's recorder")
    parser.add_argument("--out", default=None, help="output directory (default: review/ next to the log)")
    parser.add_argument("--plan-id", default=None, help="review this executed plan (default: the last one)")
    parser.add_argument("--scenario", default=None,
                        help="scenario for the limits (default: the one the plan names)")
    args = parser.parse_args(argv)
    if not Path(args.log).is_file():
        parser.error(f"log file '{args.log}' does not exist")
    try:
        result = review(args.log, args.out, plan_id=args.plan_id, scenario=args.scenario)
    except ValueError as err:
        print(f"att-review: {err}", file=sys.stderr)
        return 1
    print(result.text)
    for name, p in result.figures.items():
        print(f"figure ({name}): {p}")
    print(f"HTML: {result.html}")
    return 0
