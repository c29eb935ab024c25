"""Wheel health from the commanded against the measured wheel acceleration (no ROS).

A wheel's spin about its axis obeys ``I_w Ω̇_i = u_i − f_i`` (``u_i`` the motor torque commanded,
``f_i`` the drive friction expected at its speed, ``Ω_i = ν_i + g_iᵀ ω_BN_B`` its inertial spin rate
from the tachometer's speed ``ν_i`` relative to the body). The detector keeps, per wheel, the
residual speed ``r_i(t) = Ω_i(t) − ∫ (u_i − f_i) / I_w dt`` — constant but for the tachometer noise
while the wheel does what it is told — and compares the mean of ``r_i`` over the last ``window_s``
with its mean over the window before: ``τ_res,i = I_w (r̄_now − r̄_before) / (t̄_now − t̄_before)``
(``t̄`` the mean sample time of each window: exact for a residual that grows linearly) is the motor
torque the wheel did not deliver (a seized wheel, a wheel off, friction ``k`` times the expected).
``|τ_res,i| > threshold_Nm`` held for ``persistence_s`` isolates wheel ``i``. Averaging ``n``
samples of a tachometer of noise ``σ`` leaves ``√2 σ I_w / (√n window_s)`` of noise on ``τ_res``.

A wheel that is commanded no torque shows no residual when it is switched off: the detector sees
a fault only through torque that is asked and not delivered (or friction that is not expected).
"""
from __future__ import annotations

from collections import deque

import numpy as np

from att_planner.fdir.persistence import Persistence
from att_planner.fdir.status import Verdict

DETECTOR = "wheel_torque"


class WheelTorqueDetector:
    """Per-wheel residual torque between commanded and measured acceleration (module docstring)."""

    def __init__(self, n_wheels: int, wheel_inertia_kg_m2: float, threshold_Nm: float, persistence_s: float,
                 window_s: float, wheel_axes=None):
        """``wheel_axes``: the mounting matrix ``G`` (3 × n_wheels) to add the body rate's share to the
        relative speeds (None: the speeds are taken as the wheels' spin rates)."""
        if not wheel_inertia_kg_m2 > 0:
            raise ValueError(f"wheel_inertia_kg_m2 > 0, got {wheel_inertia_kg_m2!r}")
        self.n, self.inertia, self.threshold, self.window = n_wheels, wheel_inertia_kg_m2, threshold_Nm, window_s
        self.axes = None if wheel_axes is None else np.asarray(wheel_axes, float).reshape(3, n_wheels)
        self.persistence = [Persistence(persistence_s) for _ in range(n_wheels)]
        self.declared = [False] * n_wheels
        self.commanded = np.zeros(n_wheels)     # ∫ (u − f) / I_w dt, rad/s
        self.last_t: float | None = None
        self.samples: deque = deque()           # (t, residual speeds r)

    def update(self, t: float, speeds_rad_s, torque_Nm, friction_Nm=None, omega_BN_B=None) -> list[Verdict]:
        """A tachometer sample at ``t``: ``speeds_rad_s`` relative to the body (n), ``torque_Nm`` the
        motor torques commanded over the interval it ends (n), ``friction_Nm`` the drive friction
        expected over it (n; None: none), ``omega_BN_B`` the body rate (None: not added). The
        verdicts of the wheels declared at this sample."""
        speeds = np.asarray(speeds_rad_s, float)
        if self.axes is not None and omega_BN_B is not None:
            speeds = speeds + self.axes.T @ np.asarray(omega_BN_B, float)
        if self.last_t is not None and t > self.last_t:
            drive = np.asarray(torque_Nm, float) - (0.0 if friction_Nm is None else np.asarray(friction_Nm, float))
            self.commanded = self.commanded + drive / self.inertia * (t - self.last_t)
        self.last_t = t
        self.samples.append((t, speeds - self.commanded))
        while self.samples and self.samples[0][0] < t - 2.0 * self.window - 1e-9:
            self.samples.popleft()
        residual = self.residual_torque(t)
        if residual is None:
            return []
        out = []
        for i, tau in enumerate(residual):
            if self.persistence[i].update(abs(tau) > self.threshold, t) and not self.declared[i]:
                self.declared[i] = True
                out.append(Verdict(t, "wheel", i, DETECTOR, f"wheel {i}: {tau:+.4g} N m of motor torque not "
                                   f"delivered (measured minus commanded acceleration {tau / self.inertia:+.4g} "
                                   f"rad/s^2 over {self.window:g} s windows; threshold {self.threshold:g} N m)",
                                   since=self.persistence[i].since))
        return out

    def residual_torque(self, t: float) -> np.ndarray | None:
        """``τ_res`` (n, N m) at ``t``; None until two windows of samples are kept."""
        if len(self.samples) < 4 or self.samples[0][0] > t - 2.0 * self.window + 1e-9:
            return None
        times = np.array([s[0] for s in self.samples])
        values = np.array([s[1] for s in self.samples])
        now = times > t - self.window + 1e-9
        if now.all() or not now.any():
            return None
        span = times[now].mean() - times[~now].mean()
        return self.inertia * (values[now].mean(axis=0) - values[~now].mean(axis=0)) / span
