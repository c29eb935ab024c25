"""The planning methods served by ``PlanManeuver``: name -> function, options and their ranges.

This registry is the only place option ranges are written. Each entry names a pure function
``plan(problem, **options) -> Plan`` (:mod:`att_planner.problem`), the options a request may give
with their ranges, and a per-method hook that refuses the combinations the method cannot run.
:meth:`Method.validate` applies all of it before any numerics run (``INVALID_OPTION``, 131).
Options marked ``limit`` are bounds of the maneuver, not tuning knobs: they become fields of the
problem (and are verified), the others are passed to the function.

A new method: write ``plan_<name>(problem, **options) -> Plan`` in a module of this package and
add an entry to :data:`REGISTRY` (its options, ranges and, if some combinations cannot run, a hook).
Entries travel to the planner's child processes, so they must pickle: hooks are module-level
functions, never lambdas. A method marked ``seeded`` takes ``warm_starts``, a tuple of plans to start
from: the planner service passes its first plan (:mod:`att_planner.service.planning`); time_optimal
adds the smooth plan and answers with none slower than a verified one of them
(:mod:`att_planner.methods.time_optimal.fastest`).
"""
from __future__ import annotations

import importlib
import math
from collections.abc import Callable
from dataclasses import dataclass, field, replace

from att_msgs_py.errors import ErrorCode, RequestError
from att_msgs_py.types import Plan


@dataclass(frozen=True)
class Option:
    low: float
    high: float
    integer: bool = False
    limit: bool = False          # a bound of the maneuver (the ManeuverProblem field of that name)
    doc: str = ""

    def label(self, name: str) -> str:
        return f"{name} ({self.doc})" if self.doc else name


@dataclass(frozen=True)
class Method:
    name: str
    module: str
    function: str
    description: str
    options: dict = field(default_factory=dict)
    fixed: dict = field(default_factory=dict)     # keyword arguments always passed
    cheap: bool = False                           # closed form: run in-process, no child process
    seeded: bool = False                          # takes ``warm_starts``: plans to start from (the first plan)
    # combinations the method cannot run: check(options with ``fixed``) -> why, of the ``combined`` options
    check: Callable[[dict], str | None] | None = None
    combined: tuple = ()
    paper: str = ""                               # the publication the method follows or reproduces

    def load(self) -> Callable:
        return getattr(importlib.import_module(self.module), self.function)

    def call(self, problem, **options) -> Plan:
        """The function on ``problem`` with the ``fixed`` arguments and ``options`` (already validated)."""
        return self.load()(problem, **self.fixed, **options)

    def validate(self, options: dict) -> dict:
        """The options converted (integers as int), or RequestError: unknown name, outside its
        range, not an integer, or a combination the hook refuses."""
        out = {}
        for name, value in options.items():
            spec = self.options.get(name)
            if spec is None:
                known = ", ".join(sorted(self.options)) or "none"
                raise RequestError(ErrorCode.INVALID_OPTION,
                                   f"option {name} is not an option of method '{self.name}' (known: {known})")
            value = float(value)
            if not math.isfinite(value) or not spec.low <= value <= spec.high:
                raise RequestError(ErrorCode.INVALID_OPTION,
                                   f"option {spec.label(name)} = {value} is outside [{spec.low}, {spec.high}]")
            if spec.integer and value != int(value):
                raise RequestError(ErrorCode.INVALID_OPTION, f"option {spec.label(name)} = {value} must be an integer")
            out[name] = int(value) if spec.integer else value
        why = self.check({**out, **self.fixed}) if self.check is not None else None
        if why:
            raise RequestError(ErrorCode.INVALID_OPTION, f"method '{self.name}' cannot run these options: {why}")
        return out

    def split(self, options: dict) -> tuple[dict, dict]:
        """Validated options as (keyword arguments of the function, maneuver limits)."""
        limits = {k: v for k, v in options.items() if self.options[k].limit}
        return {k: v for k, v in options.items() if k not in limits}, limits

    def run(self, problem, **options) -> Plan:
        """Validate ``options`` and plan: the registry's checks, then the function."""
        kwargs, limits = self.split(self.validate(options))
        return self.call(replace(problem, **limits), **kwargs)


def _slepian_check(options: dict) -> str | None:
    """:func:`att_planner.methods.slepian.planner.option_problem` (``options["method"]``: the variant)."""
    from att_planner.methods.slepian.planner import option_problem
    return option_problem(options)


def _time_optimal_check(options: dict) -> str | None:
    from att_planner.methods.time_optimal.planner import option_problem
    return option_problem(options)


def _slepian(variant: str, description: str, paper: str, seeded: bool = False) -> Method:
    return Method(variant, "att_planner.methods.slepian.planner", "plan_slepian", description, SLEPIAN_OPTIONS,
                  fixed={"method": variant}, check=_slepian_check, combined=("M", "N", "W"), seeded=seeded,
                  paper=paper)


# Bounds of the maneuver the collocation methods take as options.
_RATE_MAX = Option(1e-6, 10.0, limit=True, doc="rad/s per body axis")
_MOMENTUM_MAX = Option(1e-6, 1e4, limit=True, doc="N m s per wheel")
# Basis size, DPSS length and half-bandwidth of the Slepian methods.
SLEPIAN_OPTIONS = {"M": Option(2, 12, True, doc="basis size"), "N": Option(50, 2000, True, doc="samples"),
                   "W": Option(1e-4, 0.25, doc="half-bandwidth")}
