"""The speed section of BENCHMARKS.md from ``benchmarks/speed.json`` (``att-bench speed``).

``python -m att_planner.tools.bench.speed_report benchmarks/speed.json BENCHMARKS.md`` replaces the
block after the ``<!-- generated from benchmarks/speed.json -->`` marker (up to the first blank line
after the table) with the table, the machine and the targets measured in the JSON: every figure
there is read from it, none typed.
"""
from __future__ import annotations

import json
import sys
from datetime import UTC, datetime

MARKER = "<!-- generated from benchmarks/speed.json -->"
UNITS = {"swift": "TU", "earth_obs": "s", "leo_observatory": "s"}


def _ms(seconds: float) -> str:
    return f"{1e3 * seconds:.0f} ms"


def _row(r: dict) -> str:
    f, b, t, unit = r["first"], r["best"], r["time_optimal"], UNITS.get(r["case"], "s")
    ros = r.get("ros")
    through = "—"
    if ros:
        through = (f"{_ms(ros['first']['round_trip_seconds'])} ({ros['first']['method']}), "
                   f"{ros['best']['round_trip_seconds']:.2f} s ({ros['best']['method']})")
    return (f"| {r['case']} | {f['method']}, {f['tf']:.4g} {unit}, {_ms(f['solve_seconds'])} "
            f"({_ms(f['solve_cpu_seconds'])}) | {b['method']}, {b['status']}, {b['tf']:.4g} {unit}, "
            f"{r['best_tf_ratio']:.3f} ×, {b['solve_seconds']:.2f} s ({b['solve_cpu_seconds']:.2f} s) | "
            f"{r['time_optimal_tf']:.6g} {unit} | {r['time_optimal_seconds']:.2f} s, {t['solve_seconds']:.2f} s "
            f"({t['solve_cpu_seconds']:.2f} s) | {through} |")


def _targets(payload: dict) -> str:
    rows, goal = payload["cases"], payload["targets"]

    def met(ok: bool) -> str:
        return "**met**" if ok else "**not met**"

    first = [r["first"]["solve_cpu_seconds"] for r in rows]
    best_ok = all(r["best"]["solve_seconds"] <= goal["best_seconds"] and r["best_tf_ratio"] <= goal["best_tf_ratio"]
                  for r in rows)
    to_wall = [r["time_optimal_seconds"] for r in rows]
    to_cpu = [r["time_optimal"]["solve_cpu_seconds"] for r in rows]
    to_ok = max(to_wall) <= goal["time_optimal_seconds"]
    names = "/".join(r["case"] for r in rows)
    ros = [r["ros"]["best"]["method"] for r in rows if "ros" in r]
    return (f"Targets ({names}): first verified plan ≤ {_ms(goal['first_seconds'])} of compute — "
            f"{met(max(first) <= goal['first_seconds'])} on CPU time ({', '.join(_ms(x) for x in first)}); "
            f"best smooth plan ≤ {goal['best_seconds']:g} s with t_f ≤ {goal['best_tf_ratio']:g} × t_o — "
            f"{met(best_ok)} in-process"
            + (f"; through ROS the best plan came from {', '.join(ros)}" if ros else "")
            + f"; time-optimal ≤ {goal['time_optimal_seconds']:g} s — {met(to_ok)}"
            f" on the method stage's wall time ({', '.join(f'{x:.2f}' for x in to_wall)} s; the whole request's "
            f"CPU {', '.join(f'{x:.2f}' for x in to_cpu)} s).")


def section(payload: dict, run_end: float | None = None) -> str:
    """The generated block: the table, the machine line and the targets line."""
    m = payload["machine"]
    head = ("| case | first plan: method, t_f, compute wall (CPU) | best: method, status, t_f, ratio to t_o, compute "
            "wall (CPU) | time-optimal t_o | t_o compute (method stage), request wall (CPU) | through ROS: first, "
            "best round trips (median) |\n|---|---|---|---|---|---|")
    when = "" if run_end is None else f", JSON written {datetime.fromtimestamp(run_end, UTC):%Y-%m-%d %H:%M} UTC"
    machine = (f"Machine: {m['cores']} cores, Python {m['python']}, OMP_NUM_THREADS={m['omp_num_threads']}, load "
               f"average (1 min) {m['load_1min']:.1f} at the end of the run, {m['wall_seconds']:.0f} s in all{when}.")
    return "\n".join([head, *(_row(r) for r in payload["cases"]), "", machine, "", _targets(payload)])


def replace_section(markdown: str, block: str) -> str:
    """``markdown`` with the lines after :data:`MARKER` up to the first blank line after the
    table's last row, the machine and the targets lines, replaced by ``block``."""
    start = markdown.index(MARKER) + len(MARKER) + 1
    end = start
    for _ in range(3):                                # table, machine line, targets paragraph
        end = markdown.index("\n\n", end) + 2
    return markdown[:start] + block + "\n\n" + markdown[end:]


def main(argv=None) -> int:
    import os

    json_path, md_path = (argv or sys.argv[1:])[:2]
    with open(json_path, encoding="utf-8") as fh:
        payload = json.load(fh)
    with open(md_path, encoding="utf-8") as fh:
        text = fh.read()
    with open(md_path, "w", encoding="utf-8") as fh:
        fh.write(replace_section(text, section(payload, os.path.getmtime(json_path))))
    return 0


if __name__ == "__main__":
    sys.exit(main())
