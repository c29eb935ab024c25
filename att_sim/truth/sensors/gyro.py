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
    """One gyro unit: its drawn errors and the state of its noise (see module docstring); it measures
    through :class:`Gyros` (itself alone)."""

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
        self._covariances: dict[float, np.ndarray] = {}                 # dt -> the sample's noise covariance
        self._alone: Gyros | None = None

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

    def measure(self, rotation: np.ndarray, dt: float) -> np.ndarray:
        """Measured rates for consecutive intervals of ``dt`` s whose true rotation vectors are the
        rows of ``rotation`` ((k, 3), or (3,) for one sample: then the result is (3,))."""
        self._alone = self._alone or Gyros([self])
        increments = np.asarray(rotation, float)
        rate = self._alone.measure(increments.reshape(1, -1, 3), (dt,))[0]
        return rate[0] if increments.ndim == 1 else rate


def _column(values) -> np.ndarray:
    """One value per gyro, as a column (n × 1)."""
    return np.array([[v] for v in values], float)


class Gyros:
    """The gyro model on rows of units: one unit alone (:meth:`Gyro.measure`) or the gyros of a
    batch's runs at once, each over k consecutive intervals. In order per unit: the flicker bank
    (each process ``x_k = a x_(k−1) + w_k``: one step computed directly, many by
    ``scipy.signal.lfilter``, imported then: it costs a node seconds at start), the rate random
    walk, the white noise (each unit's draws from its own stream), then the arithmetic on rows of
    units. The units' constants are stacked once, their factors for an interval kept for the few
    intervals a clock makes; each unit's noise state is read and written back."""

    def __init__(self, gyros: list[Gyro]):
        self.gyros = gyros
        self.banked = [g.flicker_sigma > 0 for g in gyros]
        self.transfer_T = np.array([g.transfer.T for g in gyros])
        self.turn_on = np.array([g.turn_on for g in gyros])[:, None, :]
        self.limit = _column([g.spec.range for g in gyros])[:, :, None]
        self.lsb = _column([g.spec.quantization for g in gyros])[:, :, None]
        self._factors: dict[tuple, tuple] = {}

    def _of_intervals(self, dts: tuple) -> tuple:
        """For the intervals ``dts`` (one per unit): their column, each flicker process's factor
        ``a = exp(−Δt/τ)`` and drive's 1σ ``σ√(1 − a²)``, the rate walk's and the white noise's 1σ."""
        factors = self._factors.get(dts)
        if factors is None:
            if len(self._factors) >= 64:
                self._factors.clear()
            gyros = self.gyros
            a = np.array([np.exp(-h / g.times) for g, h in zip(gyros, dts)])[:, :, None]          # n × m × 1
            sigma = np.array([[g.flicker_sigma] for g in gyros])[:, :, None] * np.sqrt(1.0 - a * a)
            factors = self._factors[dts] = (
                _column(dts)[:, :, None], a, sigma[:, :, None, :],
                _column([g.spec.rrw * math.sqrt(h) for g, h in zip(gyros, dts)])[:, :, None],
                _column([g.noise_sigma(h) for g, h in zip(gyros, dts)])[:, :, None])
        return factors

    def _flicker(self, a: np.ndarray, sigma: np.ndarray, k: int) -> tuple[np.ndarray, np.ndarray]:
        """The flicker bank over k intervals: the sum of its processes (n × k × 3) and each
        process's last value (n × m × 3); draws a unit's drives process by process (a bank without
        variance draws nothing)."""
        gyros = self.gyros
        state = np.array([g.flicker for g in gyros])                                             # n × m × 3
        if k == 1:
            drives = np.array([g.rng.standard_normal(g.flicker.shape) if banked else np.zeros(g.flicker.shape)
                               for g, banked in zip(gyros, self.banked)])
            last = a * state + drives * sigma[:, :, 0, :]
            return last.sum(axis=1)[:, None, :], last
        from scipy.signal import lfilter

        total, last = np.zeros((len(gyros), k, 3)), state.copy()
        for i, (g, banked) in enumerate(zip(gyros, self.banked)):
            for j in range(len(g.times)) if banked else ():
                path, _ = lfilter([1.0], [1.0, -a[i, j, 0]], g.rng.standard_normal((k, 3)) * sigma[i, j, 0],
                                  axis=0, zi=(a[i, j, 0] * state[i, j])[None, :])
                total[i] += path
                last[i, j] = path[-1]
        return total, last

    def measure(self, rotation: np.ndarray, dts) -> np.ndarray:
        """The rates each unit measures over k consecutive intervals of its ``dts`` entry, whose true
        rotation vectors are ``rotation`` (n × k × 3); n × k × 3."""
        gyros = self.gyros
        dt, a, sigma, walk_sigma, noise_sigma = self._of_intervals(tuple(dts))
        k = rotation.shape[1]
        flicker, last = self._flicker(a, sigma, k)
        walk = np.array([g.walk for g in gyros])[:, None, :] + np.add.accumulate(
            np.array([g.rng.standard_normal((k, 3)) for g in gyros]) * walk_sigma, axis=1)
        bias = self.turn_on + flicker + walk
        rate = rotation @ self.transfer_T / dt + bias
        rate = rate + np.array([g.rng.standard_normal((k, 3)) for g in gyros]) * noise_sigma
        rate = np.minimum(np.maximum(rate, -self.limit), self.limit)
        total = np.array([g.carry for g in gyros])[:, None, :] + np.add.accumulate(rate * dt, axis=1)
        counted = quantize(total, self.lsb)
        counts = counted.copy()                     # each sample's counts: the difference of the totals
        counts[:, 1:] -= counted[:, :-1]
        carry = total[:, -1] - counted[:, -1]
        for i, g in enumerate(gyros):
            g.flicker, g.walk, g.bias, g.carry = last[i], walk[i, -1], bias[i, -1], carry[i]
        rate = counts / dt
        return rate
