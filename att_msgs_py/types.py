"""Plain numpy mirror types of the att_msgs interfaces, and the vocabularies they use.

Every module of the suite speaks these types; only :mod:`att_msgs_py.convert` turns them into
messages and back. Conventions (the whole suite): SI units, quaternions ``[x, y, z, w]``
(geometry_msgs order) describing the body frame with respect to the inertial frame
(body-to-inertial), body rates in body axes.

The vocabularies (:class:`Status`, :class:`ControlMode`, :class:`ControlKind`,
:class:`Interpolation`, :class:`Stage`) are written here once; the constants of the .msg files carry the same
values, which a test checks.
"""
from __future__ import annotations

import math
from dataclasses import dataclass, field
from datetime import datetime
from enum import IntEnum, StrEnum

import numpy as np


class Status(StrEnum):
    """How a plan (or any search of the suite) ended: ``att_msgs/ManeuverPlan.STATUS_*``."""

    OPTIMAL = "optimal"                # converged to a (local) optimum
    FEASIBLE = "feasible"              # a valid answer, optimality not proven (iteration limit)
    BUDGET_EXPIRED = "budget_expired"  # the time budget ran out; the best answer so far
    FALLBACK = "fallback"              # the method failed; a safe fallback plan is returned
    FAILED = "failed"                  # no answer


class ControlMode(IntEnum):
    """Controller / actuator modes: ``att_msgs/ActuatorCommand.MODE_*``."""

    IDLE = 0
    MAGNETORQUER_PD = 1
    PLAN_TRACKING = 2
    SAFE = 3
    POINTING = 4                       # a guidance law (PointingMode) tracked through the wheels


CONTROL_MODES = tuple(int(m) for m in ControlMode)   # the values a command or set_mode may carry


class ControlKind(StrEnum):
    """What a plan's control samples are: ``att_msgs/ManeuverPlan.control_kind``."""

    BODY_TORQUE = "body_torque"        # N m, body axes
    WHEEL_TORQUE = "wheel_torque"      # N m, one motor torque per wheel


class Interpolation(StrEnum):
    """How control samples are applied between knots: ``att_msgs/ManeuverPlan.interpolation``."""

    ZOH = "zoh"                        # sample k held on [t_k, t_k+1)
    LINEAR = "linear"                  # linear between the knots


@dataclass(frozen=True)
class Cone:
    """Keep-out cone (``att_msgs/KeepOutCone``): the sensor boresight stays at least
    ``half_angle`` (rad) away from the inertial unit ``direction``."""

    direction: np.ndarray
    half_angle: float
    name: str = ""

    def __post_init__(self):
        d = np.asarray(self.direction, dtype=float)
        object.__setattr__(self, "direction", d / np.linalg.norm(d))


ZONE_BODIES = ("inertial", "sun", "moon", "earth_limb")


@dataclass(frozen=True)
class Zone:
    """A zone of a body-fixed sensor: the boresight ``R(q) sensor_axis`` stays out of
    (``keep_in`` False) or inside (True) a cone about a target seen from the spacecraft.

    ``body`` (:data:`ZONE_BODIES`): ``inertial`` (the fixed unit ``direction``: a keep-out cone),
    ``sun`` or ``moon`` (the direction from the spacecraft), ``earth_limb`` (axis −r̂, the nadir,
    and half-angle asin(R_E/|r|) + ``half_angle``: there ``half_angle`` is the margin beyond the
    limb). ``half_angle`` in rad. Vectors are normalised when they have a finite, non-zero norm
    (:func:`att_planner.cones.zone_issue` refuses the others; a vector unit to 1e-15 is kept bit for
    bit, so cones convert exactly); ``direction`` is None for the bodies.
    """

    name: str
    body: str
    sensor_axis: np.ndarray
    half_angle: float
    keep_in: bool = False
    direction: np.ndarray | None = None

    def __post_init__(self):
        for name in ("sensor_axis", "direction"):
            value = getattr(self, name)
            if value is None:
                continue
            v = np.array(value, dtype=float).reshape(-1)
            n = np.linalg.norm(v) if v.size == 3 and np.isfinite(v).all() else 0.0
            object.__setattr__(self, name, v / n if n > 0 and abs(n - 1.0) > 1e-15 else v)
        object.__setattr__(self, "half_angle", float(self.half_angle))
        object.__setattr__(self, "keep_in", bool(self.keep_in))


