"""A campaign's report: the per-run table (CSV: one row per run, the applied dispersions then the
outcomes), the summary (JSON) and the figures (PNG, matplotlib's Agg backend): histograms of the
final attitude error, the minimum zone margin, the peak wheel speed and torque against their
limits and the settling time, and the outcome against the dispersion it ranks most with
(Spearman's rank correlation, |ρ| largest).
"""
from __future__ import annotations

import csv
import io
import math
import os
from pathlib import Path

import numpy as np

from att_msgs_py.errors import clip
from att_planner.tools.monte_carlo.run import OUTCOMES

STATISTICS = ("final_error_deg", "min_margin_deg", "peak_wheel_ratio", "peak_torque_ratio", "settling_time")
WORST = 10


def columns(rows: list[dict]) -> list[str]:
    """``run``, ``seed``, the applied values (first-seen order), then the outcomes."""
    names = ["run", "seed"]
    for row in rows:
        names += [k for k in row if k not in names and k not in OUTCOMES]
    return names + list(OUTCOMES)


def by_run(row: dict) -> int:
    """The sort key of rows: their run's index in the campaign."""
    return row["run"]


def text(row: dict) -> dict:
    """``row`` as the table writes it: floats as ``repr`` (17 significant digits: read back exactly)."""
    return {k: repr(v) if isinstance(v, float) else v for k, v in row.items()}


def write_table(rows: list[dict], path: Path) -> Path:
    """The rows, ordered by run, as CSV, written whole (a temporary file renamed over ``path``)."""
    path.parent.mkdir(parents=True, exist_ok=True)
    part = path.with_name(path.name + ".part")
    with open(part, "w", newline="") as fh:
        writer = csv.DictWriter(fh, fieldnames=columns(rows))
        writer.writeheader()
        writer.writerows(text(row) for row in sorted(rows, key=by_run))
    os.replace(part, path)
    return path


class Table:
    """A campaign's table as its rows come in: each chunk's rows appended and flushed (a client
    killed mid-campaign leaves every row it had received: ``att-mc --resume`` starts from them),
    rewritten whole in run order by :meth:`close`. ``rows``: the campaign's rows by run, the ones
    already in (a resumed campaign's) included; the table starts as exactly those."""

    def __init__(self, path: Path, rows: dict[int, dict]):
        self.path, self.rows = path, rows
        self.header = columns(list(rows.values())) if rows else []
        write_table(list(rows.values()), path)

    def add(self, new: list[dict]) -> None:
        """Append ``new`` (rows already in :attr:`rows`); a row with other columns than the table's
        rewrites the table with the new columns."""
        if any(set(row) != set(self.header) for row in new):
            self.header = columns(list(self.rows.values()))
            write_table(list(self.rows.values()), self.path)
            return
        with open(self.path, "a", newline="") as fh:
            csv.DictWriter(fh, fieldnames=self.header).writerows(text(row) for row in new)

    def close(self) -> Path:
        """The table rewritten in run order."""
        return write_table(list(self.rows.values()), self.path)


TEXT_COLUMNS = {"run": int, "seed": int, "code": int, "success": {"True": True, "False": False}.__getitem__,
                "reason": str}


def read_table(path: Path) -> list[dict]:
    """The rows of a table (:func:`write_table`, :class:`Table`), typed back: ``run``, ``seed`` and
    ``code`` int, ``success`` bool, ``reason`` str, every other column float. A last line without
    its newline (a write cut short) is left out; a table without the columns of a campaign's, or a
    line with a missing or unreadable field, is a ValueError naming the line and the column."""
    content = path.read_text()
    if not content.endswith("\n"):
        content = content[:content.rfind("\n") + 1]
    reader = csv.DictReader(io.StringIO(content, newline=""))
    missing = [name for name in ("run", "seed", *OUTCOMES) if name not in (reader.fieldnames or [])]
    if missing:
        raise ValueError(f"{path}: not a campaign's table: no column {', '.join(missing)} in its header")
    rows = []
    for row in reader:
        if None in row or None in row.values():
            found = sum(v is not None for k, v in row.items() if k is not None) + len(row.get(None) or [])
            raise ValueError(f"{path}: line {reader.line_num}: {found} fields, expected the header's "
                             f"{len(reader.fieldnames)}")
        typed = {}
        for key, value in row.items():
            try:
                typed[key] = TEXT_COLUMNS.get(key, float)(value)
            except (KeyError, ValueError):
                raise ValueError(f"{path}: line {reader.line_num}: column {key}: expected "
                                 f"{'True or False' if key == 'success' else 'a number'}, found {clip(value, 40)!r}"
                                 ) from None
        rows.append(typed)
    return rows


def resumed(path: Path, runs: list[tuple[int, int]]) -> dict[int, dict]:
    """The rows of the table at ``path`` a resumed campaign keeps, by run (none when there is no
    table): each must be one of ``runs`` (``(run, seed)`` pairs) with its seed, once — else a
    ValueError naming the line (a table of another campaign, seed or run count)."""
    if not path.is_file():
        return {}
    seeds, kept = dict(runs), {}
    for line, row in enumerate(read_table(path), start=2):
        run, seed = row["run"], row["seed"]
        if run not in seeds:
            raise ValueError(f"{path}: line {line}: run {run} is not a run of this campaign "
                             f"(runs 0 to {len(runs) - 1})")
        if seed != seeds[run]:
            raise ValueError(f"{path}: line {line}: run {run} has seed {seed}, this campaign's run {run} has seed "
                             f"{seeds[run]} (a table of another campaign?)")
        if run in kept:
            raise ValueError(f"{path}: line {line}: run {run} a second time")
        kept[run] = row
    return kept


