"""Wheel health from the commanded against the measured wheel acceleration (no ROS).

A wheel's spin about its axis obeys ``I_w Ω̇_i = u_i − f_i`` (``u_i`` the motor torque commanded,
``f_i`` the drive friction expected at its speed, ``Ω_i = ν_i + g_iᵀ ω_BN_B`` its inertial spin rate
from the tachometer's speed ``ν_i`` relative to the body). The detector keeps, per wheel, the
residual speed ``r_i(t) = Ω_i(t) − ∫ (u_i − f_i) / I_w dt`` — constant but for the tachometer noise
while the wheel does what it is told — and compares the mean of ``r_i`` over the last ``window_s``
with its mean over the window before: ``τ_res,i = I_w (r̄_now − r̄_before) / (t̄_now − t̄_before)``
(``t̄`` the mean sample time of each window: exact for a residual that grows linearly) is the motor
torque the wheel did not deliver (a seized wheel, a wheel off, friction ``k`` times the expected).
Averaging ``n`` samples of a tachometer of noise ``σ`` leaves ``√2 σ I_w / (√n window_s)`` of noise on
``τ_res``.

**Drive and inertia tolerances.** A healthy wheel does not deliver exactly ``(u_i − f_i) / I_w``: its
drive's torque gain ``s_i`` (delivered over commanded motor torque) lies within ``1 ± a`` and its spin
inertia ``I_true`` within ``I_w (1 ± b)``, so its acceleration is ``(s_i u_i − f_i) / I_true`` and, with
``ρ = I_w / I_true``,

    ``τ_res,i = ρ (s_i − 1) u_i + (ρ − 1)(u_i − f_i)``,   ``|ρ| ≤ 1/(1 − b)``, ``|ρ − 1| ≤ b/(1 − b)``.

The difference of the window means is a weighted mean of the residual torque over the two windows
with non-negative weights summing to one (a triangle peaking between them); the same weighted mean
of ``|u_i|`` and ``|u_i − f_i|`` (kept as ``∫|u_i| dt`` and ``∫|u_i − f_i| dt`` beside the residual),
``ū_i`` and ``n̄_i``, bounds a healthy wheel's residual whatever the signs of its commands. The test is

    ``|τ_res,i| > threshold_Nm + a/(1 − b) ū_i + b/(1 − b) n̄_i``

(``a = drive_gain_tolerance``, ``b = wheel_inertia_tolerance``; an adaptive threshold for a
multiplicative model uncertainty, Emami-Naeini, Akhter & Rock 1988, IEEE TAC 33(12)), held for
``persistence_s``: wheel ``i`` is isolated. The shipped table's ``a`` and ``b`` are the largest draws
of the Monte Carlo campaigns' ``wheel_torque_scale`` and ``wheel_inertia_scale`` (truncated normals),
so no dispersed healthy wheel can pass the bound. ``threshold_Nm`` covers the tachometer's noise and
what the drive adds to each command (its quantisation and noise). A fault makes the wheel deliver a
fraction far from one of what it is asked: seized (no net torque, its inertial spin held),
``τ_res = −(u_i − f_i)``; off, ``−u_i``; friction ``k`` times the expected, ``−(k − 1) f_i`` whatever
the command.

A wheel that is commanded no torque shows no residual when it is switched off, and a seized wheel
only the net torque ``u_i − f_i`` it is asked (nothing where the command only compensates the
friction): the detector sees a fault only through torque that is asked and not delivered (or friction
that is not expected), once that torque exceeds the test's bound. A wheel whose tachometer is declared
frozen (:attr:`WheelTorqueDetector.unread`) is not judged: its residual is the reading's fault, not the
wheel's.

**What no test on the speeds can see in a quiet hold.** Whatever the statistic, the evidence that a
wheel does not deliver its torque is the commanded speed change it fails to make. Over ``N`` samples
the best it can do is the least-squares fraction ``θ`` of the commanded net torque delivered, in
``Ω_k = c₀ + c₁ t_k + θ C_k + v_k`` (``C_k = ∫(u_i − f_i)/I_w dt``, the line absorbing a constant
friction or drive error, ``v_k`` the tachometer's white noise ``σ_v``): ``σ_θ = σ_v / √(Σ C̃_k²)``,
``C̃`` the part of ``C`` no line explains (Kay 1993, Fundamentals of Statistical Signal Processing I,
§4.6). A healthy wheel has ``θ ≥ (1 − a)/(1 + b)`` = 0.86, a seized one ``θ = 0``: they are told apart
at ``z`` standard deviations only once ``σ_θ < 0.86/z``. In the leo_pyramid nadir hold (the faults
bench: torque-free, the wheels within 0.1 rad/s of rest) the controller asks each wheel a zero-mean,
white net torque of 2.45e-3 N m rms (its rate gain on the gyro's noise), a random walk of
6e-4 rad/s per 20 Hz step in ``C`` against ``σ_v`` = 0.01 rad/s: measured over 4 and 5 s windows of
that flight, ``σ_θ`` = 0.35–1.6 (1st to 99th percentile, median 0.7–0.9; ``θ̂`` of the healthy wheels
−1.5 to 3.0, of wheel 1 seized −2.6 to 1.7).
A seized wheel there is not observable within 5 s at any false-alarm rate near the campaigns'
target, and its window residual (at most 4.4e-4 N m in the 10 s after the onset, against a healthy
1.5e-4 N m rms) stays under any bound with a false-alarm argument; a wheel off or with friction ×5
near rest loses only the friction-sized torque ``c tanh(ν/ν_s)`` ≤ 1e-3 N m, which the wheel's own
friction drives to zero within seconds. Seeing them in such a hold needs torque asked of the wheels
that the body does not feel (a null-space excitation, an auxiliary signal for detection) or wheels
biased away from rest. The active wheel check does the former: :mod:`att_planner.control.wheel_check`
excites the null space, :mod:`att_planner.fdir.wheel_check` fits ``θ`` (and the friction's multiple).
"""
from __future__ import annotations

