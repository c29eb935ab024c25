"""The fault table (pydantic v2 schema): each fault the flight software watches for, the detector
that sees it, its threshold (the unit in the key's name), its persistence and its response.

A fault table file (``config/faults/NAME.yaml``) is a mapping ``faults:`` of fault ids to entries,
so that an id written twice is refused by the loader as a duplicate key (its file and line). Each
entry names its ``detector`` (the union's tag: an unknown one is refused with the known ones); the
detector fixes the **component** it watches (a wheel, a star tracker, the gyro...), the threshold's
key and unit, and the responses that fit that component (:data:`RESPONSES`): a response that does
not fit is refused naming the ones that do. Thresholds are > 0, persistences ≥ 0 s.

The file is read by :func:`read` through :mod:`att_sim.models.config_files` (every problem with
file, line and field path) and checked by ``att-config check``.
"""
from __future__ import annotations

import typing
from pathlib import Path
from typing import Annotated, ClassVar, Literal

from pydantic import Field, model_validator

from att_sim.models import config_files
from att_sim.models.config_base import Schema, number

DEFAULT_TABLE = Path(__file__).resolve().parents[2] / "config" / "faults" / "default.yaml"
MAX_FAULTS = 64

# response -> what it does (one definition; the docs page and the schema's descriptions read it)
RESPONSE_MEANINGS = {
    "report": "report the fault only",
    "exclude_wheel": "fly on the other wheels: the allocation re-made on the healthy set, the planner's "
                     "envelope reduced",
    "exclude_sensor": "the estimator continues on the other sensors (the excluded one re-admitted after a "
                      "healthy window where its detector allows)",
    "safe_mode": "rate damping, then Sun pointing (on the healthy wheels, else the magnetorquers)",
}
Response = Literal["report", "exclude_wheel", "exclude_sensor", "safe_mode"]

# component -> the responses that fit it
RESPONSES = {
    "wheel": ("report", "exclude_wheel", "safe_mode"),
    "wheel_tachometer": ("report", "exclude_wheel", "safe_mode"),
    "star_tracker": ("report", "exclude_sensor", "safe_mode"),
    "magnetometer": ("report", "exclude_sensor"),
    "gyro": ("report", "safe_mode"),
    "magnetorquer": ("report", "safe_mode"),
    "attitude": ("report", "safe_mode"),
    "rate": ("report", "safe_mode"),
    "estimate": ("report", "safe_mode"),
}

FaultId = Annotated[str, Field(min_length=1, max_length=64, pattern=r"^[a-z][a-z0-9_]*$")]


def persistence() -> object:
    return number(ge=0.0, le=3600.0, unit="s", meaning="sim time the detector's condition must hold before the "
                                                        "fault is declared (0: at once)")


class Entry(Schema):
    """One fault of the table: the detector (the tag), its threshold and persistence, the response."""

    component: ClassVar[str] = ""
    response: Response = Field(description="what the flight software does once the fault is declared: "
                                           + "; ".join(f"{k}: {v}" for k, v in RESPONSE_MEANINGS.items()))
    persistence_s: float = persistence()

    @model_validator(mode="after")
    def _response_fits(self):
        allowed = RESPONSES[self.component]
        if self.response not in allowed:
            raise ValueError(f"a response that fits detector {self.detector}'s component {self.component} "
                             f"(one of {', '.join(allowed)}), got {self.response}")
        return self


class WheelTorque(Entry):
    """A wheel whose measured acceleration (its tachometer speeds differentiated) departs from the
    commanded motor torque over its inertia, minus the expected friction, by more than the threshold
    expressed as a torque, grown by the drive's torque gain and the wheel's inertia tolerances times the
    torque commanded: seized, off, or with abnormal friction (:mod:`att_planner.fdir.wheel_health`)."""

    component: ClassVar[str] = "wheel"
    detector: Literal["wheel_torque"]
    threshold_Nm: float = number(gt=0.0, le=10.0, unit="N m", meaning="residual motor torque")
    window_s: float = number(1.0, gt=0.0, le=60.0, unit="s", meaning="span of each half of the two windows "
                                                                     "whose mean speeds are differenced")
    drive_gain_tolerance: float = number(0.0, ge=0.0, lt=1.0, unit="", meaning=(
        "relative tolerance a of a healthy drive's torque gain (delivered over commanded motor torque within "
        "1 +- a): the threshold grows by a/(1 - b) times the motor torque commanded over the windows; "
        "a + b below 1, or a wheel that delivers nothing would pass (0: exact drives)"))
    wheel_inertia_tolerance: float = number(0.0, ge=0.0, lt=1.0, unit="", meaning=(
        "relative tolerance b of the wheels' spin inertia against the nominal one: the threshold grows by "
        "b/(1 - b) times the net torque (motor minus expected friction) commanded over the windows (0: exact)"))

    @model_validator(mode="after")
    def _a_fault_stays_visible(self):
        a, b = self.drive_gain_tolerance, self.wheel_inertia_tolerance
        if not a + b < 1.0:
            raise ValueError(f"drive_gain_tolerance + wheel_inertia_tolerance below 1 (a wheel that delivers no "
                             f"torque would pass as healthy: a/(1 - b) >= 1), got {a:g} + {b:g} = {a + b:g}")
        return self


