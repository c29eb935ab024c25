"""``att-bench timing`` on a reduced input: the JSON holds every figure with its repeats, median, best
and target, each criterion is evaluated from those figures, the exit status follows them, and the two
16-cone requests are refused by the checks they are meant to time. No timing threshold is asserted."""
import json
import statistics

import pytest

from att_planner.tools.bench import main, timing


def figures(out: dict) -> list[tuple[str, dict]]:
    rows = [(f"sky.{name}.{kind}", f[kind]) for name, f in out["sky"].items() for kind in ("scalar", "vector")]
    rows += [(f"{name}.{kind}", f[kind]) for name, f in out["orbit"].items() for kind in ("scalar", "vector")]
    return rows + [("closed_sky", out["closed_sky"]), ("goal_in_cone", out["goal_in_cone"])]


@pytest.fixture(scope="module")
def reduced(tmp_path_factory):
    path = tmp_path_factory.mktemp("timing") / "timing.json"
    code = main(["timing", "--repeats", "10", "--scalar-calls", "10", "--json", str(path)])
    return code, json.loads(path.read_text())


def test_every_figure_has_its_repeats_and_its_criterion_evaluated(reduced):
    code, out = reduced
    assert sorted(out["sky"]) == sorted(timing.SKY_FUNCTIONS)
    assert sorted(out["orbit"]) == ["CircularOrbit", "KeplerOrbit", "TLEOrbit"]
    targets = {"scalar": timing.SCALAR_TARGET, "vector": timing.VECTOR_TARGET}
    for name, f in figures(out):
        assert len(f["repeats_s"]) == 10 and all(s > 0 for s in f["repeats_s"]), name
        assert f["median_s"] == pytest.approx(statistics.median(f["repeats_s"]), rel=1e-12), name
        assert f["best_s"] == min(f["repeats_s"]), name
        kind = name.rsplit(".", 1)[-1]
        assert f["target_s"] == targets.get(kind, timing.CLOSED_SKY_TARGET), name
        assert f["meets_target"] == (f["median_s"] <= f["target_s"]), name
        assert f["calls_per_repeat"] == (10 if kind == "scalar" else 1), name
    missed = sorted(name for name, f in figures(out) if not f["meets_target"])
    assert len(out["failed"]) == len(missed) + (not out["closed_sky"]["refused"])
    assert out["passed"] == (not out["failed"]) and code == (0 if out["passed"] else 1)
    machine = out["machine"]
    assert len(machine["load_before"]) == 3 and len(machine["load_after"]) == 3 and machine["cores"] >= 1


def test_the_16_cone_requests_are_refused_by_the_check_each_one_times(reduced):
    _, out = reduced
    assert out["closed_sky"]["codes"] == ["INFEASIBLE"] and out["closed_sky"]["refused"]
    assert out["goal_in_cone"]["codes"] == ["SENSOR_IN_CONE"]
    assert out["closed_sky"]["cones"] == out["goal_in_cone"]["cones"] == 16
