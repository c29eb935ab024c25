"""Each star tracker against the gyro-propagated attitude (no ROS): a tracker's jump, the gyro's rate step.

The gyro integrated on its own, ``q̇_G = ½ q_G ⊗ (0, ω̃)``, predicts the body attitude between two
tracker measurements without the estimator. For tracker ``k`` (mounting ``q_SB``), each valid
measurement gives the body attitude ``q̃_B = q̃_SN ⊗ q_SB*`` and the residual

    ``r_i = 2 vec((c ⊗ q_G(t_i))* ⊗ q̃_B,i)``   (rad, body axes),  ``c = q̃_B,0 ⊗ q_G(t_0)*``,

``c`` anchoring the prediction to the window's first measurement. With a healthy gyro and tracker,
over a window of ``window_s`` the residual is a line plus white noise: ``r_i = a + b t_i + v_i``
(``b`` the gyro's constant bias error, scale factor and misalignment, ``v_i ~ N(0, R_B)`` the
tracker's declared noise ``R_B = C R_S Cᵀ``, the gyro's angle random walk far below it). The two
faults add a signature ``ν s_i(j)`` with an onset ``j`` among the window's last ``onset_s``:

* a **tracker jump** (a bias jump of tracker ``k``): a step, ``s_i = 1`` for ``i ≥ j``, in that
  tracker's residual only; ``ν`` the jump (rad);
* a **gyro rate step** (a bias step, a stuck axis): a ramp, ``s_i = t_i − t_j`` for ``i ≥ j``, in
  every tracker's residual; ``ν`` the rate error (rad/s), its largest component the axis.

For each onset and signature the generalised likelihood ratio (Willsky & Jones 1976, *IEEE Trans.
Automatic Control* 21(1)) of the least-squares fit of ``a + b t + ν s`` against ``a + b t`` is

    ``G(j) = |S⊥ᵀ Z|² / |S⊥|²``,  ``Z`` the residuals whitened by ``R_B``, ``S⊥`` the signature
    with its projection on ``(1, t)`` removed (Frisch–Waugh),

χ²-distributed with 3 degrees of freedom for each ``j`` while both are healthy. A test is the
largest ``G`` over the onsets and the two signatures; its kind is the signature that gives it (a
ramp needs three samples after its onset, so that a one-sample step is never taken for one). A step
counts only when it beats the best ramp by :data:`MARGIN` (a likelihood ratio of 100: a ramp seen
early, or about a tracker's noisy boresight, fits a step almost as well, while a jump's step beats
every ramp by hundreds). A condition held on every test for the persistence gives a verdict: a
tracker whose own residual steps clearly (:class:`TrackerStepDetector`); the gyro when a tracker's
test is above the threshold while no tracker's steps clearly (:class:`GyroRampDetector`; the rate
error is the information-weighted mean of those trackers' best ramps, its axis the most significant
component). Assumptions: white tracker noise (the datasheet's, the covariance the estimator uses);
the gyro's scale factor and misalignment times the change of rate within a window far below the
noise; a window of consecutive valid measurements (an invalid one, or a gap over :data:`GAP_S`,
starts the tracker's window again), and a change of the residual between two measurements above
``discontinuity`` is the attitude itself moving under the gyro (the simulation's truth reset to
another attitude, tracker and gyro healthy): the window starts again without a verdict (a tracker
fault larger than that is left to the estimator's gate and the innovation detector). A tracker that
stepped starts its window again from the step (its new level), so that a jump is never taken later
for the gyro's ramp (the gyro's detector leaves a tracker whose residual stepped for
:data:`STEP_HOLD_S` aside until its window starts again). This needs one tracker: a lone tracker's
jump and a gyro rate step are told apart by the signature's shape, two trackers' by which residuals
move.
"""
from __future__ import annotations

import math
from collections import deque
from dataclasses import dataclass, field

import numpy as np

from att_planner.fdir.persistence import Persistence
from att_planner.fdir.status import Verdict
from att_sim.models import rotations as rot

