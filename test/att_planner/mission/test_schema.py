"""The mission and target-list models: the ranges and defaults of the readers, names distinct."""
from __future__ import annotations

import pytest
from pydantic import ValidationError

from att_planner.mission import schema as ms

MISSION = {"targets": "observatory", "sensor_axis": [0.0, 1.0, 0.0], "horizon_s": 3600}
# key -> (default, low, high) of a mission's numbers, as the mission files document them
NUMBERS = {"horizon_s": (None, 60.0, 7 * 86_400.0), "margin_deg": (1.0, 0.0, 30.0), "rate_Hz": (5.0, 0.5, 50.0),
           "start_lead_s": (240.0, 1.0, 3600.0), "time_budget_s": (10.0, 0.05, 600.0),
           "pointing_tolerance_deg": (0.05, 1e-4, 10.0), "handover_blend_s": (60.0, 0.0, 3600.0)}


def test_mission_numbers_defaults_and_ranges():
    m = ms.Mission.model_validate(MISSION)
    for key, (default, low, high) in NUMBERS.items():
        info = ms.Mission.model_fields[key]
        assert getattr(m, key) == (default if default is not None else 3600)
        assert [c.ge for c in info.metadata if hasattr(c, "ge")] == [low]
        assert [c.le for c in info.metadata if hasattr(c, "le")] == [high]


@pytest.mark.parametrize("change, words", [
    ({"sensor_axis": [0.0, 1.1, 0.0]}, r"unit vector \(norm within 1e-06 of 1\)"),
    ({"secondary_axis": [0.0, 1.0, 0.0]}, "not parallel"),
    ({"secondary": "inertial"}, "velocity"),
    ({"zones": ["sun", "sun"]}, "distinct"),
    ({"horizon_s": 10}, "greater than or equal to 60"),
    ({"method": "a\tb"}, "printable"),
])
def test_mission_refusals(change, words):
    with pytest.raises(ValidationError, match=words):
        ms.Mission.model_validate({**MISSION, **change})


def test_target_list_kind_chooses_the_model():
    ground = {"kind": "ground", "scenario": "s", "targets": [{"name": "a", "lat_deg": 1, "lon_deg": 2, "dwell_s": 5}]}
    assert ms.target_list_model(ground) is ms.GroundTargets
    assert ms.GroundTargets.model_validate(ground).targets[0].alt_m == 0.0
    assert ms.target_list_model({"kind": "sky"}) is ms.TargetListKind
    with pytest.raises(ValidationError, match="distinct target names"):
        ms.GroundTargets.model_validate({**ground, "targets": ground["targets"] * 2})
    with pytest.raises(ValidationError, match="at most 20"):
        ms.GroundTargets.model_validate({**ground, "targets": [dict(ground["targets"][0], name=f"t{i}")
                                                               for i in range(21)]})
