"""The attitude estimator's core (no ROS): measurements in, a checked estimate with its health out.

:class:`Estimator` runs the MEKF of :mod:`.mekf` on the gyro, star trackers, magnetometer and coarse
sun sensors: the node only translates messages; tests and the Monte Carlo drive the core directly.
It is three parts: the measurement history (:class:`~.history.MeasurementHistory`, out-of-sequence
replay), the filter (:mod:`.mekf`, pure functions on stacks of filters) and the health monitor
(:class:`~.health.HealthMonitor`); :func:`replay` runs the history of a batch of estimators through
the filter, their propagations and updates as stacks (a single estimator is a batch of one).

* **Time** is the gyro's: each gyro sample (the mean rate over the interval it ends) propagates the
  filter to its stamp. Its stamps must move forward by at most ``max_gyro_gap`` (no single message
  can stall or steer the filter's clock); after ``resync_timeout`` s of wall time without a gyro
  sample the next one starts a new timeline (a restarted simulator) and the filter starts afresh.
  A measurement stamped more than ``max_gyro_gap`` ahead of the gyro is refused. Other measurements
  are applied **at the instant they were taken**, late ones by reprocessing the last ``history`` s
  (:mod:`.history`).
* **Propagation** on the gyro, its scale factors and misalignments *considered* from their
  datasheet spread (:func:`.mekf.propagate`): the covariance grows with the rotation the gyro
  measures, not only with time, so a filter blind through a slew stays honest.
* **Updates**: every valid star tracker measurement (mounting ``q_SB``: the body attitude is
  ``q_SN ⊗ q_SB*``, noise ``R_B = C R_S Cᵀ``); magnetometer and sun-sensor vector updates only when
  no tracker measurement taken in the ``vector_fallback_after`` s before the vector's instant was
  accepted (:meth:`Estimator.last_tracker_at`). A magnetometer sample taken while the magnetorquers
  were commanded (the command before its stamp had a dipole) is not used: the controller blanks its
  coils before each sample (duty cycling).
* **Catching up**: a measurement is kept when it arrives (``take_*``) and applied by the next
  reprocessing (:meth:`Estimator.reprocess`, which the next gyro sample makes): the measurements
  that came between two gyro samples are applied in one replay, in time order. ``on_*`` keep and
  reprocess at once.
* **Gating**: a measurement with ``d² > χ²_k(gate_probability)`` is rejected and counted; each is
  gated once, when it first arrives, and replayed with the same decision.
* **Initialisation** without a prior: the first valid star tracker measurement (``P₀`` = its noise
  and the bias prior), else QUEST (Shuster & Oh 1981) on a sun vector and a clean magnetometer
  sample taken within ``pair_window`` s of each other.
* **Health**: :mod:`.health`.
* **Exclusion**: the sensors named in :attr:`Estimator.excluded` (a tracker's name, ``magnetometer``,
  ``sun``) are not used: a vector not at all, a tracker's measurement not applied nor used to
  initialise, but its innovation still computed (and not counted as a rejection) so that a fault
  monitor can judge when to re-admit it. Every tracker measurement's innovation, used or not, is
  kept for the monitor (:meth:`Estimator.take_innovations`, :class:`~.health.Innovation`).

Inputs are hostile until checked (:mod:`.inputs`): a refused measurement raises
:class:`~att_msgs_py.errors.RequestError` (320 INVALID_MEASUREMENT, 321 STALE_MEASUREMENT) and
changes nothing. A saturated gyro sample (any axis at its range) propagates with the attitude
covariance grown by ``(range Δt)²`` per axis: the true rate is unknown beyond it.
"""
from __future__ import annotations

import math
from dataclasses import dataclass

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
from att_planner.estimation.health import HealthMonitor, Innovation, Report
from att_planner.estimation.history import MeasurementHistory, Record, Step
from att_planner.estimation.inputs import DipoleLog, InputChecks
from att_sim.models import rotations as rot
from att_sim.models.sensor_specs import SensorSpecs

LOST_COVARIANCE = math.pi**2        # rad²: the attitude covariance published without an estimate
FLICKER_HORIZON = 300.0            # s: the bias random walk of the default tuning grows by B in this time


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


MESSAGES = {Health.INITIALISING: "waiting for a star tracker or a sun vector and a field measurement",
            Health.DIVERGED: "estimate lost: reinitialising from the next measurements",
            Health.PROPAGATING: "propagating on the gyro", Health.CONVERGED: "converged"}   # an estimate's, by health


