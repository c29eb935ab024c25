"""Hardware faults of the truth simulation: their catalogue, the typed ``faults`` entry of a scenario
(pydantic v2) and the one check of a fault against a spacecraft's hardware.

A fault is a component (``wheel``, ``star_tracker``, ``gyro``, ``magnetometer``, ``magnetorquer``),
an index (the wheel, star tracker, gyro axis or coil axis, 0-based; the one magnetometer is 0), a
kind valid for the component (:data:`KINDS`), the parameters its kind takes (:data:`PARAMETERS`:
``factor`` the friction multiplier, ``bias_rad`` a star tracker's bias rotation vector in its sensor
axes, ``bias_rad_s`` a gyro axis's bias step) and its onset ``t_s`` (sim time). The truth applies
it (:mod:`att_sim.truth.faults`); the flight side sees only its effects on the measurements. The
scenario's list, the simulator's ``/simulator/inject_fault`` service and a campaign's dispersions
are all checked by :func:`fault_problem`.
"""
from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Annotated, Literal, NamedTuple

from pydantic import Field, model_validator

from att_sim.models.config_base import Finite, Schema, Vector3

KINDS: dict[str, tuple[str, ...]] = {
    "wheel": ("seized", "off", "friction", "tachometer_stuck"),
    "star_tracker": ("outage", "bias_jump"),
    "gyro": ("axis_stuck", "bias_step"),
    "magnetometer": ("stuck",),
    "magnetorquer": ("coil_open",),
}
COMPONENTS = tuple(KINDS)
PARAMETERS: dict[str, str] = {"friction": "factor", "bias_jump": "bias_rad", "bias_step": "bias_rad_s"}
FACTOR_RANGE = (0.0, 1e3)           # friction multiplier k: 0 < k <= 1000
MAX_BIAS_RAD = math.pi              # rad: norm of a star tracker bias rotation
MAX_BIAS_RAD_S = 1.0                # rad/s: size of a gyro bias step
MAX_FAULTS = 64                     # faults of one scenario (and injected into one run)
MAX_ONSET_S = 1e9                   # s: latest onset time


@dataclass(frozen=True)
class Hardware:
    """What a spacecraft has that can fail: the counts the fault indices range over."""

    wheels: int
    star_trackers: int
    gyro: bool
    magnetometer: bool
    tachometer: bool

    @classmethod
    def of(cls, n_wheels: int, sensors) -> Hardware:
        """The hardware of a spacecraft of ``n_wheels`` wheels and the sensors ``sensors``
        (:class:`att_sim.models.sensor_specs.SensorSpecs`)."""
        return cls(wheels=n_wheels, star_trackers=len(sensors.star_trackers), gyro=sensors.gyro is not None,
                   magnetometer=sensors.magnetometer is not None, tachometer=sensors.tachometer is not None)

    def count(self, component: str, kind: str) -> tuple[int, str]:
        """How many ``component`` units a ``kind`` fault can name, and what they are called."""
        if component == "wheel":
            if kind == "tachometer_stuck" and not self.tachometer:
                return 0, "wheels with a tachometer"
            return self.wheels, "wheels"
        if component == "star_tracker":
            return self.star_trackers, "star trackers"
        if component == "gyro":
            return (3 if self.gyro else 0), "gyro axes"
        if component == "magnetometer":
            return int(self.magnetometer), "magnetometers"
        return 3, "magnetorquer coil axes"


@dataclass(frozen=True)
class FaultSpec:
    """A checked fault, its parameters filled (a kind's unused parameter at its neutral value)."""

    t_s: float
    component: str
    index: int
    kind: str
    factor: float = 1.0                                  # friction multiplier
    bias_rad: tuple[float, float, float] = (0.0, 0.0, 0.0)   # rad: star tracker bias rotation vector, sensor axes
    bias_rad_s: float = 0.0                              # rad/s: gyro bias step on its axis


class Problem(NamedTuple):
    """Why a fault cannot be: the field, what was expected and what was found."""

    field: str
    expected: str
    found: str

    def sentence(self) -> str:
        """A request's refusal: ``field: expected ...; found ...``."""
        return f"{self.field}: expected {self.expected}; found {self.found}"

    def phrase(self, prefix: str = "") -> str:
        """A configuration file's (the loader says what it expected): ``field ..., got ...``."""
        return f"{prefix}{self.field} {self.expected}, got {self.found}"


