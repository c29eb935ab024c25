"""Wheel health from the fraction of the commanded speed change each wheel delivers (no ROS).

The statistic of :mod:`att_planner.fdir.wheel_health` ("What no test on the speeds can see in a quiet
hold"), fitted on every wheel over a sliding window, made observable in a quiet hold by the active
wheel check's null-space excitation (:mod:`att_planner.control.wheel_check`). A wheel's inertial spin
rate ``Ω_i = ν_i + g_iᵀ ω_BN_B`` (tachometer ``ν_i``) obeys ``I_true Ω̇_i = s_i u_i − k_i f_i`` (drive
gain ``s_i``, friction ``k_i`` times the expected ``f_i``). With the commanded integrals
``U_k = ∫ u_i / I_w dt`` and ``F_k = ∫ f_i / I_w dt`` kept at each tachometer sample ``k``, the window's
samples are fitted by least squares

    ``Ω_k = c₀ + c₁ (t_k − t̄) + θ U_k − ψ F_k + v_k``,

the line absorbing the initial speed and a constant torque error, ``v_k`` the tachometer's white
noise ``σ_v`` (its datasheet noise and quantisation ``q/√12``): ``θ = s_i ρ``, ``ψ = k_i ρ`` with
``ρ = I_w / I_true``, and ``Cov(θ̂, ψ̂) = σ_v² (XᵀX)⁻¹`` (Kay 1993, Fundamentals of Statistical Signal
Processing I, §4.6; ``σ_θ = σ_v / √(Σ Ũ²)``, ``Ũ`` the part of ``U`` the other columns do not explain).
A healthy wheel (drive gain within ``1 ± a``, inertia within ``I_w (1 ± b)``) has
``θ ≥ θ_min = (1 − a)/(1 + b)`` and ``ψ ≤ ψ_max = 1/(1 − b)``; seized, ``θ = ψ = 0`` (its spin held);
off, ``θ = 0``; friction ``×k``, ``ψ = k ρ``. The wheel is judged on ``θ`` only when
``σ_θ ≤ (θ_min − threshold) / z`` (the window's commanded speed change is large enough that a healthy
wheel stays ``z`` standard deviations above the threshold) and on ``ψ`` only when
``σ_ψ ≤ (friction_threshold − ψ_max) / z``; it is faulty when ``θ̂ < threshold`` or
``ψ̂ > friction_threshold`` on a judged statistic, held for ``persistence_s``: wheel ``i`` is isolated.
Nothing is judged on a quiet wheel (no excitation: three wheels, safe mode), nor on a wheel whose
tachometer is declared frozen (:attr:`WheelCheckDetector.unread`). The fit is evaluated every
``evaluate_s`` (a quarter of a second) on the samples of the last ``window_s``.

A wheel at its torque limit is commanded what it can deliver (the controller clips and scales the
command, :func:`att_planner.control.wheel_check.excite`): saturation is not a fault here. A fault's
onset inside the window mixes the two regimes; ``θ̂`` crosses the threshold once about
``1 − threshold/θ`` of the window is past the onset.
"""
from __future__ import annotations

import numpy as np

from att_planner.fdir.persistence import Persistence
from att_planner.fdir.status import Verdict
from att_planner.fdir.wheel_health import SampleBuffer

DETECTOR = "wheel_check"
EVALUATE_S = 0.25


