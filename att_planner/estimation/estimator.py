"""The attitude estimator's core (no ROS): measurements in, a checked estimate with its health out.

:class:`Estimator` runs the MEKF of :mod:`.mekf` on the gyro, star trackers, magnetometer and coarse
sun sensors, in the style of :class:`att_planner.control.controller.Controller`: the node only
translates messages; tests and the Monte Carlo drive the core directly.

* **Time** is the gyro's: each gyro sample (the mean rate over the interval it ends) propagates the
  filter to its stamp. Its stamps must move forward by at most ``max_gyro_gap`` (no single message
  can stall or steer the filter's clock); after ``resync_timeout`` s of wall time without a gyro
  sample the next one starts a new timeline (a restarted simulator) and the filter starts afresh.
  A measurement stamped more than ``max_gyro_gap`` ahead of the gyro is refused. Other measurements
  are applied **at the instant they were taken**: a star tracker's message arrives its latency
  later, so the filter keeps the last ``history`` seconds of gyro samples, states and measurements
  and, when a measurement older than its newest state arrives, goes back to the state before it and
  reprocesses everything since (out-of-sequence measurements by reprocessing; Bar-Shalom, Li &
  Kirubarajan 2001 §10.4).
* **Propagation** on the gyro, its scale factors and misalignments *considered* from their
  datasheet spread (:func:`.mekf.propagate`): the covariance grows with the rotation the gyro
  measures, not only with time, so a filter blind through a slew stays honest.
* **Updates**: every valid star tracker measurement (mounting ``q_SB``: the body attitude is
  ``q_S ⊗ q_SB*``, noise ``R_B = C R_S Cᵀ``); magnetometer and sun-sensor vector updates only while
  no tracker measurement was accepted for ``vector_fallback_after`` s. A magnetometer sample taken
  while the magnetorquers were commanded (the command before its stamp had a dipole) is not used:
  the controller blanks its coils before each sample (duty cycling).
* **Gating**: a measurement with ``d² > χ²_k(gate_probability)`` is rejected and counted; each is
  gated once, when it first arrives, and replayed with the same decision.
* **Initialisation** without a prior: the first valid star tracker measurement (``P₀`` = its noise
  and the bias prior), else QUEST (Shuster & Oh 1981) on a sun vector and a clean magnetometer
  sample taken within ``pair_window`` s of each other.
* **Health** (``AttitudeEstimate.HEALTH_*``): INITIALISING without an attitude; DIVERGED when the
  covariance stops being positive definite or ``lost_after`` tracker measurements in a row are
  rejected (the estimate is dropped and the filter reinitialises from the next measurements);
  CONVERGED while an attitude fix — a star tracker measurement, or a vector measurement on a
  spacecraft without trackers — was accepted within ``propagate_timeout`` s and the attitude's 3σ is
  below ``converged_attitude_sigma``; PROPAGATING otherwise (on the gyro, with at most the coarse
  aid of the vectors while the trackers are blind).

Inputs are hostile until checked (:mod:`.inputs`): a refused measurement raises
:class:`~att_msgs_py.errors.RequestError` (320 INVALID_MEASUREMENT, 321 STALE_MEASUREMENT) and
changes nothing. A saturated gyro sample (any axis at its range) propagates with the attitude
covariance grown by ``(range Δt)²`` per axis: the true rate is unknown beyond it.
"""
from __future__ import annotations

import math
from bisect import bisect_right
from collections import deque
from dataclasses import dataclass, field
from operator import attrgetter

import numpy as np

from att_msgs_py.errors import ErrorCode, RequestError
from att_msgs_py.types import (
    AttitudeEstimate,
    GyroMeasurement,
    Health,
    MagnetometerMeasurement,
    StarTrackerMeasurement,
    SunSensorMeasurement,
)
from att_planner.estimation import mekf
from att_planner.estimation.attitude_determination import quest, sun_vector
from att_planner.estimation.inputs import DipoleLog, InputChecks
from att_planner.estimation.lockstep import resume
from att_sim.models import rotations as rot
from att_sim.models.sensor_specs import SensorSpecs

