"""Monte Carlo campaigns: the dispersed truth of one run, drawn from its seed.

A campaign file (YAML read by the one loader, :mod:`att_sim.models.config_files`, and validated by
:class:`att_sim.truth.campaign_schema.CampaignFile`; one mapping ``campaign:``) names a scenario
and declares how the truth departs from the model the plan was made with::

    campaign:
      scenario: swift_demo          # a scenario name: a file stem under config/ or $ATT_CONFIG_PATH
      seed: 16                      # campaign seed s
      runs: 1000                    # default run count (att-mc --runs overrides)
      settle_tolerance_deg: 0.01    # settling: the error to the goal stays below this after the plan
      converge_timeout_s: 30.0      # s of sim time for the estimate to converge before the maneuver
      dispersions:
        inertia_scale: {distribution: normal, three_sigma: 0.05, truncate: 3}
        wheel_misalignment_deg: {distribution: uniform, low: -0.2, high: 0.2}

Distributions: ``normal`` (``mean`` default 0, ``sigma`` or ``three_sigma``, optional ``truncate``:
kept within ``truncate`` sigmas by inverting the CDF between the two bounds, so each draw costs one
uniform and the count never depends on the values) and ``uniform`` (``low`` < ``high``). Every
component of a dispersion is drawn independently from it; :data:`DISPERSIONS` lists the names, their
sizes and units.

Seeds: run ``i`` of campaign seed ``s`` has the run seed ``SeedSequence(s, spawn_key=(i,))``'s first
32-bit word (:func:`run_seed`); everything of the run comes from that one integer — each dispersion
from its own stream ``SeedSequence(seed, spawn_key=(DISPERSION_STREAM, k))`` (``k`` its index in
:data:`DISPERSIONS`, so declaring another dispersion changes no other's values), and the sensors'
noise and drawn biases, the wheel drives' noise and the coils' misalignment from the sensor streams
of :mod:`att_sim.truth.sensors` with that seed. A run is therefore reproduced by its seed alone.

Faults: each entry ``k`` of ``faults`` (:class:`att_sim.truth.campaign_schema.FaultDispersion`)
draws two uniforms ``u₁, u₂`` from its own stream ``SeedSequence(seed, spawn_key=(FAULT_STREAM, k))``:
the run has the fault when ``u₁ < probability``, starting at ``t_s = earliest + u₂ (latest − earliest)``
(:func:`draw_faults`; both drawn whatever the outcome, so no entry changes another's). The truth
schedules it with the source ``dispersion`` (:mod:`att_sim.truth.faults`).

Physical inertia: a draw whose inertia is not positive definite or breaks the triangle inequality
(each principal moment at most the sum of the other two) is **refused**, naming the run's seed
(:func:`truth` raises ValueError; the campaign tool checks every run before any flies) — a
resampled run would no longer be reproducible from its seed, and a declared distribution that
reaches non-physical bodies is a mistake to fix in the file.
"""
from __future__ import annotations

import math
from dataclasses import dataclass, replace
from datetime import timedelta
from pathlib import Path

import numpy as np

from att_sim.models import config_files
from att_sim.models import rotations as rot
from att_sim.models import scenario as scen
from att_sim.models.actuator_specs import MagnetorquerSpec, WheelDriveSpec
from att_sim.models.config_faults import FaultSpec, Hardware
from att_sim.models.config_schema import inertia_problem
from att_sim.truth import campaign_schema as schema
from att_sim.truth.sensors import STREAMS

DISPERSION_STREAM = 1000 + len(STREAMS)     # spawn_key (DISPERSION_STREAM, k): clear of the sensors' streams
FAULT_STREAM = DISPERSION_STREAM + 1        # spawn_key (FAULT_STREAM, k): fault entry k
MAX_RUNS = schema.MAX_RUNS
MAX_FILE_BYTES = 100_000
DEG = math.pi / 180.0