class WheelCheck(Entry):
    """A wheel that does not follow the speed change it is commanded (:mod:`att_planner.fdir.wheel_check`):
    the least-squares fraction ``θ`` of the commanded speed change it delivers below ``threshold``
    (seized, off) or the multiple ``ψ`` of the expected friction it shows above ``friction_threshold``,
    each judged only when its standard deviation over the window leaves a healthy wheel ``z`` of them
    clear of its threshold. The controller excites the wheels for it: a ± square wave of ``amplitude_Nm``
    and ``period_s`` along the healthy wheels' null space, no torque on the body
    (:mod:`att_planner.control.wheel_check`; none with fewer than four healthy wheels, none in safe mode)."""

    component: ClassVar[str] = "wheel"
    detector: Literal["wheel_check"]
    amplitude_Nm: float = number(gt=0.0, le=10.0, unit="N m", meaning="the null-space excitation's amplitude per "
                                                                      "unit null vector (0.5 of it per wheel on a "
                                                                      "four-wheel pyramid)")
    period_s: float = number(gt=0.0, le=600.0, unit="s", meaning="period of the excitation's square wave")
    window_s: float = number(gt=0.0, le=600.0, unit="s", meaning="span of the tachometer samples fitted")
    threshold: float = number(gt=0.0, lt=1.0, unit="", meaning="fraction of the commanded speed change "
                                                               "delivered below which a wheel is faulty")
    friction_threshold: float = number(gt=1.0, le=1e3, unit="", meaning="multiple of the expected friction "
                                                                        "above which a wheel is faulty")
    z: float = number(gt=0.0, le=100.0, unit="", meaning="standard deviations a healthy wheel's statistic "
                                                         "must stay clear of its threshold for it to be judged")
    drive_gain_tolerance: float = number(0.0, ge=0.0, lt=1.0, unit="", meaning=(
        "relative tolerance a of a healthy drive's torque gain: a healthy wheel delivers at least "
        "(1 - a)/(1 + b) of its commanded speed change"))
    wheel_inertia_tolerance: float = number(0.0, ge=0.0, lt=1.0, unit="", meaning=(
        "relative tolerance b of the wheels' spin inertia: a healthy wheel shows at most 1/(1 - b) of "
        "the expected friction"))

    @model_validator(mode="after")
    def _thresholds_clear_of_healthy(self):
        a, b = self.drive_gain_tolerance, self.wheel_inertia_tolerance
        theta_min, psi_max = (1.0 - a) / (1.0 + b), 1.0 / (1.0 - b)
        if not self.threshold < theta_min:
            raise ValueError(f"threshold below (1 - drive_gain_tolerance)/(1 + wheel_inertia_tolerance) = "
                             f"{theta_min:.4g} (the least a healthy wheel delivers), got {self.threshold:g}")
        if not self.friction_threshold > psi_max:
            raise ValueError(f"friction_threshold above 1/(1 - wheel_inertia_tolerance) = {psi_max:.4g} (the "
                             f"most friction a healthy wheel shows), got {self.friction_threshold:g}")
        if not self.window_s >= self.period_s:
            raise ValueError(f"window_s at least period_s (a whole period of the excitation in each window, "
                             f"so no line explains it), got window_s {self.window_s:g} s and period_s "
                             f"{self.period_s:g} s")
        return self


class TachometerFrozen(Entry):
    """A tachometer whose reading does not change by more than the threshold (a stuck counter)."""

    component: ClassVar[str] = "wheel_tachometer"
    detector: Literal["tachometer_frozen"]
    threshold_rad_s: float = number(gt=0.0, le=10.0, unit="rad/s", meaning="largest change counted as frozen")


class GyroFrozen(Entry):
    """A gyro axis whose reading does not change by more than the threshold (a stuck axis)."""

    component: ClassVar[str] = "gyro"
    detector: Literal["gyro_frozen"]
    threshold_rad_s: float = number(gt=0.0, le=1.0, unit="rad/s", meaning="largest change counted as frozen")


