"""Soak run: the flight loop's nodes for a long sim time as fast as possible.

Starts the nodes of a scenario (recorder, simulator, the estimator when the scenario has a gyro,
controller) with the simulator's ``end_time_s`` set and ``real_time_factor`` 0, samples every
process's resident memory while it runs, then replays the log and counts messages against what the
configured rates imply. Reports the real-time factor reached (sim time over the wall time from the
simulator's first state to its ``end_time``). ``rate_Hz`` sets the step, the state, /clock, the
control and the estimate alike, as a mission does. With ``profile_dir`` every node runs under
cProfile and the report lists, per node, where its time went (:func:`profile_rows`); with
``cpu_dir`` every node's CPU is timed by layer (:mod:`att_planner.tools.cpu_layers`) and the
report gives, per node, each layer's CPU per second of sim time (:func:`cpu_rows`). Used by
``att-bench soak`` and by the tests (a shorter run). The lockstep waits up to ``LOCKSTEP_TIMEOUT`` s
for each command: a controller starved of CPU for half a second on a loaded machine is not what a
soak measures (the watchdog tests cover a dead one); every suspension of the lockstep is still
counted.
"""
from __future__ import annotations

import os
import time
from pathlib import Path

import numpy as np

from att_msgs_py.log import read_log
from att_msgs_py.topics import COMMAND, STATE
from att_planner.tools import cpu_layers
from att_planner.tools.launch import default_nodes, isolated_env, start_suite
from att_planner.tools.review.run import settling_time
from att_sim.models import scenario as scen

LOCKSTEP_TIMEOUT = 5.0
LOCKSTEP_SUSPENDED = "free-running at RTF"     # the simulator's warning when no command answered a state
READY_LINES = {"recorder": "recording ", "simulator": "scenario '", "controller": "scenario '",
               "estimator": "scenario '"}                                               # set up, logged once
END_LINE = "end_time reached"
PROFILE_ROWS = 15                 # per node, by own time


def rss_mib(pid: int) -> float:
    try:
        for line in Path(f"/proc/{pid}/status").read_text().splitlines():
            if line.startswith("VmRSS:"):
                return int(line.split()[1]) / 1024.0
    except FileNotFoundError:
        pass
    return float("nan")


def cpu_seconds(pid: int) -> float:
    """User plus system CPU time of process ``pid`` so far (s); NaN once it is gone."""
    try:
        fields = Path(f"/proc/{pid}/stat").read_text().rsplit(")", 1)[1].split()
    except (FileNotFoundError, IndexError):
        return float("nan")
    return (int(fields[11]) + int(fields[12])) / os.sysconf("SC_CLK_TCK")


def soak_nodes(scenario: str) -> tuple[str, ...]:
    """The flight loop of ``scenario``: :func:`~att_planner.tools.launch.default_nodes` without the planner."""
    return tuple(n for n in default_nodes(scenario) if n != "planner")