TRACKER, GYRO = "tracker_step", "gyro_ramp"
GAP_S = 1.0                 # s without a valid measurement of a tracker after which its window starts again
RAMP_MIN_SAMPLES = 3        # samples after a ramp's onset before it is a candidate
MARGIN = 2.0 * math.log(100.0)   # GLR by which a signature must beat the other: 100 times as likely
STEP_HOLD_S = 1.0           # s a tracker's residual steps before the gyro's detector leaves it aside
STEP, RAMP = "step", "ramp"


@dataclass(frozen=True)
class Test:
    """One test of tracker ``name`` at ``t``: the largest GLR, its signature and its amplitude (body axes)."""

    t: float
    name: str
    stat: float
    kind: str                  # STEP or RAMP
    amplitude_B: np.ndarray    # rad (step) or rad/s (ramp)
    onset: float               # s: the onset of the best signature
    covariance_B: np.ndarray   # rad² or (rad/s)²: the amplitude's covariance, R_B / |S⊥|²
    margin: float              # the best GLR less the best of the other signature's
    ramp_B: np.ndarray         # rad/s: the best ramp's amplitude (body axes), its covariance and onset
    ramp_covariance_B: np.ndarray
    ramp_onset: float

    def clear(self, threshold: float, kind: str) -> bool:
        """The test above ``threshold``, of signature ``kind``, by :data:`MARGIN` over the other."""
        return self.kind == kind and self.stat > threshold and self.margin > MARGIN


@dataclass
class _Window:
    samples: deque = field(default_factory=deque)     # (t, q_G(t), q̃_B)


