"""``att-bench``: the one entry point for the suite's benchmark figures.

``att-bench <study> [options] --json PATH`` runs a study, prints a table and writes its JSON.
Each study is a module of this package providing ``configure(parser)`` and ``run(args) -> dict``
(``run`` prints the table and returns the JSON payload). The exit status is 1 when the payload
says ``"passed": false`` (a study that states a criterion and found it failed), 0 otherwise.
"""
from __future__ import annotations

import argparse
import importlib
import json

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
}


def _json_default(obj):
    import numpy as np
    if isinstance(obj, np.ndarray):
        return obj.tolist()
    if isinstance(obj, np.generic):
        return obj.item()
    raise TypeError(f"not JSON serialisable: {type(obj).__name__}")


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(prog="att-bench", description=__doc__.splitlines()[0])
    sub = parser.add_subparsers(dest="study", required=True)
    modules = {}
    for name, modname in STUDIES.items():
        modules[name] = importlib.import_module(modname)
        p = sub.add_parser(name, help=(modules[name].__doc__ or "").strip().splitlines()[0])
        modules[name].configure(p)
        p.add_argument("--json", metavar="PATH", help="write the study's JSON here")
    args = parser.parse_args(argv)
    payload = modules[args.study].run(args)
    if args.json:
        with open(args.json, "w") as fh:
            json.dump(payload, fh, indent=1, default=_json_default)
        print(f"JSON: {args.json}")
    return 0 if payload.get("passed", True) else 1
