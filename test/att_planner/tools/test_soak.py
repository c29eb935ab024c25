"""Soak (short): simulator + controller + recorder as fast as possible; nothing dropped, memory
flat, the log replays. ``att-bench soak`` runs the full 10 orbits."""
import pytest

from att_planner.tools.soak import run_soak

pytestmark = [pytest.mark.ros, pytest.mark.slow]
MAX_GROWTH = 0.10      # resident memory may grow by 10 % of its start (first half of the run) at most


def test_half_orbit_as_fast_as_possible(tmp_path):
    r = run_soak("bruni_celani", 0.5, tmp_path)
    assert r["reached_end"] and r["real_time_factor"] > 5
    assert r["dropped_state"] == 0 and r["state_messages"] == r["state_expected"]
    assert r["lockstep_suspensions"] == 0
    assert r["command_messages"] >= r["state_messages"] - 2       # one command answers each state
    assert all(code == 0 for code in r["exit_codes"].values()), r["exit_codes"]
    for name, m in r["memory"].items():
        assert m["end_mib"] <= m["start_mib"] * (1 + MAX_GROWTH), f"{name} memory grew: {m}"


def test_a_real_sky_loop_with_the_estimator_profiled(tmp_path):
    """leo_observatory (every sensor, the MEKF, the real sky) at a mission's 5 Hz for 72 s of sim
    time: every state recorded, every node profiled, the real-time factor over the loop's own time."""
    r = run_soak("leo_observatory", None, tmp_path / "run", hours=0.02, rate_Hz=5.0, profile_dir=tmp_path / "prof")
    assert r["nodes"] == ["recorder", "simulator", "estimator", "controller"]
    assert r["reached_end"] and r["rate_Hz"] == 5.0 and r["state_expected"] == 361
    assert r["dropped_state"] == 0 and r["lockstep_suspensions"] == 0
    assert 0 < r["loop_wall_seconds"] < r["wall_seconds"]
    assert r["real_time_factor"] == pytest.approx(r["sim_time"] / r["loop_wall_seconds"])
    for name in r["nodes"]:
        rows = r["profile"][name]["functions"]
        assert len(rows) > 5 and all(row["own_s"] >= 0 and row["calls"] > 0 for row in rows), name
    assert all(code == 0 for code in r["exit_codes"].values()), r["exit_codes"]