# Collocation: mesh intervals, and the tightening of every zone at the collocation points.
_INTERVALS = Option(4, 200, True, doc="collocation intervals")
_CONE_MARGIN = Option(0.0, 5.0, doc="zone tightening at the collocation points, deg")
_CELANI_BRUNI = "Celani & Bruni (2021), smooth keep-out maneuvers on a Slepian basis"
_MELTON = "Melton (2012), time-optimal constrained reorientation by direct collocation"


# The forced boundary arc: the index of the request's cone whose boundary the sensor rides
# (at most 16 cones per request); a bound of the maneuver, checked against the cones by the service.
BOUNDARY_CONE = Option(0, 15, True, limit=True, doc="index of the cone whose boundary the sensor rides")

# Best first: the default method is the first one.
REGISTRY = [
    Method("smooth_collocation", "att_planner.methods.time_optimal.smooth", "plan_smooth_collocation",
           "minimum time with a C1 torque (its second derivative bounded; torque and its rate zero at both ends) "
           "by Hermite-Simpson collocation with IPOPT, started from the first plan; zone-aware",
           {"intervals": _INTERVALS, "torque_accel": Option(1.0, 1e4, doc="|d2T/dt2| in T/tu^2"),
            "cone_margin_deg": _CONE_MARGIN, "rate_max": _RATE_MAX, "wheel_momentum_max": _MOMENTUM_MAX},
           seeded=True, paper=_MELTON + ", with the torque a C1 state"),
    _slepian("slepian_minimum_time", "smooth torque on a Slepian basis, t_f minimised exactly; zone-aware",
             _CELANI_BRUNI + " (their basis and conventions)", seeded=True),
    Method("time_optimal", "att_planner.methods.time_optimal.planner", "plan_time_optimal",
           "minimum-time bang-bang slew by direct collocation with IPOPT (Melton 2012); zone-aware",
           {"intervals": _INTERVALS, "max_intervals": Option(4, 400, True, doc="intervals after mesh refinement"),
            "starts": Option(1, 20, True, doc="initial guesses solved"),
            "refine_rounds": Option(0, 6, True, doc="mesh refinement rounds"),
            "refine_split": Option(2, 8, True, doc="parts per refined interval"),
            "cone_margin_deg": _CONE_MARGIN, "rate_max": _RATE_MAX, "wheel_momentum_max": _MOMENTUM_MAX,
            "smooth_warm_start": Option(0, 1, True, doc="the smooth Slepian plan among the starts"),
            "global_stage": Option(0, 1, True, doc="particle swarm first"),
            "parallel_starts": Option(0, 1, True, doc="the starts on two cores (a forked child)"),
            "boundary_cone": BOUNDARY_CONE}, check=_time_optimal_check,
           # the smooth C1 plan among its starts: never slower than the smooth plan of the same request
           fixed={"smooth_seed": True}, combined=("intervals", "max_intervals"), seeded=True, paper=_MELTON),
    Method("constrained_axis", "att_planner.methods.constrained_axis", "plan_constrained_axis",
           "eigenaxis bang-bang, or lambda-rotations riding a zone boundary when the path is blocked",
           {"ride_margin_deg": Option(0.0, 10.0, doc="how far outside a zone boundary the sensor rides, deg"),
            "boundary_cone": BOUNDARY_CONE}, cheap=True),
    Method("graph_smooth", "att_planner.methods.graph_smooth", "plan_graph_smooth",
           "the constructive first plan: the quickest rest-to-rest legs round the zones on a graph of sensor "
           "directions (exact checks on every leg), C1 torque zero at every leg's ends; zone-aware", cheap=True),
    Method("eigenaxis_smooth", "att_planner.methods.eigenaxis", "plan_eigenaxis_smooth",
           "eigenaxis slew with a quintic angle profile (C1 rate, zero torque at both ends); ignores zones",
           # at most 5000 knots: a plan verified, signed and sent within its budget (+ 1 s)
           {"samples": Option(61, 5000, True, doc="knots of the linear torque profile")}, cheap=True),
    Method("eigenaxis", "att_planner.methods.eigenaxis", "plan_eigenaxis",
           "eigenaxis bang-bang slew with the largest torque the per-axis limits allow; ignores zones", cheap=True),
    _slepian("mssa", "Slepian basis, minimum sum of squared coefficients (Celani & Lucarelli); zone-aware",
             "Celani & Lucarelli, the MSSA method"),
    _slepian("dfsp", "Slepian basis, derivative-free sequential penalty on t_f (Celani & Bruni); zone-aware, slow",
             _CELANI_BRUNI + ", the DFSP method"),
]
METHODS = {m.name: m for m in REGISTRY}
# the methods that end a slew on a moving pointing mode (graph_smooth: the first plan's construction)
END_POINTING_METHODS = ("time_optimal", "smooth_collocation", "graph_smooth")


def get(name: str) -> Method:
    """The registered method ``name`` or RequestError UNKNOWN_METHOD."""
    method = METHODS.get(name)
    if method is None:
        raise RequestError(ErrorCode.UNKNOWN_METHOD,
                           f"method '{name[:128]}' is unknown (available: {', '.join(METHODS)})")
    return method


def run(name: str, problem, **options) -> Plan:
    """``get(name).run(problem, **options)``: plan with a registered method, options validated."""
    return get(name).run(problem, **options)
