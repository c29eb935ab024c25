"""Three-axis rate gyro: the mean body rate over each sample interval, with the errors of a datasheet.

Measurement of sample k (interval Δt ending at t_k), in the gyro's nominal (body) axes::

    ω_m,k = Q( sat( (I + S + M) Δθ_k / Δt + b_k + σ_v / √Δt · n_k ) )

* ``Δθ_k``: the true rotation vector over the interval (the gyro integrates: its output is the mean
  rate, so a propagation over the interval with it is exact for a fixed axis);
* ``S`` scale factors, ``M`` misalignment (six small off-diagonal angles), drawn once per unit;
* ``b_k = b_0 + b_flicker,k + b_rrw,k``: turn-on bias (drawn once), the bias instability and the rate
  random walk ``b_rrw,k+1 = b_rrw,k + σ_u √Δt · n`` (Farrenkopf's model, Markley & Crassidis 2014 §4.7);
* ``σ_v`` the angle random walk: white rate noise of standard deviation ``σ_v/√Δt`` per sample;
* ``sat`` the range per axis, ``Q`` quantisation of the angle increment with the remainder carried to
  the next sample (an integrating gyro's pulse counting: no error accumulates).

Bias instability ``B`` is flicker (1/f) noise, whose Allan deviation is flat at ``√(2 ln 2/π) B =
0.664 B`` (IEEE Std 952-1997, Annex C). It is realised as a bank of first-order Gauss–Markov processes
with correlation times spaced by ``r = √10`` over ``FLICKER_SPAN``: a bank of equal variances ``σ²``
has the one-sided PSD ``Σ 4σ²T/(1 + (2πfT)²) ≈ σ²/(f ln r)`` between its corners, i.e. flicker with
``h₋₁ = σ²/ln r`` and Allan variance ``2 ln 2 · h₋₁``; hence ``σ = B √(ln r / π)`` per process.
The simulated unit's Allan deviation recovers the configured ARW and B (test/att_sim/truth/test_sensors.py).
"""
from __future__ import annotations

import math

import numpy as np

from att_sim.models.rotations import small_error_matrix
from att_sim.models.sensor_specs import GyroSpec
from att_sim.truth.actuators import quantize

FLICKER_SPAN = (1.0, 1e5)          # s: correlation times of the flicker bank (Allan floor between them)
FLICKER_RATIO = math.sqrt(10.0)    # spacing of the correlation times


def flicker_times() -> np.ndarray:
    """Correlation times of the flicker bank (s)."""
    lo, hi = FLICKER_SPAN
    count = int(round(math.log(hi / lo) / math.log(FLICKER_RATIO))) + 1
    return lo * FLICKER_RATIO ** np.arange(count)


class Gyro:
    """One gyro unit: its drawn errors and the state of its noise (see module docstring)."""

    def __init__(self, spec: GyroSpec, rng: np.random.Generator):
        self.spec, self.rng = spec, rng
        self.transfer = small_error_matrix(rng, spec.scale_factor, spec.misalignment)
        self.turn_on = rng.normal(0.0, spec.initial_bias, 3)
        self.times = flicker_times()
        self.flicker_sigma = spec.bias_instability * math.sqrt(math.log(FLICKER_RATIO) / math.pi)
        self.flicker = rng.normal(0.0, self.flicker_sigma, (len(self.times), 3))   # stationary start
        self.walk = np.zeros(3)
        self.carry = np.zeros(3)          # rad: angle not yet output by the quantiser
        self.bias = self.turn_on + self.flicker.sum(axis=0)
        self._banks: dict[float, tuple[np.ndarray, np.ndarray]] = {}    # dt -> (a, σ√(1 − a²)) of each process
        self._covariances: dict[float, np.ndarray] = {}                 # dt -> the sample's noise covariance
        self._alone: GyrosOfRuns | None = None                         # this gyro's one-sample path

    def noise_sigma(self, dt: float) -> float:
        """1σ of the white rate noise of one sample (rad/s)."""
        return self.spec.arw / math.sqrt(dt)

    def noise_covariance(self, dt: float) -> np.ndarray:
        """``σ² I`` of one sample's white rate noise over ``dt`` ((rad/s)²): read-only, shared by the
        samples of one interval (kept for the few intervals a simulator's clock makes)."""
        covariance = self._covariances.get(dt)
        if covariance is None:
            if len(self._covariances) >= 64:
                self._covariances.clear()
            covariance = self._covariances[dt] = np.eye(3) * self.noise_sigma(dt) ** 2
            covariance.flags.writeable = False
        return covariance

    def _bank(self, dt: float) -> tuple[np.ndarray, np.ndarray]:
        """Each flicker process's step over ``dt``: its factor ``a = exp(−Δt/τ)`` and the drive's 1σ
        (columns), kept for the few intervals a simulator's clock makes."""
        bank = self._banks.get(dt)
        if bank is None:
            if len(self._banks) >= 64:
                self._banks.clear()
            a = np.exp(-dt / self.times)[:, None]
            bank = self._banks[dt] = (a, self.flicker_sigma * np.sqrt(1.0 - a * a))
        return bank

    def _bias(self, n: int, dt: float) -> np.ndarray:
        """The bias at the end of each of ``n`` intervals (n, 3); advances the noise state. Each
        flicker process is ``x_k = a x_(k-1) + w_k``: a batch (n > 1) through ``scipy.signal.lfilter``
        (imported then: it costs a node seconds at start); one interval is :class:`GyrosOfRuns`'s."""
        flicker = np.zeros((n, 3))
        if self.flicker_sigma > 0:
            for j, tau in enumerate(self.times):
                a = math.exp(-dt / tau)
                drive = self.rng.standard_normal((n, 3)) * (self.flicker_sigma * math.sqrt(1.0 - a * a))
                from scipy.signal import lfilter

                path, _ = lfilter([1.0], [1.0, -a], drive, axis=0, zi=(a * self.flicker[j])[None, :])
                flicker += path
                self.flicker[j] = path[-1]
        walk = self.walk + np.cumsum(self.rng.standard_normal((n, 3)) * (self.spec.rrw * math.sqrt(dt)), axis=0)
        self.walk = walk[-1]
        bias = self.turn_on + flicker + walk
        self.bias = bias[-1]
        return bias

    def measure(self, rotation: np.ndarray, dt: float) -> np.ndarray:
        """Measured rates for consecutive intervals of ``dt`` s whose true rotation vectors are the
        rows of ``rotation`` ((n, 3), or (3,) for one sample: then the result is (3,))."""
        increments = np.atleast_2d(np.asarray(rotation, float))
        n = len(increments)
        if n == 1:                        # the simulator's case
            self._alone = self._alone or GyrosOfRuns([self])
            rate = self._alone.measure([(increments[0], dt)])[0]
            return rate if np.ndim(rotation) == 1 else rate[None, :]
        rate = increments @ self.transfer.T / dt + self._bias(n, dt)
        rate += self.rng.standard_normal((n, 3)) * self.noise_sigma(dt)
        rate = np.minimum(np.maximum(rate, -self.spec.range), self.spec.range)
        lsb = self.spec.quantization
        if lsb > 0:
            total = self.carry + np.cumsum(rate * dt, axis=0)
            counted = quantize(total, lsb)
            self.carry = total[-1] - counted[-1]
            rate = np.diff(counted, axis=0, prepend=0.0) / dt     # the counts of each sample
        return rate


