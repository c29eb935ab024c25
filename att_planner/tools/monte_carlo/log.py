"""The full log of one run (``att-mc rerun SEED --mcap PATH``): every message the nodes would
publish during the in-process run, plus the plan (:func:`att_planner.tools.loop_log.open_loop_log`).

Why in process and not through the nodes: the log is then of exactly the run whose row the
campaign's table holds (same cores, same seed, same order of events, bit for bit); over DDS the
same run differs by the scheduling of the nodes.
"""
from __future__ import annotations

from pathlib import Path

from att_planner.tools.loop_log import open_loop_log
from att_planner.tools.monte_carlo.run import Setup, fly


def write_run_log(setup: Setup, seed: int, path: Path, run: int = -1) -> dict:
    """Fly the run of seed ``seed`` with every message written to the MCAP at ``path``; its row."""
    log, tap = open_loop_log(path, setup.plan)
    try:
        return fly(setup, seed, run, tap=tap)
    finally:
        log.close()