@dataclass
class Verification:
    """A plan predicted by verification's prediction model (``att_msgs/PlanVerification``).

    The fields from ``duration`` on are not on the wire.
    """

    final_attitude_error: float        # rad, to the goal attitude (semi-free: boresight to target)
    final_rate: float                  # rad/s, ‖ω(t_f)‖ (a moving goal: ‖ω(t_f) − ω_goal(t_f)‖)
    min_cone_margin: float             # rad over the dense grid and every zone (+inf without zones): the clearance
    cone_margins: list                 # rad, minimum clearance per zone: the cones, then the zones (request order)
    torque_ratio: float                # max |control| / its limit over the applied samples
    wheel_speed_ratio: float           # max |Ω_i| / limit over the dense grid (0 without wheels)
    rate_max: float                    # rad/s, largest ‖ω‖ over the dense grid
    dense_samples: int                 # integration samples the figures are taken over
    goal: str = ""                     # the pointing kind of a moving goal ('' : at rest or semi-free)
    duration: float = math.nan         # s
    body_rate_ratio: float = 0.0       # max |ω_j| / the problem's rate bound (0 without one)
    wheel_momentum_ratio: float = 0.0  # max |h_w,i| / the problem's momentum bound (0 without one)
    passage_attitude_errors: list = field(default_factory=list)   # rad, per passage
    passage_rates_z: list = field(default_factory=list)           # rad/s, |ω_z| per passage
    zone_names: list = field(default_factory=list)                # name per entry of cone_margins
    zone_keep_in: list = field(default_factory=list)              # keep-in flag per entry of cone_margins
    boundary_arc: str = ""             # name of the cone a forced boundary arc rides ('' : none)


class Stage(StrEnum):
    """The stages of a maneuver answer: ``att_msgs/PlanStage.STAGE_*``."""

    FIRST = "first"              # the constructive first plan
    METHOD = "method"            # the requested method, seeded with the first plan
    FALLBACK = "fallback"        # the eigenaxis slew


@dataclass
class StageReport:
    """One stage of a maneuver answer (``att_msgs/PlanStage``): which method ran, how long it and
    the verification of its plan took, how it ended."""

    name: Stage
    method: str
    seconds: float
    status: str = ""                   # the method's Status ("" when it did not run)
    verified: bool = False
    duration: float = math.nan         # s, t_f of its plan
    message: str = ""


@dataclass(frozen=True)
class Passage:
    """A target a plan passes through: its name, the passage time (s from the plan start), the
    target attitude and how long the plan holds it there (s; 0: a passage, not an observation)."""

    name: str
    time: float
    attitude: np.ndarray
    dwell: float = 0.0


def _empty(*shape):
    return field(default_factory=lambda: np.zeros(shape))


@dataclass
class Plan:
    """A maneuver plan (``att_msgs/ManeuverPlan``), in the style of ``scipy.optimize.OptimizeResult``.

    Samples: ``torque[k]`` (body torque, (K, 3), or one motor torque per wheel, (K, N), as
    ``control_kind`` says) is applied from ``t[k]`` as ``interpolation`` says; ``t[0] = 0`` and
    ``t[-1]`` is the duration; ``q``/``omega`` are the planner's reference states at ``t`` (what the
    controller tracks). Outcome: ``status``, ``message``, ``nit``/``nfev`` (solver iterations and
    function evaluations, 0 where they do not apply), ``wall_time`` (s) and free-form ``stats``.
    Context, filled by the planner service: ``plan_id``, ``spacecraft``, ``frame_id``,
    ``sensor_axis``, ``cones``, ``verification`` and, for a schedule, the ``passages``; then
    ``spacecraft_digest``, ``key_id`` and the Ed25519 ``signature`` (:mod:`att_msgs_py.signing`);
    ``zones`` (:class:`Zone`, besides the cones) and the ``epoch`` of t = 0. A method
    that finds nothing returns a plan without samples and status FAILED (or BUDGET_EXPIRED).
    ``nit``, ``nfev``, ``stats`` and ``passages`` are not on the wire.
    """

    t: np.ndarray = _empty(0)
    torque: np.ndarray = _empty(0, 3)
    q: np.ndarray = _empty(0, 4)
    omega: np.ndarray = _empty(0, 3)
    control_kind: ControlKind = ControlKind.BODY_TORQUE
    interpolation: Interpolation = Interpolation.ZOH
    method: str = ""
    status: Status = Status.FAILED
    message: str = ""
    nit: int = 0
    nfev: int = 0
    wall_time: float = 0.0
    stats: dict = field(default_factory=dict)
    plan_id: str = ""
    spacecraft: str = ""
    frame_id: str = ""
    sensor_axis: np.ndarray = field(default_factory=lambda: np.array([1.0, 0.0, 0.0]))
    cones: list = field(default_factory=list)
    verification: Verification | None = None
    passages: list = field(default_factory=list)
    spacecraft_digest: str = ""
    key_id: str = ""
    signature: bytes = b""
    zones: list = field(default_factory=list)          # Zone, the request's (besides the cones)
    epoch: datetime | None = None                      # UTC instant of t = 0 (None: no epoch)

    @property
    def duration(self) -> float:
        return float(self.t[-1] - self.t[0]) if len(self.t) else 0.0

    @property
    def order(self) -> list[str]:
        """The names of the passages, in the order they are flown (a schedule's visiting order)."""
        return [p.name for p in self.passages]

    @property
    def success(self) -> bool:
        """A usable plan: at least two samples and a status other than FAILED."""
        return self.status != Status.FAILED and len(self.t) >= 2


