"""Monte Carlo dispersions: the draws follow the declared distributions, a run is
reproduced by its seed alone, the dispersed truth carries exactly the drawn values, and every bad
campaign is refused in one sentence naming the field (or the seed of a non-physical draw)."""
from __future__ import annotations

import math
import re
from dataclasses import replace
from pathlib import Path

import numpy as np
import pytest
from scipy import stats

from att_sim.models import rotations as rot
from att_sim.models import scenario as scen
from att_sim.models.config_schema import inertia_problem
from att_sim.truth import dispersions as disp
from att_sim.truth.simulation import Simulation

ROOT = Path(__file__).resolve().parents[3]
SHIPPED = disp.load_campaign(ROOT / "campaigns" / "swift_demo.yaml")
SWIFT = scen.load("swift_demo")
DRAWS = 3000


def campaign(dispersions: dict, **fields) -> disp.Campaign:
    doc = {"campaign": {"scenario": "swift_demo", "seed": 3, **fields, "dispersions": dispersions}}
    return disp.campaign_from(doc, Path("test.yaml"))


@pytest.fixture(scope="module")
def drawn():
    runs = [disp.draw(SHIPPED, SWIFT, disp.run_seed(SHIPPED.seed, i)) for i in range(DRAWS)]
    return {name: np.array([r[name] for r in runs]) for name in SHIPPED.dispersions}


def test_the_shipped_campaign_declares_the_issues_dispersions():
    d = SHIPPED.dispersions
    assert d["inertia_scale"].b * 3 == pytest.approx(0.05) and d["wheel_torque_scale"].b * 3 == pytest.approx(0.10)
    assert d["wheel_misalignment_deg"].b * 3 == pytest.approx(0.5)
    assert d["initial_attitude_error_deg"].b * 3 == pytest.approx(0.1)
    assert d["initial_rate_error_rad_s"].b * 3 == pytest.approx(1e-4)
    assert all(x.kind == "normal" and x.truncate == 3 for x in d.values())


def test_the_applied_values_follow_the_declared_distributions(drawn):
    """Every component against scipy's truncated normal (an independent implementation): the
    Kolmogorov–Smirnov test at 0.1 %, the sample mean and deviation within 4 standard errors."""
    for name, values in drawn.items():
        d = SHIPPED.dispersions[name]
        mean, std = d.moments()
        law = stats.truncnorm(-d.truncate, d.truncate, loc=d.a, scale=d.b)
        assert std == pytest.approx(law.std(), rel=1e-9)
        for k in range(values.shape[1]):
            v = values[:, k]
            assert stats.kstest(v, law.cdf).pvalue > 1e-3, (name, k)
            assert abs(v.mean() - mean) < 4 * std / math.sqrt(DRAWS), (name, k)
            assert abs(v.std(ddof=1) / std - 1) < 4 / math.sqrt(2 * DRAWS), (name, k)
            assert np.abs(v - mean).max() <= d.truncate * d.b


def test_uniform_draws_stay_within_their_bounds_and_fill_them():
    c = campaign({"initial_rate_error_rad_s": {"distribution": "uniform", "low": -2e-4, "high": 1e-4}})
    v = np.concatenate([disp.draw(c, SWIFT, disp.run_seed(c.seed, i))["initial_rate_error_rad_s"]
                        for i in range(2000)])
    assert v.min() >= -2e-4 and v.max() <= 1e-4
    assert stats.kstest(v, stats.uniform(-2e-4, 3e-4).cdf).pvalue > 1e-3
    assert c.dispersions["initial_rate_error_rad_s"].moments() == pytest.approx((-0.5e-4, 3e-4 / math.sqrt(12)))


def test_a_run_is_reproduced_by_its_seed_alone_and_declaring_another_dispersion_changes_no_other():
    seed = disp.run_seed(SHIPPED.seed, 17)
    assert seed == disp.run_seed(SHIPPED.seed, 17) != disp.run_seed(SHIPPED.seed, 18)
    a, b = disp.draw(SHIPPED, SWIFT, seed), disp.draw(SHIPPED, SWIFT, seed)
    assert all(np.array_equal(a[k], b[k]) for k in a)
    only = campaign({"initial_rate_error_rad_s": {"distribution": "normal", "three_sigma": 1e-4, "truncate": 3}})
    assert np.array_equal(disp.draw(only, SWIFT, seed)["initial_rate_error_rad_s"], a["initial_rate_error_rad_s"])