class Estimator:
    def __init__(self, specs: SensorSpecs, config: EstimatorConfig, environment=None, frame_id: str = "",
                 body_frame_id: str = ""):
        """``specs``: the datasheets (mountings, ranges); ``environment``: the onboard models of
        the field and the Sun (:meth:`att_sim.models.world.Environment.bodies`), needed for vector updates."""
        self.specs, self.config, self.environment = specs, config, environment
        self.frame_id, self.body_frame_id = frame_id, body_frame_id
        self.checks = InputChecks(specs, frame_id, body_frame_id)
        self.trackers = {s.name: s for s in specs.star_trackers}
        variances = np.array([config.scale_factor_sigma**2] * 3 + [config.misalignment_sigma**2] * 6)
        self.consider = variances if np.any(variances > 0) else None
        # what a propagation takes besides the state: estimators of one tuning propagate as one stack
        self.tuning = (config.arw, config.rrw, None if self.consider is None else self.consider.tobytes())
        from scipy.special import gammaincinv  # the chi-square quantile; scipy.stats costs seconds to import

        self.gates = {k: 2.0 * float(gammaincinv(k / 2.0, config.gate_probability)) for k in (3,)}
        self.history = MeasurementHistory(config.history, config.max_gyro_gap)
        self.monitor = HealthMonitor(config.propagate_timeout, config.converged_attitude_sigma, config.lost_after,
                                     bool(self.trackers))
        self.dipoles = DipoleLog()
        self.last_bias_B = np.zeros(3)
        self.last_q_BN = rot.IDENTITY.copy()
        self.next_publish = -math.inf
        self.last_wall = -math.inf                # when the last gyro sample arrived (monotonic s)
        self.excluded: set[str] = set()           # sensors not used (a fault monitor's exclusion)
        self.pending: int | None = None           # the oldest state a measurement kept since the last
                                                  # reprocessing sends the filter back to

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
        """The newest filter state (None: no estimate)."""
        return self.history.state

    @property
    def newest(self) -> int:
        """Index of the newest state: :meth:`reprocess` from it catches up with a new gyro sample."""
        return self.history.newest

    # -- inputs -----------------------------------------------------------------------------------
    def on_gyro(self, m: GyroMeasurement, wall: float = 0.0) -> AttitudeEstimate | None:
        """Propagate to the sample's stamp (and apply what arrived meanwhile); the estimate when
        one is due (every ``publish_period``). ``wall``: the monotonic time it arrived: a sample more
        than ``max_gyro_gap`` after the last is refused unless none came for ``resync_timeout`` s, in
        which case it starts a new timeline (a restarted simulator): the filter starts afresh. In
        three parts — :meth:`take_gyro`, :meth:`reprocess` from :attr:`newest`, :meth:`publish` — so
        that a batch of estimators can make the middle one together (:func:`replay`)."""
        omega = self.take_gyro(m, wall)
        self.reprocess(self.newest)
        return self.publish(m.t, omega)

    def take_gyro(self, m: GyroMeasurement, wall: float = 0.0) -> np.ndarray:
        """Check and keep a gyro sample (see :meth:`on_gyro`); its measured rate ``omega_BN_B``."""
        last = self.history.last_gyro
        silent = wall - self.last_wall > self.config.resync_timeout
        omega, saturated = self.checks.gyro(m, None if silent else last)
        if last is not None and not 0.0 < m.t - last <= self.config.max_gyro_gap:
            if not silent:
                raise RequestError(ErrorCode.STALE_MEASUREMENT,
                                   f"gyro stamp {m.t:.6g} s is {m.t - last:+.6g} s from the last ({last:.6g} s); "
                                   f"it must move forward by at most max_gyro_gap_s = {self.config.max_gyro_gap:g} s")
            self.monitor.report.notes.append(f"gyro timeline restarted: {last:.3f} s then {m.t:.3f} s; "
                                             "filter restarted")
            self._restart()
        self.last_wall = wall
        if saturated:
            self.monitor.report.notes.append(f"gyro saturated at t = {m.t:.3f} s: attitude covariance grown")
        self.history.keep_gyro(m.t, omega, saturated)
        return omega

    def publish(self, t: float, omega_BN_B_measured: np.ndarray) -> AttitudeEstimate | None:
        """After a gyro sample of time ``t`` was caught up with: what is older than ``history``
        forgotten; the estimate when one is due (every ``publish_period``), else None."""
        self.history.trim(t)
        if t < self.next_publish - 1e-9:
            return None
        self.next_publish = t + self.config.publish_period
        return self.estimate(t, omega_BN_B_measured)

    def _restart(self) -> None:
        """Forget every state, sample and measurement (a new timeline): initialising again."""
        self.history.clear()
        self.pending = None
        self.monitor.restart()
        self.next_publish = -math.inf

    def on_star_tracker(self, m: StarTrackerMeasurement) -> None:
        """Apply a valid tracker measurement at its instant (an invalid one says only that)."""
        self.take_star_tracker(m)
        self.reprocess(self.newest)

    def take_star_tracker(self, m: StarTrackerMeasurement) -> None:
        """Check and keep a tracker measurement for the next :meth:`reprocess`."""
        q_SN = self.checks.star_tracker(m)
        if q_SN is not None:
            self._keep(Record(m.t, "tracker", (m.name, q_SN)))

    def on_magnetometer(self, m: MagnetometerMeasurement) -> None:
        """Apply a magnetometer sample at its instant (one taken while the coils were on is not used)."""
        self.take_magnetometer(m)
        self.reprocess(self.newest)

    def take_magnetometer(self, m: MagnetometerMeasurement) -> None:
        """Check and keep a magnetometer sample for the next :meth:`reprocess`."""
        field_B = self.checks.magnetometer(m)
        if self.dipoles.clean(m.t):
            self._keep(Record(m.t, "magnetometer", field_B))

    def on_sun_sensors(self, m: SunSensorMeasurement) -> None:
        """Apply the sun vector of the coarse sun sensors at its instant (none when the Sun is not seen)."""
        self.take_sun_sensors(m)
        self.reprocess(self.newest)

    def take_sun_sensors(self, m: SunSensorMeasurement) -> None:
        """Check the coarse sun sensors' outputs and keep their sun vector for the next :meth:`reprocess`."""
        values = self.checks.sun_sensors(m)
        sun_B = sun_vector(values, self.specs.sun_sensors.normals, self.config.sun_threshold)
        if sun_B is not None:
            self._keep(Record(m.t, "sun", sun_B))

    def _keep(self, record: Record) -> None:
        """Keep ``record``; :attr:`pending` goes back to the state before it when that is older."""
        start = self.history.insert(record)
        if start is not None and (self.pending is None or start < self.pending):
            self.pending = start

    def on_dipole_command(self, t: float, dipole: np.ndarray) -> None:
        """The controller's magnetorquer command stamped ``t`` (for the magnetometer's blanking)."""
        self.dipoles.record(t, dipole)

    def take_report(self) -> Report:
        return self.monitor.take_report()

    def take_innovations(self) -> list[Innovation]:
        """The tracker innovations computed since the last call, in the order they were first processed."""
        return self.monitor.take_innovations()

    def is_excluded(self, r: Record) -> bool:
        """Whether the sensor of ``r`` is in :attr:`excluded`."""
        return bool(self.excluded) and (r.data[0] if r.kind == "tracker" else r.kind) in self.excluded

    # -- output -----------------------------------------------------------------------------------
    def health(self, t: float) -> Health:
        return self.monitor.health(t, self.state)

    def estimate(self, t: float, omega_BN_B_measured: np.ndarray) -> AttitudeEstimate:
        """The estimate at gyro time ``t`` (the filter's newest state)."""
        x, health = self.state, self.health(t)
        if x is None:
            P_att, P_bias = np.eye(3) * LOST_COVARIANCE, np.eye(3) * self.config.initial_bias_sigma**2
            q_BN, bias_B = self.last_q_BN, self.last_bias_B
        else:
            P_att, P_bias, q_BN, bias_B = x.P[:3, :3].copy(), x.P[3:, 3:].copy(), x.q_BN, x.bias_B
            self.last_q_BN, self.last_bias_B = q_BN, bias_B
        last_fix = self.monitor.last_fix
        return AttitudeEstimate(t=t, q=q_BN.copy(), omega=omega_BN_B_measured - bias_B, gyro_bias=bias_B.copy(),
                                attitude_covariance=P_att, bias_covariance=P_bias, health=int(health),
                                time_since_update=t - last_fix, rejected=self.monitor.rejected,
                                message=MESSAGES[health], frame_id=self.frame_id, body_frame_id=self.body_frame_id)

    # -- the filter over its history ---------------------------------------------------------------
    def reprocess(self, start: int | None) -> None:
        """Rebuild every state after snapshot ``start`` (None: nothing to do), or after the older
        :attr:`pending`, from it: :func:`replay` of this estimator alone."""
        replay([(self, start)])

    def interval(self, x: mekf.FilterState, t: float, saturated: bool) -> tuple[float, float]:
        """``dt`` from ``x`` to ``t`` and the attitude variance a saturated sample adds over it."""
        dt = t - x.t
        return dt, (self.specs.gyro.range * dt) ** 2 if saturated and self.specs.gyro else 0.0

    def correction(self, x: mekf.FilterState, r: Record) -> mekf.Correction | None:
        """The Kalman update the measurement ``r`` asks of ``x`` (gated the first time; replayed as
        decided then); None when ``r`` is not used (a vector while the trackers are fresh)."""
        if r.kind == "tracker":
            name, q_SN = r.data
            q_SB = self.trackers[name].mounting
            dcm_BS = rot.dcm_NB(q_SB)
            y = mekf.attitude_residual(x.q_BN, rot.multiply(q_SN, rot.conjugate(q_SB)))
            H, R = mekf.attitude_sensitivity(), dcm_BS @ self.trackers[name].covariance @ dcm_BS.T
        elif (r.t - self.last_tracker_at(r.t) <= self.config.vector_fallback_after or self.environment is None
              or self.is_excluded(r)):
            return None
        else:
            reference_N, measured_B, R = self._vector(r)
            y, H = mekf.vector_residual(x.q_BN, measured_B, reference_N)
        if r.accepted is None and self.is_excluded(r):
            return mekf.Correction(x, y, H, R, -math.inf)          # its innovation only
        return mekf.Correction(x, y, H, R, self.gates[3] if r.accepted is None else math.inf)

    def last_tracker_at(self, t: float) -> float:
        """Instant of the newest accepted tracker measurement taken at or before ``t`` (-inf: none):
        a replay decides whether a vector is used from the trackers before it, not from a later one
        that arrived first."""
        last = self.monitor.last_tracker
        return last if last <= t else self.history.last_accepted("tracker", t)

    def corrected(self, x: mekf.FilterState, r: Record, update: mekf.Update,
                  correction: mekf.Correction | None = None) -> mekf.FilterState | None:
        """``x`` after the measurement ``r`` made ``update`` (None: the estimate is lost); ``correction``
        (the update asked): its innovation kept the first time ``r`` is processed."""
        monitor = self.monitor
        if r.accepted is None and correction is not None and r.kind == "tracker":
            used = not self.is_excluded(r)
            monitor.innovation(Innovation(r.t, r.data[0], correction.y.copy(), update.d2, correction.R.copy(), used))
            if not used:
                r.accepted = False
                return x
        if r.accepted is None and monitor.judged(r, update, self.gates[3]):
            return monitor.lose(r.t, f"{self.config.lost_after} star tracker measurements in a row rejected")
        if not (r.accepted and update.accepted):
            return x
        if not mekf.healthy(update.state.P[None])[0]:
            return monitor.lose(r.t, f"covariance not positive definite after a {r.kind} update at t = {r.t:.3f} s")
        monitor.accepted(r)
        return update.state

    def propagated(self, t: float, x: mekf.FilterState, healthy: bool) -> mekf.FilterState | None:
        """``x`` propagated to ``t``, or None (the estimate lost) when its covariance is not ``healthy``."""
        return x if healthy else self.monitor.lose(t, f"covariance not positive definite at t = {t:.3f} s")

    def _vector(self, r: Record) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """(inertial reference, body measurement, noise) of a magnetometer or sun record."""
        bodies = self.environment.bodies(r.t)
        if r.kind == "magnetometer":
            return bodies.field_N, r.data, np.eye(3) * self.config.magnetometer_sigma**2
        return bodies.sun, r.data, np.eye(3) * self.config.sun_sigma**2

    def initialise(self, r: Record) -> mekf.FilterState | None:
        """A first state from a tracker, or from a sun vector and a field sample close in time."""
        bias_cov = np.eye(3) * self.config.initial_bias_sigma**2
        if self.is_excluded(r):
            return None
        if r.kind == "tracker":
            name, q_SN = r.data
            spec = self.trackers[name]
            dcm_BS = rot.dcm_NB(spec.mounting)
            q_BN = rot.multiply(q_SN, rot.conjugate(spec.mounting))
            P_att = dcm_BS @ spec.covariance @ dcm_BS.T
        else:
            pair = self._pair(r)
            if pair is None or self.environment is None:
                return None
            (sun_B, sun_N, sun_var), (field_B, field_N, field_var) = pair
            q_BN, P_att = quest([sun_B, field_B / np.linalg.norm(field_B)],
                                [sun_N, field_N / np.linalg.norm(field_N)], [1.0 / sun_var, 1.0 / field_var])
        self.monitor.initialised(r)
        return mekf.FilterState(r.t, q_BN, self.last_bias_B.copy(), np.block([[P_att, np.zeros((3, 3))],
                                                                              [np.zeros((3, 3)), bias_cov]]))

    def _pair(self, r: Record):
        """The sun and field observations (body, inertial, variance of the unit vector) of ``r`` and
        its partner of the other kind within ``pair_window``; None without one."""
        partner = self.history.partner("magnetometer" if r.kind == "sun" else "sun", r.t, self.config.pair_window)
        if partner is None:
            return None
        sun, field_record = (r, partner) if r.kind == "sun" else (partner, r)
        if self.is_excluded(partner):
            return None
        bodies = self.environment.bodies(r.t)
        field_B = field_record.data
        field_var = (self.config.magnetometer_sigma / max(float(np.linalg.norm(field_B)), 1e-9)) ** 2
        return (sun.data, bodies.sun, self.config.sun_sigma**2), (field_B, bodies.field_N, field_var)


