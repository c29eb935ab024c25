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

from functools import cached_property

import numpy as np

from att_sim.models.actuator_specs import MagnetorquerSpec, WheelDriveSpec, friction_torque
from att_sim.models.rotations import small_error_matrix


def quantize(value: np.ndarray, lsb) -> np.ndarray:
    """``value`` in whole multiples of ``lsb`` (0: unchanged); ``lsb`` a number, or a column of one
    per row (rows of runs)."""
    value = np.asarray(value, float)
    if np.ndim(lsb) == 0:
        return lsb * np.rint(value / lsb) if lsb > 0 else value
    return np.where(lsb > 0, lsb * np.rint(value / np.where(lsb > 0, lsb, 1.0)), value)


class WheelDrive:
    """The wheel drives of one spacecraft (see module docstring), or of the n runs of a batch stacked
    (:meth:`stack`): every method works on rows of runs (n, N) (one vector: a run of one), each
    run's parameters a row of columns, its noise from its own stream."""

    def __init__(self, spec: WheelDriveSpec, rng: np.random.Generator, n_wheels: int | None = None):
        width = n_wheels or len(spec.torque_scale) or 1
        self.rngs = [rng]
        self.lsb = np.array([[spec.torque_quantization]])
        self.scale = np.array([spec.torque_scale or (1.0,) * width], float)
        self.noise = np.array([[spec.torque_noise]])
        self.power = np.array([[spec.power_max]])
        self.friction_columns = tuple(np.array([[v]]) for v in (spec.coulomb_friction, spec.viscous_friction,
                                                                spec.friction_speed))

    @classmethod
    def stack(cls, drives: list[WheelDrive]) -> WheelDrive:
        """The drives of several runs as one (their rows in order; each keeps its own stream)."""
        out = cls.__new__(cls)
        out.rngs = [rng for d in drives for rng in d.rngs]
        for name in ("lsb", "scale", "noise", "power"):
            setattr(out, name, np.concatenate([getattr(d, name) for d in drives]))
        out.friction_columns = tuple(np.concatenate(c) for c in zip(*(d.friction_columns for d in drives)))
        return out

    @cached_property
    def unlimited(self) -> bool:
        """No drive is power-limited (:meth:`motor` clips nothing)."""
        return bool(np.all(np.isinf(self.power)))

    def hold(self, u: np.ndarray, active=None) -> np.ndarray:
        """The motor torques commands ``u`` become for one step: quantised, scaled, plus each drive's
        noise — for the runs whose watchdog is not tripped (``active``, one bool per row; None: all);
        the others' ``u`` unchanged, nothing drawn from their streams."""
        u = np.asarray(u, float)
        width = u.shape[-1]
        if active is None:
            noise = np.array([rng.standard_normal(width) for rng in self.rngs])
            return quantize(u, self.lsb) * self.scale + noise * self.noise
        noise = np.array([rng.standard_normal(width) if on else np.zeros(width) for rng, on in zip(self.rngs, active)])
        return np.where(np.asarray(active)[:, None], quantize(u, self.lsb) * self.scale + noise * self.noise, u)

    def motor(self, u: np.ndarray, speed: np.ndarray) -> np.ndarray:
        """Held torques ``u`` within each drive's envelope at relative speeds ``speed``: a motor speeding
        its wheel up (``u ν > 0``) delivers at most ``P_max/|ν|``."""
        if self.unlimited:
            return u
        limit = self.power / np.maximum(np.abs(speed), 1e-12)
        return np.where(u * speed > 0, np.minimum(np.maximum(u, -limit), limit), u)

    def __call__(self, u: np.ndarray, speed: np.ndarray) -> np.ndarray:
        """Net torques on the wheels (motor minus friction) at relative speeds ``speed``: what
        :func:`att_sim.models.dynamics.rates` applies at each stage."""
        return self.motor(u, speed) - friction_torque(*self.friction_columns, speed)


class Magnetorquers:
    """The coils of one spacecraft, or of the n runs of a batch stacked (:meth:`stack`), on rows (n, 3)."""

    def __init__(self, spec: MagnetorquerSpec, rng: np.random.Generator):
        self.lsb = np.array([[spec.quantization]])
        self.scale = np.array([spec.scale or (1.0, 1.0, 1.0)], float)
        self.transfer = small_error_matrix(rng, 0.0, spec.misalignment)[None]

    @classmethod
    def stack(cls, coils: list[Magnetorquers]) -> Magnetorquers:
        """The coils of several runs as one (their rows in order)."""
        out = cls.__new__(cls)
        for name in ("lsb", "scale", "transfer"):
            setattr(out, name, np.concatenate([getattr(c, name) for c in coils]))
        return out

    def __call__(self, m: np.ndarray) -> np.ndarray:
        """The dipoles the coils produce for the (saturated) commands ``m`` (rows)."""
        m = np.asarray(m, float).reshape(-1, 3)
        return (self.transfer @ (quantize(m, self.lsb) * self.scale)[:, :, None])[:, :, 0]