def test_the_dispersed_truth_carries_the_drawn_values():
    seed = disp.run_seed(SHIPPED.seed, 3)
    truth, v = disp.seed_truth(SHIPPED, SWIFT, seed)
    sc = truth.scenario.spacecraft
    # swift_demo's inertia is 100 I: the principal moments are 100 (1 + scale), in some order
    assert np.sort(np.linalg.eigvalsh(sc.inertia)) == pytest.approx(np.sort(100 * (1 + v["inertia_scale"])))
    tilts = np.hypot(*v["wheel_misalignment_deg"].reshape(-1, 2).T)
    turned = np.degrees(np.arccos(np.clip(np.sum(sc.wheel_axes * SWIFT.spacecraft.wheel_axes, axis=0), -1, 1)))
    assert turned == pytest.approx(tilts, rel=1e-6)
    assert sc.wheel_inertia == pytest.approx(0.01 * (1 + v["wheel_inertia_scale"][0]))
    assert truth.scenario.actuators.wheels.torque_scale == pytest.approx(tuple(1 + v["wheel_torque_scale"]))
    assert truth.scenario.actuators.wheels.coulomb_friction == SWIFT.actuators.wheels.coulomb_friction
    assert math.degrees(rot.angle_between(truth.q0, rot.IDENTITY)) == pytest.approx(
        np.linalg.norm(v["initial_attitude_error_deg"]))
    assert truth.omega0 == pytest.approx(v["initial_rate_error_rad_s"])
    assert SWIFT.spacecraft.inertia[0, 0] == 100.0                   # the nominal scenario is untouched


def test_the_drives_deliver_the_scaled_torque():
    c = campaign({"wheel_torque_scale": {"distribution": "uniform", "low": 0.2, "high": 0.3}})
    ideal = replace(SWIFT, actuators=replace(SWIFT.actuators, wheels=None))
    truth, v = disp.seed_truth(c, ideal, 5)
    sim = Simulation.for_scenario(truth.scenario)
    held = sim.wheel_drive.hold(np.array([[0.1, -0.1, 0.05]]))[0]       # one run's row
    assert held == pytest.approx(np.array([0.1, -0.1, 0.05]) * (1 + v["wheel_torque_scale"]), rel=1e-12)


def test_a_non_physical_inertia_is_refused_naming_the_runs_seed():
    c = campaign({"inertia_scale": {"distribution": "uniform", "low": -0.9, "high": 2.0}})
    refused = []
    for i in range(20):
        seed = disp.run_seed(c.seed, i)
        try:
            disp.seed_truth(c, SWIFT, seed)
        except ValueError as err:
            refused.append((seed, str(err)))
    assert refused, "a draw this wide breaks the triangle inequality in 20 runs"
    seed, message = refused[0]
    assert f"seed {seed}" in message and "triangle inequality" in message and "never resampled" in message
    assert inertia_problem(np.diag([1.0, 1.0, -0.5])).startswith("a positive definite matrix")
    assert inertia_problem(np.diag([1.0, 2.0, 3.0])) is None