@dataclass
class State:
    """Spacecraft truth state (``att_msgs/SpacecraftState``)."""

    t: float                           # s of sim time
    q: np.ndarray                      # (4,) body-to-inertial
    omega: np.ndarray                  # (3,) rad/s, body axes
    wheel_speeds: np.ndarray           # (N,) rad/s
    wheel_torques: np.ndarray = _empty(0)       # (N,) N m, applied motor torques
    field_body: np.ndarray = _empty(3)          # T, body axes
    dipole: np.ndarray = _empty(3)              # A m², applied
    applied_torque: np.ndarray = _empty(3)      # N m, body axes
    position: np.ndarray = _empty(3)            # m, inertial
    command_timeout: bool = False
    frame_id: str = ""
    body_frame_id: str = ""


@dataclass
class Command:
    """Actuator command (``att_msgs/ActuatorCommand``); only the fields of ``mode`` are used."""

    mode: int
    wheel_torques: np.ndarray          # (N,) or empty, N m
    dipole: np.ndarray = _empty(3)     # A m², body axes
    body_torque: np.ndarray = _empty(3)  # N m, body axes
    plan_id: str = ""
    t: float = 0.0                     # s of sim time: the state this command answers
    frame_id: str = ""


@dataclass
class ControllerStatus:
    """Controller status (``att_msgs/ControllerStatus``)."""

    mode: int
    t: float = 0.0
    plan_id: str = ""
    plan_progress: float = 0.0
    state_stale: bool = False
    message: str = ""
    frame_id: str = ""
    guidance: str = ""                                  # the pointing mode's kind (POINTING)
    reference_q: np.ndarray = _empty(4)                 # tracked attitude now (zero: none)
    reference_rate: np.ndarray = _empty(3)              # rad/s, reference axes
    attitude_error: float = math.nan                    # rad, from the reference
    dumping: bool = False


@dataclass
class ManeuverFeedback:
    """Feedback of ``att_msgs/action/ExecuteManeuver``."""

    elapsed: float                     # s of sim time
    progress: float                    # 0..1
    attitude_error: float              # rad, to the plan reference
    min_cone_margin: float             # rad, now


@dataclass
class ManeuverResult:
    """Result of ``att_msgs/action/ExecuteManeuver``."""

    success: bool
    error_code: int
    message: str
    duration: float = 0.0              # s of sim time
    final_attitude_error: float = math.nan   # rad, to the plan's final attitude
    final_rate: float = math.nan       # rad/s


# ---------------------------------------------------------------------------------------------
# Sensors and the attitude estimate
# ---------------------------------------------------------------------------------------------

class TrackerStatus(IntEnum):
    """Why a star tracker measurement is (in)valid: ``att_msgs/StarTracker.STATUS_*``."""

    OK = 0
    SUN = 1                            # the Sun inside its exclusion angle
    EARTH = 2                          # the Earth's limb inside its exclusion angle
    MOON = 3
    EXCLUDED = 4                       # an inertial exclusion direction
    RATE = 5                           # turning too fast to track stars


