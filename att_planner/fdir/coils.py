"""A magnetorquer coil that does not produce its commanded dipole (no ROS): an open coil.

The body's angular momentum about the centre of mass, in body axes, from what is measured:
``H_B = J ω + I_w G Ω`` (gyro rate ``ω``, the wheels' inertial spins ``Ω_i = ν_i + g_iᵀ ω`` from the
tachometers' relative speeds ``ν_i``), obeys ``Ḣ_B + ω × H_B = Σ_i α_i m_i (e_i × B) + τ_d``: coil
``i`` along body axis ``e_i`` commanded ``m_i`` (A m²) in the measured field ``B`` (T, body axes)
gives the fraction ``α_i`` of its torque (1 healthy, 0 open), ``τ_d`` the disturbances (gravity
gradient, pressure, drag, residual dipole). Over a window of ``window_s`` the disturbance is taken as
constant, so that with ``y(t) = H_B(t) − H_B(t_0) + ∫ ω × H_B dt`` and ``C_i(t) = ∫ m_i (e_i × B) dt``

    ``y(t) = Σ_i α_i C_i(t) + τ_d (t − t_0) + a + v(t)``,

``a`` the first sample's noise, ``v`` the momentum's white measurement noise, per body axis ``k``
``σ_H,k² = (J_kk σ_ω)² + (I_w σ_ν |G_k|)²`` (:func:`momentum_noise`: the gyro's sample noise
``σ_ω = σ_v √f`` on ``J ω``, the tachometers' ``σ_ν`` through the row ``G_k``). Each hypothesis
fixes ``α`` (every coil healthy: ``α = 1``; coil ``i`` open from an onset ``t_j`` in the window,
tried every :data:`ONSET_STEP_S`: ``α_i = 0`` from ``t_j``, the others 1) and leaves
the line ``a + τ_d (t − t_0)`` of each axis free; its residual sum of squares ``RSS`` is that of
``y − Σ α_k C_k`` with the line removed by least squares. The generalised likelihood ratio of coil
``i`` open against every coil healthy is ``GLR_i = max_j (RSS_healthy − RSS_i,j) / σ_H²`` (Willsky &
Jones 1976); the coil with the largest, above ``threshold``, for the persistence, is open. A coil's torque
is seen only through its variation against a line: a coil commanded a constant dipole in a constant
field cannot be told from the disturbance, and **a coil never commanded cannot be seen at all**
(``C_i = 0``: ``GLR_i = 0``). Assumptions: the disturbance constant over the window (its change over it far
below the commanded torque's variation), the inertia and wheel axes as declared, the field
measured at the coils (the magnetometer's bias a constant fraction of it), the dipole commanded over
each gyro interval the last one sent.
"""
from __future__ import annotations

import math
from collections import deque

import numpy as np

from att_planner.fdir.persistence import Persistence
from att_planner.fdir.status import Verdict
from att_sim.models import rotations as rot

DETECTOR = "coil_torque"
JUDGE_PERIOD_S = 0.5   # s between two fits of the window
ONSET_STEP_S = 2.0     # s between two onsets tried for a coil opening within the window


def momentum_noise(inertia_kg_m2, wheel_axes, wheel_inertia_kg_m2: float, gyro_arw_rad_sqrt_s: float,
                   gyro_rate_Hz: float, tachometer_noise_rad_s: float) -> np.ndarray:
    """``σ_H`` (N m s) per body axis of the momentum measured from one gyro and tachometer sample."""
    J = np.asarray(inertia_kg_m2, float).reshape(3, 3)
    G = np.asarray(wheel_axes, float).reshape(3, -1)
    sigma_omega = gyro_arw_rad_sqrt_s * math.sqrt(gyro_rate_Hz)
    wheels = wheel_inertia_kg_m2 * tachometer_noise_rad_s * np.linalg.norm(G, axis=1) if G.size else np.zeros(3)
    return np.hypot(np.sqrt(np.sum((J * sigma_omega) ** 2, axis=1)), wheels)