class Residuals:
    """The gyro's own propagation and each tracker's window of residuals (module docstring), shared by
    the two detectors: a measurement is tested once (:meth:`on_tracker` memoises on its name and instant)."""

    def __init__(self, trackers, window_s: float, onset_s: float, discontinuity_rad: float = math.inf):
        """``trackers``: the :class:`att_sim.models.sensor_specs.StarTrackerSpec` of each tracker;
        ``discontinuity_rad``: a change of the residual between two measurements above which the window
        starts again without a test."""
        if not 0.0 < onset_s < window_s:
            raise ValueError(f"onset_s must be in (0, window_s = {window_s:g} s), got {onset_s!r}")
        if not discontinuity_rad > 0.0:
            raise ValueError(f"discontinuity_rad must be > 0, got {discontinuity_rad!r}")
        self.window_s, self.onset_s, self.discontinuity = window_s, onset_s, discontinuity_rad
        self.specs = {s.name: s for s in trackers}
        self.whiten = {}
        for s in trackers:
            C = rot.dcm_NB(np.asarray(s.mounting, float))
            self.whiten[s.name] = np.linalg.cholesky(C @ s.covariance @ C.T)       # R_B = L Lᵀ
        self.windows = {s.name: _Window() for s in trackers}
        self.epoch = dict.fromkeys(self.windows, 0)     # windows started so far, per tracker
        self.gyro: deque = deque()              # (t, q_G)
        self.last_gyro_t = -math.inf
        self.cache: dict[str, Test | None] = {}
        self.cache_t: dict[str, float] = {}

    def on_gyro(self, t: float, omega_BN_B_measured) -> None:
        """A gyro sample: the mean body rate over the interval that ends at ``t`` (repeats ignored)."""
        if not t > self.last_gyro_t:
            return
        w = np.asarray(omega_BN_B_measured, float)
        if not self.gyro:
            q = np.array([0.0, 0.0, 0.0, 1.0])
        else:
            q = rot.normalize(rot.propagate_constant_rate(self.gyro[-1][1], w, t - self.last_gyro_t))
        self.gyro.append((t, q))
        self.last_gyro_t = t
        while len(self.gyro) > 2 and self.gyro[1][0] < t - self.window_s - 2.0 * GAP_S:
            self.gyro.popleft()

    def _q_G(self, t: float) -> np.ndarray | None:
        """The gyro's propagation at ``t`` (between two of its samples: interpolated), None outside."""
        g = self.gyro
        if not g or t < g[0][0] or t > g[-1][0] + 1e-9:
            return None
        k = next(i for i in range(len(g) - 1, -1, -1) if g[i][0] <= t + 1e-12)
        if k == len(g) - 1 or g[k][0] >= t:
            return g[k][1]
        (t0, q0), (t1, q1) = g[k], g[k + 1]
        return rot.slerp(q0, q1, (t - t0) / (t1 - t0))

    def restart(self, name: str) -> None:
        """Start tracker ``name``'s window again (its next measurements make a new one)."""
        if self.windows[name].samples:
            self.windows[name].samples.clear()
            self.epoch[name] += 1

    def on_tracker(self, t: float, name: str, q_SN, valid: bool) -> Test | None:
        """A measurement of tracker ``name`` taken at ``t``; its test (None: no test, a window not full)."""
        if name not in self.windows:
            return None
        if self.cache_t.get(name) == t:
            return self.cache[name]
        self.cache_t[name], self.cache[name] = t, None
        w = self.windows[name].samples
        q_G = self._q_G(t) if valid else None
        if q_G is None or (w and t - w[-1][0] > GAP_S):
            self.restart(name)
            if q_G is None:
                return None
        q_B = rot.multiply(np.asarray(q_SN, float), rot.conjugate(np.asarray(self.specs[name].mounting, float)))
        if w:
            _, q_G0, q_B0 = w[-1]
            if rot.angle_between(q_B, rot.multiply(rot.multiply(q_B0, rot.conjugate(q_G0)), q_G)) > self.discontinuity:
                self.restart(name)          # the attitude itself moved (a simulation reset): no fault of a unit
        w.append((t, q_G, q_B))
        while len(w) > 1 and w[1][0] <= t - self.window_s + 1e-9:
            w.popleft()
        if t - w[0][0] < self.window_s - 1.0 / max(self.specs[name].rate, 1e-9) - 1e-9:
            return None
        self.cache[name] = test = self._test(name, w)
        return test

    def _test(self, name: str, w: deque) -> Test:
        ts = np.array([s[0] for s in w])
        q_G = np.array([s[1] for s in w])
        q_B = np.array([s[2] for s in w])
        c = rot.multiply(q_B[0], rot.conjugate(q_G[0]))
        predicted = rot.multiply(np.broadcast_to(c, q_G.shape), q_G)
        r = 2.0 * rot.error_vector(q_B, predicted)                      # (M, 3) rad, body axes
        L = self.whiten[name]
        Z = np.linalg.solve(L, r.T).T
        tau = ts - ts.mean()
        Q, _ = np.linalg.qr(np.column_stack([np.ones_like(tau), tau]))
        onsets = np.flatnonzero(ts > ts[-1] - self.onset_s)
        steps = (np.arange(len(ts))[:, None] >= onsets[None, :]).astype(float)
        ramp_onsets = onsets[onsets <= len(ts) - 1 - RAMP_MIN_SAMPLES]
        ramps = np.maximum(ts[:, None] - ts[ramp_onsets][None, :], 0.0)
        S = np.hstack([steps, ramps])
        S_perp = S - Q @ (Q.T @ S)
        den = np.einsum("ij,ij->j", S_perp, S_perp)
        num = S_perp.T @ Z                                              # (K, 3)
        G = np.einsum("ij,ij->i", num, num) / den
        best = int(np.argmax(G))
        kind = STEP if best < len(onsets) else RAMP
        other = G[len(onsets):] if kind == STEP else G[:len(onsets)]
        margin = float(G[best] - (other.max() if other.size else 0.0))
        onset = ts[onsets[best]] if kind == STEP else ts[ramp_onsets[best - len(onsets)]]
        r = len(onsets) + int(np.argmax(G[len(onsets):])) if ramp_onsets.size else best
        return Test(float(ts[-1]), name, float(G[best]), kind, L @ (num[best] / den[best]), float(onset),
                    L @ L.T / den[best], margin, L @ (num[r] / den[r]), L @ L.T / den[r],
                    float(ts[ramp_onsets[r - len(onsets)]]) if ramp_onsets.size else float(onset))


class _Detector:
    """A detector of one signature on the shared :class:`Residuals`."""

    def __init__(self, residuals: Residuals, threshold: float, persistence_s: float):
        self.residuals, self.threshold, self.persistence_s = residuals, threshold, persistence_s
        self.names = list(residuals.windows)

    def on_gyro(self, t: float, omega_BN_B_measured) -> list[Verdict]:
        self.residuals.on_gyro(t, omega_BN_B_measured)
        return []

    def on_tracker(self, t: float, name: str, q_SN, valid: bool) -> list[Verdict]:
        test = self.residuals.on_tracker(t, name, q_SN, valid)
        return self._judge(name, t, test)

    def _judge(self, name: str, t: float, test: Test | None) -> list[Verdict]:
        raise NotImplementedError