LOST_COVARIANCE = math.pi**2        # rad²: the attitude covariance published without an estimate
FLICKER_HORIZON = 300.0            # s: the bias random walk of the default tuning grows by B in this time
MAX_NOTES = 100                    # notes kept for the node between two reports


@dataclass(frozen=True)
class EstimatorConfig:
    """Tuning of the filter (the estimator node's parameters; defaults from the datasheets:
    :meth:`Estimator.default_config`)."""

    publish_period: float = 0.05           # s of sim time between estimates
    arw: float = 1e-6                      # rad/√s: σ_v of the gyro model
    rrw: float = 1e-9                      # rad/s/√s: σ_u of the bias random walk
    initial_bias_sigma: float = 1e-5       # rad/s 1σ of the bias prior
    scale_factor_sigma: float = 0.0        # 1σ of the gyro's scale factors, considered (Schmidt)
    misalignment_sigma: float = 0.0        # rad 1σ of its misalignments, considered
    gate_probability: float = 0.9999       # chi-square gate of every measurement
    converged_attitude_sigma: float = 1e-3  # rad: 3σ attitude at most this to be CONVERGED
    propagate_timeout: float = 2.0         # s without an accepted attitude measurement: PROPAGATING
    history: float = 2.0                   # s of samples kept to apply late measurements
    lost_after: int = 5                    # tracker measurements rejected in a row: DIVERGED
    vector_fallback_after: float = 2.0     # s without a tracker update: vector updates
    magnetometer_sigma: float = 300e-9     # T: noise + field-model error per axis
    sun_sigma: float = 0.02                # rad: coarse sun vector error per axis
    sun_threshold: float = 0.05            # a detector above this output is lit
    pair_window: float = 0.5               # s between the two vectors of a QUEST initialisation
    max_gyro_gap: float = 1.0              # s: a gyro sample further ahead is refused (or a measurement that far
                                           # ahead of the gyro), unless the gyro was silent for resync_timeout
    resync_timeout: float = 1.0            # s of wall time without a gyro sample: the next starts a new timeline


@dataclass
class _Record:
    """A measurement kept for reprocessing: its instant, kind, data and the gate's decision."""

    t: float
    kind: str                              # "tracker", "magnetometer", "sun"
    data: object
    accepted: bool | None = None           # None until it is first processed


MESSAGES = {Health.INITIALISING: "waiting for a star tracker or a sun vector and a field measurement",
            Health.DIVERGED: "estimate lost: reinitialising from the next measurements",
            Health.PROPAGATING: "propagating on the gyro", Health.CONVERGED: "converged"}   # an estimate's, by health
_instant = attrgetter("t")                 # a record's instant: the records' sort key


@dataclass
class Report:
    """What the estimator has to say since it was last asked (the node logs it)."""

    notes: deque = field(default_factory=lambda: deque(maxlen=MAX_NOTES))
    rejected: int = 0