def fault_problem(component, index, kind, factor=None, bias_rad=None, bias_rad_s=None, t_s=0.0,
                  hardware: Hardware | None = None) -> Problem | None:
    """Why the fault is not one ``hardware`` can have (None when it is). A parameter is given (not
    None) for its kind and only for it; ``hardware`` None checks everything but the index's upper bound."""
    if not isinstance(component, str) or component not in KINDS:
        return Problem("component", f"one of {', '.join(COMPONENTS)}", repr(str(component)[:40]))
    if not isinstance(kind, str) or kind not in KINDS[component]:
        return Problem("kind", f"one of {', '.join(KINDS[component])} for a {component}", repr(str(kind)[:40]))
    if isinstance(index, bool) or not isinstance(index, int) or index < 0:
        return Problem("index", "a whole number >= 0", str(index)[:40])
    if hardware is not None:
        n, what = hardware.count(component, kind)
        if index >= n:
            return (Problem("index", f"below {n} (the spacecraft has {n} {what})", str(index)) if n else
                    Problem("component", f"hardware the spacecraft has for a {component} {kind} fault",
                            f"no {what}"))
    if not isinstance(t_s, (int, float)) or not (0.0 <= t_s <= MAX_ONSET_S):
        return Problem("t_s", f"a finite sim time in [0, {MAX_ONSET_S:g}] s", str(t_s))
    wanted = PARAMETERS.get(kind)
    for name, value in (("factor", factor), ("bias_rad", bias_rad), ("bias_rad_s", bias_rad_s)):
        if value is None and name == wanted:
            return Problem(name, f"a value for a {kind} fault", "none")
        if value is not None and name != wanted:
            return Problem(name, f"none for a {kind} fault (it takes {wanted or 'no parameter'})", str(value)[:60])
    low, high = FACTOR_RANGE
    if factor is not None and not (low < factor <= high):
        return Problem("factor", f"a friction multiplier in ({low:g}, {high:g}]", str(factor))
    if bias_rad is not None:
        if len(bias_rad) != 3 or not all(math.isfinite(v) for v in bias_rad):
            return Problem("bias_rad", "3 finite numbers (a rotation vector, rad)", str(list(bias_rad)[:6]))
        norm = math.sqrt(sum(v * v for v in bias_rad))
        if not (0.0 < norm <= MAX_BIAS_RAD):
            return Problem("bias_rad", f"a rotation of norm in (0, {MAX_BIAS_RAD:.6g}] rad", f"norm {norm:.6g}")
    if bias_rad_s is not None and not (0.0 < abs(bias_rad_s) <= MAX_BIAS_RAD_S):
        return Problem("bias_rad_s", f"a non-zero step of at most {MAX_BIAS_RAD_S:g} rad/s in size", str(bias_rad_s))
    return None


def spec(component: str, index: int, kind: str, factor=None, bias_rad=None, bias_rad_s=None,
         t_s: float = 0.0) -> FaultSpec:
    """The :class:`FaultSpec` of checked values (the unused parameters neutral)."""
    return FaultSpec(t_s=float(t_s), component=component, index=int(index), kind=kind,
                     factor=1.0 if factor is None else float(factor),
                     bias_rad=(0.0, 0.0, 0.0) if bias_rad is None else tuple(float(v) for v in bias_rad),
                     bias_rad_s=0.0 if bias_rad_s is None else float(bias_rad_s))


class FaultKind(Schema):
    """What fails and how: a component, its index, a kind valid for it and the parameters of the kind."""

    component: Literal[COMPONENTS] = Field(description="the failing component")
    index: int = Field(0, ge=0, le=63, description="wheel, star tracker, gyro axis or coil axis (0-based)")
    kind: str = Field(description="the fault: " + "; ".join(f"{c}: {', '.join(k)}" for c, k in KINDS.items()))
    factor: float | None = Field(None, description="friction multiplier k in (0, 1000] (kind friction only)")
    bias_rad: Vector3 | None = Field(None, description="star tracker bias rotation vector, sensor axes, norm in "
                                                       "(0, pi] (rad; kind bias_jump only)")
    bias_rad_s: Finite | None = Field(None, description="gyro bias step on the axis, non-zero, at most 1 in size "
                                                        "(rad/s; kind bias_step only)")

    @model_validator(mode="after")
    def _consistent(self):
        problem = self.problem()
        if problem:
            raise ValueError(problem.phrase())
        return self

    def problem(self, hardware: Hardware | None = None) -> Problem | None:
        """:func:`fault_problem` of this entry (on ``hardware``, when given)."""
        return fault_problem(self.component, self.index, self.kind, self.factor, self.bias_rad, self.bias_rad_s,
                             getattr(self, "t_s", 0.0), hardware)

    def spec(self, t_s: float | None = None) -> FaultSpec:
        """The fault starting at ``t_s`` (default: the entry's own onset)."""
        onset = getattr(self, "t_s", 0.0) if t_s is None else t_s
        return spec(self.component, self.index, self.kind, self.factor, self.bias_rad, self.bias_rad_s, onset)


class Fault(FaultKind):
    """One entry of a scenario's ``faults`` list: a hardware fault the truth starts at ``t_s``."""

    t_s: Annotated[Finite, Field(ge=0.0, le=MAX_ONSET_S)] = Field(description="sim time of the onset (s)")