class MagnetometerFrozen(Entry):
    """A magnetometer whose field does not change by more than the threshold on any axis."""

    component: ClassVar[str] = "magnetometer"
    detector: Literal["magnetometer_frozen"]
    threshold_nT: float = number(gt=0.0, le=1e5, unit="nT", meaning="largest change counted as frozen")


class TrackerInnovation(Entry):
    """A star tracker whose normalised innovation squared ``d² = yᵀ S⁻¹ y`` exceeds the threshold
    on every measurement for the persistence while another tracker stays consistent; re-admitted
    after ``readmit_s`` of consistent measurements."""

    component: ClassVar[str] = "star_tracker"
    detector: Literal["tracker_innovation"]
    threshold: float = number(gt=0.0, le=1e6, unit="", meaning="d² above which a measurement is inconsistent "
                                                               "(the chi-square quantile with 3 degrees of freedom)")
    readmit_s: float = number(30.0, ge=0.0, le=3600.0, unit="s", meaning="consistent sim time before an "
                                                                         "excluded tracker is used again")


class GyroInnovation(Entry):
    """The gyro, when every star tracker (at least two) is inconsistent at once for the persistence:
    the common cause of their innovations is the propagation (a bias step); the axis is the largest
    component of their mean innovation."""

    component: ClassVar[str] = "gyro"
    detector: Literal["gyro_innovation"]
    threshold: float = number(gt=0.0, le=1e6, unit="", meaning="d² above which a measurement is inconsistent")


class GyroBiasJump(Entry):
    """The gyro, when the estimator's bias estimate moves on one axis by more than the threshold within
    ``window_s`` (a bias step the filter is following; one star tracker is enough)."""

    component: ClassVar[str] = "gyro"
    detector: Literal["gyro_bias_jump"]
    threshold_deg_h: float = number(gt=0.0, le=1e5, unit="deg/h", meaning="change of the bias estimate")
    window_s: float = number(10.0, gt=0.0, le=3600.0, unit="s", meaning="span the change is measured over")


class _TrackerGyro(Entry):
    """The fields of the detectors that compare each star tracker with the gyro's propagation
    (:mod:`att_planner.fdir.tracker_gyro`): a GLR threshold, the window and the onsets' span."""

    threshold: float = number(gt=0.0, le=1e6, unit="", meaning="generalised likelihood ratio above which a tracker's "
                                                               "residual against the gyro has changed (chi-square, "
                                                               "3 degrees of freedom)")
    window_s: float = number(12.0, gt=0.0, le=600.0, unit="s", meaning="span of each tracker's residuals fitted "
                                                                       "(a line, and the change)")
    onset_s: float = number(4.0, gt=0.0, le=600.0, unit="s", meaning="span, at the window's end, of the onsets tried")
    discontinuity_deg: float = number(1.0, gt=0.0, le=180.0, unit="deg", meaning="change of a tracker's residual "
                                      "between two measurements taken as the attitude itself moving (a simulation "
                                      "reset): its window starts again, no verdict")

    @model_validator(mode="after")
    def _onset_in_window(self):
        if not self.onset_s < self.window_s:
            raise ValueError(f"onset_s below window_s (the onsets tried lie inside the window), got onset_s "
                             f"{self.onset_s:g} s and window_s {self.window_s:g} s")
        return self


class TrackerStep(_TrackerGyro):
    """A star tracker whose attitude steps against the gyro's propagation (a bias jump), its residual
    alone: one tracker is enough."""

    component: ClassVar[str] = "star_tracker"
    detector: Literal["tracker_step"]


class GyroRamp(_TrackerGyro):
    """The gyro, when a star tracker's attitude ramps away from the gyro's propagation (a rate bias
    step, a stuck axis) while no tracker's steps: one tracker is enough; the axis is the rate error's
    most significant component."""

    component: ClassVar[str] = "gyro"
    detector: Literal["gyro_ramp"]


class CoilCheck(Schema):
    """The active coil check (:mod:`att_planner.control.coil_check`): every ``period_s`` one magnetometer
    sample is taken with one coil commanded ``dipole_fraction`` of the coils' limit for ``dwell_s`` before
    it, the coils in turn, each one's sign alternating; its torque is fed forward to the wheels and the
    magnetometer reads the dipole back (:mod:`att_planner.fdir.coils`)."""

    period_s: float = number(1.0, gt=0.0, le=600.0, unit="s", meaning="sim time between two check samples (rounded "
                                                                       "to the magnetometer's samples; each coil is "
                                                                       "checked every 3 periods)")
    dipole_fraction: float = number(0.5, gt=0.0, le=1.0, unit="", meaning="fraction of the coils' dipole limit "
                                                                          "commanded on the coil checked")
    dwell_s: float = number(0.05, gt=0.0, le=60.0, unit="s", meaning="sim time the check's dipole is held before "
                                                                     "its magnetometer sample (the coil's settling)")
    window_s: float = number(20.0, gt=0.0, le=3600.0, unit="s", meaning="span of the magnetometer samples fitted "
                                                                        "(a line per axis and the check's read-back)")

    @model_validator(mode="after")
    def _a_visible_pattern(self):
        if not self.dwell_s < self.period_s:
            raise ValueError(f"dwell_s below period_s (the coils are off between two checks, so the other "
                             f"magnetometer samples stay clean), got dwell_s {self.dwell_s:g} s and period_s "
                             f"{self.period_s:g} s")
        if not self.window_s >= 6.0 * self.period_s:
            raise ValueError(f"window_s at least 6 period_s (each coil seen with both signs in a window), got "
                             f"window_s {self.window_s:g} s and period_s {self.period_s:g} s")
        return self