class TrackerStepDetector(_Detector):
    """A tracker whose residual against the gyro steps (module docstring): that tracker is isolated.
    While :attr:`gyro_failed` (a gyro fault declared: the propagation is no reference) no tracker is judged."""

    def __init__(self, residuals: Residuals, threshold: float, persistence_s: float):
        super().__init__(residuals, threshold, persistence_s)
        self.persistence = {n: Persistence(persistence_s) for n in self.names}
        self.declared: set[str] = set()
        self.gyro_failed = False

    def _judge(self, name: str, t: float, test: Test | None) -> list[Verdict]:
        if name not in self.persistence or name in self.declared:
            return []
        if self.gyro_failed:
            self.persistence[name].update(False, t)
            return []
        holds = test is not None and test.clear(self.threshold, STEP)
        p = self.persistence[name]
        if not p.update(holds, t):
            return []
        self.declared.add(name)
        self.residuals.restart(name)
        jump = test.amplitude_B
        arcsec = math.degrees(float(np.linalg.norm(jump))) * 3600.0
        return [Verdict(t, "star_tracker", self.names.index(name), TRACKER,
                        f"{name}: its attitude against the gyro's propagation stepped by "
                        f"{np.array2string(jump, precision=3)} rad (body axes; {arcsec:.3g} arcsec) at t = "
                        f"{test.onset:.3f} s: GLR {test.stat:.4g} > {self.threshold:g} since "
                        f"t = {p.since:.3f} s", since=p.since)]


class GyroRampDetector(_Detector):
    """The gyro, when a tracker's residual ramps while no tracker's steps (module docstring); the axis
    is the largest component of the rate error."""

    def __init__(self, residuals: Residuals, threshold: float, persistence_s: float):
        super().__init__(residuals, threshold, persistence_s)
        self.persistence = Persistence(persistence_s)
        self.latest: dict[str, Test | None] = dict.fromkeys(self.names)
        self.stepped: dict[str, int] = {}       # tracker -> the window in which it stepped (ignored while it lasts)
        self.step_runs = {n: Persistence(STEP_HOLD_S) for n in self.names}
        self.declared = False

    def _judge(self, name: str, t: float, test: Test | None) -> list[Verdict]:
        if name not in self.latest or self.declared:
            return []
        if self.step_runs[name].update(test is not None and test.clear(self.threshold, STEP), t):
            self.stepped[name] = self.residuals.epoch[name]
        if self.stepped.get(name) == self.residuals.epoch[name]:
            test = None                         # a tracker that stepped: not judged until its window starts again
        self.latest[name] = test
        ramps = [x for x in self.latest.values() if x is not None and x.stat > self.threshold]
        holds = bool(ramps) and not any(x.clear(self.threshold, STEP) for x in ramps)
        if not self.persistence.update(holds, t):
            return []
        self.declared = True
        info = sum(np.linalg.inv(x.ramp_covariance_B) for x in ramps)
        cov = np.linalg.inv(info)
        rate = cov @ sum(np.linalg.solve(x.ramp_covariance_B, x.ramp_B) for x in ramps)
        z = np.abs(rate) / np.sqrt(np.diag(cov))
        axis = int(np.argmax(z))
        names = ", ".join(x.name for x in ramps)
        return [Verdict(t, "gyro", axis, GYRO, f"{names}: attitude against the gyro's propagation ramps at "
                        f"{np.array2string(rate, precision=3)} rad/s ({math.degrees(rate[axis]):+.3g} deg/s about axis "
                        f"{axis}, {z[axis]:.3g} sigma) from t = {min(x.ramp_onset for x in ramps):.3f} s: GLR "
                        f"{max(x.stat for x in ramps):.4g} > {self.threshold:g} since t = "
                        f"{self.persistence.since:.3f} s", since=self.persistence.since)]
