"""``att-bench``: the one entry point for the suite's benchmark figures.

``att-bench <study> [options] --json PATH`` runs a study, prints a table and writes its JSON.
Each study is a module of this package providing ``configure(parser)`` and ``run(args) -> dict``
(``run`` prints the table and returns the JSON payload; a module's ``JSON_INDENT``, 1 by default,
sets the JSON's indentation: None writes it on one line). The exit status is 1 when the payload
says ``"passed": false`` (a study that states a criterion and found it failed), 0 otherwise. A JSON
that names no ``machine`` gets one (cores, Python, the 1-min load at the end of the run, the UTC
time and the commit), so that ``att-bench history --append PATH`` can record where it was measured.

``att-bench history --append PATH`` appends a run's summary line to ``benchmarks/history.jsonl``;
``att-bench summary`` renders BENCHMARKS.md's summary table from that history (``--check`` compares).
"""
from __future__ import annotations

import argparse
import importlib
import json
import os
import platform
from datetime import UTC, datetime

STUDIES = {
    "smooth": "att_planner.tools.bench.smooth",
    "time-optimal": "att_planner.tools.bench.time_optimal",
    "schedule": "att_planner.tools.bench.schedule",
    "gains": "att_planner.tools.bench.gains",
    "soak": "att_planner.tools.bench.soak",
    "sky": "att_planner.tools.bench.sky",
    "speed": "att_planner.tools.bench.speed",
    "estimation": "att_planner.tools.bench.estimation",
    "momentum": "att_planner.tools.bench.momentum",
    "observe": "att_planner.tools.bench.observe",
    "day": "att_planner.tools.bench.day",
    "timing": "att_planner.tools.bench.timing",
    "logtools": "att_planner.tools.bench.logtools",
    "flood": "att_planner.tools.bench.flood",
    "cluster": "att_planner.tools.bench.cluster",
    "fastest": "att_planner.tools.bench.fastest",
    "rtf": "att_planner.tools.bench.rtf",
    "aeos": "att_planner.tools.bench.aeos",
    "faults": "att_planner.tools.bench.faults",
}
TOOLS = {
    "history": "att_planner.tools.bench.history",
    "summary": "att_planner.tools.bench.summary",
}


def _json_default(obj):
    import numpy as np
    if isinstance(obj, np.ndarray):
        return obj.tolist()
    if isinstance(obj, np.generic):
        return obj.item()
    raise TypeError(f"not JSON serialisable: {type(obj).__name__}")


def machine() -> dict:
    """Where and when a study ran: cores, Python, the 1-min load now, the UTC time and the commit."""
    from att_planner.tools.bench.history import head_commit
    return {"cores": os.cpu_count(), "python": platform.python_version(), "load_1min": os.getloadavg()[0],
            "omp_num_threads": os.environ.get("OMP_NUM_THREADS"),
            "date": datetime.now(UTC).strftime("%Y-%m-%dT%H:%M:%SZ"), "commit": head_commit()}


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(prog="att-bench", description=__doc__.splitlines()[0])
    sub = parser.add_subparsers(dest="subcommand", required=True)
    modules = {}
    for name, modname in {**STUDIES, **TOOLS}.items():
        modules[name] = importlib.import_module(modname)
        p = sub.add_parser(name, help=(modules[name].__doc__ or "").strip().splitlines()[0])
        modules[name].configure(p)
        if name in STUDIES:
            p.add_argument("--json", metavar="PATH", help="write the study's JSON here")
    args = parser.parse_args(argv)
    if args.subcommand in TOOLS:
        return modules[args.subcommand].run(args)
    payload = modules[args.subcommand].run(args)
    if isinstance(payload, dict) and not isinstance(payload.get("machine"), dict):
        payload["machine"] = machine()
    if args.json:
        with open(args.json, "w") as fh:
            json.dump(payload, fh, indent=getattr(modules[args.subcommand], "JSON_INDENT", 1), default=_json_default)
        print(f"JSON: {args.json}")
    return 0 if payload.get("passed", True) else 1