class Health(IntEnum):
    """State of the attitude estimate: ``att_msgs/AttitudeEstimate.HEALTH_*``."""

    INITIALISING = 0                   # no attitude yet (waiting for a tracker or two vectors)
    CONVERGED = 1                      # attitude measurements flow and the covariance is small
    PROPAGATING = 2                    # no accepted attitude measurement for a while: gyro only
    DIVERGED = 3                       # numerically broken or lost: to be reinitialised


@dataclass
class GyroMeasurement:
    """Mean body rate over the last sample interval (``sensor_msgs/Imu.angular_velocity``)."""

    t: float                           # s of sim time: the end of the interval
    omega: np.ndarray                  # (3,) rad/s, body axes (nominal mounting)
    covariance: np.ndarray = _empty(3, 3)   # (rad/s)², the white noise of one sample
    frame_id: str = ""


@dataclass
class StarTrackerMeasurement:
    """Attitude of a tracker's sensor frame (``att_msgs/StarTracker``); ``q`` is sensor-to-inertial."""

    t: float                           # s of sim time: the instant measured (the message comes latency later)
    name: str                          # the tracker (its sensor frame)
    q: np.ndarray                      # (4,) sensor-to-inertial, x y z w
    covariance: np.ndarray = _empty(3, 3)   # rad², attitude error about the sensor axes
    valid: bool = True
    status: int = TrackerStatus.OK
    frame_id: str = ""                 # the inertial frame


@dataclass
class MagnetometerMeasurement:
    """Field in body axes (``sensor_msgs/MagneticField``)."""

    t: float
    field: np.ndarray                  # (3,) T
    covariance: np.ndarray = _empty(3, 3)   # T²
    frame_id: str = ""


@dataclass
class SunSensorMeasurement:
    """Coarse sun sensor outputs, 1 at normal incidence (``att_msgs/CoarseSunSensors``)."""

    t: float
    values: np.ndarray                 # (N,) one per detector
    noise: float = 0.0                 # 1σ of each value
    frame_id: str = ""


@dataclass
class WheelSpeedMeasurement:
    """Tachometer speeds relative to the body (``sensor_msgs/JointState.velocity``)."""

    t: float
    speeds: np.ndarray                 # (N,) rad/s
    frame_id: str = ""


@dataclass
class SensorTruth:
    """What the sensors' errors are now (``att_msgs/SensorTruth``): for evaluation only."""

    t: float
    gyro_bias: np.ndarray = _empty(3)          # rad/s, body axes
    magnetometer_bias: np.ndarray = _empty(3)  # T
    frame_id: str = ""


@dataclass
class AttitudeEstimate:
    """The estimator's output (``att_msgs/AttitudeEstimate``)."""

    t: float
    q: np.ndarray                      # (4,) body-to-inertial
    omega: np.ndarray                  # (3,) rad/s: gyro minus the bias estimate
    gyro_bias: np.ndarray              # (3,) rad/s
    attitude_covariance: np.ndarray = _empty(3, 3)   # rad², body-frame attitude error
    bias_covariance: np.ndarray = _empty(3, 3)       # (rad/s)²
    health: int = Health.INITIALISING
    time_since_update: float = math.inf              # s since the last attitude fix (tracker, or vectors without one)
    rejected: int = 0                  # measurements gated out so far
    message: str = ""
    frame_id: str = ""
    body_frame_id: str = ""


# ---------------------------------------------------------------------------------------------
# Pointing modes
# ---------------------------------------------------------------------------------------------

POINTING_KINDS = ("inertial", "nadir", "sun", "ground", "inertial_target", "strip")
SECONDARY_KINDS = ("velocity", "ground_velocity", "orbit_normal", "sun", "nadir", "north", "inertial")