class CoilDetector:
    """The three coils from the momentum balance over a window (module docstring)."""

    def __init__(self, inertia_kg_m2, wheel_axes, wheel_inertia_kg_m2: float, sigma_H_Nms,
                 threshold: float, window_s: float, persistence_s: float):
        """``sigma_H_Nms``: the momentum's white measurement noise per body axis (:func:`momentum_noise`)."""
        self.sigma_H = np.broadcast_to(np.asarray(sigma_H_Nms, float), (3,)).copy()
        if not np.all(self.sigma_H > 0.0):
            raise ValueError(f"sigma_H_Nms (the momentum's measurement noise) must be > 0, got {sigma_H_Nms!r}")
        self.J = np.asarray(inertia_kg_m2, float).reshape(3, 3)
        self.G = np.asarray(wheel_axes, float).reshape(3, -1)
        self.I_w = float(wheel_inertia_kg_m2)
        self.threshold, self.window = threshold, window_s
        self.persistence = [Persistence(persistence_s) for _ in range(3)]
        self.declared = [False] * 3
        self.dipole = np.zeros(3)                       # A m², the last commanded
        self.field: np.ndarray | None = None            # T, the last measured
        self.speeds = np.zeros(self.G.shape[1])         # rad/s, the wheels' last relative speeds
        self.last_t: float | None = None
        self.next_judged = -math.inf
        self.samples: deque = deque()                   # (t, H_B, ∫ω×H, C (3 coils × 3))
        self.cross = np.zeros(3)
        self.commanded = np.zeros((3, 3))

    def on_dipole(self, t: float, dipole_Am2) -> list[Verdict]:
        d = np.asarray(dipole_Am2, float)
        self.dipole = d if d.shape == (3,) and np.all(np.isfinite(d)) else np.zeros(3)
        return []

    def on_field(self, t: float, field_B_T) -> list[Verdict]:
        self.field = np.asarray(field_B_T, float)
        return []

    def on_wheels(self, t: float, speeds_rad_s) -> list[Verdict]:
        s = np.asarray(speeds_rad_s, float)
        if s.shape == self.speeds.shape:
            self.speeds = s
        return []

    def on_gyro(self, t: float, omega_BN_B) -> list[Verdict]:
        """A gyro sample (the body rate over the interval ending at ``t``): the balance advanced to ``t``."""
        w = np.asarray(omega_BN_B, float)
        H = self.J @ w + self.I_w * self.G @ (self.speeds + self.G.T @ w)
        if self.last_t is None or self.field is None or not t > self.last_t:
            self.last_t = t if self.last_t is None or t > self.last_t else self.last_t
            return []
        dt = t - self.last_t
        self.last_t = t
        self.cross = self.cross + rot.cross(w, H) * dt
        self.commanded = self.commanded + self.dipole[:, None] * rot.hat(self.field) * dt   # row i: m_i (e_i × B)
        self.samples.append((t, H, self.cross.copy(), self.commanded.copy()))
        while len(self.samples) > 1 and self.samples[1][0] <= t - self.window + 1e-9:
            self.samples.popleft()
        if t - self.samples[0][0] < self.window - dt - 1e-9 or t < self.next_judged:
            return []
        self.next_judged = t + JUDGE_PERIOD_S - 1e-9
        return self._judge(t)

    def ratios(self) -> np.ndarray:
        """Each coil's GLR over the window (module docstring), the momenta whitened by ``σ_H``."""
        t = np.array([x[0] for x in self.samples])
        y = np.array([x[1] + x[2] for x in self.samples])
        C = np.array([x[3] for x in self.samples])                  # (M, coil, axis)
        dt, y, C = t[1:] - t[0], (y[1:] - y[0]) / self.sigma_H, (C[1:] - C[0]) / self.sigma_H
        Q, _ = np.linalg.qr(np.column_stack([np.ones_like(dt), dt]))

        def rss(r):                                                  # (M, 3): the line of each axis removed
            return float(np.sum((r - Q @ (Q.T @ r)) ** 2))

        healthy = y - C.sum(axis=1)
        base = rss(healthy)
        glr = np.zeros(3)
        step = max(int(round(ONSET_STEP_S * (len(dt) - 1) / max(dt[-1] - dt[0], 1e-9))), 1)
        onsets = range(0, len(dt) - 1, step)
        for i in range(3):
            if not np.any(C[-1, i]):
                continue                                             # never commanded in the window: not seen
            glr[i] = max(base - rss(healthy + np.where((np.arange(len(dt)) >= j)[:, None], C[:, i] - C[j, i], 0.0))
                         for j in onsets)
        return glr

    def _judge(self, t: float) -> list[Verdict]:
        if not np.any(self.samples[-1][3] - self.samples[0][3]):
            for p in self.persistence:                  # no coil commanded in the window: nothing to see
                p.update(False, t)
            return []
        glr = self.ratios()
        best = int(np.argmax(glr))
        out = []
        for i in range(3):
            p = self.persistence[i]
            if p.update(bool(i == best and glr[i] > self.threshold), t) and not self.declared[i]:
                self.declared[i] = True
                missing = float(np.linalg.norm(self.samples[-1][3][i] - self.samples[0][3][i]))
                out.append(Verdict(t, "magnetorquer", i, DETECTOR, f"coil {i} open explains the momentum over "
                                   f"{self.window:g} s better than every coil healthy: GLR {glr[i]:.4g} > "
                                   f"{self.threshold:g} (its commanded momentum {missing:.3g} N m s, the noise "
                                   f"{np.array2string(self.sigma_H, precision=3)} N m s) since t = {p.since:.3f} s",
                                   since=p.since))
        return out
