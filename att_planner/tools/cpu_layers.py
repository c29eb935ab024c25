"""A node's CPU time by layer: run a node module with its layers' functions timed on the CPU clock.

``python -m att_planner.tools.cpu_layers OUT.json MODULE [node arguments]`` runs the node module
``MODULE`` (as ``python -m MODULE`` would) with the functions of each layer of :data:`LAYERS` wrapped:
each call's CPU time on the calling thread (:func:`time.thread_time`) is added to its layer; a call
made inside another timed call counts for the outer one only, so no CPU is counted twice. When the
node exits, ``OUT.json`` gets the process's CPU time (every thread's), the main thread's, and per
layer its CPU seconds and calls (:func:`read`), all counted from the first timed call: the node's
imports and set-up are not in them.

Unlike cProfile on the wall clock, what this reports is CPU the process spent: a publisher that the
scheduler preempts to run the subscriber it just woke (two cores, four processes) is not charged the
subscriber's time. The cost is two clock reads per timed call (about a microsecond), not one per
Python call, so the node runs at its own speed. ``att-bench soak --cpu DIR`` runs each node so.
"""
from __future__ import annotations

import atexit
import importlib
import json
import math
import runpy
import sys
import time
from pathlib import Path

# layer: the functions it times, "module:function" or "module:Class.method"; "module:*_msg" names the
# module's public functions whose names end in "_msg" (the "*_from_msg" ones too) and marker_array
COMMON = {
    "message conversion": ("att_msgs_py.convert:*_msg", "att_msgs_py.markers:*_msg"),
    "publish": ("rclpy.publisher:Publisher.publish",),
    "executor wait": ("rclpy.executors:Executor.wait_for_ready_callbacks",),
    "take": ("rclpy.executors:Executor._take_subscription",),
}
LAYERS = {
    "att_sim.truth.simulator_node": {
        "truth model": ("att_sim.truth.simulation:Simulation.advance", "att_sim.truth.simulation:Simulation.sense",
                        "att_sim.truth.simulation:Simulation.state"),
        "3D view": ("att_sim.models.scene:zone_views", "att_sim.models.scene:zone_margins",
                    "att_sim.models.scene:sky_shapes", "att_sim.models.scene:earth_fixed"),
    },
    "att_planner.nodes.estimator_node": {
        "estimator core": tuple(f"att_planner.estimation.estimator:Estimator.{name}" for name in (
            "on_gyro", "take_star_tracker", "take_magnetometer", "take_sun_sensors", "on_dipole_command",
            "take_report")),
    },
    "att_planner.nodes.controller_node": {
        "controller core": tuple(f"att_planner.control.controller:Controller.{name}"
                                 for name in ("accept_estimate", "accept_state", "step")),
    },
    "att_msgs_py.log.recorder_node": {
        "log write": ("att_msgs_py.log.writer:LogWriter.write",),
    },
}


OWN_WORK = frozenset(layer for layers in LAYERS.values() for layer in layers)    # each node's own job


PARTS = ("own work", "message conversion", "rclpy and DDS", "node code")


def parts(nodes: dict) -> dict[str, float]:
    """The CPU of the nodes of a soak timed by layer (node: its ``att_planner.tools.soak.cpu_rows``,
    ``{}`` for a node that wrote none), in ms per second of sim time, summed in :data:`PARTS`: the
    nodes' own work (:data:`OWN_WORK`), message conversion, rclpy and DDS (``publish``, take, the
    executor's wait, the middleware's threads) and the rest of the nodes' code. ValueError for a
    figure that is not a finite number."""
    def finite(value, what: str) -> float:
        if isinstance(value, bool) or not isinstance(value, int | float) or not math.isfinite(value):
            raise ValueError(f"{what} must be a finite number, found {value!r}")
        return float(value)

    split = dict.fromkeys(PARTS, 0.0)
    for name, node in nodes.items():
        if not node:
            continue
        for layer, row in node["layers"].items():
            part = "own work" if layer in OWN_WORK else layer if layer == "message conversion" else "rclpy and DDS"
            split[part] += finite(row["ms_per_sim_s"], f"{name}: {layer}")
        split["rclpy and DDS"] += finite(node["other_threads_ms_per_sim_s"], f"{name}: other threads")
        split["node code"] += finite(node["other_main_thread_ms_per_sim_s"], f"{name}: other (main thread)")
    return split


class _Clock:
    """CPU seconds and calls per layer; ``depth`` > 0 inside a timed call; ``start``: the process's
    and the main thread's CPU clocks at the first timed call (None before it)."""

    def __init__(self):
        self.layers: dict[str, list] = {}
        self.depth = 0
        self.start: tuple[float, float] | None = None

    def timed(self, layer: str, f):
        totals = self.layers.setdefault(layer, [0.0, 0])

        def wrapper(*args, **kwargs):
            if self.depth:
                return f(*args, **kwargs)
            if self.start is None:
                self.start = time.process_time(), time.thread_time()
            self.depth = 1
            start = time.thread_time()
            try:
                return f(*args, **kwargs)
            finally:
                self.depth = 0
                totals[0] += time.thread_time() - start
                totals[1] += 1
        wrapper.__wrapped__ = f
        return wrapper


def _targets(spec: str):
    """``(owner, attribute name)`` of each function ``spec`` names."""
    module_name, path = spec.split(":")
    owner = importlib.import_module(module_name)
    if path == "*_msg":
        return [(owner, n) for n in vars(owner) if not n.startswith("_") and callable(getattr(owner, n))
                and (n.endswith("_msg") or n == "marker_array")]
    *classes, name = path.split(".")
    for c in classes:
        owner = getattr(owner, c)
    return [(owner, name)]


def install(module: str, clock: _Clock) -> None:
    """Time the layers of node module ``module`` (and the common ones) with ``clock``."""
    for layer, specs in {**COMMON, **LAYERS.get(module, {})}.items():
        for spec in specs:
            for owner, name in _targets(spec):
                setattr(owner, name, clock.timed(layer, getattr(owner, name)))


def read(path: str | Path) -> dict:
    """A node's CPU by layer, as written at its exit: ``process_s``, ``main_thread_s`` and ``layers``
    (layer: ``{"cpu_s", "calls"}``)."""
    return json.loads(Path(path).read_text())


def main() -> None:
    if len(sys.argv) < 3:
        raise SystemExit("usage: python -m att_planner.tools.cpu_layers OUT.json MODULE [node arguments]")
    out, module = Path(sys.argv[1]), sys.argv[2]
    clock = _Clock()

    def write() -> None:
        start = clock.start or (time.process_time(), time.thread_time())
        out.write_text(json.dumps({
            "module": module, "process_s": time.process_time() - start[0],
            "main_thread_s": time.thread_time() - start[1],
            "layers": {k: {"cpu_s": v[0], "calls": v[1]} for k, v in clock.layers.items() if v[1]}}))
    install(module, clock)
    atexit.register(write)
    sys.argv = [module, *sys.argv[3:]]
    runpy.run_module(module, run_name="__main__", alter_sys=True)


if __name__ == "__main__":
    main()