class Estimator:
    def __init__(self, specs: SensorSpecs, config: EstimatorConfig, environment=None, frame_id: str = "",
                 body_frame_id: str = ""):
        """``specs``: the datasheets (mountings, ranges); ``environment``: the onboard models of
        the field and the Sun (:meth:`att_sim.models.world.Environment.bodies`), needed for vector updates."""
        self.specs, self.config, self.environment = specs, config, environment
        self.frame_id, self.body_frame_id = frame_id, body_frame_id
        self._sigma3: tuple = (None, 0.0)        # (state, its attitude 3σ): health()'s cache
        self.checks = InputChecks(specs, frame_id, body_frame_id)
        self.trackers = {s.name: s for s in specs.star_trackers}
        variances = np.array([config.scale_factor_sigma**2] * 3 + [config.misalignment_sigma**2] * 6)
        self.consider = variances if np.any(variances > 0) else None
        # what a propagation takes besides the state: equal tunings propagate as one stack (lockstep)
        self.tuning = (config.arw, config.rrw, None if self.consider is None else self.consider.tobytes())
        from scipy.special import gammaincinv  # the chi-square quantile; scipy.stats costs seconds to import

        self.gates = {k: 2.0 * float(gammaincinv(k / 2.0, config.gate_probability)) for k in (3,)}
        self.gyro: deque[tuple[float, np.ndarray, bool]] = deque()       # (t, ω_m, saturated)
        # filter states at the gyro instants, after the measurements up to each; the first is the anchor
        self.snapshots: deque[tuple[float, mekf.FilterState | None]] = deque([(-math.inf, None)])
        self.records: list[_Record] = []
        self.dipoles = DipoleLog()
        self.last_bias = np.zeros(3)
        self.last_q = rot.IDENTITY.copy()
        self.diverged = False
        self.lost_at = -math.inf                  # instant the estimate was last dropped
        self.last_update: float = -math.inf       # time of the last accepted attitude measurement
        self.last_tracker: float = -math.inf      # ... of the last accepted tracker measurement
        self.rejected = 0
        self.rejected_in_a_row = 0
        self.next_publish = -math.inf
        self.last_wall = -math.inf                # when the last gyro sample arrived (monotonic s)
        self.report = Report()

    @staticmethod
    def default_config(specs: SensorSpecs, publish_period: float = 0.05) -> EstimatorConfig:
        """Tuning from the datasheets: the gyro's ARW; a bias random walk that covers its bias
        instability over ``FLICKER_HORIZON`` s; the bias prior from its turn-on bias."""
        g = specs.gyro
        if g is None:
            return EstimatorConfig(publish_period=publish_period)
        rrw = math.hypot(g.rrw, g.bias_instability / math.sqrt(FLICKER_HORIZON))
        tracker_sigma = max((s.about_boresight for s in specs.star_trackers), default=1e-4)
        return EstimatorConfig(publish_period=publish_period, arw=max(g.arw, 1e-9), rrw=max(rrw, 1e-12),
                               initial_bias_sigma=max(3.0 * g.initial_bias, g.bias_instability, 1e-7),
                               scale_factor_sigma=g.scale_factor, misalignment_sigma=g.misalignment,
                               converged_attitude_sigma=max(10.0 * tracker_sigma, 1e-4))

    @property
    def state(self) -> mekf.FilterState | None:
        return self.snapshots[-1][1]

    # -- inputs -----------------------------------------------------------------------------------
    def on_gyro(self, m: GyroMeasurement, wall: float = 0.0) -> AttitudeEstimate | None:
        """Propagate to the sample's stamp (and apply what arrived meanwhile); the estimate when
        one is due (every ``publish_period``). ``wall``: the monotonic time it arrived: a sample more
        than ``max_gyro_gap`` after the last is refused unless none came for ``resync_timeout`` s, in
        which case it starts a new timeline (a restarted simulator): the filter starts afresh. In
        three parts (:meth:`take_gyro`, :meth:`reprocess` from :attr:`newest`, :meth:`publish`) for
        :func:`att_planner.estimation.lockstep.reprocess_together`."""
        omega = self.take_gyro(m, wall)
        self.reprocess(self.newest)
        return self.publish(m.t, omega)

    def take_gyro(self, m: GyroMeasurement, wall: float = 0.0) -> np.ndarray:
        """Check and keep a gyro sample (see :meth:`on_gyro`); its measured rate."""
        last = self.gyro[-1][0] if self.gyro else None
        silent = wall - self.last_wall > self.config.resync_timeout
        omega, saturated = self.checks.gyro(m, None if silent else last)
        if last is not None and not 0.0 < m.t - last <= self.config.max_gyro_gap:
            if not silent:
                raise RequestError(ErrorCode.STALE_MEASUREMENT,
                                   f"gyro stamp {m.t:.6g} s is {m.t - last:+.6g} s from the last ({last:.6g} s); "
                                   f"it must move forward by at most max_gyro_gap = {self.config.max_gyro_gap:g} s")
            self.report.notes.append(f"gyro timeline restarted: {last:.3f} s then {m.t:.3f} s; filter restarted")
            self._restart()
        self.last_wall = wall
        if saturated:
            self.report.notes.append(f"gyro saturated at t = {m.t:.3f} s: attitude covariance grown")
        self.gyro.append((m.t, omega, saturated))
        return omega

    @property
    def newest(self) -> int:
        """Index of the newest state: :meth:`reprocess` from it catches up with a new gyro sample."""
        return len(self.snapshots) - 1

    def publish(self, t: float, omega_measured: np.ndarray) -> AttitudeEstimate | None:
        """After a gyro sample of time ``t`` was caught up with: what is older than ``history``
        forgotten; the estimate when one is due (every ``publish_period``), else None."""
        self._trim(t)
        if t < self.next_publish - 1e-9:
            return None
        self.next_publish = t + self.config.publish_period
        return self.estimate(t, omega_measured)

    def _restart(self) -> None:
        """Forget every state, sample and measurement (a new timeline): initialising again."""
        self.gyro.clear()
        self.snapshots = deque([(-math.inf, None)])
        self.records = []
        self.diverged, self.lost_at = False, -math.inf
        self.last_update = self.last_tracker = self.next_publish = -math.inf
        self.rejected_in_a_row = 0

    def on_star_tracker(self, m: StarTrackerMeasurement) -> None:
        """Apply a valid tracker measurement at its instant (an invalid one says only that)."""
        self.reprocess(self.take_star_tracker(m))

    def take_star_tracker(self, m: StarTrackerMeasurement) -> int | None:
        """Check and keep a tracker measurement; the state to :meth:`reprocess` from (None: none)."""
        q = self.checks.star_tracker(m)
        return None if q is None else self._insert(_Record(m.t, "tracker", (m.name, q)))

    def on_magnetometer(self, m: MagnetometerMeasurement) -> None:
        field_B = self.checks.magnetometer(m)
        if self.dipoles.clean(m.t):
            self.reprocess(self._insert(_Record(m.t, "magnetometer", field_B)))

    def on_sun_sensors(self, m: SunSensorMeasurement) -> None:
        values = self.checks.sun_sensors(m)
        s = sun_vector(values, self.specs.sun_sensors.normals, self.config.sun_threshold)
        if s is not None:
            self.reprocess(self._insert(_Record(m.t, "sun", s)))

    def on_dipole_command(self, t: float, dipole: np.ndarray) -> None:
        """The controller's magnetorquer command stamped ``t`` (for the magnetometer's blanking)."""
        self.dipoles.record(t, dipole)

    def take_report(self) -> Report:
        out, self.report = self.report, Report()
        return out

    # -- output -----------------------------------------------------------------------------------
    @property
    def last_fix(self) -> float:
        """Time of the last accepted attitude fix (tracker, or any attitude measurement without trackers)."""
        return self.last_tracker if self.trackers else self.last_update

    def health(self, t: float) -> Health:
        x = self.state
        if x is None:
            return Health.DIVERGED if self.diverged else Health.INITIALISING
        if self._sigma3[0] is not x:          # asked several times per state: its largest eigenvalue once
            self.keep_largest_attitude_variance(float(np.linalg.eigvalsh(x.P[:3, :3]).max()))
        sigma3 = self._sigma3[1]
        recent = t - self.last_fix <= self.config.propagate_timeout
        return Health.CONVERGED if recent and sigma3 <= self.config.converged_attitude_sigma else Health.PROPAGATING

    def keep_largest_attitude_variance(self, largest: float) -> None:
        """The largest eigenvalue of the newest state's attitude covariance, which :meth:`health`
        needs (computed for many estimators at once by :func:`~att_planner.estimation.lockstep.reprocess_together`)."""
        self._sigma3 = (self.state, 3.0 * math.sqrt(max(largest, 0.0)))

    def estimate(self, t: float, omega_measured: np.ndarray) -> AttitudeEstimate:
        """The estimate at gyro time ``t`` (the filter's newest state)."""
        x, health = self.state, self.health(t)
        if x is None:
            P_att, P_bias = np.eye(3) * LOST_COVARIANCE, np.eye(3) * self.config.initial_bias_sigma**2
            q, bias = self.last_q, self.last_bias
        else:
            P_att, P_bias, q, bias = x.P[:3, :3].copy(), x.P[3:, 3:].copy(), x.q, x.bias
            self.last_q, self.last_bias = q, bias
        return AttitudeEstimate(t=t, q=q.copy(), omega=omega_measured - bias, gyro_bias=bias.copy(),
                                attitude_covariance=P_att, bias_covariance=P_bias, health=int(health),
                                time_since_update=t - self.last_fix, rejected=self.rejected, message=MESSAGES[health],
                                frame_id=self.frame_id, body_frame_id=self.body_frame_id)

    # -- the filter over its history ---------------------------------------------------------------
    def _insert(self, record: _Record) -> int | None:
        """Keep ``record``; the last state before its instant when that is not the newest (the
        state to reprocess from; None: the next gyro sample applies it)."""
        if record.t <= self.snapshots[0][0]:
            oldest = self.snapshots[0][0]
            raise RequestError(ErrorCode.STALE_MEASUREMENT,
                               f"{record.kind} measurement of t = {record.t:.6g} s is older than the filter's history "
                               f"(from t = {oldest:.6g} s, {self.config.history:g} s)")
        newest = self.gyro[-1][0] if self.gyro else -math.inf
        if self.gyro and record.t > newest + self.config.max_gyro_gap:
            raise RequestError(ErrorCode.STALE_MEASUREMENT,
                               f"{record.kind} measurement of t = {record.t:.6g} s is ahead of the gyro (t = "
                               f"{newest:.6g} s) by more than max_gyro_gap = {self.config.max_gyro_gap:g} s")
        self.records.append(record)
        self.records.sort(key=_instant)               # stable: equal instants keep their arrival order
        if record.t <= self.snapshots[-1][0]:
            return max(i for i, (t, _) in enumerate(self.snapshots) if t < record.t)
        return None

    def reprocess(self, start: int | None) -> None:
        """Rebuild every state after snapshot ``start`` from it (None: nothing to do): propagate
        through each gyro interval, stopping at measurement instants to apply them."""
        if start is None:
            return
        steps = self.reprocess_steps(start)
        request = next(steps, None)
        while request is not None:
            request = resume(steps, mekf.update(*request) if isinstance(request, mekf.Correction)
                             else self.propagate_to(*request))

    def reprocess_steps(self, start: int):
        """:meth:`reprocess` as a generator: yields each propagation ``(x, ω_m, t, saturated)`` and
        goes on with the state sent back (:meth:`propagate_to`'s, or
        :func:`~att_planner.estimation.lockstep.reprocess_together`'s), and each Kalman update
        (:class:`~.mekf.Correction`), going on with its :class:`~.mekf.Update`."""
        t0, x = self.snapshots[start]
        while len(self.snapshots) > start + 1:
            self.snapshots.pop()
        records = self._records_after(t0)
        k = 0
        for t_j, omega, saturated in self._gyro_after(t0):
            while k < len(records) and records[k].t <= t_j:
                x = yield from self._apply((yield x, omega, records[k].t, saturated), records[k])
                k += 1
            self.snapshots.append((t_j, (yield x, omega, t_j, saturated)))
            x = self.snapshots[-1][1]
        self._forget_before_loss()

    def _forget_before_loss(self) -> None:
        if self.lost_at > self.snapshots[0][0]:       # nothing before a loss is replayed: drop it
            while len(self.snapshots) > 1 and self.snapshots[0][0] < self.lost_at:
                self.snapshots.popleft()
            self.records = self._records_after(self.snapshots[0][0])

    def _records_after(self, t: float) -> list[_Record]:
        """The records later than ``t`` (kept sorted by time)."""
        return self.records[bisect_right(self.records, t, key=_instant):]

    def _gyro_after(self, t: float) -> list[tuple[float, np.ndarray, bool]]:
        """The gyro samples later than ``t``, oldest first (their stamps increase)."""
        after = []
        for sample in reversed(self.gyro):
            if sample[0] <= t:
                break
            after.append(sample)
        return after[::-1]

    def propagate_to(self, x: mekf.FilterState | None, omega: np.ndarray, t: float,
                     saturated: bool) -> mekf.FilterState | None:
        """``x`` propagated to ``t`` on the gyro rate ``omega`` (unchanged when there is nothing to do;
        None when the covariance goes bad: the estimate is lost)."""
        if x is None or t <= x.t:
            return x
        dt, extra = self.interval(x, t, saturated)
        x = mekf.propagate(x, omega, dt, self.config.arw, self.config.rrw, self.consider, extra)
        return self.checked(t, x, mekf.healthy(x.P))

    def interval(self, x: mekf.FilterState, t: float, saturated: bool) -> tuple[float, float]:
        """``dt`` from ``x`` to ``t`` and the attitude variance a saturated sample adds over it."""
        dt = t - x.t
        return dt, (self.specs.gyro.range * dt) ** 2 if saturated and self.specs.gyro else 0.0

    def checked(self, t: float, x: mekf.FilterState, healthy: bool) -> mekf.FilterState | None:
        """``x`` propagated to ``t``, or None (the estimate lost) when its covariance is not ``healthy``."""
        return x if healthy else self._lose(t, f"covariance not positive definite at t = {t:.3f} s")

    def _lose(self, t: float, why: str) -> None:
        """Drop the estimate at ``t``: DIVERGED until the next initialisation."""
        self.diverged, self.lost_at = True, max(self.lost_at, t)
        self.report.notes.append(f"estimate diverged ({why}): reinitialising")

    def _apply(self, x: mekf.FilterState | None, r: _Record):
        """``x`` after the measurement ``r`` (gated the first time; replayed as decided then), as a
        generator (``yield from``): it yields its Kalman update (:class:`~.mekf.Correction`) and goes
        on with the :class:`~.mekf.Update` sent back."""
        if x is None:
            return self._initialise(r)
        if r.kind == "tracker":
            name, q_S = r.data
            mounting = self.trackers[name].mounting
            C = rot.dcm_NB(mounting)
            y = mekf.attitude_residual(x.q, rot.multiply(q_S, rot.conjugate(mounting)))
            H, R = mekf.attitude_sensitivity(), C @ self.trackers[name].covariance @ C.T
        elif r.t - self.last_tracker <= self.config.vector_fallback_after or self.environment is None:
            return x
        else:
            reference, measured, R = self._vector(r)
            y, H = mekf.vector_residual(x.q, measured, reference)
        first = r.accepted is None
        result = yield mekf.Correction(x, y, H, R, self.gates[3] if first else math.inf)
        if first and self._decided(r, result):
            return self._lose(r.t, f"{self.config.lost_after} star tracker measurements in a row rejected")
        if not (r.accepted and result.accepted):
            return x
        if not mekf.healthy(result.state.P):
            return self._lose(r.t, f"covariance not positive definite after a {r.kind} update at t = {r.t:.3f} s")
        self.last_update = max(self.last_update, r.t)
        if r.kind == "tracker":
            self.last_tracker = max(self.last_tracker, r.t)
        return result.state

    def _decided(self, r: _Record, result: mekf.Update) -> bool:
        """Record the gate's decision on ``r``; True when it loses the estimate (``lost_after``
        tracker measurements in a row rejected)."""
        r.accepted = result.accepted
        if result.accepted:
            if r.kind == "tracker":
                self.rejected_in_a_row = 0
            return False
        self.rejected += 1
        self.report.rejected += 1
        self.report.notes.append(f"{r.kind} measurement of t = {r.t:.3f} s rejected by the gate (d² = "
                                 f"{result.d2:.4g} > {self.gates[3]:.4g})")
        if r.kind != "tracker":
            return False
        self.rejected_in_a_row += 1
        if self.rejected_in_a_row < self.config.lost_after:
            return False
        self.rejected_in_a_row = 0
        return True

    def _vector(self, r: _Record) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """(inertial reference, body measurement, noise) of a magnetometer or sun record."""
        bodies = self.environment.bodies(r.t)
        if r.kind == "magnetometer":
            return bodies.field_N, r.data, np.eye(3) * self.config.magnetometer_sigma**2
        return bodies.sun, r.data, np.eye(3) * self.config.sun_sigma**2

    def _initialise(self, r: _Record) -> mekf.FilterState | None:
        """A first state from a tracker, or from a sun vector and a field sample close in time."""
        bias_cov = np.eye(3) * self.config.initial_bias_sigma**2
        if r.kind == "tracker":
            name, q_S = r.data
            spec = self.trackers[name]
            C = rot.dcm_NB(spec.mounting)
            q = rot.multiply(q_S, rot.conjugate(spec.mounting))
            P_att = C @ spec.covariance @ C.T
        else:
            pair = self._pair(r)
            if pair is None or self.environment is None:
                return None
            (sun_B, sun_N, sun_var), (field_B, field_N, field_var) = pair
            q, P_att = quest([sun_B, field_B / np.linalg.norm(field_B)], [sun_N, field_N / np.linalg.norm(field_N)],
                             [1.0 / sun_var, 1.0 / field_var])
        r.accepted = True
        self.diverged = False
        self.last_update = r.t
        if r.kind == "tracker":
            self.last_tracker = r.t
        self.report.notes.append(f"estimate initialised at t = {r.t:.3f} s from {r.kind}")
        return mekf.FilterState(r.t, q, self.last_bias.copy(), np.block([[P_att, np.zeros((3, 3))],
                                                                          [np.zeros((3, 3)), bias_cov]]))

    def _pair(self, r: _Record):
        """The sun and field observations (body, inertial, variance of the unit vector) of ``r`` and
        its partner of the other kind within ``pair_window``; None without one."""
        other = "magnetometer" if r.kind == "sun" else "sun"
        partner = next((p for p in reversed(self.records) if p.kind == other
                        and abs(p.t - r.t) <= self.config.pair_window), None)
        if partner is None:
            return None
        sun, field_rec = (r, partner) if r.kind == "sun" else (partner, r)
        bodies = self.environment.bodies(r.t)
        field_B = field_rec.data
        field_var = (self.config.magnetometer_sigma / max(float(np.linalg.norm(field_B)), 1e-9)) ** 2
        return (sun.data, bodies.sun, self.config.sun_sigma**2), (field_B, bodies.field_N, field_var)

    def _trim(self, now: float) -> None:
        """Forget what is older than ``history`` s (one snapshot stays: the oldest state kept)."""
        horizon = now - self.config.history
        while len(self.snapshots) > 1 and self.snapshots[1][0] <= horizon:
            self.snapshots.popleft()
        while self.gyro and self.gyro[0][0] <= self.snapshots[0][0]:
            self.gyro.popleft()
        self.records = self._records_after(self.snapshots[0][0])