def run_soak(scenario: str, orbits: float | None, out_dir: str | Path, sample_period: float = 1.0,
             timeout: float = 3600.0, *, hours: float | None = None, rate_Hz: float | None = None,
             profile_dir: str | Path | None = None, cpu_dir: str | Path | None = None) -> dict:
    """Fly ``scenario`` for ``orbits`` orbits (or ``hours`` h) of sim time through its nodes as fast as
    they go; the figures of the module docstring. ``rate_Hz``: step, state, clock, control and
    estimate rate (default: the scenario's)."""
    s = scen.load(scenario)
    sim_params = {**s.node_params.get("simulator", {})}
    end_time = hours * 3600.0 if hours is not None else orbits * s.orbit_model.period
    out = Path(out_dir)
    nodes = soak_nodes(scenario)
    params = {"simulator": {"end_time_s": end_time, "real_time_factor": 0.0, "lockstep_timeout_s": LOCKSTEP_TIMEOUT}}
    if rate_Hz is not None:
        rates = {"step_s": 1.0 / rate_Hz, "publish_rate_Hz": rate_Hz, "clock_rate_Hz": rate_Hz}
        params = {"simulator": {**params["simulator"], **rates}, "controller": {"control_rate_Hz": rate_Hz},
                  "estimator": {"publish_rate_Hz": rate_Hz}}
        sim_params.update(rates)
    if profile_dir is not None and cpu_dir is not None:
        raise ValueError("a soak runs its nodes under cProfile (profile_dir) or timed by layer (cpu_dir), not both")
    for directory in (profile_dir, cpu_dir):
        if directory is not None:
            Path(directory).mkdir(parents=True, exist_ok=True)
    suite = start_suite(scenario, out / "soak.mcap", out, env=isolated_env(), nodes=nodes, params=params,
                        profile_dir=profile_dir, cpu_dir=cpu_dir)
    memory = {name: [] for name in suite.procs}
    cpu = {name: [] for name in suite.procs}
    start = time.monotonic()
    try:
        # memory is sampled once every node has started (its imports and set-up are not growth)
        for name in nodes:
            suite.wait_for_output(name, READY_LINES[name], max(timeout - (time.monotonic() - start), 0.0))
        while time.monotonic() - start < timeout:
            for name, proc in suite.procs.items():
                memory[name].append(rss_mib(proc.pid))
                cpu[name].append(cpu_seconds(proc.pid))
            if END_LINE in suite.log_text("simulator") or not all(suite.alive().values()):
                break
            time.sleep(sample_period)
        wall = time.monotonic() - start
    finally:
        codes = suite.stop()
    suspensions = suite.log_text("simulator").count(LOCKSTEP_SUSPENDED)
    log = read_log(out / "soak.mcap", topics=[STATE, COMMAND])
    state, command = log[STATE], log[COMMAND]
    sim_time = float(state["header.stamp"][-1])
    # the loop's own wall time: from the first state recorded to the last (start-up and shutdown excluded)
    received = state.log_time
    loop_wall = float(received[-1] - received[0])
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
    report = {"scenario": scenario, "orbits": sim_time / s.orbit_model.period, "hours": sim_time / 3600.0,
              "nodes": list(nodes), "rate_Hz": publish_rate, "sim_time": sim_time, "wall_seconds": wall,
              "loop_wall_seconds": loop_wall, "real_time_factor": sim_time / loop_wall,
              "state_messages": len(state), "state_expected": expected,
              "command_messages": len(command), "lockstep_suspensions": suspensions,
              "dropped_state": expected - len(state),
              "memory": growth, "exit_codes": codes, "settling_orbits": settling_orbits,
              "reached_end": sim_time >= end_time - 1.0 / publish_rate}
    # CPU each node used between its first sample (started) and its last (the end reached)
    report["cpu_seconds"] = {name: float(np.nanmax(c) - c[0]) if len(c) > 1 else 0.0 for name, c in cpu.items()}
    if profile_dir is not None:
        report["profile"] = {name: profile_rows(Path(profile_dir) / f"{name}.prof") for name in nodes}
    if cpu_dir is not None:
        report["cpu_layers"] = {name: cpu_rows(Path(cpu_dir) / f"{name}.json", sim_time) for name in nodes}
    return report


def cpu_rows(path: Path, sim_time: float) -> dict:
    """A node's CPU by layer (:func:`att_planner.tools.cpu_layers.read`) in ms per second of sim
    time: ``process`` (every thread), ``main_thread``, each layer's ms and calls per second of sim
    time, ``other (main thread)`` (the main thread's CPU outside the layers: the node's own code
    around them) and ``other threads`` (the middleware's); ``{}`` when the node wrote none."""
    if not path.is_file():
        return {}
    got = cpu_layers.read(path)
    per_s = 1e3 / sim_time
    layers = {name: {"ms_per_sim_s": v["cpu_s"] * per_s, "calls_per_sim_s": v["calls"] / sim_time}
              for name, v in sorted(got["layers"].items(), key=lambda kv: -kv[1]["cpu_s"])}
    inside = sum(v["cpu_s"] for v in got["layers"].values())
    return {"process_ms_per_sim_s": got["process_s"] * per_s, "main_thread_ms_per_sim_s": got["main_thread_s"] * per_s,
            "layers": layers, "other_main_thread_ms_per_sim_s": (got["main_thread_s"] - inside) * per_s,
            "other_threads_ms_per_sim_s": (got["process_s"] - got["main_thread_s"]) * per_s}


def profile_rows(path: Path, rows: int = PROFILE_ROWS) -> dict:
    """The functions of a node's cProfile file that took the most own time: total seconds, and per
    function its calls, own and cumulative seconds (``{}`` when the node wrote none)."""
    import pstats

    if not path.is_file():
        return {}
    stats = pstats.Stats(str(path)).stats
    top = sorted(stats.items(), key=lambda kv: kv[1][2], reverse=True)[:rows]
    return {"total_s": sum(v[2] for v in stats.values()),
            "functions": [{"function": f"{Path(f).name}:{line}({name})", "calls": int(v[1]),
                           "own_s": float(v[2]), "cumulative_s": float(v[3])} for (f, line, name), v in top]}
