"""Build benchmarks/history.jsonl once, from every committed version of every study JSON.

``python benchmarks/seed_history.py [--out benchmarks/history.jsonl]`` (run from the repository's
root) walks the git history of ``benchmarks/*.json`` (files since removed included): each committed
version of a study's JSON is one recorded run, summarised by :func:`att_planner.tools.bench.history.line`
with the commit that recorded it and that commit's date (for a per-commit A/B JSON,
``monte_carlo_ab_<code>_<round>.json``, the code it measured). A line keeps ``json`` only for the
version the repository holds; the others name ``git show <commit>:<path>`` as their source.

Figures that exist only in BENCHMARKS.md's text (the gains searches, the soak, the bilimoria_wie and
swift time-optimal plans: their JSONs were written outside the repository) are carried over from
:data:`TEXT_RUNS`, each line naming its section of BENCHMARKS.md at :data:`TEXT_AT`. The lines are
written in date order. Later runs append themselves: ``att-bench history --append PATH``.
"""
from __future__ import annotations

import argparse
import json
import re
import subprocess
import sys
from datetime import UTC, datetime

from att_planner.tools.bench import history as hist

TEXT_AT = "dfcf2d1"       # the BENCHMARKS.md the text figures were read from
SKIP = {"benchmarks/sky_search.json"}     # the sky case search's output (benchmarks/sky_search.py), not a study run

# file -> (case, command) where the study's defaults do not name the run
NAMED = {
    "benchmarks/monte_carlo.json": (None, "att-mc campaigns/swift_demo.yaml --runs 1000 --out /tmp/mc1000/out "
                                          "--json benchmarks/monte_carlo.json"),
    "benchmarks/monte_carlo_w1.json": (None, "att-mc campaigns/swift_demo.yaml --runs 50 --workers 1 --chunk 25 "
                                             "--no-figures --out /tmp/mc_w1 --json benchmarks/monte_carlo_w1.json"),
    "benchmarks/monte_carlo_w2.json": (None, "att-mc campaigns/swift_demo.yaml --runs 50 --workers 2 --chunk 25 "
                                             "--no-figures --out /tmp/mc_w2 --json benchmarks/monte_carlo_w2.json"),
    "benchmarks/schedule_B_prove.json": ("experiment B, --prove", "att-bench schedule --experiment B --prove "
                                                                  "--json benchmarks/schedule_B_prove.json"),
    "benchmarks/schedule_C_prove.json": ("experiment C, --prove", "att-bench schedule --experiment C --prove "
                                                                  "--json benchmarks/schedule_C_prove.json"),
    "benchmarks/schedule_A_exhaustive.json": (
        "experiment A, all 720 orders",
        "att-bench schedule --experiment A --prove --exhaustive --grid-study 8,16,24,48 --substeps 2 "
        "--json benchmarks/schedule_A_exhaustive.json"),
    "benchmarks/time_optimal_ba1.json": (None, "att-bench time-optimal --case ba1 --sweep --json "
                                               "benchmarks/time_optimal_ba1.json"),
    "benchmarks/time_optimal_ba2.json": (None, "att-bench time-optimal --case ba2 --sweep --json "
                                               "benchmarks/time_optimal_ba2.json"),
    "benchmarks/momentum.json": (None, "att-bench momentum --in-process --orbits 15 --out bench_out/momentum "
                                       "--json benchmarks/momentum.json"),
    "benchmarks/estimation_swift_demo.json": (None, "att-bench estimation "
                                                    "--json benchmarks/estimation_swift_demo.json"),
}
AB = re.compile(r"benchmarks/monte_carlo_ab_(?P<code>[0-9a-f]{7,})_(?P<round>\d+)\.json$")