# name -> (components as a function of the spacecraft, unit and meaning)
DISPERSIONS = {
    "inertia_scale": (lambda sc: 3, "relative error of each principal moment of inertia"),
    "inertia_rotation_deg": (lambda sc: 3, "rotation vector of the principal axes (deg, body)"),
    "wheel_misalignment_deg": (lambda sc: 2 * sc.n_wheels, "two perpendicular tilts of each wheel axis (deg)"),
    "wheel_inertia_scale": (lambda sc: 1, "relative error of the wheels' spin inertia"),
    "wheel_torque_scale": (lambda sc: sc.n_wheels, "relative error of each wheel drive's torque (scale factor)"),
    "magnetorquer_scale": (lambda sc: 3, "relative error of each magnetorquer coil's dipole (scale factor)"),
    "com_offset_m": (lambda sc: 3, "centre of mass offset (m, body): facets' centres of pressure move by -offset"),
    "epoch_offset_s": (lambda sc: 1, "the truth's epoch minus the flight software's (s): orbit, sky and field move"),
    "initial_attitude_error_deg": (lambda sc: 3, "rotation vector of the initial attitude error (deg, body)"),
    "initial_rate_error_rad_s": (lambda sc: 3, "initial body rate error (rad/s)"),
}


@dataclass(frozen=True)
class Distribution:
    kind: str                   # "normal" | "uniform"
    a: float                    # normal: mean; uniform: low
    b: float                    # normal: sigma; uniform: high
    truncate: float = math.inf  # normal: kept within truncate sigmas

    def draw(self, rng: np.random.Generator, n: int) -> np.ndarray:
        """``n`` independent draws (inverse CDF of one uniform each)."""
        from scipy.special import ndtr, ndtri  # here: the simulator node imports this module at start

        u = rng.random(n)
        if self.kind == "uniform":
            return self.a + (self.b - self.a) * u
        lo = ndtr(-self.truncate)
        return self.a + self.b * ndtri(lo + (1.0 - 2.0 * lo) * u)

    def moments(self) -> tuple[float, float]:
        """Mean and standard deviation of the distribution (truncated normal: Johnson, Kotz &
        Balakrishnan 1994, §10.1: ``σ² (1 − 2kφ(k)/(2Φ(k) − 1))``)."""
        if self.kind == "uniform":
            return 0.5 * (self.a + self.b), (self.b - self.a) / math.sqrt(12.0)
        k = self.truncate
        if math.isinf(k):
            return self.a, self.b
        phi = math.exp(-0.5 * k * k) / math.sqrt(2.0 * math.pi)
        from scipy.special import ndtr

        return self.a, self.b * math.sqrt(1.0 - 2.0 * k * phi / (2.0 * ndtr(k) - 1.0))


@dataclass(frozen=True)
class Campaign:
    path: Path
    scenario: str
    seed: int
    runs: int
    dispersions: dict             # name -> Distribution, in DISPERSIONS order
    settle_tolerance: float       # rad
    converge_timeout_s: float     # s
    faults: tuple = ()            # FaultDispersion: the faults a run may have


def distribution_from(d: schema.Normal | schema.Uniform) -> Distribution:
    """The validated distribution of a dispersion."""
    if isinstance(d, schema.Uniform):
        return Distribution("uniform", d.low, d.high)
    return Distribution("normal", d.mean, d.standard_deviation, d.truncate)


def campaign_of(model: schema.CampaignFile, path: Path) -> Campaign:
    """The :class:`Campaign` of a validated campaign file."""
    c = model.campaign
    dispersions = {name: distribution_from(getattr(c.dispersions, name)) for name in DISPERSIONS
                   if getattr(c.dispersions, name) is not None}
    return Campaign(path, c.scenario, c.seed, c.runs, dispersions, c.settle_tolerance_deg * DEG, c.converge_timeout_s,
                    tuple(c.faults))


