"""Imperfect actuators of the truth model: wheel drives with friction, quantisation, noise and a
torque–speed envelope; magnetorquers with quantisation and misalignment, each applying its
datasheet (:mod:`att_sim.models.actuator_specs`).

Wheel drive (per wheel, ``ν`` the speed relative to the body, ``u`` the commanded motor torque after
the torque limit): the command is quantised and given white noise once per control step (held), the
motor delivers at most ``P_max/|ν|`` while it speeds the wheel up (the back-EMF envelope of a
power-limited drive; braking is not limited), and friction opposes the spin::

    u_net = env(k Q(u) + ε, ν) − (c tanh(ν/ν_s) + b ν)

(Coulomb ``c`` smoothed over ``ν_s`` so the integration stays smooth through zero speed, viscous
``b``; Bialke 1998, "High fidelity mathematical modeling of reaction wheel performance"; the scale
factor ``k`` is 1 but in a Monte Carlo run's truth, :mod:`att_sim.truth.dispersions`). The planner's
model knows none of this: the controller compensates the friction it expects from measured wheel
speeds. Magnetorquers: ``m_applied = (I + M) Q(m)`` with misalignment ``M`` drawn
once (six small off-diagonal angles) and quantisation ``Q``.
"""
from __future__ import annotations

import math

import numpy as np

from att_sim.models.actuator_specs import MagnetorquerSpec, WheelDriveSpec
from att_sim.models.rotations import small_error_matrix


def quantize(value: np.ndarray, lsb) -> np.ndarray:
    """``value`` in whole multiples of ``lsb`` (0: unchanged); ``lsb`` a number, or a column of one
    per row (rows of runs)."""
    value = np.asarray(value, float)
    if np.ndim(lsb) == 0:
        return lsb * np.rint(value / lsb) if lsb > 0 else value
    return np.where(lsb > 0, lsb * np.rint(value / np.where(lsb > 0, lsb, 1.0)), value)


def _clip(value: float, limit: float) -> float:
    return min(max(value, -limit), limit)


class WheelDrive:
    """The wheel drives of one spacecraft (see module docstring)."""

    def __init__(self, spec: WheelDriveSpec, rng: np.random.Generator):
        self.spec, self.rng = spec, rng

    def hold(self, u: np.ndarray) -> np.ndarray:
        """The motor torques a command becomes for one step: quantised, scaled, with the drive's noise."""
        u = quantize(u, self.spec.torque_quantization)
        if self.spec.torque_scale:
            u = u * np.asarray(self.spec.torque_scale)
        return u + self.rng.standard_normal(len(u)) * self.spec.torque_noise

    def motor(self, u: list, speed: list) -> list:
        """Held torques ``u`` within the envelope at relative speeds ``speed`` (lists of floats:
        :func:`att_sim.models.dynamics.derivative` works on Python floats)."""
        power = self.spec.power_max
        if math.isinf(power):
            return list(u)
        return [_clip(u_k, power / max(abs(v), 1e-12)) if u_k * v > 0 else u_k for u_k, v in zip(u, speed)]

    def __call__(self, u: list, speed: list) -> list:
        """Net torques on the wheels (motor minus friction) at relative speeds ``speed``: what
        :func:`att_sim.models.dynamics.derivative` applies at each stage."""
        return [m - self.spec.friction_at(v) for m, v in zip(self.motor(u, speed), speed)]


class Magnetorquers:
    def __init__(self, spec: MagnetorquerSpec, rng: np.random.Generator):
        self.spec = spec
        self.transfer = small_error_matrix(rng, 0.0, spec.misalignment)

    def __call__(self, m: np.ndarray) -> np.ndarray:
        """The dipole the coils produce for the (saturated) command ``m``."""
        m = quantize(m, self.spec.quantization)
        return self.transfer @ (m * np.asarray(self.spec.scale) if self.spec.scale else m)


class MagnetorquersOfRuns:
    """:class:`Magnetorquers` of several runs on rows of runs (R × 3), the same operations per run
    (the transfer matrices as one stack: each run's product has its own bits)."""

    def __init__(self, coils: list[Magnetorquers]):
        self.lsb = np.array([[c.spec.quantization] for c in coils])
        self.scale = _per_run([c.spec.scale for c in coils], 1.0, 3)
        self.transfer = np.array([c.transfer for c in coils])

    def __call__(self, m: np.ndarray) -> np.ndarray:
        return (self.transfer @ (quantize(m, self.lsb) * self.scale)[:, :, None])[:, :, 0]


def _per_run(values: list, default: float, width: int) -> np.ndarray:
    """Rows of runs (R × width) of per-run tuples, ``default`` for an empty one."""
    return np.array([v if v else (default,) * width for v in values], float)


class DrivesOfRuns:
    """The wheel drives of several runs acting at once (:class:`att_sim.truth.lockstep.Lockstep`): the
    torques of :class:`WheelDrive` on arrays of runs — :meth:`hold` on rows of runs (R × wheels),
    the others one array per wheel — by the same operations element by element (the friction's
    ``tanh`` is ``math.tanh``, as one run's; a missing scale is a product by 1), so every run gets
    the bits its own drive gives it."""

    def __init__(self, drives: list[WheelDrive], n_wheels: int):
        specs = [d.spec for d in drives]
        self.rngs = [d.rng for d in drives]
        self.lsb = np.array([[s.torque_quantization] for s in specs])
        self.scale = _per_run([s.torque_scale for s in specs], 1.0, n_wheels)
        self.noise = np.array([[s.torque_noise] for s in specs])
        self.power = np.array([s.power_max for s in specs])
        self.unlimited = bool(np.all(np.isinf(self.power)))
        self.coulomb = np.array([s.coulomb_friction for s in specs])
        self.viscous = np.array([s.viscous_friction for s in specs])
        self.friction_speed = np.array([s.friction_speed for s in specs])

    def hold(self, u: np.ndarray, active: list[bool]) -> np.ndarray:
        """:meth:`WheelDrive.hold` of the runs whose watchdog is not tripped (``active``; the others'
        ``u`` unchanged, nothing drawn from their streams): quantised, scaled, plus each drive's noise."""
        noise = np.array([rng.standard_normal(u.shape[1]) if on else np.zeros(u.shape[1])
                          for rng, on in zip(self.rngs, active)])
        return np.where(np.array(active)[:, None], quantize(u, self.lsb) * self.scale + noise * self.noise, u)

    def motor(self, u: list, speed: list) -> list:
        """:meth:`WheelDrive.motor`: held torques within each run's envelope (an infinite power limit
        clips nothing)."""
        if self.unlimited:
            return list(u)
        out = []
        for u_k, v in zip(u, speed):
            limit = self.power / np.maximum(np.abs(v), 1e-12)
            out.append(np.where(u_k * v > 0, np.minimum(np.maximum(u_k, -limit), limit), u_k))
        return out

    def __call__(self, u: list, speed: list) -> list:
        """:meth:`WheelDrive.__call__`: net torques on the wheels, motor minus friction."""
        return [m - (self.coulomb * np.array([math.tanh(a) for a in (v / self.friction_speed).tolist()])
                     + self.viscous * v) for m, v in zip(self.motor(u, speed), speed)]