# (study, payload of the study's keys, date, commit, load_1min, section of BENCHMARKS.md, command)
TEXT_RUNS = (
    ("gains", {"mode": "fixed", "kp": 237982.0, "kd": 69104475.0, "ts": 1.3136, "solve_seconds": 50.1},
     "2026-12-01T23:18:00Z", "1406361", 4.0, "gains (table 'Fixed IC (20)', row 'ours'; truth path 1.3136)",
     "att-bench gains --mode fixed --json out.json"),
    ("gains", {"mode": "robust", "kp": 162905.0, "kd": 117478623.0, "ts": 4.049, "solve_seconds": 572.0},
     "2026-11-22T00:53:14Z", "9e481ee", None, "gains (table 'Robust min-max over H', row 'ours'; load 5–10)",
     "att-bench gains --mode robust --json out.json"),
    ("gains", {"mode": "robust", "kp": 165498.0, "kd": 116003710.0, "ts": 3.910, "solve_seconds": 159.4},
     "2026-12-01T18:24:24Z", "758b9b3", None,
     "The architecture change ('gains robust', column 'after'; load 0.8–1.7)",
     "att-bench gains --mode robust --json out.json"),
    ("soak", {"orbits": 10.0, "dropped_state": 0, "exit_codes": {"simulator": 0, "controller": 0, "recorder": 0},
              "real_time_factor": 165.0, "state_messages": 56153, "settling_orbits": 1.990},
     "2026-11-22T01:28:00Z", "c5b5a78", 2.6, "soak (table)",
     "att-bench soak --orbits 10 --out bench_out/soak --json bench_out/soak.json"),
)
# time-optimal plans whose JSON was written to /tmp: (case, t_f TU, solve s or None, date, commit, section)
TEXT_TIME_OPTIMAL = (
    ("bilimoria_wie", 3.2431, 1.87, "2026-11-21T23:50:07Z", "e583415", "time-optimal (table; load ≈ 6)"),
    ("swift", 3.0661, 3.07, "2026-11-21T23:50:07Z", "e583415", "time-optimal (table; load ≈ 6)"),
    ("bilimoria_wie", 3.2434, None, "2026-12-04T22:38:04Z", "8d9ba7a",
     "Summary before and after 'one model, one implementation' (row 'time-optimal'; load 0.7–10.8)"),
    ("swift", 3.0682, None, "2026-12-04T22:38:04Z", "8d9ba7a",
     "Summary before and after 'one model, one implementation' (row 'time-optimal'; load 0.7–10.8)"),
)
# load of the kept JSONs that hold none, as BENCHMARKS.md gives it
TEXT_LOAD = {
    "benchmarks/monte_carlo.json": "1.5–2.1 (Monte Carlo)",
    "benchmarks/monte_carlo_w1.json": "1.6 (Monte Carlo)",
    "benchmarks/monte_carlo_w2.json": "1.6 (Monte Carlo)",
    "benchmarks/day.json": "2.7–3.5 (day)",
    "benchmarks/observe.json": "1.0–1.4 (observe)",
    "benchmarks/momentum.json": "0.7–10.8 (Summary before and after 'one model, one implementation')",
    "benchmarks/estimation_swift_demo.json": "0.7–10.8 (Summary before and after 'one model, one implementation')",
    "benchmarks/flood.json": "5–6 (flood)",
    "benchmarks/flood_160.json": "2.4–3.9 (flood)",
    "benchmarks/schedule_A.json": "0.3–1.6 (schedule)",
    "benchmarks/schedule_B.json": "0.3–1.6 (schedule)",
    "benchmarks/schedule_C.json": "0.3–1.6 (schedule)",
    "benchmarks/schedule_B_prove.json": "0.3–1.6 (schedule)",
    "benchmarks/schedule_C_prove.json": "0.3–1.6 (schedule)",
    "benchmarks/schedule_A_exhaustive.json": "0.3–1.6 (schedule)",
    "benchmarks/time_optimal_bp1.json": "2.5–2.6 (Melton's boundary cases)",
    "benchmarks/time_optimal_bp2.json": "2.5–2.6 (Melton's boundary cases)",
    "benchmarks/time_optimal_ba1.json": "1.5–4.0 (Melton's boundary cases)",
    "benchmarks/time_optimal_ba2.json": "3.0–4.0 (Melton's boundary cases)",
}


def git(*args: str) -> str:
    return subprocess.run(["git", *args], capture_output=True, text=True, check=True).stdout