class CoilTorque(Entry):
    """A magnetorquer coil whose commanded dipole does not turn the body: the momentum measured (gyro and
    tachometers) explained better with that coil open than with every coil healthy
    (:mod:`att_planner.fdir.coils`); a coil never commanded cannot be seen. With a ``check``, the coils
    are pulsed in turn and the magnetometer's read-back of their dipole judged too."""

    component: ClassVar[str] = "magnetorquer"
    detector: Literal["coil_torque"]
    threshold: float = number(gt=0.0, le=1e6, unit="", meaning="generalised likelihood ratio of the coil open "
                                                               "against every coil healthy (chi-square, 1 degree "
                                                               "of freedom)")
    window_s: float = number(60.0, gt=0.0, le=3600.0, unit="s", meaning="span of the momentum balance, the "
                                                                        "disturbance taken as constant over it")
    check: CoilCheck | None = Field(None, description="the active coil check (none: the coils are judged only "
                                                      "while a law commands them)")


class TrackerOutage(Entry):
    """A star tracker from which no measurement (valid or not) arrived for the threshold."""

    component: ClassVar[str] = "star_tracker"
    detector: Literal["tracker_outage"]
    threshold_s: float = number(gt=0.0, le=3600.0, unit="s", meaning="silence after which the tracker is out")


class AttitudeError(Entry):
    """The attitude error from the reference above the threshold (the attitude cannot be controlled)."""

    component: ClassVar[str] = "attitude"
    detector: Literal["attitude_error"]
    threshold_deg: float = number(gt=0.0, le=180.0, unit="deg", meaning="attitude error from the reference")


class RateError(Entry):
    """The body rate error from the reference above the threshold."""

    component: ClassVar[str] = "rate"
    detector: Literal["rate_error"]
    threshold_deg_s: float = number(gt=0.0, le=360.0, unit="deg/s", meaning="rate error from the reference")


class EstimateUncertain(Entry):
    """The estimate lost (diverged or initialising) or its attitude 3σ above the threshold: the
    attitude cannot be known."""

    component: ClassVar[str] = "estimate"
    detector: Literal["estimate_uncertain"]
    threshold_deg: float = number(gt=0.0, le=180.0, unit="deg", meaning="attitude 3 sigma of the estimate")


Detector = Annotated[WheelTorque | WheelCheck | TachometerFrozen | GyroFrozen | MagnetometerFrozen | TrackerInnovation
                     | GyroInnovation | GyroBiasJump | TrackerStep | GyroRamp | CoilTorque | TrackerOutage
                     | AttitudeError | RateError | EstimateUncertain,
                     Field(discriminator="detector")]
DETECTORS = {typing.get_args(m.model_fields["detector"].annotation)[0]: m
             for m in typing.get_args(typing.get_args(Detector)[0])}   # detector name -> its entry model


class FaultTable(Schema):
    """A fault table file (``config/faults/NAME.yaml``): fault ids and their entries."""

    faults: dict[FaultId, Detector] = Field(max_length=MAX_FAULTS, description="fault id -> its entry")

    @model_validator(mode="after")
    def _one_wheel_hardware(self):
        """The wheels' tolerances describe one set of hardware: every entry that declares them agrees."""
        for name in ("drive_gain_tolerance", "wheel_inertia_tolerance"):
            seen = {fid: getattr(e, name) for fid, e in self.faults.items() if hasattr(e, name)}
            if len(set(seen.values())) > 1:
                raise ValueError(f"{name} differs between entries ({', '.join(f'{k}: {v:g}' for k, v in seen.items())})"
                                 ": they describe the same wheels")
        return self


def read(path=DEFAULT_TABLE) -> FaultTable:
    """The fault table file ``path`` read by the one loader;
    :class:`att_sim.models.config_files.ConfigFileError` (``INVALID_CONFIG``) with every problem."""
    return config_files.load_file(path, FaultTable).model