def statistics(values) -> dict:
    """Mean, median, 99th percentile, min and max of the finite values (NaN-free; None when none)."""
    v = np.asarray(values, float)
    v = v[np.isfinite(v)]
    if v.size == 0:
        return {"mean": None, "p50": None, "p99": None, "min": None, "max": None, "count": 0}
    return {"mean": float(v.mean()), "p50": float(np.percentile(v, 50)), "p99": float(np.percentile(v, 99)),
            "min": float(v.min()), "max": float(v.max()), "count": int(v.size)}


def applied(rows: list[dict]) -> list[str]:
    return [k for k in columns(rows) if k not in ("run", "seed") and k not in OUTCOMES]


def ranks(x: np.ndarray) -> np.ndarray:
    """Ranks 0..n−1 (average ranks are not needed: continuous draws do not tie)."""
    r = np.empty(x.size)
    r[np.argsort(x, kind="stable")] = np.arange(x.size)
    return r


def rank_correlations(rows: list[dict], outcome: str = "final_error_deg") -> dict[str, float]:
    """Spearman's ρ of ``outcome`` with every applied dispersion (runs with a finite outcome; in run
    order, whatever order the rows came back in)."""
    rows = sorted(rows, key=by_run)
    y = np.array([r[outcome] for r in rows], float)
    keep = np.isfinite(y)
    out = {}
    if keep.sum() < 3:
        return out
    ry = ranks(y[keep])
    for name in applied(rows):
        x = np.array([r.get(name, math.nan) for r in rows], float)[keep]
        if np.all(np.isfinite(x)) and np.ptp(x) > 0:
            out[name] = float(np.corrcoef(ranks(x), ry)[0, 1])
    return out


def plain(value):
    """``value`` for strict JSON: a non-finite float becomes None (no margin without zones, a run
    that never settled)."""
    return value if not isinstance(value, float) or math.isfinite(value) else None


def worst(rows: list[dict], count: int = WORST) -> list[dict]:
    """The failed runs first, then the largest final errors: run, seed and outcomes."""
    def badness(r):
        return (bool(r["success"]), -np.nan_to_num(r["final_error_deg"], nan=np.inf))
    return [{k: plain(r[k]) for k in ("run", "seed", *OUTCOMES) if k != "cpu_seconds"}
            for r in sorted(rows, key=badness)[:count]]


def summary(rows: list[dict], *, runs: int, wall: float, workers: int, table: Path, figures: list[str],
            interrupted: bool, campaign: str, scenario: str, plan: dict, resumed: int = 0) -> dict:
    """The campaign's summary (the JSON ``att-mc --json`` writes): of the rows in run order, so the
    same runs give the same figures whatever order they finished in. ``resumed``: rows taken from
    the table of an earlier, interrupted session (``wall`` and the rate are of the runs flown in this one)."""
    rows = sorted(rows, key=by_run)
    n = len(rows)
    correlations = rank_correlations(rows)
    top = max(correlations, key=lambda k: abs(correlations[k])) if correlations else None
    return {
        "campaign": campaign, "scenario": scenario, "plan": plan,
        "runs": n, "requested": runs, "interrupted": interrupted, "resumed": resumed,
        "wall_seconds": wall, "workers": workers, "runs_per_second": (n - resumed) / wall if wall > 0 else None,
        "cpu_seconds_per_run": statistics([r["cpu_seconds"] for r in rows]),
        "success_rate": sum(bool(r["success"]) for r in rows) / n if n else None,
        **{name: statistics([r[name] for r in rows]) for name in STATISTICS},
        "dispersions": {k: {"mean": float(np.mean(v)), "std": float(np.std(v, ddof=1)) if len(v) > 1 else None}
                        for k in applied(rows) for v in [[r[k] for r in rows if k in r]]},
        "rank_correlation_final_error": correlations, "most_influential": top,
        "worst": worst(rows), "table": str(table), "figures": figures,
    }


def figures(rows: list[dict], out: Path, top: str | None) -> list[str]:
    """The histograms and the scatter of the final error against ``top`` as PNG files in ``out``."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    out.mkdir(parents=True, exist_ok=True)
    panels = (("final_error_deg", "final attitude error (deg)", None),
              ("min_margin_deg", "minimum zone margin (deg)", 0.0),
              ("peak_wheel_ratio", "peak wheel speed / limit", 1.0),
              ("peak_torque_ratio", "peak wheel torque / limit", 1.0),
              ("settling_time", "settling time after the plan (s)", None))
    fig, axes = plt.subplots(1, len(panels), figsize=(4 * len(panels), 3.2))
    for ax, (name, label, limit) in zip(axes, panels):
        v = np.array([r[name] for r in rows], float)
        ax.hist(v[np.isfinite(v)], bins=30, color="tab:blue")
        if limit is not None:
            ax.axvline(limit, color="tab:red", lw=1)
        ax.set_xlabel(label)
        ax.set_ylabel("runs")
    fig.tight_layout()
    paths = [out / "histograms.png"]
    fig.savefig(paths[0], dpi=100)
    plt.close(fig)
    if top is not None:
        fig, ax = plt.subplots(figsize=(5, 4))
        ok = np.array([bool(r["success"]) for r in rows])
        x = np.array([r[top] for r in rows], float)
        y = np.array([r["final_error_deg"] for r in rows], float)
        ax.scatter(x[ok], y[ok], s=6, label="success")
        ax.scatter(x[~ok], y[~ok], s=12, color="tab:red", label="failure")
        ax.set_xlabel(top)
        ax.set_ylabel("final attitude error (deg)")
        ax.legend()
        fig.tight_layout()
        paths.append(out / "influence.png")
        fig.savefig(paths[-1], dpi=100)
        plt.close(fig)
    return [str(p) for p in paths]