def campaign_from(doc, path: Path) -> Campaign:
    """The campaign of the parsed file ``doc`` (read from ``path``), validated by
    :class:`att_sim.truth.campaign_schema.CampaignFile`;
    :class:`att_sim.models.config_files.ConfigFileError` (a ValueError) with every problem."""
    path = Path(path)
    if not isinstance(doc, dict):
        raise config_files.ConfigFileError([config_files.Problem(str(path), None, "", "a mapping 'campaign:'",
                                                                 config_files.shown(doc))])
    return campaign_of(config_files.validate(path, schema.CampaignFile, doc, {}), path)


def load_campaign(path) -> Campaign:
    """The campaign file at ``path``, read by the one loader (:mod:`att_sim.models.config_files`) and
    validated by :class:`att_sim.truth.campaign_schema.CampaignFile`; a
    :class:`~att_sim.models.config_files.ConfigFileError` (a ValueError, ``INVALID_CONFIG``) lists
    every problem as ``file:line: field.path: expected ...; found ...``."""
    path = Path(path)
    data, lines = config_files.read_yaml(path, MAX_FILE_BYTES, aliases=True)
    return campaign_of(config_files.validate(path, schema.CampaignFile, data, lines), path)


def run_seed(campaign_seed: int, run: int) -> int:
    """The seed of run ``run`` of a campaign (see module docstring)."""
    return int(np.random.SeedSequence(campaign_seed, spawn_key=(run,)).generate_state(1)[0])


def draw(campaign: Campaign, scenario: scen.Scenario, seed: int) -> dict[str, np.ndarray]:
    """The applied values of the run of seed ``seed``: each declared dispersion's components."""
    out = {}
    for k, name in enumerate(DISPERSIONS):
        if name in campaign.dispersions:
            rng = np.random.default_rng(np.random.SeedSequence(seed, spawn_key=(DISPERSION_STREAM, k)))
            out[name] = campaign.dispersions[name].draw(rng, DISPERSIONS[name][0](scenario.spacecraft))
    return out


def draw_faults(campaign: Campaign, scenario: scen.Scenario, seed: int) -> list[FaultSpec | None]:
    """Each fault entry's draw for the run of seed ``seed`` (see module docstring): the fault, or None
    when the run does not have it; ValueError naming the entry when the scenario's hardware cannot
    have it."""
    hardware = Hardware.of(scenario.spacecraft.n_wheels, scenario.sensors)
    out = []
    for k, entry in enumerate(campaign.faults):
        problem = entry.problem(hardware)
        if problem:
            raise ValueError(problem.phrase(f"campaign.faults[{k}]."))
        occurs, where = np.random.default_rng(np.random.SeedSequence(seed, spawn_key=(FAULT_STREAM, k))).random(2)
        low, high = entry.window_s
        out.append(entry.spec(low + where * (high - low)) if occurs < entry.probability else None)
    return out


def _tilted(axes: np.ndarray, tilts_rad: np.ndarray) -> np.ndarray:
    """Each unit column of ``axes`` turned by its two tilts about two axes perpendicular to it."""
    out = np.empty_like(axes)
    for i, (a, b) in enumerate(tilts_rad.reshape(-1, 2)):
        e1, e2 = rot.orthonormal_basis(axes[:, i])
        out[:, i] = rot.dcm_NB(rot.exp_map(a * e1 + b * e2)) @ axes[:, i]
    return out


@dataclass(frozen=True)
class Truth:
    """The dispersed truth of one run: the scenario the simulator integrates, its start and seed."""

    scenario: scen.Scenario
    q0: np.ndarray
    omega0: np.ndarray
    seed: int
    faults: tuple = ()          # FaultSpec: the faults drawn for the run (source: dispersion)


