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
(``C_i = 0``: ``GLR_i = 0``). A coil whose commanded momentum spans so little of the noise over the window
that an open coil's own ``GLR ≈ ‖C_i − C_i(t_j)‖²/σ_H²`` stays below a quarter of the threshold
(``N Σ_k span_k(C_i)²/σ_H,k² <`` :data:`VISIBLE` ``× threshold``: the active check's 0.05 s pulses) is
not fitted: any GLR it would reach is not its own. Assumptions: the disturbance constant over the window
(its change over it far below the commanded torque's variation), the inertia and wheel axes as declared, the field
measured at the coils (the magnetometer's bias a constant fraction of it), the dipole commanded over
each gyro interval the last one sent.

**The read-back of the active check** (:class:`Readback`, the table's ``check``). The momentum cannot
see a coil in time: a ± square wave of half-period ``P`` and torque ``τ = m |e_i × B|`` leaves in the
momentum a triangle of RMS ``τ P / (2√3)``, against the ``σ_H`` of 0.03–0.04 N m s per 20 Hz sample
on the axes ``e_0 × B`` lies in (the gyro's noise on ``J ω``), so that after ``T`` s ``GLR ≈ T f
(τ P)² / (12 σ_H²)``: 1.6 for the whole 50 A m² (``τ`` 1.5e-3 N m), ``P`` 10 s and ``T`` 30 s, far
below 30. The magnetometer sees the coils directly instead: it measures ``B̃ = B + k m_applied + n``
(``k`` the coupling of its datasheet, T per A m², along the applied dipole; ``n`` white, ``σ_m² =
σ_noise² + q²/12`` with its quantum ``q``), and the controller's check (:mod:`att_planner.control.coil_check`)
commands ``m`` on one coil over the dwell that ends at one magnetometer sample every period, the
coils in turn, each one's sign alternating; the other samples are taken with the coils off. On
magnetometer axis ``i`` over a window of ``window_s``, with ``x_i(t) = k m_i(t)`` (``m`` the dipole
last commanded before the sample)

    ``B̃_i(t) = α_i x_i(t) + c_0 + c_1 τ + c_2 τ² + n(t)``,

the quadratic (``τ`` the time from the window's middle) taking the field's own change (the orbit, a
slew) and the bias. Coil ``i`` open from the onset ``t_j`` (each check sample of coil ``i`` in the
window) sets ``α_i = 0`` from ``t_j``; with ``RSS`` the residual's sum of squares after the quadratic
is removed, over ``σ_m²``, ``GLR_i = max_j RSS(B̃_i − x_i) − RSS(B̃_i − x_i 1[t < t_j])`` (1 degree of
freedom; a check of ``a m_max`` = 25 A m² at ``k`` = 20 nT per A m² gives 500 nT, ``GLR`` ≈ 96 from one
sample). The magnetometer itself must still see: coil ``i`` is open only if another coil ``l`` was
read back after that onset, ``RSS(B̃_l − x_l 1[t < t_j]) − RSS(B̃_l − x_l) > threshold`` (a stuck or
lost magnetometer reads no coil back and blames none). A field that changes between two samples by more than
:data:`FIELD_JUMP_T` beyond the dipoles' read-back (the attitude reset, no slew turns it that fast) starts the
window again. Assumptions: ``k`` as declared (a 10 % error
leaves 1 % of the evidence), the field quadratic over the window, the dipole commanded the one applied
(an open coil is the only way it is not).
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
VISIBLE = 0.25         # a coil is fitted when N Σ_k (its C's span on axis k / σ_H,k)² reaches this × threshold
MIN_READBACK_SAMPLES = 8   # magnetometer samples in the window before the read-back is judged
FIELD_JUMP_T = 3e-6        # T between two samples beyond the dipoles' read-back: the attitude reset, a new window


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
                 threshold: float, window_s: float, persistence_s: float, readback: Readback | None = None):
        """``sigma_H_Nms``: the momentum's white measurement noise per body axis (:func:`momentum_noise`);
        ``readback``: the magnetometer's read-back of the active check (None: no check)."""
        self.readback = readback
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
        return self._undeclared(self.readback.on_dipole(t, self.dipole)) if self.readback is not None else []

    def on_field(self, t: float, field_B_T) -> list[Verdict]:
        self.field = np.asarray(field_B_T, float)
        return self._undeclared(self.readback.on_field(t, self.field)) if self.readback is not None else []

    def _undeclared(self, verdicts: list[Verdict]) -> list[Verdict]:
        out = [v for v in verdicts if not self.declared[v.index]]
        for v in out:
            self.declared[v.index] = True
        return out

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

    def ratios(self, judged=None) -> np.ndarray:
        """Each coil's GLR over the window (module docstring), the momenta whitened by ``σ_H``; ``judged``:
        a mask of the coils fitted (default every one; the others 0)."""
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
            if not np.any(C[-1, i]) or judged is not None and not judged[i]:
                continue                                             # never commanded in the window: not seen
            glr[i] = max(base - rss(healthy + np.where((np.arange(len(dt)) >= j)[:, None], C[:, i] - C[j, i], 0.0))
                         for j in onsets)
        return glr

    def _judge(self, t: float) -> list[Verdict]:
        C = np.array([x[3] for x in self.samples]) / self.sigma_H            # (M, coil, axis)
        visible = len(C) * np.sum(np.ptp(C, axis=0) ** 2, axis=1) >= VISIBLE * self.threshold
        if not visible.any():
            for p in self.persistence:                  # no coil commanded enough in the window: nothing to see
                p.update(False, t)
            return []
        glr = self.ratios(visible)
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


class Readback:
    """The magnetometer's read-back of the active check's dipoles (module docstring): ``coupling_T_per_Am2``
    the datasheet's ``k``, ``sigma_T`` the noise of a sample per axis, the threshold, window and persistence."""

    def __init__(self, coupling_T_per_Am2: float, sigma_T: float, threshold: float, window_s: float,
                 persistence_s: float):
        if not (coupling_T_per_Am2 > 0.0 and sigma_T > 0.0):
            raise ValueError(f"the coupling and the magnetometer noise must be > 0, got {coupling_T_per_Am2!r} and "
                             f"{sigma_T!r}")
        self.k, self.sigma, self.threshold, self.window = coupling_T_per_Am2, sigma_T, threshold, window_s
        self.persistence = [Persistence(persistence_s) for _ in range(3)]
        self.declared = [False] * 3
        self.commands: deque = deque(maxlen=256)       # (t, dipole A m²) as commanded
        self.pending: deque = deque(maxlen=64)         # (t, field T) not yet paired with its dipole
        self.samples: deque = deque()                  # (t, field T, dipole A m² in force at t)
        self.next_judged = -math.inf

    def on_dipole(self, t: float, dipole_Am2) -> list[Verdict]:
        """A command stamped ``t``: every field sample up to ``t`` now knows the dipole it was taken under."""
        if self.commands and t < self.commands[-1][0]:
            self._restart()
        self.commands.append((float(t), np.asarray(dipole_Am2, float).copy()))
        return self._settle(t)

    def on_field(self, t: float, field_B_T) -> list[Verdict]:
        f = np.asarray(field_B_T, float)
        if f.shape != (3,) or not np.all(np.isfinite(f)):
            return []
        if self.pending and t < self.pending[-1][0] or self.samples and t < self.samples[-1][0]:
            self._restart()
        self.pending.append((float(t), f.copy()))
        return self._settle(self.commands[-1][0]) if self.commands else []

    def _restart(self) -> None:
        """A new timeline (a simulation reset): the windows start again."""
        self.commands.clear()
        self.pending.clear()
        self.samples.clear()
        self.next_judged = -math.inf

    def _settle(self, t_command: float) -> list[Verdict]:
        """The pending samples stamped at or before the last command paired with the dipole in force
        (the last command stamped before each), then judged."""
        moved = False
        while self.pending and self.pending[0][0] <= t_command + 1e-9:
            ts, f = self.pending.popleft()
            before = [d for tc, d in self.commands if tc < ts - 1e-9]
            m = before[-1] if before else np.zeros(3)
            if self.samples:
                _, f0, m0 = self.samples[-1]
                jump = np.abs(f - self.k * m - f0 + self.k * m0) > FIELD_JUMP_T + self.k * (np.abs(m) + np.abs(m0))
                if jump.any():          # the field jumped (a simulation reset to another attitude): start again
                    self.samples.clear()
            self.samples.append((ts, f, m))
            moved = True
        if not moved or not self.samples:
            return []
        t = self.samples[-1][0]
        while self.samples and self.samples[0][0] < t - self.window + 1e-9:
            self.samples.popleft()
        if len(self.samples) < MIN_READBACK_SAMPLES or t < self.next_judged:
            return []
        self.next_judged = t + JUDGE_PERIOD_S - 1e-9
        return self._judge(t)

    def statistics(self) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """Per coil: ``GLR_i`` (module docstring), its onset (s; nan: no check sample of it in the window)
        and the evidence ``E_i(t_j)`` that coil ``i`` was read back from each onset ``t_j`` as a function
        (an array (3, M): coil, sample index of the onset)."""
        t = np.array([s[0] for s in self.samples])
        y = np.array([s[1] for s in self.samples]) / self.sigma              # (M, axis)
        x = self.k * np.array([s[2] for s in self.samples]) / self.sigma     # (M, coil = axis)
        tau = (t - 0.5 * (t[0] + t[-1])) / max(self.window, 1e-9)
        Q, _ = np.linalg.qr(np.column_stack([np.ones_like(tau), tau, tau**2]))

        def rss(r):
            return float(np.sum((r - Q @ (Q.T @ r)) ** 2))

        glr, onset = np.zeros(3), np.full(3, math.nan)
        seen = np.full((3, len(t)), -math.inf)
        for i in range(3):
            r = y[:, i] - x[:, i]
            base = rss(r)
            for j in np.flatnonzero(x[:, i]):
                after = np.where(np.arange(len(t)) >= j, x[:, i], 0.0)
                e = rss(r + after) - base
                seen[i, j] = e
                if -e > glr[i]:
                    glr[i], onset[i] = -e, t[j]
            seen[i] = np.maximum.accumulate(seen[i][::-1])[::-1]           # from any check at or after
        return glr, onset, seen

    def _judge(self, t: float) -> list[Verdict]:
        glr, onset, seen = self.statistics()
        times = np.array([s[0] for s in self.samples])
        best = int(np.argmax(glr))
        others = -math.inf
        if glr[best] > self.threshold:
            j = int(np.searchsorted(times, onset[best] - 1e-9))
            others = max(float(seen[i, j]) for i in range(3) if i != best)
        out = []
        for i in range(3):
            p = self.persistence[i]
            holds = i == best and glr[i] > self.threshold and others > self.threshold
            if p.update(holds, t) and not self.declared[i]:
                self.declared[i] = True
                expected = self.k * max((abs(float(s[2][i])) for s in self.samples), default=0.0) * 1e9
                out.append(Verdict(t, "magnetorquer", i, DETECTOR, f"coil {i} open: the magnetometer does not read "
                                   f"back its check dipole ({expected:.4g} nT expected on axis {i}, noise "
                                   f"{self.sigma * 1e9:.3g} nT) since t = {onset[i]:.3f} s: GLR {glr[i]:.4g} > "
                                   f"{self.threshold:g}, while another coil is read back ({others:.4g})",
                                   since=p.since))
        return out
