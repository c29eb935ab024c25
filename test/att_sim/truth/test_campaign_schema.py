"""The campaign model: its dispersions are those the truth draws, distributions checked."""
from __future__ import annotations

import pytest
from pydantic import ValidationError

from att_sim.truth import campaign_schema as cps
from att_sim.truth.dispersions import DISPERSIONS


def test_dispersion_names_are_the_truths():
    assert list(cps.Dispersions.model_fields) == list(DISPERSIONS)


def test_distributions():
    c = cps.Campaign.model_validate({"scenario": "swift_demo", "seed": 1, "dispersions": {
        "inertia_scale": {"distribution": "normal", "three_sigma": 0.3}}})
    assert c.runs == 100 and c.dispersions.inertia_scale.standard_deviation == pytest.approx(0.1)
    with pytest.raises(ValidationError, match="exactly one of sigma"):
        cps.Normal.model_validate({"distribution": "normal", "sigma": 1.0, "three_sigma": 3.0})
    with pytest.raises(ValidationError, match="low below high"):
        cps.Uniform.model_validate({"distribution": "uniform", "low": 1.0, "high": 1.0})
    with pytest.raises(ValidationError):
        cps.Campaign.model_validate({"scenario": "s", "seed": 1.5})
