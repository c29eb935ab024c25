"""The attitude estimate of a recorded run against the truth: numpy, and one figure.

:func:`estimation_of` matches the estimator's ``/estimator/attitude`` with the simulator's truth
(``/spacecraft/state`` at the same stamps, the gyro's actual bias from ``/simulator/sensor_truth``)
and the sensors' measurements with what they measured (gyro rate, field). :func:`estimation_summary`
gives the figures of ``att-bench estimation`` — from the log alone, so anyone can recompute them —
and :func:`figure_estimation` the review's ``estimation.png``: estimation error per body axis with
the filter's ±3σ, the bias estimate against the truth, the health and the trackers' validity, the
measured-vs-true residuals of the gyro and the magnetometer.

The estimation error is the body-frame rotation from the estimate to the truth, ``δθ = 2 vec(q̂* ⊗
q)`` (the filter's own error definition), so its NEES ``δθᵀ P⁻¹ δθ`` (3 dof) is comparable with the
chi-square: a consistent filter averages 3.
"""
from __future__ import annotations

import math
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from att_msgs_py.log import TopicLog
from att_msgs_py.topics import ESTIMATE, IMU, MAGNETOMETER, SENSOR_TRUTH, STAR_TRACKER, STATE
from att_msgs_py.types import Health, TrackerStatus
from att_sim.models import rotations as rot

TOPICS = [STATE, ESTIMATE, SENSOR_TRUTH, STAR_TRACKER, IMU, MAGNETOMETER]
ARCSEC = math.degrees(1.0) * 3600.0          # arcsec per rad
DEG_PER_H = math.degrees(1.0) * 3600.0       # deg/h per rad/s