import numpy as np

from att_planner.fdir.persistence import Persistence
from att_planner.fdir.status import Verdict

DETECTOR = "wheel_torque"


class WheelTorqueDetector:
    """Per-wheel residual torque between commanded and measured acceleration (module docstring)."""

    def __init__(self, n_wheels: int, wheel_inertia_kg_m2: float, threshold_Nm: float, persistence_s: float,
                 window_s: float, wheel_axes=None, drive_gain_tolerance: float = 0.0,
                 wheel_inertia_tolerance: float = 0.0):
        """``wheel_axes``: the mounting matrix ``G`` (3 × n_wheels) to add the body rate's share to the
        relative speeds (None: the speeds are taken as the wheels' spin rates); ``drive_gain_tolerance``
        ``a`` and ``wheel_inertia_tolerance`` ``b``: the relative tolerances of a healthy drive's torque
        gain and of the wheel's spin inertia (module docstring; 0: exact)."""
        if not wheel_inertia_kg_m2 > 0:
            raise ValueError(f"wheel_inertia_kg_m2 > 0, got {wheel_inertia_kg_m2!r}")
        if not 0.0 <= drive_gain_tolerance < 1.0 or not 0.0 <= wheel_inertia_tolerance < 1.0:
            raise ValueError(f"drive_gain_tolerance and wheel_inertia_tolerance in [0, 1), got "
                             f"{drive_gain_tolerance!r} and {wheel_inertia_tolerance!r}")
        self.n, self.inertia, self.threshold, self.window = n_wheels, wheel_inertia_kg_m2, threshold_Nm, window_s
        self.motor_tolerance = drive_gain_tolerance / (1.0 - wheel_inertia_tolerance)     # bounds |ρ (s − 1)|
        self.net_tolerance = wheel_inertia_tolerance / (1.0 - wheel_inertia_tolerance)    # bounds |ρ − 1|
        self.axes = None if wheel_axes is None else np.asarray(wheel_axes, float).reshape(3, n_wheels)
        self.persistence = [Persistence(persistence_s) for _ in range(n_wheels)]
        self.declared = [False] * n_wheels
        self.unread: set[int] = set()           # wheels whose speed reading is declared bad: not judged
        self.commanded = np.zeros(n_wheels)     # ∫ (u − f) / I_w dt, rad/s
        self.asked = np.zeros((2, n_wheels))    # ∫ |u| dt, ∫ |u − f| dt, N m s
        self.last_t: float | None = None
        self.samples = SampleBuffer(n_wheels)   # t, residual speeds r, ∫ |u| dt and ∫ |u − f| dt

    def update(self, t: float, speeds_rad_s, torque_Nm, friction_Nm=None, omega_BN_B=None) -> list[Verdict]:
        """A tachometer sample at ``t``: ``speeds_rad_s`` relative to the body (n), ``torque_Nm`` the
        motor torques commanded over the interval it ends (n), ``friction_Nm`` the drive friction
        expected over it (n; None: none), ``omega_BN_B`` the body rate (None: not added). The
        verdicts of the wheels declared at this sample."""
        speeds = np.asarray(speeds_rad_s, float)
        if self.axes is not None and omega_BN_B is not None:
            speeds = speeds + self.axes.T @ np.asarray(omega_BN_B, float)
        if self.last_t is not None and t > self.last_t:
            torque = np.asarray(torque_Nm, float)
            drive = torque - (0.0 if friction_Nm is None else np.asarray(friction_Nm, float))
            self.commanded = self.commanded + drive / self.inertia * (t - self.last_t)
            self.asked = self.asked + np.abs([torque, drive]) * (t - self.last_t)
        self.last_t = t
        self.samples.append(t, speeds - self.commanded, self.asked)
        self.samples.drop_before(t - 2.0 * self.window - 1e-9)
        means = self.window_means(t)
        if means is None:
            return []
        residual, bound = means[0], self.bound(means[1], means[2])
        out = []
        for i, tau in enumerate(residual):
            if self.persistence[i].update(abs(tau) > bound[i] and i not in self.unread, t) and not self.declared[i]:
                self.declared[i] = True
                out.append(Verdict(t, "wheel", i, DETECTOR, f"wheel {i}: {tau:+.4g} N m of motor torque not "
                                   f"delivered (measured minus commanded acceleration {tau / self.inertia:+.4g} "
                                   f"rad/s^2 over {self.window:g} s windows; bound {bound[i]:.4g} N m for "
                                   f"{means[1][i]:.4g} N m of motor torque asked, {means[2][i]:.4g} N m net)",
                                   since=self.persistence[i].since))
        return out

    def bound(self, motor_Nm, net_Nm) -> np.ndarray:
        """The largest ``|τ_res|`` of a healthy wheel (N m) asked the mean motor torque magnitude
        ``motor_Nm`` and net torque magnitude ``net_Nm``: ``threshold_Nm + a/(1 − b) ū + b/(1 − b) n̄``."""
        return self.threshold + self.motor_tolerance * np.asarray(motor_Nm) + self.net_tolerance * np.asarray(net_Nm)

    def window_means(self, t: float) -> tuple[np.ndarray, np.ndarray, np.ndarray] | None:
        """``(τ_res, ū, n̄)`` (n each, N m) at ``t``: the residual torque and the same weighted means of
        the commanded motor torque's and net torque's magnitudes (module docstring); None until two
        windows of samples are kept."""
        if len(self.samples) < 4 or self.samples.first_t() > t - 2.0 * self.window + 1e-9:
            return None
        times, values, asked = self.samples.views()
        k = int(np.searchsorted(times, t - self.window + 1e-9, side="right"))   # the samples in time order
        if k == 0 or k == len(times):
            return None
        span = times[k:].mean() - times[:k].mean()
        motor, net = (asked[k:].mean(axis=0) - asked[:k].mean(axis=0)) / span
        return self.inertia * (values[k:].mean(axis=0) - values[:k].mean(axis=0)) / span, motor, net

    def residual_torque(self, t: float) -> np.ndarray | None:
        """``τ_res`` (n, N m) at ``t``; None until two windows of samples are kept."""
        means = self.window_means(t)
        return None if means is None else means[0]


