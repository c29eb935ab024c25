"""Soak run: simulator + controller (+ recorder) for a long sim time as fast as possible.

Starts the nodes of a scenario with the simulator's ``end_time_s`` set, samples every process's
resident memory while it runs, then replays the log and counts messages against what the
configured rates imply. Reports the real-time factor reached. Used by ``att-bench soak`` (10
orbits) and by the tests (a shorter run). The lockstep waits up to ``LOCKSTEP_TIMEOUT`` s for each
command: a controller starved of CPU for half a second on a loaded machine is not what a soak
measures (the watchdog tests cover a dead one); every suspension of the lockstep is still counted.
"""
from __future__ import annotations

import time
from pathlib import Path

import numpy as np

from att_msgs_py.log import read_log
from att_msgs_py.topics import COMMAND, STATE
from att_planner.tools.launch import isolated_env, start_suite
from att_planner.tools.review.run import settling_time
from att_sim.models import scenario as scen

LOCKSTEP_TIMEOUT = 5.0
LOCKSTEP_SUSPENDED = "free-running at RTF"     # the simulator's warning when no command answered a state
READY_LINES = {"recorder": "recording ", "simulator": "scenario '", "controller": "scenario '"}   # set up, logged once


def rss_mib(pid: int) -> float:
    try:
        for line in Path(f"/proc/{pid}/status").read_text().splitlines():
            if line.startswith("VmRSS:"):
                return int(line.split()[1]) / 1024.0
    except FileNotFoundError:
        pass
    return float("nan")


def run_soak(scenario: str, orbits: float, out_dir: str | Path, sample_period: float = 1.0,
             timeout: float = 3600.0) -> dict:
    s = scen.load(scenario)
    sim_params = s.node_params.get("simulator", {})
    end_time = orbits * s.orbit_model.period
    out = Path(out_dir)
    suite = start_suite(scenario, out / "soak.mcap", out, env=isolated_env(),
                        nodes=("recorder", "simulator", "controller"),
                        params={"simulator": {"end_time_s": end_time, "real_time_factor": 0.0,
                                                      "lockstep_timeout_s": LOCKSTEP_TIMEOUT}})
    memory = {name: [] for name in suite.procs}
    start = time.monotonic()
    try:
        # memory is sampled once every node has started (its imports and set-up are not growth)
        for name, line in READY_LINES.items():
            suite.wait_for_output(name, line, max(timeout - (time.monotonic() - start), 0.0))
        while time.monotonic() - start < timeout:
            for name, proc in suite.procs.items():
                memory[name].append(rss_mib(proc.pid))
            if "end_time reached" in suite.log_text("simulator") or not all(suite.alive().values()):
                break
            time.sleep(sample_period)
        wall = time.monotonic() - start
    finally:
        codes = suite.stop()
    suspensions = suite.log_text("simulator").count(LOCKSTEP_SUSPENDED)
    log = read_log(out / "soak.mcap", topics=[STATE, COMMAND])
    state, command = log[STATE], log[COMMAND]
    sim_time = float(state["header.stamp"][-1])
    publish_rate = float(sim_params.get("publish_rate_Hz", 10.0))
    expected = int(np.floor(sim_time * publish_rate + 1e-6)) + 1          # t = 0, 1/rate, ..., sim_time
    growth = {}
    for name, series in memory.items():
        series = np.asarray(series)
        n = len(series)
        growth[name] = {"start_mib": float(np.nanmean(series[n // 4: n // 2])) if n >= 4 else float(series[0]),
                        "end_mib": float(np.nanmean(series[-max(1, n // 4):]))}
    settled_at = settling_time(state["header.stamp"], state["attitude"])       # None: not within the run
    settling_orbits = None if settled_at is None else settled_at / s.orbit_model.period
    return {"scenario": scenario, "orbits": orbits, "sim_time": sim_time, "wall_seconds": wall,
            "real_time_factor": sim_time / wall, "state_messages": len(state), "state_expected": expected,
            "command_messages": len(command), "lockstep_suspensions": suspensions,
            "dropped_state": expected - len(state),
            "memory": growth, "exit_codes": codes, "settling_orbits": settling_orbits,
            "reached_end": sim_time >= end_time - 1.0 / publish_rate}