def truth(scenario: scen.Scenario, values: dict, seed: int, q0=rot.IDENTITY, omega0=(0.0, 0.0, 0.0)) -> Truth:
    """``scenario`` with the applied ``values`` (:func:`draw`) and the nominal start ``q0``,
    ``omega0`` dispersed; ValueError naming the seed when the draw is not physical or a dispersion
    has nothing to act on."""
    zero = {name: np.zeros(DISPERSIONS[name][0](scenario.spacecraft)) for name in DISPERSIONS}
    v = {**zero, **values}
    if "epoch_offset_s" in values:
        if scenario.epoch is None:
            raise ValueError(f"epoch_offset_s: scenario '{scenario.name}' has no epoch, so an epoch offset would "
                             f"change nothing")
        scenario = scen.with_epoch(scenario, scenario.epoch + timedelta(seconds=float(v["epoch_offset_s"][0])))
    sc, actuators, environment = scenario.spacecraft, scenario.actuators, scenario.environment
    moments, axes = np.linalg.eigh(sc.inertia)
    turn = rot.dcm_NB(rot.exp_map(v["inertia_rotation_deg"] * DEG)) @ axes
    inertia = turn @ np.diag(moments * (1.0 + v["inertia_scale"])) @ turn.T
    inertia = 0.5 * (inertia + inertia.T)
    problem = inertia_problem(inertia)
    if problem is not None:
        raise ValueError(f"run seed {seed}: the dispersed inertia is not a rigid body's: expected {problem}; narrow "
                         f"inertia_scale or inertia_rotation_deg (a non-physical draw is refused, never resampled)")
    wheel_inertia = sc.wheel_inertia * (1.0 + float(v["wheel_inertia_scale"][0]))
    if wheel_inertia < 0:
        raise ValueError(f"run seed {seed}: the dispersed wheel inertia {wheel_inertia:.6g} is negative")
    sc = replace(sc, inertia=inertia, wheel_axes=_tilted(sc.wheel_axes, v["wheel_misalignment_deg"] * DEG),
                 wheel_inertia=wheel_inertia)
    if "wheel_torque_scale" in values:
        scale = 1.0 + v["wheel_torque_scale"]
        if np.any(scale < 0):
            raise ValueError(f"run seed {seed}: a wheel torque scale factor is negative ({scale.min():.6g})")
        actuators = replace(actuators, wheels=replace(actuators.wheels or WheelDriveSpec(), torque_scale=tuple(scale)))
    if "magnetorquer_scale" in values:
        if not sc.dipole_max > 0:
            raise ValueError(f"magnetorquer_scale: scenario '{scenario.name}' has no magnetorquers")
        scale = 1.0 + v["magnetorquer_scale"]
        if np.any(scale < 0):
            raise ValueError(f"run seed {seed}: a magnetorquer scale factor is negative ({scale.min():.6g})")
        actuators = replace(actuators, magnetorquers=replace(actuators.magnetorquers or MagnetorquerSpec(),
                                                             scale=tuple(scale)))
    if "com_offset_m" in values:
        if not (environment.get("solar_pressure") or environment.get("drag")):
            raise ValueError(f"com_offset_m: scenario '{scenario.name}' has no solar pressure or drag, so a centre "
                             f"of mass offset would change nothing")
        offset = v["com_offset_m"]
        environment = {**environment, "facets": [replace(f, center_B=tuple(np.asarray(f.center_B) - offset))
                                                 for f in environment["facets"]]}
    q = rot.multiply(np.asarray(q0, float), rot.exp_map(v["initial_attitude_error_deg"] * DEG))
    dispersed = replace(scenario, spacecraft=sc, actuators=actuators, environment=environment)
    return Truth(dispersed, q, np.asarray(omega0, float) + v["initial_rate_error_rad_s"], seed)


def seed_truth(campaign: Campaign, scenario: scen.Scenario, seed: int, q0=rot.IDENTITY,
               omega0=(0.0, 0.0, 0.0)) -> tuple[Truth, dict]:
    """The run of seed ``seed`` of ``campaign`` on ``scenario``: its truth (with the faults drawn for it)
    and applied values (each fault entry's onset ``fault_t_s[k]``, NaN when the run does not have it)."""
    values = draw(campaign, scenario, seed)
    faults = draw_faults(campaign, scenario, seed)
    run = replace(truth(scenario, values, seed, q0, omega0), faults=tuple(f for f in faults if f is not None))
    if faults:
        values = {**values, "fault_t_s": np.array([math.nan if f is None else f.t_s for f in faults])}
    return run, values