def _column(values) -> np.ndarray:
    """One value per gyro, as a column (R × 1)."""
    return np.array([[v] for v in values], float)


class GyrosOfRuns:
    """Gyros sampled together — one gyro's sample in the simulator, or the gyros of a lockstep's runs
    at once: the whole flicker bank in one step, then the rate random walk, the white noise (each
    gyro's draws from its own stream, in that order), the arithmetic on rows of gyros (element by
    element; the stacked bank sums and products give each row the bits it gets alone). The gyros'
    constants are stacked once, their factors for an interval kept for the few intervals a clock
    makes. Gyros unlike in their noise's form (a bank or none, a quantiser or none) measure one by one."""

    def __init__(self, gyros: list[Gyro]):
        self.gyros, first = gyros, gyros[0]
        self.banked, self.quantized = first.flicker_sigma > 0, first.spec.quantization > 0
        self.alike = all((g.flicker_sigma > 0) == self.banked and (g.spec.quantization > 0) == self.quantized
                         and g.flicker.shape == first.flicker.shape for g in gyros)
        if self.alike:
            self.transfer_T = np.array([g.transfer.T for g in gyros])
            self.turn_on = np.array([g.turn_on for g in gyros])
            self.limit = _column([g.spec.range for g in gyros])
            self.lsb = _column([g.spec.quantization for g in gyros])
        self._factors: dict[tuple, tuple] = {}

    def _of_intervals(self, dts: tuple) -> tuple:
        """For the intervals ``dts`` (one per gyro): their column, the bank's factors and drives' 1σ,
        the rate walk's and the white noise's 1σ (columns)."""
        factors = self._factors.get(dts)
        if factors is None:
            if len(self._factors) >= 64:
                self._factors.clear()
            gyros = self.gyros
            banks = [g._bank(h) for g, h in zip(gyros, dts)] if self.banked else []
            factors = self._factors[dts] = (
                _column(dts), np.array([a for a, _ in banks]), np.array([s for _, s in banks]),
                _column([g.spec.rrw * math.sqrt(h) for g, h in zip(gyros, dts)]),
                _column([g.noise_sigma(h) for g, h in zip(gyros, dts)]))
        return factors

    def measure(self, intervals: list[tuple[np.ndarray, float]]) -> list[np.ndarray]:
        """The rate each gyro measures over its interval ``(rotation, dt)`` (the gyros' order)."""
        gyros = self.gyros
        if not self.alike:
            return [g.measure(*interval) for g, interval in zip(gyros, intervals)]
        dt, a, sigma, walk_sigma, noise_sigma = self._of_intervals(tuple(h for _, h in intervals))
        flicker_sum = np.zeros((len(gyros), 3))
        if self.banked:
            flicker = a * np.array([g.flicker for g in gyros]) \
                + np.array([g.rng.standard_normal(g.flicker.shape) for g in gyros]) * sigma
            flicker_sum = flicker.sum(axis=1)
            for g, row in zip(gyros, flicker):
                g.flicker = row
        walk = np.array([g.walk for g in gyros]) + np.array([g.rng.standard_normal(3) for g in gyros]) * walk_sigma
        bias = self.turn_on + flicker_sum + walk
        rotation = np.array([r for r, _ in intervals])[:, None, :]
        rate = (rotation @ self.transfer_T)[:, 0, :] / dt + bias
        rate = rate + np.array([g.rng.standard_normal(3) for g in gyros]) * noise_sigma
        rate = np.minimum(np.maximum(rate, -self.limit), self.limit)
        if self.quantized:
            total = np.array([g.carry for g in gyros]) + rate * dt
            counted = quantize(total, self.lsb)
            rate = counted / dt
            for g, row in zip(gyros, total - counted):
                g.carry = row
        for g, w, b in zip(gyros, walk, bias):
            g.walk, g.bias = w, b
        return list(rate)
