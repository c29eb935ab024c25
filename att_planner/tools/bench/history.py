"""history: one summary line per recorded run of a study, appended to ``benchmarks/history.jsonl``.

``att-bench history --append PATH [--study NAME] [--case NAME] [--command CMD]`` reads the JSON a
study wrote (``att-bench <study> --json PATH``, or ``att-mc ... --json PATH`` for the Monte Carlo
campaign), recognises the study from its keys (or takes ``--study``), and adds one line, in date
order (after the last line dated no later: runs that overlapped can be added in any order):

``study``, ``case``, ``metric`` (the headline figure's name), ``value`` and ``unit``, ``target`` (the
criterion in words) and ``met`` (``true``/``false``, ``null`` where the study states none),
``metrics`` (the other figures of the run), ``date`` (UTC) and ``commit`` (the run's, see :func:`run`),
``machine`` and ``load_1min`` (from the JSON when it holds them), ``command``, ``json`` (the file,
when it is kept in the repository) and ``source`` (where the figures were read).

Every figure of a line is read from the JSON; the criterion of each study is written once, in
:data:`att_planner.tools.bench.criteria.STUDIES`. ``att-bench summary`` renders BENCHMARKS.md's
summary table from the latest line of each study and case.
"""
from __future__ import annotations

import json
import os
import subprocess
from datetime import UTC, datetime
from pathlib import Path

from att_planner.tools.bench.criteria import BY_NAME, HistoryError, detect

HISTORY = Path("benchmarks") / "history.jsonl"
DATE_FORMAT = "%Y-%m-%dT%H:%M:%SZ"
FIELDS = ("study", "case", "metric", "value", "unit", "target", "met", "metrics", "date", "commit", "machine",
          "load_1min", "command", "json", "source")

def load_json(path: str | Path) -> dict:
    """A study's JSON object from ``path``, refused with a sentence when it is not one."""
    try:
        text = Path(path).read_text()
    except OSError as exc:
        raise HistoryError(f"{path}: cannot be read ({exc.strerror or exc})") from None
    try:
        payload = json.loads(text)
    except json.JSONDecodeError as exc:
        raise HistoryError(f"{path}: not JSON (line {exc.lineno}: {exc.msg})") from None
    if not isinstance(payload, dict):
        raise HistoryError(f"{path}: expected a JSON object, found {type(payload).__name__}")
    return payload


def machine_of(payload: dict) -> tuple[dict | None, float | None]:
    """The machine a JSON names and its 1-min load (at the end of the run when both ends are recorded)."""
    machine = payload.get("machine")
    if not isinstance(machine, dict):
        return None, None
    load = machine.get("load_1min")
    if load is None and isinstance(machine.get("load_after"), list) and machine["load_after"]:
        load = machine["load_after"][0]
    kept = {k: machine[k] for k in ("cores", "python", "omp_num_threads") if k in machine}
    return kept or None, (float(load) if isinstance(load, int | float) else None)


def line(payload: dict, *, study: str | None = None, case: str | None = None, json_path: str | None,
         command: str | None = None, date: str, commit: str | None, source: str,
         machine: dict | None = None, load_1min: float | None = None) -> dict:
    """The history line of one run: ``payload`` (a study's JSON) summarised and its provenance."""
    if study is not None and study not in BY_NAME:
        raise HistoryError(f"unknown study '{study}': expected one of {', '.join(BY_NAME)}")
    kind = BY_NAME[study] if study else detect(payload)
    s = kind.summarise(payload, case)
    json_machine, json_load = machine_of(payload)
    return {"study": kind.name, "case": s.case, "metric": s.metric, "value": s.value, "unit": s.unit,
            "target": s.target, "met": s.met, "metrics": s.metrics, "date": date, "commit": commit,
            "machine": json_machine or machine, "load_1min": json_load if json_load is not None else load_1min,
            "command": command or kind.command(payload, json_path or "PATH"), "json": json_path, "source": source}