class WheelCheckDetector:
    """Per-wheel least-squares fraction of the commanded speed change delivered (module docstring)."""

    def __init__(self, n_wheels: int, wheel_inertia_kg_m2: float, sigma_rad_s: float, threshold: float,
                 friction_threshold: float, z: float, window_s: float, persistence_s: float, wheel_axes=None,
                 drive_gain_tolerance: float = 0.0, wheel_inertia_tolerance: float = 0.0,
                 evaluate_s: float = EVALUATE_S):
        a, b = drive_gain_tolerance, wheel_inertia_tolerance
        if not wheel_inertia_kg_m2 > 0 or not sigma_rad_s > 0:
            raise ValueError(f"wheel_inertia_kg_m2 and sigma_rad_s > 0, got {wheel_inertia_kg_m2!r}, {sigma_rad_s!r}")
        self.theta_min, self.psi_max = (1.0 - a) / (1.0 + b), 1.0 / (1.0 - b)
        if not 0.0 < threshold < self.theta_min or not friction_threshold > self.psi_max:
            raise ValueError(f"threshold in (0, {self.theta_min:.4g}) and friction_threshold above "
                             f"{self.psi_max:.4g}, got {threshold!r} and {friction_threshold!r}")
        self.n, self.inertia, self.sigma = n_wheels, wheel_inertia_kg_m2, sigma_rad_s
        self.threshold, self.friction_threshold, self.z = threshold, friction_threshold, z
        self.sigma_theta_max = (self.theta_min - threshold) / z
        self.sigma_psi_max = (friction_threshold - self.psi_max) / z
        self.window, self.evaluate = window_s, evaluate_s
        self.axes = None if wheel_axes is None else np.asarray(wheel_axes, float).reshape(3, n_wheels)
        self.persistence = [Persistence(persistence_s) for _ in range(n_wheels)]
        self.declared = [False] * n_wheels
        self.unread: set[int] = set()
        self.integrals = np.zeros((2, n_wheels))   # ∫ u / I_w dt, ∫ f / I_w dt (rad/s)
        self.last_t: float | None = None
        self.next_eval = -np.inf
        self.samples = SampleBuffer(n_wheels)      # t, inertial speeds, the two integrals

    def update(self, t: float, speeds_rad_s, torque_Nm, friction_Nm=None, omega_BN_B=None) -> list[Verdict]:
        """A tachometer sample (as :meth:`att_planner.fdir.wheel_health.WheelTorqueDetector.update`):
        the verdicts of the wheels declared at this sample."""
        speeds = np.asarray(speeds_rad_s, float)
        if self.axes is not None and omega_BN_B is not None:
            speeds = speeds + self.axes.T @ np.asarray(omega_BN_B, float)
        if self.last_t is not None and t > self.last_t:
            dt = (t - self.last_t) / self.inertia
            self.integrals[0] += np.asarray(torque_Nm, float) * dt
            if friction_Nm is not None:
                self.integrals[1] += np.asarray(friction_Nm, float) * dt
        self.last_t = t
        self.samples.append(t, speeds, self.integrals)
        self.samples.drop_before(t - self.window - 1e-9)
        if t < self.next_eval - 1e-9:
            return []
        self.next_eval = t + self.evaluate
        fit = self.fit()
        if fit is None:
            return []
        theta, psi, s_theta, s_psi = fit
        stuck = theta < self.threshold
        braked = psi > self.friction_threshold
        faulty = (stuck & (s_theta <= self.sigma_theta_max)) | (braked & (s_psi <= self.sigma_psi_max))
        out = []
        for i in range(self.n):
            if self.persistence[i].update(bool(faulty[i]) and i not in self.unread, t) and not self.declared[i]:
                self.declared[i] = True
                out.append(Verdict(t, "wheel", i, DETECTOR, f"wheel {i}: delivers {theta[i]:.3g} of its commanded "
                                   f"speed change (sigma {s_theta[i]:.2g}, threshold {self.threshold:g}) and "
                                   f"{psi[i]:.3g} times the expected friction (sigma {s_psi[i]:.2g}, threshold "
                                   f"{self.friction_threshold:g}) over {self.window:g} s",
                                   since=self.persistence[i].since))
        return out

    def fit(self) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray] | None:
        """``(θ̂, ψ̂, σ_θ, σ_ψ)`` per wheel over the kept window (module docstring); None until the window
        is nearly full (90 % of ``window_s`` and 8 samples)."""
        times, speeds, integrals = self.samples.views()
        if len(times) < 8 or times[-1] - times[0] < 0.9 * self.window:
            return None
        tc = times - times.mean()
        m = len(times)
        X = np.empty((self.n, m, 4))
        X[:, :, 0] = 1.0
        X[:, :, 1] = tc
        X[:, :, 2] = integrals[:, 0, :].T
        X[:, :, 3] = -integrals[:, 1, :].T
        scale = np.sqrt(np.einsum("wmk,wmk->wk", X, X)) + 1e-12      # columns to unit norm (conditioning)
        Xs = X / scale[:, None, :]
        XtX = np.einsum("wmk,wml->wkl", Xs, Xs) + 1e-12 * np.eye(4)
        Xty = np.einsum("wmk,mw->wk", Xs, speeds)
        inv = np.linalg.inv(XtX)
        beta = np.einsum("wkl,wl->wk", inv, Xty) / scale
        var = np.diagonal(inv, axis1=1, axis2=2) / scale ** 2
        sd = self.sigma * np.sqrt(np.maximum(var, 0.0))
        return beta[:, 2], beta[:, 3], sd[:, 2], sd[:, 3]