def _matched(a: np.ndarray, b: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Indices of the stamps ``a`` and ``b`` (s) that are the same instant (to the microsecond)."""
    ka, kb = np.round(np.asarray(a) * 1e6).astype(np.int64), np.round(np.asarray(b) * 1e6).astype(np.int64)
    _, ia, ib = np.intersect1d(ka, kb, return_indices=True)
    return ia, ib


@dataclass
class EstimationRun:
    t: np.ndarray                  # (n,) s of sim time: estimates that have a truth state
    error: np.ndarray              # (n, 3) rad, body axes: estimate -> truth
    covariance: np.ndarray         # (n, 3, 3) rad², the filter's attitude covariance
    health: np.ndarray             # (n,)
    bias_estimate: np.ndarray      # (n, 3) rad/s
    bias_truth: np.ndarray         # (n, 3) rad/s (NaN without the truth topic)
    tracker_t: np.ndarray          # (m,) measurement instants
    tracker_status: np.ndarray     # (m,) TrackerStatus
    tracker_period: float          # s between a tracker's samples (median)
    gyro_t: np.ndarray             # (k,)
    gyro_residual: np.ndarray      # (k, 3) rad/s, measured minus the true rate at the sample
    field_t: np.ndarray            # (j,)
    field_residual: np.ndarray     # (j, 3) T, measured minus the true field in body axes

    @property
    def sigma(self) -> np.ndarray:
        return np.sqrt(np.einsum("kii->ki", self.covariance))

    @property
    def nees(self) -> np.ndarray:
        return np.einsum("ki,ki->k", self.error, np.linalg.solve(self.covariance, self.error[..., None])[..., 0])


def estimation_of(log: dict[str, TopicLog], t_from: float = -math.inf, t_to: float = math.inf
                  ) -> EstimationRun | None:
    """The estimate against the truth between sim times ``t_from`` and ``t_to`` (None without both)."""
    if ESTIMATE not in log or STATE not in log:
        return None
    est, state = log[ESTIMATE], log[STATE]
    ie, is_ = _matched(est["header.stamp"], state["header.stamp"])
    t = np.asarray(est["header.stamp"])[ie]
    keep = (t >= t_from) & (t <= t_to) & (np.asarray(est["health"])[ie] != Health.INITIALISING)
    ie, is_, t = ie[keep], is_[keep], t[keep]
    if not len(t):
        return None
    q_est, q_true = est["attitude"][ie], state["attitude"][is_]
    error = 2 * np.array([rot.error_vector(qt, qe) for qt, qe in zip(q_true, q_est)]).reshape(-1, 3)
    bias_truth = np.full((len(t), 3), math.nan)
    if SENSOR_TRUTH in log:
        it, ie2 = _matched(log[SENSOR_TRUTH]["header.stamp"], t)
        bias_truth[ie2] = log[SENSOR_TRUTH]["gyro_bias"][it]
    tracker_t, status, period = np.zeros(0), np.zeros(0, int), math.nan
    if STAR_TRACKER in log:
        tracker_t = np.asarray(log[STAR_TRACKER]["header.stamp"])
        status = np.asarray(log[STAR_TRACKER]["status"], int)
        window = (tracker_t >= t[0]) & (tracker_t <= t[-1])
        tracker_t, status = tracker_t[window], status[window]
        period = float(np.median(np.diff(np.unique(tracker_t)))) if len(np.unique(tracker_t)) > 1 else math.nan
    gyro_t, gyro_res = _gyro_residual(log, t[0], t[-1])
    field_t, field_res = _residual(log, MAGNETOMETER, "magnetic_field", "magnetic_field_body", t[0], t[-1])
    return EstimationRun(t, error, np.asarray(est["attitude_covariance"])[ie].reshape(-1, 3, 3),
                         np.asarray(est["health"])[ie], est["gyro_bias"][ie], bias_truth, tracker_t, status, period,
                         gyro_t, gyro_res, field_t, field_res)


def _residual(log, topic: str, measured: str, true: str, t0: float, t1: float):
    """Measured minus the truth state's value at the same stamps, within [t0, t1]."""
    if topic not in log:
        return np.zeros(0), np.zeros((0, 3))
    im, is_ = _matched(log[topic]["header.stamp"], log[STATE]["header.stamp"])
    t = np.asarray(log[topic]["header.stamp"])[im]
    keep = (t >= t0) & (t <= t1)
    return t[keep], (log[topic][measured][im] - log[STATE][true][is_])[keep]


def _gyro_residual(log, t0: float, t1: float):
    """The gyro's output minus the true mean rate over the interval it ends (the rotation between
    the truth states at its previous and its own stamp, divided by the interval)."""
    if IMU not in log:
        return np.zeros(0), np.zeros((0, 3))
    imu_t = np.asarray(log[IMU]["header.stamp"])
    im, is_ = _matched(imu_t, log[STATE]["header.stamp"])
    q, t = log[STATE]["attitude"][is_], imu_t[im]
    true = np.array([rot.log_map(rot.multiply(rot.conjugate(a), b)) for a, b in zip(q[:-1], q[1:])]).reshape(-1, 3)
    true /= np.diff(t)[:, None]
    residual = log[IMU]["angular_velocity"][im][1:] - true
    keep = (t[1:] >= t0) & (t[1:] <= t1)
    return t[1:][keep], residual[keep]


def estimation_summary(run: EstimationRun) -> dict:
    """The figures of the estimate (angles in arcsec, bias in deg/h)."""
    angle = np.linalg.norm(run.error, axis=1)
    bias_error = run.bias_estimate[-1] - run.bias_truth[-1]
    invalid = int(np.sum(run.tracker_status != TrackerStatus.OK))
    return {
        "estimates": len(run.t), "from_s": float(run.t[0]), "to_s": float(run.t[-1]),
        "attitude_error_rms_arcsec": float(np.sqrt(np.mean(angle**2)) * ARCSEC),
        "attitude_error_max_arcsec": float(angle.max() * ARCSEC),
        "attitude_error_final_arcsec": float(angle[-1] * ARCSEC),
        "bias_error_final_deg_per_h": float(np.linalg.norm(bias_error) * DEG_PER_H),
        "nees_mean": float(np.mean(run.nees)), "nees_dof": 3,
        "tracker_invalid_seconds": float(invalid * run.tracker_period) if invalid else 0.0,
        "health_seconds": {h.name.lower(): float(np.sum(run.health == h) * np.median(np.diff(run.t)))
                           for h in Health if len(run.t) > 1},
    }


def figure_estimation(run: EstimationRun, path: Path, t0: float = 0.0) -> Path:
    """``estimation.png``: error ±3σ per axis, bias, health and tracker validity, sensor residuals."""
    from att_planner.tools.review.figures import _figure, _save

    plt, fig = _figure(figsize=(11, 13))
    axes = fig.subplots(5, 1, sharex=True)
    t = run.t - t0
    for i, (axis, color) in enumerate(zip("xyz", ("C0", "C1", "C2"))):
        axes[0].plot(t, run.error[:, i] * ARCSEC, color=color, lw=0.8, label=f"δθ_{axis}")
        axes[0].fill_between(t, -3 * run.sigma[:, i] * ARCSEC, 3 * run.sigma[:, i] * ARCSEC, color=color,
                             alpha=0.12, lw=0)
        axes[1].plot(t, run.bias_estimate[:, i] * DEG_PER_H, color=color, lw=1.0, label=f"estimate {axis}")
        axes[1].plot(t, run.bias_truth[:, i] * DEG_PER_H, color=color, lw=0.8, ls="--", label=f"truth {axis}")
    axes[0].set_ylabel("estimation error (arcsec)\nshaded: ±3σ")
    span = np.percentile(np.abs(run.error) * ARCSEC, 99.5) if len(t) else 1.0
    axes[0].set_ylim(-3 * span, 3 * span)
    axes[1].set_ylabel("gyro bias (deg/h)")
    for ax in axes[:2]:
        ax.legend(ncol=6, fontsize=7, loc="upper right")
    axes[2].step(t, run.health, where="post", color="k", lw=1.0, label="estimate health")
    axes[2].set_yticks([int(h) for h in Health], [h.name.lower() for h in Health])
    if len(run.tracker_t):
        blind = run.tracker_status != TrackerStatus.OK
        axes[2].plot(run.tracker_t[blind] - t0, np.full(blind.sum(), -0.5), "|", color="C3", ms=8,
                     label="tracker invalid (" + ", ".join(sorted({TrackerStatus(s).name.lower()
                                                                    for s in run.tracker_status[blind]})) + ")")
    axes[2].set_ylim(-1, 3.5)
    axes[2].legend(fontsize=7, loc="upper right")
    for i, axis in enumerate("xyz"):
        axes[3].plot(run.gyro_t - t0, run.gyro_residual[:, i] * DEG_PER_H, lw=0.5, label=axis)
        axes[4].plot(run.field_t - t0, run.field_residual[:, i] * 1e9, lw=0.8, label=axis)
    axes[3].set_ylabel("gyro measured − true\n(deg/h)")
    axes[4].set_ylabel("magnetometer measured −\ntrue field (nT)")
    for ax in axes[3:]:
        ax.legend(ncol=3, fontsize=7, loc="upper right")
    axes[-1].set_xlabel("time (s)")
    for ax in axes:
        ax.grid(alpha=0.3)
    fig.suptitle("Attitude estimate against the truth")
    return _save(plt, fig, path)
