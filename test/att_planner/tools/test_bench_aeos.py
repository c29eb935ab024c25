"""``att-bench aeos``: the accessible bound and the greedy baseline (planned, not flown) of a small
uniform set over one orbit, its JSON rechecked, its history line, and bad options refused."""
from __future__ import annotations

import json

import pytest

from att_planner.imaging import access, sites
from att_planner.tools.bench import history, main
from att_sim.models import scenario as scen
from att_sim.models import world


@pytest.fixture(scope="module")
def payload(tmp_path_factory):
    path = tmp_path_factory.mktemp("aeos") / "aeos.json"
    assert main(["aeos", "--targets", "uniform:50", "--seed", "4", "--orbits", "1", "--json", str(path)]) == 0
    return json.loads(path.read_text())


def test_the_json_holds_the_bound_the_windows_and_the_plan(payload, capsys):
    assert payload["sites"] == 50 and payload["orbits"] == 1 and payload["targets"] == "uniform:50"
    windows = payload["access_windows"]
    assert sum(windows["per_site"].values()) == windows["total"] == len(windows["windows"])
    with_window = {w["site"] for w in windows["windows"]}
    assert payload["accessible"]["sites"] == len(with_window) == sum(n > 0 for n in windows["per_site"].values())
    greedy = payload["greedy"]
    assert greedy["status"] == "planned, not flown" and greedy["images"] == len(greedy["plan"])
    assert 0 < greedy["images"] <= payload["accessible"]["sites"]
    assert greedy["priority"] <= payload["accessible"]["priority"] + 1e-12
    assert len({p["site"] for p in greedy["plan"]}) == greedy["images"]
    for image in greedy["plan"]:       # every image inside one of its site's windows (times rounded to 1 ms)
        assert any(w["site"] == image["site"] and w["open_s"] - 1e-3 <= image["time_s"] <= w["close_s"] + 1e-3
                   for w in windows["windows"])
    assert payload["compute_s"]["access"] > 0 and payload["rate_max_deg_per_s"] == pytest.approx(5.0)


def test_the_windows_are_the_access_modules(payload):
    s = scen.load("aeos")
    w = access.access_windows(world.Environment.from_scenario(s), sites.uniform(50, 4), 0.0, s.orbit_model.period)
    assert payload["access_windows"]["total"] == len(w) and payload["accessible"]["sites"] == int(w.accessible().sum())


def test_the_history_line_names_the_estimate(payload):
    line = history.line(payload, json_path=None, date="2026-01-01T00:00:00Z", commit=None, source="test")
    assert line["study"] == "aeos" and line["met"] is None and line["value"] == payload["greedy"]["images"]
    assert "planned, not flown" in line["metric"]
    assert line["command"] == "att-bench aeos --targets uniform:50 --seed 4 --orbits 1 --json PATH"


@pytest.mark.parametrize("argv, says", [
    (["--targets", "uniform:0"], "uniform target count"),
    (["--targets", "/no/such.csv"], "expected a readable CSV file"),
    (["--orbits", "0"], "--orbits"), (["--orbits", "nan"], "--orbits"),
    (["--dwell-s", "-1"], "--dwell-s"), (["--lookahead", "0"], "--lookahead"),
    (["--scenario", "no_such"], "unknown spacecraft/scenario 'no_such'"),
])
def test_bad_options_are_refused_with_a_sentence(argv, says, capsys):
    with pytest.raises(SystemExit) as exit_:
        main(["aeos", *argv])
    assert exit_.value.code == 2 and says in capsys.readouterr().err


def test_a_csv_target_list_is_planned(tmp_path, capsys):
    csv_path = tmp_path / "sites.csv"
    csv_path.write_text("name,latitude_deg,longitude_deg,priority\nnorth,60,10,1\nsouth,-30,170,2\nequator,0,0,0.5\n")
    out = tmp_path / "aeos.json"
    assert main(["aeos", "--targets", str(csv_path), "--orbits", "2", "--json", str(out)]) == 0
    payload = json.loads(out.read_text())
    assert payload["targets"] == str(csv_path) and payload["sites"] == 3
    assert set(payload["access_windows"]["per_site"]) == {"north", "south", "equator"}
    assert payload["greedy"]["images"] <= payload["accessible"]["sites"] <= 3
    assert "planned, not flown" in capsys.readouterr().out
