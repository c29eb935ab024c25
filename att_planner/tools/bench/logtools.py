"""logtools: each log tool on 40 damaged or hostile MCAP files — time, memory, lines, exit code.

``att-bench logtools [--case NAME ...] [--tool NAME ...] [--keep DIR] --json PATH`` makes the files of
:mod:`.hostile_logs` from a 5 s recording of swift_demo's closed loop (cuts, flipped bytes in every
kind of record, decompression bombs, hostile names) and runs ``att-log info``, ``att-log repair``,
``att-review`` and ``att-replay`` (``--rate 0 --wait 0 --linger 0``, on a random ROS domain with
localhost-only discovery) as a subprocess on each, one at a time. Per run: the wall time, the peak
resident memory of that child alone (``os.wait4``), the lines on stdout and stderr and the exit code.

The criterion, per run: exit code among those the tool documents for the kind of file (below); at
most one line on stderr, exactly one for a refusal (``att-log info`` answers in its report, whose
status line names the offset); for a cut, flipped or bomb file refused, the byte offset named (but
for ``att-review``'s "the log has no ... messages to review" of a cut file: its readable part holds no
run, a refusal about content); no
traceback; no raw control character from the file reaching the terminal; a schema name never
imported (the module ``this`` prints the Zen of Python when imported); peak RSS <= 256 MB; wall time
<= 2 s, except for a review ``att-review`` completed on the readable part of a file (it draws its
figures; its time is reported). The exit status is 1 when a run fails the criterion.

Exit codes documented, per kind of file (``cut``: the file ends early; ``flip``: a damaged record;
``bomb``: a chunk that inflates or claims too much; ``name``: a whole file with hostile names):

* ``att-log info``: 0 only for a complete, indexed file (a ``name`` file), 1 for a file that needs
  repair (cut or damaged), 2 for one that is not MCAP;
* ``att-log repair``: 0 when a cut file's whole records were written out (a cut is what it
  repairs) or a ``name`` file copied, 1 when written but the input held a damaged record, 2 when
  nothing can be recovered;
* ``att-review``: 0 when the readable part of a cut file (or a ``name`` file) holds a run it
  reviews, 1 when it refuses the file;
* ``att-replay``: 0 when it replays the readable part of a cut file (or a ``name`` file whose names
  it accepts), 2 when it refuses the file or a name.
"""
from __future__ import annotations

import json
import os
import platform
import re
import shutil
import subprocess
import sys
import tempfile
import time
from pathlib import Path

from att_planner.tools.bench import hostile_logs

TIME_LIMIT = 2.0              # s
RSS_LIMIT_MB = 256.0
HARD_TIMEOUT = 30.0           # s: a run still going is killed (and fails)
ZEN = "Beautiful is better than ugly"
# att-review's refusal of a file read whole up to its cut that holds no run: about content, not damage
NOTHING_TO_REVIEW = re.compile(r"^att-review: the log has no \S+ messages to review$", re.M)
TOOLS = {
    "att-log info": lambda f, out: ["att-log", "info", str(f)],
    "att-log repair": lambda f, out: ["att-log", "repair", str(f), "-o", str(out / "repaired.mcap")],
    "att-review": lambda f, out: ["att-review", str(f), "--out", str(out / "review")],
    "att-replay": lambda f, out: ["att-replay", str(f), "--rate", "0", "--wait", "0", "--linger", "0"],
}
ALLOWED = {     # tool -> kind -> exit codes documented for that kind of file
    "att-log info": {"cut": {1, 2}, "flip": {1, 2}, "bomb": {1, 2}, "name": {0}},
    "att-log repair": {"cut": {0, 2}, "flip": {1, 2}, "bomb": {1, 2}, "name": {0}},
    "att-review": {"cut": {0, 1}, "flip": {1}, "bomb": {1}, "name": {0, 1}},
    "att-replay": {"cut": {0, 2}, "flip": {2}, "bomb": {2}, "name": {0, 2}},
}


def configure(parser) -> None:
    names = [c.name for c in hostile_logs.CASES]
    parser.add_argument("--case", action="append", choices=names, metavar="NAME",
                        help="a file of the study (repeatable; default: all 40)")
    parser.add_argument("--tool", action="append", choices=list(TOOLS), help="a tool (repeatable; default: all 4)")
    parser.add_argument("--keep", default=None, help="make the files in this directory and keep them")


def raw_control(text: str) -> bool:
    """A C0 (but newline or tab), DEL or C1 character: one the tool should have escaped."""
    return any((ord(c) < 0x20 and c not in "\n\t") or 0x7f <= ord(c) < 0xa0 for c in text)