BAD = {
    "not a campaign": ({"scenario": "swift_demo"}, "bad.yaml: campaign: expected this key (required)"),
    "unknown key": ({"campaign": {"scenario": "swift_demo", "seed": 1, "rnus": 3}},
        "campaign.rnus: expected one of the keys"),
    "unknown dispersion": ({"campaign": {"scenario": "swift_demo", "seed": 1,
                                         "dispersions": {"inertia_scal": {}}}},
        "campaign.dispersions.inertia_scal: expected one of the keys"),
    "no runs": ({"campaign": {"scenario": "swift_demo", "seed": 1, "runs": 0}},
        "campaign.runs: expected greater than or equal to 1"),
    "fractional runs": ({"campaign": {"scenario": "swift_demo", "seed": 1, "runs": 2.5}},
        "campaign.runs: expected a valid integer"),
    "negative seed": ({"campaign": {"scenario": "swift_demo", "seed": -1}},
        "campaign.seed: expected greater than or equal to 0"),
    "no seed": ({"campaign": {"scenario": "swift_demo"}}, "campaign.seed: expected this key (required)"),
    "unknown distribution": ({"campaign": {"scenario": "swift_demo", "seed": 1, "dispersions": {
        "inertia_scale": {"distribution": "cauchy", "sigma": 1}}}},
        "inertia_scale.distribution: expected one of 'normal', 'uniform'; found 'cauchy'"),
    "sigma and three_sigma": ({"campaign": {"scenario": "swift_demo", "seed": 1, "dispersions": {
        "inertia_scale": {"distribution": "normal", "sigma": 0.1, "three_sigma": 0.3}}}},
        "inertia_scale: expected exactly one of sigma, three_sigma"),
    "negative sigma": ({"campaign": {"scenario": "swift_demo", "seed": 1, "dispersions": {
        "inertia_scale": {"distribution": "normal", "sigma": -0.1}}}},
        "inertia_scale.sigma: expected greater than or equal to 0"),
    "uniform upside down": ({"campaign": {"scenario": "swift_demo", "seed": 1, "dispersions": {
        "inertia_scale": {"distribution": "uniform", "low": 0.1, "high": -0.1}}}},
        "inertia_scale: expected low below high"),
    "unknown distribution key": ({"campaign": {"scenario": "swift_demo", "seed": 1, "dispersions": {
        "inertia_scale": {"distribution": "normal", "sigma": 0.1, "mu": 1}}}},
        "inertia_scale.mu: expected one of the keys"),
    "truncate zero": ({"campaign": {"scenario": "swift_demo", "seed": 1, "dispersions": {
        "inertia_scale": {"distribution": "normal", "sigma": 0.1, "truncate": 0}}}},
        "inertia_scale.truncate: expected greater than 0"),
    "fault probability 1.5": ({"campaign": {"scenario": "swift_demo", "seed": 1, "faults": [
        {"component": "wheel", "index": 0, "kind": "off", "probability": 1.5, "window_s": [0.0, 10.0]}]}},
        "campaign.faults[0].probability: expected less than or equal to 1"),
    "fault window reversed": ({"campaign": {"scenario": "swift_demo", "seed": 1, "faults": [
        {"component": "wheel", "index": 0, "kind": "off", "probability": 0.5, "window_s": [10.0, 5.0]}]}},
        "campaign.faults[0]: expected window_s [earliest, latest] with 0 <= earliest <= latest"),
    "fault window negative": ({"campaign": {"scenario": "swift_demo", "seed": 1, "faults": [
        {"component": "wheel", "index": 0, "kind": "off", "probability": 0.5, "window_s": [-1.0, 5.0]}]}},
        "window_s [earliest, latest] with 0 <= earliest"),
    "fault kind unknown": ({"campaign": {"scenario": "swift_demo", "seed": 1, "faults": [
        {"component": "gyro", "index": 0, "kind": "seized", "probability": 0.5, "window_s": [0.0, 5.0]}]}},
        "campaign.faults[0]: expected kind one of axis_stuck, bias_step for a gyro, got 'seized'"),
    "fault probability NaN": ({"campaign": {"scenario": "swift_demo", "seed": 1, "faults": [
        {"component": "wheel", "index": 0, "kind": "off", "probability": math.nan, "window_s": [0.0, 5.0]}]}},
        "campaign.faults[0].probability"),
}


@pytest.mark.parametrize("name", BAD)
def test_a_bad_campaign_is_refused_naming_the_field(name):
    doc, words = BAD[name]
    with pytest.raises(ValueError, match=re.escape(words)):
        disp.campaign_from(doc, Path("bad.yaml"))


def test_the_coils_deliver_the_scaled_dipole():
    c = campaign({"magnetorquer_scale": {"distribution": "uniform", "low": -0.3, "high": -0.2}})
    ideal = replace(SWIFT, actuators=replace(SWIFT.actuators, magnetorquers=None))
    truth, v = disp.seed_truth(c, ideal, 5)
    coils = Simulation.for_scenario(truth.scenario).magnetorquers
    m = np.array([2.0, -1.0, 0.5])
    assert coils(m[None])[0] == pytest.approx(m * (1 + v["magnetorquer_scale"]), rel=1e-12)


