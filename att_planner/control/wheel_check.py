"""The active wheel check (no ROS, pure): a known torque pattern along the wheels' null space.

In a quiet hold the controller asks each wheel only a zero-mean net torque of a few 1e-3 N m (its rate
gain on the gyro's noise): a seized wheel, a wheel off or a wheel with abnormal friction cannot be told
from a healthy one within seconds from its tachometer (:mod:`att_planner.fdir.wheel_health`, "What no
test on the speeds can see in a quiet hold"). With more wheels than body axes the mounting matrix ``G``
(3 × N) has a null space, ``G n = 0``: motor torques along ``n`` spin the wheels against each other and
put no torque on the body. So, as an auxiliary input for active fault diagnosis (Niemann 2006, IEEE TAC
51(9), "A setup for active fault diagnosis"), the controller adds to the wheel torques it allocates

    ``δu(t) = s(t) A n̂``,   ``s(t) = sign cos(2π t / P)``   (+1 at ``cos = 0``),

``n̂`` the unit null vector of the *healthy* wheels' columns (:func:`null_vector`: the failed wheels'
entries zero; the first right singular vector of the null space when there are several; none with
fewer than four healthy wheels, none for three wheels), ``A`` the amplitude (N m per unit null
vector) and ``P`` the period: a zero-mean ± square wave whose integral, each wheel's commanded speed
change, is a zero-mean triangle of ``± A |n̂_i| P / (4 I_w)`` (the pyramid's ``n̂ = (1, −1, 1, −1)/2``:
``± A P / (8 I_w)``). Every wheel gets a known, sizeable commanded speed change that a seized wheel,
a wheel off or one braked by abnormal friction does not follow (:mod:`att_planner.fdir.wheel_check`).

The excitation is scaled down as a whole (:func:`excite`) to the headroom the demand leaves under each
wheel's torque limit, so it never clips a wheel (a clipped null-space torque would leak onto the body)
and a saturated demand keeps priority. What the body feels is what the drives do not deliver as
commanded: a drive gain within ``1 ± a`` and a wheel axis tilted by ``δ`` leave at most
``(a + δ) A Σ|n̂_i|`` (``a`` = 0.1: 0.04 N m for the shipped ``A`` = 0.2 N m on the pyramid, if every
drive's error lined up), a square wave of period ``P`` the attitude law rejects: on the leo_pyramid body
(3000 kg m² and more) its half period moves the rate by under ``0.04 · P/2 / 3000`` = 2.7e-5 rad/s, the
attitude by a few arcsec before the feedback (measured in the faults bench's fault-free flights: the
commit that shipped it). It is flown in the pointing modes and plan tracking (and the hold after it),
never in safe mode, magnetorquer modes or idle.
"""
from __future__ import annotations

import math
from dataclasses import dataclass
from functools import lru_cache

import numpy as np


def null_vector(wheel_axes, healthy=None) -> np.ndarray | None:
    """The unit null vector (N) of the ``healthy`` columns of ``wheel_axes`` (3 × N; None: every wheel),
    the other wheels' entries zero, sign fixed by its largest entry positive; None without a null space
    (fewer than four healthy wheels, or axes of rank 3 in as many wheels)."""
    G = np.ascontiguousarray(wheel_axes, float)
    n = G.shape[1]
    mask = (True,) * n if healthy is None else tuple(bool(h) for h in healthy)
    v = _null_vector(G.tobytes(), n, mask)
    return None if v is None else v.copy()


@lru_cache(maxsize=32)
def _null_vector(axes: bytes, n: int, healthy: tuple) -> np.ndarray | None:
    G = np.frombuffer(axes).reshape(3, n)
    mask = np.asarray(healthy, bool)
    if mask.sum() < 4:
        return None
    Gh = G[:, mask]
    _, s, vt = np.linalg.svd(Gh)
    rank = int(np.sum(s > 1e-9 * s.max())) if s.size else 0
    if vt.shape[0] <= rank:
        return None
    v = vt[rank]
    v = v if v[np.argmax(np.abs(v))] > 0 else -v
    out = np.zeros(n)
    out[mask] = v / np.linalg.norm(v)
    return out


@dataclass(frozen=True)
class WheelCheck:
    """The check's pattern (module docstring): ``amplitude_Nm`` ``A`` per unit null vector, ``period_s`` ``P``."""

    amplitude_Nm: float
    period_s: float

    def sign(self, t: float) -> float:
        """``s(t) = sign cos(2π t / P)`` (+1 where the cosine is zero): the square wave at ``t``."""
        return 1.0 if math.cos(2.0 * math.pi * t / self.period_s) >= 0.0 else -1.0

    def torques(self, t: float, wheel_axes, healthy=None) -> np.ndarray | None:
        """``s(t) A n̂`` (N m per wheel), None without a null space on the healthy wheels."""
        n = null_vector(wheel_axes, healthy)
        return None if n is None else self.sign(t) * self.amplitude_Nm * n


def excite(u, delta, limit: float) -> np.ndarray:
    """``u + λ δ`` with the largest ``λ ∈ [0, 1]`` that keeps every wheel within ``±limit`` (the
    excitation scaled as a whole, so it stays in the null space; ``u`` already within the limit)."""
    u, delta = np.asarray(u, float), np.asarray(delta, float)
    lam = 1.0
    for ui, di in zip(u, delta):
        if di > 0:
            lam = min(lam, max(limit - ui, 0.0) / di)
        elif di < 0:
            lam = min(lam, max(limit + ui, 0.0) / -di)
    return u + lam * delta