@dataclass
class PointingMode:
    """A pointing mode (``att_msgs/PointingMode``): see the message for the fields' meaning."""

    kind: str
    attitude: np.ndarray = _empty(4)           # inertial: all zero = the current attitude
    primary_axis: np.ndarray = field(default_factory=lambda: np.array([0.0, 0.0, 1.0]))
    secondary_axis: np.ndarray = field(default_factory=lambda: np.array([1.0, 0.0, 0.0]))
    secondary: str = "velocity"
    secondary_direction: np.ndarray = _empty(3)
    yaw: float = 0.0
    latitude: float = 0.0
    longitude: float = 0.0
    altitude: float = 0.0
    target_direction: np.ndarray = _empty(3)
    end_latitude: float = 0.0                  # strip: its end, rad (latitude, longitude, altitude: its start)
    end_longitude: float = 0.0
    scan_speed: float = 0.0                    # strip: m/s along the ground
    scan_start: float = 0.0                    # strip: sim time (s) the aim point leaves the start


class ShapeKind(StrEnum):
    """How a :class:`Shape` is drawn (``visualization_msgs/Marker`` TRIANGLE_LIST, LINE_STRIP, ARROW)."""

    TRIANGLES = "triangles"
    LINE = "line"
    ARROW = "arrow"


@dataclass(frozen=True)
class Shape:
    """One marker of the 3D view: ``points`` (N, 3) m in frame ``frame_id`` (a
    triangle list, a line strip, or an arrow's tail and head), colour ``rgba`` in [0, 1], line or
    shaft ``width`` m. ``(ns, id)`` names it, so a newer shape with the same name replaces it."""

    ns: str
    id: int
    frame_id: str
    kind: ShapeKind
    points: np.ndarray
    rgba: tuple[float, float, float, float]
    width: float = 0.02


class MissionEventKind(StrEnum):
    """What a mission event reports: ``att_msgs/MissionEvent``'s constants."""

    SCHEDULED = "scheduled"
    SLEW = "slew"
    DWELL = "dwell"
    PARK = "park"
    MISSED = "missed"
    REFUSED = "refused"
    ENDED = "ended"


@dataclass(frozen=True)
class MissionEvent:
    """One event of a mission (``att_msgs/MissionEvent``): at sim time ``t``, ``event`` about
    ``target`` over ``[start, end]`` s of sim time, its attitude and direction when it has them, the
    body ``sensor_axis`` put on it and the pointing ``tolerance`` (rad) a dwell is observed within;
    a ground site's ``pointing`` mode; the names of the ``zones`` the mission keeps."""

    t: float
    event: MissionEventKind
    target: str = ""
    start: float = 0.0
    end: float = 0.0
    attitude: np.ndarray = field(default_factory=lambda: np.array([0.0, 0.0, 0.0, 1.0]))
    direction: np.ndarray = field(default_factory=lambda: np.zeros(3))
    sensor_axis: np.ndarray = field(default_factory=lambda: np.zeros(3))
    tolerance: float = 0.0
    plan_id: str = ""
    message: str = ""
    frame_id: str = ""
    pointing: PointingMode | None = None
    zones: tuple = ()


class FaultSource(StrEnum):
    """Where an injected fault came from: ``att_msgs/FaultEvent.SOURCE_*``."""

    SCENARIO = "scenario"              # the scenario's faults list
    SERVICE = "service"                # a /simulator/inject_fault request
    DISPERSION = "dispersion"          # drawn for a Monte Carlo run from its seed


@dataclass(frozen=True)
class FaultEvent:
    """A hardware fault the truth started at sim time ``t`` (``att_msgs/FaultEvent``): the failing
    ``component`` and its ``index``, the ``kind``, its parameters (``factor`` the friction multiplier,
    ``bias_rad`` a star tracker's bias rotation vector in its sensor axes (rad; empty for another kind),
    ``bias_rad_s`` a gyro axis's bias step) and its ``source``."""

    t: float
    component: str
    index: int
    kind: str
    factor: float = 1.0
    bias_rad: tuple = ()
    bias_rad_s: float = 0.0
    source: FaultSource = FaultSource.SCENARIO
    frame_id: str = ""


@dataclass(frozen=True)
class FaultStatus:
    """A fault the flight software detected (``att_msgs/FaultStatus``), reported at sim time ``t``:
    the fault table entry ``fault_id``, the ``component`` and ``index`` it isolated, the ``detector``
    that fired on what ``evidence``, the ``response`` taken, whether the fault stands (``active``)
    and when it was confirmed (``detected_at``, s of sim time)."""

    t: float
    fault_id: str
    component: str
    index: int
    detector: str
    evidence: str
    response: str
    active: bool
    detected_at: float
    frame_id: str = ""