def read(path: str | Path = HISTORY) -> list[dict]:
    """Every line of a history file, each checked to carry :data:`FIELDS`."""
    rows = []
    for n, text in enumerate(Path(path).read_text().splitlines(), 1):
        if not text.strip():
            continue
        try:
            row = json.loads(text)
        except json.JSONDecodeError as exc:
            raise HistoryError(f"{path}:{n}: not JSON ({exc.msg})") from None
        missing = [f for f in FIELDS if not isinstance(row, dict) or f not in row]
        if missing:
            raise HistoryError(f"{path}:{n}: a history line needs {', '.join(missing)}")
        rows.append(row)
    return rows


def append(row: dict, path: str | Path = HISTORY) -> None:
    """Add ``row`` as one JSON line (keys in :data:`FIELDS` order; NaN and infinity refused), after the
    last line dated no later than it: the history stays in date order when runs that overlapped are
    added in another order (a line that is not JSON, or a row without a date, stops the search)."""
    text = json.dumps({k: row[k] for k in FIELDS}, ensure_ascii=False, allow_nan=False)
    path = Path(path)
    lines = path.read_text().splitlines() if path.exists() else []
    at = len(lines)
    while at and isinstance(row["date"], str) and _date(lines[at - 1]) > row["date"]:
        at -= 1
    lines.insert(at, text)
    partial = path.with_name(path.name + ".partial")      # replaced whole: an interrupted write loses no line
    partial.write_text("".join(line + "\n" for line in lines))
    os.replace(partial, path)


def _date(text: str) -> str:
    """A history line's date ('' when it has none to compare)."""
    try:
        date = json.loads(text).get("date")
    except (json.JSONDecodeError, AttributeError):
        return ""
    return date if isinstance(date, str) else ""


def latest(rows: list[dict]) -> dict[tuple[str, str], dict]:
    """The last line of each (study, case), in the order the pairs first appear."""
    out: dict[tuple[str, str], dict] = {}
    for row in rows:
        out[(row["study"], row["case"])] = row
    return out


def head_commit() -> str | None:
    """The short hash of the checkout's HEAD (``+`` when the tree has changes), or ``None`` outside git."""
    try:
        commit = subprocess.run(["git", "rev-parse", "--short", "HEAD"], capture_output=True, text=True,
                                check=True).stdout.strip()
        dirty = subprocess.run(["git", "status", "--porcelain", "--untracked-files=no"], capture_output=True,
                               text=True, check=True).stdout.strip()
    except (OSError, subprocess.CalledProcessError):
        return None
    return commit + ("+" if dirty else "")


def configure(parser) -> None:
    parser.add_argument("--append", metavar="JSON", required=True, help="the JSON a study wrote")
    parser.add_argument("--study", choices=sorted(BY_NAME), help="the study that wrote it (default: from its keys)")
    parser.add_argument("--case", help="the case's name in the history (default: from the JSON)")
    parser.add_argument("--command", help="the command that wrote the JSON (default: the study's usual one)")
    parser.add_argument("--history", default=str(HISTORY), help="the history file (default: %(default)s)")
    parser.add_argument("--no-json", action="store_true", help="the JSON is not kept in the repository")


def run(args) -> int:
    """Append the summary line of ``args.append`` to ``args.history``; 2 with a sentence when refused.

    The line's date and commit are the run's when its JSON names them (``machine.date``,
    ``machine.commit``, written by ``att-bench``), else the time of the append and the checkout's HEAD.
    """
    try:
        payload = load_json(args.append)
        ran = payload.get("machine") if isinstance(payload.get("machine"), dict) else {}
        date = ran.get("date")
        if date is not None:
            try:
                datetime.strptime(date, DATE_FORMAT)
            except (TypeError, ValueError):
                raise HistoryError(f"'machine.date' must be a UTC time like 2026-12-05T01:26:04Z, "
                                   f"found {date!r}") from None
        row = line(payload, study=args.study, case=args.case, json_path=None if args.no_json else args.append,
                   command=args.command, date=date or datetime.now(UTC).strftime(DATE_FORMAT),
                   commit=ran.get("commit") or head_commit(), source="json")
        append(row, args.history)
    except (HistoryError, ValueError) as exc:
        print(f"att-bench history: {exc}")
        return 2
    met = {True: "met", False: "NOT met", None: "no target"}[row["met"]]
    print(f"{row['study']} {row['case']}: {row['metric']} {row['value']:.6g} {row['unit']} ({met}) -> {args.history}")
    return 0
