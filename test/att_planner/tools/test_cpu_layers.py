"""att_planner.tools.cpu_layers: a call inside a timed call counts for the outer layer only; a node
module run through it writes each layer's CPU and calls at exit, from the first timed call on; the
soak's summary splits the nodes' CPU into parts that add up to it."""
import json
import math
import os
import subprocess
import sys
import time

import pytest

from att_planner.tools import cpu_layers
from att_planner.tools.bench import criteria
from att_planner.tools.soak import cpu_rows


def busy(seconds: float) -> None:
    end = time.thread_time() + seconds
    while time.thread_time() < end:
        pass


def test_a_nested_timed_call_counts_for_the_outer_layer_only():
    clock = cpu_layers._Clock()
    inner = clock.timed("inner", busy)
    outer = clock.timed("outer", lambda: inner(0.02) or busy(0.01))
    outer()
    inner(0.01)
    (outer_s, outer_calls), (inner_s, inner_calls) = clock.layers["outer"], clock.layers["inner"]
    assert (outer_calls, inner_calls) == (1, 1)
    assert 0.03 <= outer_s < 0.03 + 0.02 and 0.01 <= inner_s < 0.01 + 0.02
    assert clock.start is not None and clock.depth == 0


def test_a_module_run_through_it_writes_its_layers_at_exit(tmp_path):
    (tmp_path / "fake_node.py").write_text(
        "import sys\n"
        "from att_msgs_py import convert\n"
        "assert sys.argv[1:] == ['--ros-args', '-p', 'x:=1'], sys.argv\n"
        "for k in range(7):\n"
        "    convert.time_msg(1.5 + k)\n")
    out = tmp_path / "fake.json"
    done = subprocess.run([sys.executable, "-m", "att_planner.tools.cpu_layers", str(out), "fake_node",
                           "--ros-args", "-p", "x:=1"], cwd=tmp_path, capture_output=True, text=True, timeout=120,
                          env={**os.environ, "PYTHONPATH": str(tmp_path)})
    assert done.returncode == 0, done.stderr
    got = cpu_layers.read(out)
    assert got["module"] == "fake_node" and got["layers"]["message conversion"]["calls"] == 7
    assert set(got["layers"]) == {"message conversion"}            # layers never called are left out
    assert 0 <= got["layers"]["message conversion"]["cpu_s"] <= got["main_thread_s"] <= got["process_s"]


def test_without_a_module_it_says_how_to_call_it():
    done = subprocess.run([sys.executable, "-m", "att_planner.tools.cpu_layers"], capture_output=True, text=True,
                          timeout=120)
    assert done.returncode != 0 and "usage: python -m att_planner.tools.cpu_layers OUT.json MODULE" in done.stderr


def test_the_soak_summary_splits_every_nodes_cpu_into_four_parts_that_add_up(tmp_path):
    def node(name, process, main, layers):
        path = tmp_path / f"{name}.json"
        path.write_text(json.dumps({"module": name, "process_s": process, "main_thread_s": main,
                                    "layers": {k: {"cpu_s": v, "calls": 3} for k, v in layers.items()}}))
        return cpu_rows(path, sim_time=10.0)

    p = {"dropped_state": 0, "exit_codes": {}, "rtf_target": 50.0, "real_time_factor": 20.0, "nodes": ["simulator"],
         "scenario": "leo_observatory", "hours": 1.0, "rate_Hz": 5.0, "sim_time": 10.0, "loop_wall_seconds": 0.5,
         "cpu_seconds": {"simulator": 0.3, "controller": 0.2},
         "cpu_layers": {"simulator": node("simulator", 0.3, 0.28, {"truth model": 0.1, "publish": 0.05,
                                                                   "message conversion": 0.04}),
                        "controller": node("controller", 0.2, 0.19, {"controller core": 0.01, "executor wait": 0.08}),
                        "estimator": cpu_rows(tmp_path / "none.json", sim_time=10.0)}}
    split = criteria._soak(p, None).metrics["cpu_by_layer_ms_per_sim_s"]
    assert split == pytest.approx({"own work": 11.0, "message conversion": 4.0, "rclpy and DDS": 5.0 + 8.0 + 2.0 + 1.0,
                                   "node code": 9.0 + 10.0})
    assert sum(split.values()) == pytest.approx((0.3 + 0.2) / 10.0 * 1e3)      # every node's process CPU
    for damaged in (math.nan, "1.0", None):
        p["cpu_layers"]["controller"]["layers"]["take"] = {"ms_per_sim_s": damaged, "calls_per_sim_s": 1.0}
        with pytest.raises(criteria.HistoryError, match="'cpu_layers' is not a soak's CPU by layer"):
            criteria._soak(p, None)
    p["cpu_layers"]["controller"] = {"layers": []}
    with pytest.raises(criteria.HistoryError, match="cpu_layers"):
        criteria._soak(p, None)
