"""``att-bench rtf --in-process`` on swift_demo's demo maneuver (a short flight): the JSON's RTF is its sim
seconds over the flight loop's wall seconds, the maneuver succeeded on the estimate, the profile holds
the requested rows in order, the criterion is evaluated from the figures (never typed) and the history
summarises the run. No timing threshold is asserted: that is the benchmark's."""
import json

import pytest

from att_planner.tools.bench import history as hist
from att_planner.tools.bench import main, rtf


@pytest.fixture(scope="module")
def swift(tmp_path_factory):
    path = tmp_path_factory.mktemp("rtf") / "rtf.json"
    code = main(["rtf", "--in-process", "--scenario", "swift_demo", "--profile-rows", "5", "--json", str(path)])
    return code, path, json.loads(path.read_text())


def test_the_figures_are_the_flight_loops(swift):
    code, _, out = swift
    assert out["scenario"] == "swift_demo" and out["in_process"] is True and out["estimator"] is True
    assert out["rtf"] == pytest.approx(out["sim_seconds"] / out["wall_seconds"], rel=1e-12)
    assert out["rtf_cpu"] == pytest.approx(out["sim_seconds"] / out["cpu_seconds"], rel=1e-12)
    # the flight: the lead, the plan, then the controller's settle time (60 s in swift_demo's params)
    assert rtf.LEAD_S + out["maneuver_seconds"] < out["sim_seconds"] < rtf.LEAD_S + out["maneuver_seconds"] + 70.0
    assert out["steps"] == round(out["sim_seconds"] / out["step_s"])
    assert out["success"] and out["code"] == 0 and out["refusals"] == 0
    assert 0.0 <= out["final_error_deg"] < 0.05
    assert out["setup_seconds"] > 0 and out["planning_seconds"] > 0 and out["wall_seconds"] > 0
    assert out["met"] == (out["rtf"] >= rtf.TARGET_RTF and out["success"]) == out["passed"]
    assert code == (0 if out["passed"] else 1)
    assert out["load_before"] >= 0 and out["machine"]["load_1min"] >= 0


def test_the_profile_holds_the_top_rows_of_a_separate_run(swift):
    _, _, out = swift
    for key in ("tottime", "cumtime"):
        rows = out["profile"][key]
        assert len(rows) == 5 and set(rows[0]) == {"function", "calls", "tottime", "cumtime"}
        values = [r[key] for r in rows]
        assert values == sorted(values, reverse=True) and values[0] > 0
        assert all(r["calls"] >= 1 and r["cumtime"] >= r["tottime"] for r in rows)
    assert out["profiled_wall_seconds"] > 0
    # the flight loop is what is profiled: the loop's tick is among the top cumulative rows
    assert any("closed_loop.py" in r["function"] for r in out["profile"]["cumtime"])


def test_the_history_summarises_the_run(swift, tmp_path):
    _, path, out = swift
    row = hist.line(out, json_path=str(path), date="2026-12-05T00:00:00Z", commit=None, source="json")
    assert row["study"] == "rtf" and row["case"] == "swift_demo, in process" and row["value"] == out["rtf"]
    assert row["met"] == out["met"] and "365" in row["target"]
    assert row["command"] == f"att-bench rtf --in-process --scenario swift_demo --json {path}"
    failed = dict(out, success=False)
    assert hist.line(failed, json_path=None, date="2026-12-05T00:00:00Z", commit=None, source="json")["met"] is False


@pytest.mark.parametrize("argv, says", [
    (["rtf", "--scenario", "swift_demo"], "--in-process"),
    (["rtf", "--in-process", "--scenario", "no_such_scenario"], "no_such_scenario"),
    (["rtf", "--in-process", "--scenario", "bruni_celani"], "has no 'demo:' section"),
    (["rtf", "--in-process", "--scenario", "swift_demo", "--profile-rows", "0"], "--profile-rows must be at least 1"),
])
def test_a_wrong_request_is_refused_with_a_sentence(argv, says, capsys):
    with pytest.raises(SystemExit) as exc:
        main(argv)
    assert says in str(exc.value.code) + capsys.readouterr().err


def test_a_maneuver_the_planner_refuses_is_said_in_one_sentence(monkeypatch):
    from att_msgs_py.errors import ErrorCode, RequestError

    def refuse(*args, **kwargs):
        raise RequestError(ErrorCode.INFEASIBLE, "no path clears the zones")
    monkeypatch.setattr(rtf, "plan_in_process", refuse)
    with pytest.raises(SystemExit) as exc:
        main(["rtf", "--in-process", "--scenario", "swift_demo", "--no-profile"])
    assert str(exc.value.code) == (f"att-bench rtf: the demo maneuver of 'swift_demo' was not planned: "
                                   f"code {int(ErrorCode.INFEASIBLE)}: no path clears the zones")