def test_an_epoch_offset_moves_the_truths_orbit_and_sky():
    """leo_observatory's epoch moved by the draw: the orbit's position at t = 0 is where the nominal
    orbit is at the offset (the TLE is the same), and the Sun and the zones follow."""
    leo = scen.load("leo_observatory")
    c = replace(campaign({"epoch_offset_s": {"distribution": "uniform", "low": 100.0, "high": 200.0}}),
                scenario="leo_observatory")
    truth, v = disp.seed_truth(c, leo, 9)
    offset = float(v["epoch_offset_s"][0])
    assert 100.0 <= offset <= 200.0
    assert (truth.scenario.epoch - leo.epoch).total_seconds() == pytest.approx(offset, abs=1e-6)
    moved, nominal = truth.scenario.orbit_model, leo.orbit_model
    assert moved.position(np.array([0.0, 60.0])) == pytest.approx(nominal.position(np.array([offset, offset + 60.0])),
                                                                 abs=0.01)      # m
    assert leo.epoch == scen.load("leo_observatory").epoch                # the nominal scenario is untouched
    with pytest.raises(ValueError, match="'swift_demo' has no epoch"):
        disp.seed_truth(campaign({"epoch_offset_s": {"distribution": "normal", "sigma": 1.0}}), SWIFT, 1)


def test_bad_files_and_a_dispersion_with_nothing_to_act_on_are_refused(tmp_path):
    with pytest.raises(ValueError, match=r"missing\.yaml: \(file\): expected a readable file"):
        disp.load_campaign(tmp_path / "missing.yaml")
    (tmp_path / "broken.yaml").write_text("campaign: {{{\n")
    with pytest.raises(ValueError, match=r"broken\.yaml:2: \(file\): expected valid YAML"):
        disp.load_campaign(tmp_path / "broken.yaml")
    c = campaign({"com_offset_m": {"distribution": "normal", "sigma": 0.01}})
    with pytest.raises(ValueError, match="no solar pressure or drag"):
        disp.seed_truth(c, SWIFT, 1)


FAULTS = [{"component": "wheel", "index": 1, "kind": "seized", "probability": 0.3, "window_s": [10.0, 20.0]},
          {"component": "gyro", "index": 2, "kind": "bias_step", "bias_rad_s": 1e-3, "probability": 1.0,
           "window_s": [5.0, 5.0]}]


def test_faults_occur_with_their_probability_in_their_window_and_a_run_keeps_its_own():
    c = campaign({}, faults=FAULTS)
    seeds = [disp.run_seed(c.seed, i) for i in range(2000)]
    runs = [disp.seed_truth(c, SWIFT, seed) for seed in seeds]
    seized = [f for truth, _ in runs for f in truth.faults if f.kind == "seized"]
    # binomial: 0.3 of 2000 runs, standard error 0.010
    assert len(seized) / len(runs) == pytest.approx(0.3, abs=0.035)
    onsets = np.array([f.t_s for f in seized])
    assert onsets.min() >= 10.0 and onsets.max() <= 20.0
    assert stats.kstest((onsets - 10.0) / 10.0, "uniform").pvalue > 1e-3
    assert all(any(f.kind == "bias_step" and f.t_s == 5.0 and f.bias_rad_s == 1e-3 for f in truth.faults)
               for truth, _ in runs)
    # the applied values name each entry's onset (NaN: the run does not have it)
    for truth, values in runs[:50]:
        by_kind = {f.kind: f.t_s for f in truth.faults}
        assert values["fault_t_s"][1] == 5.0
        assert (math.isnan(values["fault_t_s"][0]) and "seized" not in by_kind) or \
            values["fault_t_s"][0] == by_kind["seized"]
    # reproduced by its seed; another entry declared after it changes nothing of it
    more = campaign({}, faults=[*FAULTS, {**FAULTS[0], "index": 2}])
    for seed, (truth, _) in zip(seeds[:50], runs[:50]):
        again = disp.seed_truth(more, SWIFT, seed)[0]
        assert again.faults[:len(truth.faults)] == truth.faults


def test_a_dispersed_fault_is_scheduled_as_a_dispersion_and_refused_beyond_the_hardware():
    c = campaign({}, faults=[FAULTS[1]])
    truth = disp.seed_truth(c, SWIFT, 7)[0]
    sim = Simulation.for_scenario(truth.scenario, seed=truth.seed, dispersed_faults=truth.faults)
    for _ in range(101):
        sim.advance(0.05)
    [event] = sim.faults.take_events()
    assert (event.kind, event.source, event.t) == ("bias_step", "dispersion", pytest.approx(5.0))
    bad = campaign({}, faults=[{**FAULTS[0], "index": 3}])
    with pytest.raises(ValueError, match=re.escape("campaign.faults[0].index below 3 (the spacecraft has 3 wheels)")):
        disp.seed_truth(bad, SWIFT, 7)