# Runs the tool from a lean Python (a few MB): a child's peak RSS (ru_maxrss) counts the memory of
# the process it was forked from until its exec, and this study's own process holds ~150 MB.
PROBE = """
import json, os, subprocess, sys, threading, time
limit, out, err, argv = float(sys.argv[1]), sys.argv[2], sys.argv[3], sys.argv[4:]
with open("/proc/self/statm") as statm:      # this process's resident size now: the child's floor
    parent_kb = int(statm.read().split()[1]) * os.sysconf("SC_PAGE_SIZE") // 1024
with open(out, "wb") as o, open(err, "wb") as e:
    start = time.monotonic()
    proc = subprocess.Popen(argv, stdout=o, stderr=e, stdin=subprocess.DEVNULL)
    killer = threading.Timer(limit, proc.kill)
    killer.start()
    _, status, usage = os.wait4(proc.pid, 0)
    killer.cancel()
    wall = time.monotonic() - start
print(json.dumps([os.waitstatus_to_exitcode(status), wall, usage.ru_maxrss, parent_kb]))
"""


def measure(argv: list[str], env: dict, cwd: Path) -> dict:
    """Run ``argv`` alone from a lean parent (:data:`PROBE`): wall time, peak RSS of that child
    (``os.wait4``; the parent's RSS at the fork, ``parent_rss_mb``, is its floor), output, exit code."""
    out_path, err_path = cwd / "stdout.txt", cwd / "stderr.txt"
    probe = subprocess.run([sys.executable, "-I", "-c", PROBE, str(HARD_TIMEOUT), str(out_path), str(err_path), *argv],
                           env=env, cwd=cwd, capture_output=True, text=True, timeout=HARD_TIMEOUT + 30, check=True)
    code, wall, rss_kb, parent_kb = json.loads(probe.stdout)
    stdout = out_path.read_bytes().decode("utf-8", "replace")
    stderr = err_path.read_bytes().decode("utf-8", "replace")
    return {"exit": code, "wall_s": wall, "max_rss_mb": rss_kb / 1024.0, "parent_rss_mb": parent_kb / 1024.0,
            "stdout_lines": len(stdout.splitlines()), "stderr_lines": len(stderr.splitlines()),
            "killed": wall >= HARD_TIMEOUT and code < 0, "stdout": stdout[-2000:], "stderr": stderr[-2000:]}


def judge(tool: str, kind: str, run: dict) -> list[str]:
    """What ``run`` fails of the criterion (module docstring), as short phrases."""
    failed, code = [], run["exit"]
    text = run["stdout"] + run["stderr"]
    if code not in ALLOWED[tool][kind]:
        failed.append(f"exit {code} (documented {sorted(ALLOWED[tool][kind])})")
    if run["stderr_lines"] > 1 or (code != 0 and run["stderr_lines"] != 1 and tool != "att-log info"):
        failed.append(f"{run['stderr_lines']} lines on stderr")
    if code != 0 and kind != "name" and "byte" not in text and not NOTHING_TO_REVIEW.search(text):
        failed.append("no byte offset named")
    if "Traceback" in text:
        failed.append("traceback")
    if raw_control(text):
        failed.append("raw control characters printed")
    if ZEN in text:
        failed.append("imported a module the file named")
    if run["max_rss_mb"] > RSS_LIMIT_MB:
        failed.append(f"peak RSS {run['max_rss_mb']:.0f} MB")
    if run["killed"]:
        failed.append(f"killed after {HARD_TIMEOUT:g} s")
    elif run["wall_s"] > TIME_LIMIT and not (tool == "att-review" and code == 0):
        failed.append(f"{run['wall_s']:.2f} s")
    return failed


def tool_env() -> dict:
    """This environment on a random ROS domain, localhost discovery, this checkout first on the path."""
    from att_planner.tools.launch import isolated_env

    env = isolated_env()
    root = str(Path(__file__).resolve().parents[3])
    env["PYTHONPATH"] = os.pathsep.join([root, *filter(None, [env.get("PYTHONPATH")])])
    env.setdefault("OMP_NUM_THREADS", "1")
    return env