@dataclass
class _Replay:
    """One estimator's replay: its state and the steps left (:meth:`.history.MeasurementHistory.replay_from`)."""

    estimator: Estimator
    x: mekf.FilterState | None
    steps: list[Step]


def replay(jobs) -> None:
    """:meth:`Estimator.reprocess` of each ``(estimator, start)`` of a batch (from its :attr:`~Estimator.pending`
    state when that is older; start None and nothing pending: nothing to do).

    Each estimator's history says the steps from its state ``start`` (:class:`~.history.Step`); the
    estimators take their k-th steps together: the propagations of the estimators of one tuning as
    one stack (:func:`.mekf.propagate`), then the Kalman updates asked as stacks (:func:`.mekf.update`),
    each estimator's own operations in their order, so each reaches the state it reaches alone. At
    the end the largest attitude variance of each newest state, which its health needs, as one stack
    (:meth:`.health.HealthMonitor.keep_largest_attitude_variance`)."""
    runs = []
    for e, start in jobs:
        if e.pending is not None:
            start, e.pending = e.pending if start is None else min(start, e.pending), None
        if start is not None:
            runs.append(_Replay(e, *e.history.replay_from(start)))
    live, k = [run for run in runs if run.steps], 0
    while live:
        _propagate([(run, run.steps[k]) for run in live])
        _correct([(run, run.steps[k].record) for run in live if run.steps[k].record is not None])
        for run in live:
            if run.steps[k].record is None:
                run.estimator.history.snapshots.append((run.steps[k].t, run.x))
        k += 1
        live = [run for run in live if len(run.steps) > k]
    for run in runs:
        run.estimator.history.forget_before(run.estimator.monitor.lost_at)
    newest = [(run.estimator, run.estimator.state) for run in runs if run.estimator.state is not None]
    if len(newest) > 1:                # alone, health() computes it when asked
        largest = mekf.largest_attitude_variance(np.array([x.P for _, x in newest]))
        for (e, x), value in zip(newest, largest):
            e.monitor.keep_largest_attitude_variance(x, value)


