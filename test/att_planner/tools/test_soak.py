"""Soak (short): simulator + controller + recorder as fast as possible; nothing dropped, memory
flat, the log replays. ``att-bench soak`` runs the full 10 orbits."""
import pytest

from att_planner.tools.soak import run_soak

pytestmark = [pytest.mark.ros, pytest.mark.slow]
MAX_GROWTH = 0.10      # resident memory may grow by 10 % of its start (first half of the run) at most


def test_half_orbit_as_fast_as_possible(tmp_path):
    """bruni_celani (no sensors) for half an orbit, every node under cProfile."""
    r = run_soak("bruni_celani", 0.5, tmp_path / "run", profile_dir=tmp_path / "prof")
    assert r["reached_end"] and r["real_time_factor"] > 5
    assert r["dropped_state"] == 0 and r["state_messages"] == r["state_expected"]
    assert r["lockstep_suspensions"] == 0
    assert r["command_messages"] >= r["state_messages"] - 2       # one command answers each state
    assert all(code == 0 for code in r["exit_codes"].values()), r["exit_codes"]
    for name, m in r["memory"].items():
        assert m["end_mib"] <= m["start_mib"] * (1 + MAX_GROWTH), f"{name} memory grew: {m}"
    for name in r["nodes"]:
        rows = r["profile"][name]["functions"]
        assert len(rows) > 5 and all(row["own_s"] >= 0 and row["calls"] > 0 for row in rows), name


def test_a_real_sky_loop_with_the_estimator_timed_by_layer(tmp_path):
    """leo_observatory (every sensor, the MEKF, the real sky) at a mission's 5 Hz for 72 s of sim
    time: every state recorded, the real-time factor over the loop's own time, every node's CPU by
    layer: the layers within the main thread's CPU and that within the process's, each layer called
    as often as the loop says (a step a state, a command a controller step, a message a write)."""
    r = run_soak("leo_observatory", None, tmp_path / "run", hours=0.02, rate_Hz=5.0, cpu_dir=tmp_path / "cpu")
    assert r["nodes"] == ["recorder", "simulator", "estimator", "controller"]
    assert r["reached_end"] and r["rate_Hz"] == 5.0 and r["state_expected"] == 361
    assert r["dropped_state"] == 0 and r["lockstep_suspensions"] == 0
    assert 0 < r["loop_wall_seconds"] < r["wall_seconds"]
    assert r["real_time_factor"] == pytest.approx(r["sim_time"] / r["loop_wall_seconds"])
    assert all(code == 0 for code in r["exit_codes"].values()), r["exit_codes"]
    cpu = r["cpu_layers"]
    models = {"recorder": "log write", "simulator": "truth model", "estimator": "estimator core",
              "controller": "controller core"}
    for name in r["nodes"]:
        c = cpu[name]
        inside = sum(row["ms_per_sim_s"] for row in c["layers"].values())
        assert 0 < inside <= c["main_thread_ms_per_sim_s"] <= c["process_ms_per_sim_s"] * (1 + 1e-9), name
        assert c["other_main_thread_ms_per_sim_s"] == pytest.approx(c["main_thread_ms_per_sim_s"] - inside)
        assert c["layers"][models[name]]["ms_per_sim_s"] > 0, name
    calls = {name: {k: v["calls_per_sim_s"] * r["sim_time"] for k, v in cpu[name]["layers"].items()} for name in cpu}
    assert calls["simulator"]["truth model"] >= 3 * (r["state_messages"] - 1)        # advance, sense, state
    assert calls["simulator"]["publish"] >= r["state_messages"]
    assert calls["estimator"]["estimator core"] >= r["state_messages"] - 1               # a gyro sample a step
    assert calls["controller"]["controller core"] >= r["command_messages"]
    assert calls["recorder"]["log write"] >= r["state_messages"] + r["command_messages"]
    assert {"executor wait", "take", "publish", "message conversion"} <= calls["controller"].keys()