class SampleBuffer:
    """The detector's kept samples in preallocated arrays (no arrays rebuilt per sample): times,
    residual speeds (n) and the two torque integrals (2, n), appended at the end and dropped from the
    front; the live rows are moved to the start when the end is reached (the capacity doubled when
    they fill it), so :meth:`views` are contiguous slices in arrival order."""

    def __init__(self, n: int, capacity: int = 256):
        self.t = np.empty(capacity)
        self.r = np.empty((capacity, n))
        self.a = np.empty((capacity, 2, n))
        self.lo = self.hi = 0

    def __len__(self) -> int:
        return self.hi - self.lo

    def append(self, t: float, r: np.ndarray, a: np.ndarray) -> None:
        if self.hi == len(self.t):
            k = self.hi - self.lo
            if 2 * k > len(self.t):
                for name in ("t", "r", "a"):
                    old = getattr(self, name)
                    new = np.empty((2 * len(old),) + old.shape[1:])
                    new[:k] = old[self.lo:self.hi]
                    setattr(self, name, new)
            else:
                for arr in (self.t, self.r, self.a):
                    arr[:k] = arr[self.lo:self.hi]
            self.lo, self.hi = 0, k
        self.t[self.hi], self.r[self.hi], self.a[self.hi] = t, r, a
        self.hi += 1

    def drop_before(self, t: float) -> None:
        """Drop the front samples older than ``t``."""
        while self.lo < self.hi and self.t[self.lo] < t:
            self.lo += 1

    def first_t(self) -> float:
        return float(self.t[self.lo])

    def views(self) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """The kept samples' times (k), residual speeds (k, n) and torque integrals (k, 2, n)."""
        return self.t[self.lo:self.hi], self.r[self.lo:self.hi], self.a[self.lo:self.hi]
