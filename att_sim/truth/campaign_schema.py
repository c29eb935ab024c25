"""The typed schema of a Monte Carlo campaign file (``campaigns/``): one mapping ``campaign:``.

The campaign names a scenario, its seed and run count, and the dispersions of the truth, each a
distribution (:class:`Normal` or :class:`Uniform`) drawn independently per component
(:mod:`att_sim.truth.dispersions`), and the hardware faults a run may have (:class:`FaultDispersion`:
a probability and an onset window each). Ranges and defaults are written once, here.
"""
from __future__ import annotations

import math
from typing import Annotated, ClassVar, Literal

from pydantic import Discriminator, Field, Tag, model_validator

from att_sim.models.config_base import Finite, Name, Schema, number
from att_sim.models.config_faults import MAX_FAULTS, MAX_ONSET_S, FaultKind

MAX_RUNS = 10_000_000


class Normal(Schema):
    """A normal distribution, optionally truncated at ``truncate`` sigmas (inverse CDF between the bounds)."""

    distribution: Literal["normal"]
    mean: Finite = Field(0.0, description="mean, in the dispersion's unit")
    sigma: float | None = number(None, ge=0.0, unit="the dispersion's", meaning="standard deviation")
    three_sigma: float | None = number(None, ge=0.0, unit="the dispersion's", meaning="three standard deviations")
    truncate: float = Field(math.inf, gt=0.0, description="kept within this many sigmas; .inf: not truncated")

    @model_validator(mode="after")
    def _one_spread(self):
        if (self.sigma is None) == (self.three_sigma is None):
            raise ValueError("exactly one of sigma, three_sigma")
        return self

    @property
    def standard_deviation(self) -> float:
        return self.sigma if self.sigma is not None else self.three_sigma / 3.0


class Uniform(Schema):
    distribution: Literal["uniform"]
    low: Finite = Field(description="lower bound, in the dispersion's unit")
    high: Finite = Field(description="upper bound, above low")

    @model_validator(mode="after")
    def _ordered(self):
        if not self.low < self.high:
            raise ValueError(f"low below high, got low {self.low:g} and high {self.high:g}")
        return self


def _distribution(value) -> str | None:
    return value.get("distribution") if isinstance(value, dict) else None


Distribution = Annotated[Annotated[Normal, Tag("normal")] | Annotated[Uniform, Tag("uniform")],
                         Discriminator(_distribution)]


class Dispersions(Schema):
    """Every dispersion a campaign may declare (the order of :data:`att_sim.truth.dispersions.DISPERSIONS`)."""

    renamed: ClassVar = {"initial_rate_error": "initial_rate_error_rad_s"}

    inertia_scale: Distribution | None = Field(None, description="relative error of each principal moment")
    inertia_rotation_deg: Distribution | None = Field(None, description="rotation vector of the principal axes")
    wheel_misalignment_deg: Distribution | None = Field(None, description="two tilts of each wheel axis")
    wheel_inertia_scale: Distribution | None = Field(None, description="relative error of the wheels' inertia")
    wheel_torque_scale: Distribution | None = Field(None, description="relative error of each drive's torque")
    magnetorquer_scale: Distribution | None = Field(None, description="relative error of each coil's dipole")
    com_offset_m: Distribution | None = Field(None, description="centre of mass offset, body")
    epoch_offset_s: Distribution | None = Field(None, description="the truth's epoch minus the flight software's")
    initial_attitude_error_deg: Distribution | None = Field(None, description="rotation vector of the initial "
                                                                              "attitude error, body")
    initial_rate_error_rad_s: Distribution | None = Field(None, description="initial body rate error")


class FaultDispersion(FaultKind):
    """A hardware fault a run may have: it occurs with ``probability``, its onset uniform in ``window_s``."""

    probability: float = number(ge=0.0, le=1.0, unit="", meaning="probability that a run has the fault")
    window_s: Annotated[list[Finite], Field(min_length=2, max_length=2)] = Field(
        description="[earliest, latest] onset (s of sim time), drawn uniformly between them")

    @model_validator(mode="after")
    def _window(self):
        low, high = self.window_s
        if not 0.0 <= low <= high <= MAX_ONSET_S:
            raise ValueError(f"window_s [earliest, latest] with 0 <= earliest <= latest <= {MAX_ONSET_S:g} s, got "
                             f"[{low:g}, {high:g}]")
        return self


class Campaign(Schema):
    renamed: ClassVar = {"converge_timeout": "converge_timeout_s"}

    scenario: Name = Field(description="the scenario flown: a name, config/scenarios/NAME.yaml")
    seed: int = Field(ge=0, le=2**63 - 1, description="campaign seed; run i's seed derives from it")
    runs: int = Field(100, ge=1, le=MAX_RUNS, description="default run count")
    settle_tolerance_deg: float = number(0.01, gt=0.0, le=180.0, unit="deg", meaning="settled: the error to the "
                                                                                     "goal stays below this")
    converge_timeout_s: float = number(30.0, gt=0.0, le=3600.0, unit="s", meaning="sim time for the estimate to "
                                                                                  "converge before the maneuver")
    dispersions: Dispersions = Field(default_factory=Dispersions)
    faults: list[FaultDispersion] = Field([], max_length=MAX_FAULTS, description="hardware faults drawn per run "
                                                                                "(att_sim.truth.faults)")


class CampaignFile(Schema):
    campaign: Campaign