def versions(path: str) -> list[tuple[str, str, str]]:
    """(full hash, short hash, commit date) of every commit that wrote ``path``, oldest first."""
    out = git("log", "--reverse", "--no-renames", "--format=%H %h %cI", "--diff-filter=AM", "--", path)
    rows = [row.split() for row in out.splitlines() if row.strip()]
    return [(full, short, datetime.fromisoformat(date).astimezone(UTC).strftime("%Y-%m-%dT%H:%M:%SZ"))
            for full, short, date in rows]


def json_lines(notes: list[str]) -> list[dict]:
    names = sorted({n for n in git("log", "--no-renames", "--format=", "--name-only", "--diff-filter=A", "--",
                                   "benchmarks/*.json").split() if n not in SKIP})
    rows = []
    for path in names:
        head_blob = git("ls-files", "-s", "--", path).split()[1] if git("ls-files", "--", path).strip() else None
        for full, short, date in versions(path):
            try:
                payload = json.loads(git("show", f"{full}:{path}"))
            except (subprocess.CalledProcessError, json.JSONDecodeError) as exc:
                notes.append(f"{path}@{short}: not read ({exc})")
                continue
            ab = AB.search(path)        # a per-commit A/B JSON is history only, never the kept figure
            kept = not ab and head_blob is not None and git("rev-parse", f"{full}:{path}").strip() == head_blob
            case, command = NAMED.get(path, (None, None))
            commit, source = short, "json" if kept else f"git show {short}:{path}"
            if ab:
                commit = ab["code"]
                case = f"{payload.get('requested')} runs, {payload.get('workers')} workers, A/B round {ab['round']}"
                command = (f"att-mc campaigns/swift_demo.yaml --runs {payload.get('requested')} --workers "
                           f"{payload.get('workers')} --no-figures --json {path}   # at {ab['code']}")
            if kept and path in TEXT_LOAD:
                load, section = TEXT_LOAD[path].split(" (", 1)
                source = f"the JSON; load {load} from BENCHMARKS.md at {TEXT_AT} ({section}"
            try:
                row = hist.line(payload, case=case, json_path=path if kept else None, command=command,
                                date=date, commit=commit, source=source)
            except hist.HistoryError as exc:
                notes.append(f"{path}@{short}: not summarised ({exc})")
                continue
            row["command"] = row["command"].replace("--json PATH", f"--json {path}")
            rows.append(row)
    return rows


def text_lines() -> list[dict]:
    rows = []
    for study, payload, date, commit, load, section, command in TEXT_RUNS:
        rows.append(hist.line(payload, study=study, json_path=None, command=command, date=date, commit=commit,
                              source=f"BENCHMARKS.md at {TEXT_AT}, {section}", load_1min=load))
    for case, tf, solve_s, date, commit, section in TEXT_TIME_OPTIMAL:
        metrics = {"tf": tf, "method": "time_optimal", "verified": True}
        if solve_s is not None:
            metrics["solve_s"] = solve_s
        rows.append({"study": "time-optimal", "case": case, "metric": "t_f, time-optimal plan", "value": tf,
                     "unit": "TU", "target": "a verified plan", "met": True, "metrics": metrics, "date": date,
                     "commit": commit, "machine": None, "load_1min": 6.0 if "≈ 6" in section else None,
                     "command": f"att-bench time-optimal --case {case} --json /tmp/to_{case}.json", "json": None,
                     "source": f"BENCHMARKS.md at {TEXT_AT}, {section}"})
    return rows


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--out", default=str(hist.HISTORY))
    args = parser.parse_args()
    notes: list[str] = []
    rows = json_lines(notes) + text_lines()
    rows.sort(key=lambda r: (r["date"][:19], r["study"], r["case"]))
    with open(args.out, "w"):
        pass
    for row in rows:
        hist.append(row, args.out)
    for note in notes:
        print(note, file=sys.stderr)
    print(f"{len(rows)} lines -> {args.out} ({len(notes)} versions not summarised)")
    return 0


if __name__ == "__main__":
    sys.exit(main())