def _propagate(steps: list[tuple[_Replay, Step]]) -> None:
    """Each run's state propagated to its step's instant (unchanged when there is nothing to do; None
    when the covariance goes bad: the estimate is lost), one stack per tuning."""
    tunings: dict[tuple, list[tuple[_Replay, Step]]] = {}
    for run, step in steps:
        if run.x is not None and step.t > run.x.t:
            tunings.setdefault(run.estimator.tuning, []).append((run, step))
    for group in tunings.values():
        e = group[0][0].estimator
        intervals = [run.estimator.interval(run.x, step.t, step.saturated) for run, step in group]
        states = mekf.propagate([run.x for run, _ in group], np.array([step.omega_BN_B_measured for _, step in group]),
                                [dt for dt, _ in intervals], e.config.arw, e.config.rrw, e.consider,
                                [extra for _, extra in intervals])
        for (run, step), x, ok in zip(group, states, mekf.healthy(np.array([x.P for x in states]))):
            run.x = run.estimator.propagated(step.t, x, ok)


def _correct(records: list[tuple[_Replay, Record]]) -> None:
    """Each run's state after its step's measurement: a first state when it has none, else the
    Kalman updates of the batch as stacks."""
    asked = []
    for run, r in records:
        if run.x is None:
            run.x = run.estimator.initialise(r)
        else:
            correction = run.estimator.correction(run.x, r)
            if correction is not None:
                asked.append((run, r, correction))
    for (run, r, correction), update in zip(asked, mekf.update([c for _, _, c in asked])):
        run.x = run.estimator.corrected(run.x, r, update, correction)