def summarise(runs: list[dict], tool: str) -> dict:
    mine = [r for r in runs if r["tool"] == tool]
    answers = [r for r in mine if not (tool == "att-review" and r["exit"] == 0)]
    return {"runs": len(mine), "worst_wall_s": max((r["wall_s"] for r in answers), default=None),
            "worst_wall_all_s": max(r["wall_s"] for r in mine), "worst_rss_mb": max(r["max_rss_mb"] for r in mine),
            "max_stdout_lines": max(r["stdout_lines"] for r in mine),
            "max_stderr_lines": max(r["stderr_lines"] for r in mine),
            "exit_codes": sorted({r["exit"] for r in mine}),
            "exit_codes_by_kind": {k: sorted({r["exit"] for r in mine if r["kind"] == k})
                                   for k in dict.fromkeys(r["kind"] for r in mine)},
            "failures": [{"case": r["case"], "failed": r["failed"]} for r in mine if r["failed"]]}


def _print(summary: dict, tools: list[str], load: tuple) -> None:
    print(f"logtools: {summary['files']} files x {len(tools)} tools; load {load[0]:.2f} on {os.cpu_count()} cores; "
          f"criterion: documented exit, one line, byte offset, <= {TIME_LIMIT:g} s, <= {RSS_LIMIT_MB:g} MB")
    head = f"{'tool':<16}{'worst s':>9}{'worst MB':>10}{'out/err':>9}  {'exit codes by kind':<44}{'failed':>7}"
    print(head)
    print("-" * len(head))
    for tool in tools:
        s = summary["tools"][tool]
        codes = " ".join(f"{k}:{','.join(map(str, v))}" for k, v in s["exit_codes_by_kind"].items())
        worst = "-" if s["worst_wall_s"] is None else f"{s['worst_wall_s']:.2f}"
        print(f"{tool:<16}{worst:>9}{s['worst_rss_mb']:10.1f}{s['max_stdout_lines']:>5}/{s['max_stderr_lines']:<3}"
              f"  {codes:<44}{len(s['failures']):>7}")
        if tool == "att-review":
            print(f"{'':<16}(worst s: refusals; reviews completed on a readable part took up to "
                  f"{s['worst_wall_all_s']:.2f} s)")
        for f in s["failures"]:
            print(f"{'':<4}FAIL {f['case']}: {'; '.join(f['failed'])}")
    print("documented exits: " + "; ".join(f"{t} " + ", ".join(f"{k} {sorted(v)}" for k, v in ALLOWED[t].items())
                                           for t in tools))


def run(args) -> dict:
    started, load_before = time.perf_counter(), os.getloadavg()
    cases = [c for c in hostile_logs.CASES if not args.case or c.name in args.case]
    tools = [t for t in TOOLS if not args.tool or t in args.tool]
    bin_dir = Path(sys.executable).parent
    env = tool_env()
    where = Path(args.keep) if args.keep else Path(tempfile.mkdtemp(prefix="att_logtools_"))
    where.mkdir(parents=True, exist_ok=True)
    runs = []
    try:
        made = time.perf_counter()
        source, files = hostile_logs.make_files(where, cases)
        made, source_bytes = time.perf_counter() - made, source.stat().st_size
        for case in cases:
            for tool in tools:
                out = Path(tempfile.mkdtemp(prefix="run_", dir=where))
                argv = TOOLS[tool](files[case.name], out)
                r = measure([str(bin_dir / argv[0]), *argv[1:]], env, out)
                r.update(case=case.name, kind=case.kind, tool=tool, file=files[case.name].name,
                         size=files[case.name].stat().st_size)
                r["failed"] = judge(tool, case.kind, r)
                runs.append(r)
                shutil.rmtree(out, ignore_errors=True)
    finally:
        if not args.keep:
            shutil.rmtree(where, ignore_errors=True)
    summary = {"files": len(cases), "tools": {t: summarise(runs, t) for t in tools}}
    _print(summary, tools, load_before)
    failed = [f"{t}: {f['case']}" for t in tools for f in summary["tools"][t]["failures"]]
    print(f"criterion: {'met by every run' if not failed else f'{len(failed)} runs failed'}")
    return {**summary, "runs": runs, "cases": [{"name": c.name, "kind": c.kind} for c in cases],
            "allowed_exits": {t: {k: sorted(v) for k, v in ALLOWED[t].items()} for t in tools},
            "limits": {"wall_s": TIME_LIMIT, "rss_mb": RSS_LIMIT_MB, "hard_timeout_s": HARD_TIMEOUT},
            "source": {"scenario": "swift_demo", "seconds": hostile_logs.SOURCE_SECONDS,
                       "bytes": source_bytes, "make_seconds": made},
            "failed": failed, "passed": not failed,
            "machine": {"cores": os.cpu_count(), "load_before": list(load_before), "load_after": list(os.getloadavg()),
                        "python": platform.python_version(), "nice": os.nice(0),
                        "wall_seconds": time.perf_counter() - started}}
