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

    def load(self) -> Callable:
        return getattr(importlib.import_module(self.module), self.function)


# Best first: the default method is the first one available.
REGISTRY = [
    Method("eigenaxis_smooth", "att_planner.eigenaxis", "plan_eigenaxis_smooth",
           "eigenaxis slew with a quintic angle profile (C1 rate, zero torque at both ends); ignores cones",
           {"samples": Option(11, 100_000, True)}),
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
