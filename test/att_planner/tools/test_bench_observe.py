"""att-bench observe: the zones' cost on a tour of observatory sources, both tours
verified, the JSON complete enough to integrate the plans independently."""
import json
from types import SimpleNamespace

import numpy as np
import pytest

from att_planner.tools.bench import _json_default, observe


def test_a_two_source_tour_with_and_without_the_zones():
    args = SimpleNamespace(sources="vega,andromeda", dwell=20.0, intervals=8, search_intervals=6, substeps=4,
                           cone_margin_deg=0.2)
    out = json.loads(json.dumps(observe.run(args), default=_json_default))
    free, zoned = out["without_zones"], out["with_zones"]
    for entry in (free, zoned):
        assert entry["verified"], entry["message"]
        assert sorted(entry["order"]) == ["andromeda", "vega"]
        for p in entry["passages"]:
            assert p["observation_end"] - p["arrival"] == pytest.approx(20.0)
        t, torque = np.array(entry["t"]), np.array(entry["torque"])
        assert t[0] == 0.0 and np.all(np.diff(t) > 0) and t[-1] == pytest.approx(entry["tf"])
        assert torque.shape == (len(t), 3) and np.abs(torque).max() <= out["spacecraft"]["wheel_torque_max"] + 1e-9
        assert entry["interpolation"] == "zoh" and entry["control_kind"] == "wheel_torque"
    assert [z["name"] for z in out["zones"]] == ["sun", "moon", "earth"]
    assert zoned["verification"]["zone_names"] == ["sun", "moon", "earth"]
    assert out["zone_cost_ratio"] == pytest.approx(zoned["tf"] / free["tf"])
    assert out["zone_cost_ratio"] >= 1.0 - 1e-3            # the zones can only cost


def test_an_unknown_source_is_named():
    with pytest.raises(ValueError, match="unknown source.*nowhere"):
        observe.tour_problems(["vega", "nowhere"], 10.0)
