"""Registry of the planning methods served by ``PlanManeuver``: name -> function and options.

Each entry names a pure function ``plan(problem, **options) -> ManeuverPlan`` and the options it
accepts with their ranges, so requests are validated before any numerics run. Methods whose
module is missing (optional dependency) are simply not offered.
"""
from __future__ import annotations

import importlib
from dataclasses import dataclass, field
from typing import Callable


@dataclass(frozen=True)
class Option:
    low: float
    high: float
    integer: bool = False


@dataclass(frozen=True)
class Method:
    name: str
    module: str
    function: str
    description: str
    options: dict = field(default_factory=dict)
    fixed: dict = field(default_factory=dict)     # keyword arguments always passed
    cheap: bool = False                           # closed form: run in-process, no child process

    def load(self) -> Callable:
        return getattr(importlib.import_module(self.module), self.function)


# Basis size, DPSS length and half-bandwidth of the Slepian methods (issue 3).
SLEPIAN_OPTIONS = {"M": Option(2, 12, True), "N": Option(50, 2000, True), "W": Option(1e-4, 0.25)}

# Best first: the default method is the first one available.
REGISTRY = [
    Method("slepian_minimum_time", "att_planner.slepian", "plan_slepian",
           "smooth torque on a Slepian basis, t_f minimised exactly (issue 3); cone-aware",
           SLEPIAN_OPTIONS,
           fixed={"method": "slepian_minimum_time"}),
    Method("time_optimal", "att_planner.time_optimal", "plan_time_optimal",
           "minimum-time bang-bang slew by direct collocation with IPOPT (Melton 2012); cone-aware",
           {"intervals": Option(4, 200, True), "max_intervals": Option(4, 400, True), "starts": Option(1, 20, True),
            "refine_rounds": Option(0, 6, True), "cone_margin_deg": Option(0.0, 5.0),
            "rate_max": Option(1e-6, 10.0), "wheel_momentum_max": Option(1e-6, 1e4),
            "smooth_warm_start": Option(0, 1, True)}),
    Method("constrained_axis", "att_planner.baselines", "plan_constrained_axis",
           "eigenaxis bang-bang, or lambda-rotations riding a cone boundary when the eigenaxis path is blocked",
           {"ride_margin_deg": Option(0.0, 10.0)}, cheap=True),
    Method("eigenaxis_smooth", "att_planner.eigenaxis", "plan_eigenaxis_smooth",
           "eigenaxis slew with a quintic angle profile (C1 rate, zero torque at both ends); ignores cones",
           {"samples": Option(11, 100_000, True)}, cheap=True),
    Method("eigenaxis", "att_planner.baselines", "plan_eigenaxis",
           "eigenaxis bang-bang slew with the largest torque the per-axis limits allow; ignores cones", cheap=True),
    Method("mssa", "att_planner.slepian", "plan_slepian",
           "Slepian basis, minimum sum of squared coefficients (Celani & Lucarelli); cone-aware",
           SLEPIAN_OPTIONS,
           fixed={"method": "mssa"}),
    Method("dfsp", "att_planner.slepian", "plan_slepian",
           "Slepian basis, derivative-free sequential penalty on t_f (Celani & Bruni); cone-aware, slow",
           SLEPIAN_OPTIONS,
           fixed={"method": "dfsp"}),
]


def available() -> dict[str, Method]:
    out = {}
    for m in REGISTRY:
        try:
            m.load()
        except (ImportError, AttributeError):
            continue
        out[m.name] = m
    return out
