"""Imaging requests (no ROS): a slew onto a ground site and its dwell (``ImageTarget``), or onto a
strip's first point at the scan's rate (``ImageStrip``), validated field by field, planned and
verified as a maneuver that ends on a moving goal (:mod:`.requests`, :mod:`.planning`), then checked
for the instrument's view.

Every field is checked before any numerics: finite; latitudes in [−90, 90] deg, longitudes in
[−180, 180] deg, altitudes in [−500 m, 100 km] (the ground modes' range), a dwell in [0, a day], a
strip of 1 m to 2000 km (:mod:`att_planner.guidance.strip`), a scan speed in (0, 20 km/s] (0: the
sub-satellite point's ground speed at the start: the scan that keeps a push-broom's line rate);
refusals are INVALID_SITE (162) naming the field. The site (a strip: its first point) must rise
above the instrument's minimum elevation within the planning window, and the arrival and the whole
dwell or scan must be seen above it (SITE_NOT_VISIBLE, 163): elevation ``sin e = û · (r − s)/|r − s|``
(:func:`att_planner.guidance.ground_arrival.elevation_sines`), sampled every :data:`VISIBILITY_STEP_S` over the
window and every :data:`IMAGE_STEP_S` over the image. A strip's tracking (its reference rate and the
torque ``J ω̇ + ω × J ω``, :func:`att_planner.guidance.strip.tracking_demand`) must stay within the
body-rate bound and the per-axis torque bound: before the plan from at least one of
:data:`TRACKING_STARTS` starts where the strip's start is in view, after it from the arrival
(INVALID_SITE naming ``scan_speed_m_s``).
"""
from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass, field

import numpy as np

from att_msgs_py import validation
from att_msgs_py.errors import ErrorCode, RequestError
from att_msgs_py.types import PointingMode
from att_planner.guidance.ground_arrival import MIN_ELEVATION_DEG, earth_axis_N, elevation_sines, itrs_to_geodetic
from att_planner.guidance.laws import PointingGeometry, geodetic_to_itrs
from att_planner.guidance.modes import MAX_ALTITUDE, MIN_ALTITUDE, strip_mode
from att_planner.guidance.strip import (
    MAX_SCAN_SPEED_M_S,
    MAX_STRIP_LENGTH_M,
    MIN_STRIP_LENGTH_M,
    Strip,
    tracking_demand,
)
from att_planner.methods import END_POINTING_METHODS
from att_planner.service.moving_goal import onboard_geometry, strip_goal_law
from att_planner.service.planning import PlanOutcome, plan_maneuver, run_method
from att_planner.service.requests import (
    MAX_DWELL,
    ManeuverRequest,
    ValidRequest,
    load_scenario,
    validate_maneuver,
)
from att_planner.verification import TOLERANCES, Tolerances
from att_sim.models import rotations as rot
from att_sim.models.geomagnetic import EARTH_ROTATION_RATE

BAD = ErrorCode.INVALID_SITE
VISIBILITY_STEP_S = 5.0           # s between the elevation samples over the planning window
IMAGE_STEP_S = 1.0                # s between the elevation samples over a dwell or a scan ...
IMAGE_SAMPLES = 600               # ... at most this many
TRACKING_STARTS = 8               # scan starts in view a strip's tracking is checked at before the plan
# an imaging request naming no method, when the node's default cannot end on a moving goal
DEFAULT_IMAGE_METHOD = "time_optimal"


@dataclass
class ImageCommon:
    """The fields every imaging request has (as numpy, as the node received them)."""

    frame_id: str
    q_initial: np.ndarray
    sensor_axis: np.ndarray                   # the instrument's boresight, body axes
    along_track_axis: np.ndarray              # the detector's along-track axis, body axes
    method: str = ""
    time_budget: float = 0.0
    spacecraft: str = ""
    epoch: tuple = (0, 0)
    wheel_speeds: list = field(default_factory=list)
    zones: list = field(default_factory=list)     # kept by the slew (att_msgs_py.types.Zone), as PlanManeuver's


@dataclass
class ImageTargetRequest(ImageCommon):
    latitude_deg: float = 0.0
    longitude_deg: float = 0.0
    altitude_m: float = 0.0
    dwell_s: float = 0.0
    align_along_track: bool = True            # the along-track axis on the ground track (else on the velocity)


@dataclass
class ImageStripRequest(ImageCommon):
    start_latitude_deg: float = 0.0
    start_longitude_deg: float = 0.0
    end_latitude_deg: float = 0.0             # used unless by_azimuth
    end_longitude_deg: float = 0.0
    by_azimuth: bool = False                  # the strip from its start along azimuth_deg for length_m
    azimuth_deg: float = 0.0
    length_m: float = 0.0
    altitude_m: float = 0.0
    scan_speed_m_s: float = 0.0               # 0: the sub-satellite point's ground speed at the start


@dataclass
class ValidImage:
    """A checked imaging request: the maneuver onto its goal and what its image needs."""

    maneuver: ValidRequest
    geometry: PointingGeometry
    offset: float                             # s: sim time of plan time 0
    sites_E: Callable                         # (sim time the image starts, sim times (K,)) ↦ aim points (K, 3) ITRS
    duration: float                           # s: the dwell, or the scan
    min_elevation: float                      # rad
    mode: PointingMode | None = None          # the target's pointing mode (the controller's law after the slew)
    strip: Strip | None = None
    axes: tuple = ()                          # a strip's (boresight, along-track axis), body axes
    rate_max: float = math.inf                # rad/s per axis: a strip's scan keeps it


@dataclass
class ImageOutcome(PlanOutcome):
    """A planned image: the maneuver's outcome, and when the image starts and ends (s after the plan's
    start), the lowest elevation the site or strip is seen at through it (rad) and the pointing mode
    the controller hands over to at the slew's end (the site's ground mode, or the strip's scan from
    the arrival)."""

    image_start: float = math.nan
    image_end: float = math.nan
    lowest_elevation: float = math.nan
    pointing_after: PointingMode | None = None


def _degrees(value, name: str, limit: float) -> float:
    return math.radians(validation.number(value, name, BAD, -limit, limit))


def _altitude(value, name: str) -> float:
    return validation.number(value, name, BAD, MIN_ALTITUDE, MAX_ALTITUDE)


def _maneuver(req: ImageCommon, end_pointing=None, end_goal=None, *, frame_id: str, default_spacecraft: str,
              default_method: str, default_budget: float) -> ValidRequest:
    method = default_method if default_method in END_POINTING_METHODS else DEFAULT_IMAGE_METHOD
    return validate_maneuver(
        ManeuverRequest(req.frame_id, req.q_initial, req.q_initial, req.sensor_axis, [], method=req.method,
                        time_budget=req.time_budget, spacecraft=req.spacecraft, epoch=req.epoch,
                        wheel_speeds=list(req.wheel_speeds), zones=list(req.zones), end_pointing=end_pointing,
                        end_goal=end_goal),
        frame_id=frame_id, default_spacecraft=default_spacecraft, default_method=method,
        default_budget=default_budget)


def _axes(req: ImageCommon) -> tuple[np.ndarray, np.ndarray]:
    boresight = validation.unit_vector(req.sensor_axis, "sensor_axis", ErrorCode.INVALID_SENSOR_AXIS)
    along = validation.unit_vector(req.along_track_axis, "along_track_axis", ErrorCode.INVALID_SENSOR_AXIS)
    if np.linalg.norm(rot.cross(boresight, along)) < 1e-3:
        raise RequestError(ErrorCode.INVALID_SENSOR_AXIS, "along_track_axis is parallel to sensor_axis: the detector "
                                                          "needs an along-track axis across the boresight")
    return boresight, along


def elevation(geometry: PointingGeometry, sites_E: np.ndarray, t: np.ndarray) -> np.ndarray:
    """The spacecraft's elevation (rad) above the horizon of the point ``sites_E[k]`` (ITRS) at sim time ``t[k]``."""
    r_E = np.array([np.asarray(geometry.dcm_EN(tk)) @ geometry.state_N(tk)[0] for tk in t])
    sites_E = np.asarray(sites_E, float).reshape(-1, 3)
    up = np.array([_up(s) for s in sites_E])
    return np.arcsin(np.clip(elevation_sines(r_E, sites_E, up, pairs=True), -1.0, 1.0))


def _up(site_E: np.ndarray) -> np.ndarray:
    """The geodetic up of a point (the WGS-84 normal, through its geodetic latitude and longitude)."""
    lat, lon, _ = itrs_to_geodetic(site_E)
    return np.array([math.cos(lat) * math.cos(lon), math.cos(lat) * math.sin(lon), math.sin(lat)])


def check_rises(valid: ValidImage, what: str) -> np.ndarray:
    """The image's first point rises above the minimum elevation somewhere in the planning window;
    the sampled sim times when it stands above it."""
    window = valid.maneuver.problem.zone_sky().window
    t = valid.offset + np.arange(0.0, window + VISIBILITY_STEP_S, VISIBILITY_STEP_S)
    first = valid.sites_E(0.0, np.zeros(1))[0]
    seen = elevation(valid.geometry, np.tile(first, (len(t), 1)), t)
    if seen.max() < valid.min_elevation:
        raise RequestError(ErrorCode.SITE_NOT_VISIBLE,
                           f"{what} rises to {math.degrees(seen.max()):.1f} deg above its horizon at most within the "
                           f"{window:.0f} s planning window; the instrument images above "
                           f"{math.degrees(valid.min_elevation):.1f} deg (ask with a later epoch)")
    return t[seen >= valid.min_elevation]


def validate_image_target(req: ImageTargetRequest, *, frame_id: str, default_spacecraft: str, default_method: str,
                          default_budget: float, min_elevation_deg: float = MIN_ELEVATION_DEG) -> ValidImage:
    """Check an ImageTarget request (module docstring); the maneuver onto the site's ground mode."""
    lat = _degrees(req.latitude_deg, "latitude_deg", 90.0)
    lon = _degrees(req.longitude_deg, "longitude_deg", 180.0)
    alt = _altitude(req.altitude_m, "altitude_m")
    dwell = validation.number(req.dwell_s, "dwell_s", BAD, 0.0, MAX_DWELL)
    boresight, along = _axes(req)
    mode = PointingMode("ground", primary_axis=boresight, secondary_axis=along,
                        secondary="ground_velocity" if req.align_along_track else "velocity",
                        latitude=lat, longitude=lon, altitude=alt)
    maneuver = _maneuver(req, mode, frame_id=frame_id, default_spacecraft=default_spacecraft,
                         default_method=default_method, default_budget=default_budget)
    geometry, offset = onboard_geometry(load_scenario(maneuver.spacecraft), maneuver.problem.epoch)
    site = geodetic_to_itrs(lat, lon, alt)
    valid = ValidImage(maneuver, geometry, offset, lambda start, t: np.tile(site, (len(t), 1)), dwell,
                       math.radians(min_elevation_deg), mode=mode)
    check_rises(valid, f"the site ({req.latitude_deg:.4f}, {req.longitude_deg:.4f}) deg")
    return valid


def sub_satellite_speed(geometry: PointingGeometry, t: float, site_E: np.ndarray) -> float:
    """The ground speed (m/s) of the point under the spacecraft at ``t``, at the radius of ``site_E``:
    the spacecraft's velocity over the turning Earth without its radial part, scaled by ``|s|/|r|``."""
    r, v = geometry.state_N(t)
    g = v - EARTH_ROTATION_RATE * rot.cross(earth_axis_N(geometry, t), r)
    r_hat = r / np.linalg.norm(r)
    return float(np.linalg.norm(g - r_hat * float(g @ r_hat)) * np.linalg.norm(site_E) / np.linalg.norm(r))


def validate_image_strip(req: ImageStripRequest, *, frame_id: str, default_spacecraft: str, default_method: str,
                         default_budget: float, min_elevation_deg: float = MIN_ELEVATION_DEG,
                         rate_max: float = math.inf, default_scan_speed_m_s: float = 0.0) -> ValidImage:
    """Check an ImageStrip request (module docstring); the maneuver onto the strip's first point at its
    rate. ``rate_max``: the body-rate bound (rad/s per axis) the scan keeps (with the problem's own);
    ``default_scan_speed_m_s``: the speed of a request that gives none (0: the sub-satellite point's)."""
    lat0 = _degrees(req.start_latitude_deg, "start_latitude_deg", 90.0)
    lon0 = _degrees(req.start_longitude_deg, "start_longitude_deg", 180.0)
    alt = _altitude(req.altitude_m, "altitude_m")
    speed = validation.number(req.scan_speed_m_s, "scan_speed_m_s", BAD, 0.0, MAX_SCAN_SPEED_M_S) or \
        default_scan_speed_m_s
    # every field is checked, the form's unused ones too (a NaN is never silently ignored)
    lat1 = _degrees(req.end_latitude_deg, "end_latitude_deg", 90.0)
    lon1 = _degrees(req.end_longitude_deg, "end_longitude_deg", 180.0)
    azimuth = _degrees(req.azimuth_deg, "azimuth_deg", 360.0)
    length = validation.number(req.length_m, "length_m", BAD, MIN_STRIP_LENGTH_M if req.by_azimuth else 0.0,
                               MAX_STRIP_LENGTH_M)
    boresight, along = _axes(req)
    built = {}

    def end_goal(scenario, epoch):
        """The strip (its speed's default needs the orbit) and the law onto its first point."""
        geometry, offset = onboard_geometry(scenario, epoch)
        v = speed or sub_satellite_speed(geometry, offset, geodetic_to_itrs(lat0, lon0, alt))
        try:
            strip = (Strip.from_azimuth(lat0, lon0, azimuth, length, alt, v) if req.by_azimuth
                     else Strip.between(lat0, lon0, lat1, lon1, alt, v))
        except ValueError as err:
            where = "length_m" if req.by_azimuth else "end_latitude_deg, end_longitude_deg"
            raise RequestError(BAD, f"{where}: {err}") from None
        built.update(geometry=geometry, offset=offset, strip=strip)
        return strip_goal_law(strip, scenario, epoch, boresight, along), "strip"

    maneuver = _maneuver(req, end_goal=end_goal, frame_id=frame_id, default_spacecraft=default_spacecraft,
                         default_method=default_method, default_budget=default_budget)
    strip = built["strip"]
    window = maneuver.problem.zone_sky().window
    if strip.duration_s > window:
        raise RequestError(BAD, f"scan_speed_m_s: the {strip.length_m:.0f} m strip scanned at "
                                f"{strip.scan_speed_m_s:.4g} m/s lasts {strip.duration_s:.0f} s, longer than the "
                                f"{window:.0f} s planning window (a strip is imaged within one pass)")

    def aim(start: float, t: np.ndarray) -> np.ndarray:
        return np.array([strip.point(strip.theta_of(strip.scan_speed_m_s * (tk - start)))[0] for tk in t])

    valid = ValidImage(maneuver, built["geometry"], built["offset"], aim, strip.duration_s,
                       math.radians(min_elevation_deg), strip=strip, axes=(boresight, along),
                       rate_max=min(rate_max, maneuver.problem.rate_max))
    visible = check_rises(valid, f"the strip's start ({req.start_latitude_deg:.4f}, "
                                 f"{req.start_longitude_deg:.4f}) deg")
    check_tracking(valid, visible[np.linspace(0, len(visible) - 1, min(len(visible), TRACKING_STARTS)).astype(int)])
    return valid


def check_tracking(valid: ValidImage, starts) -> None:
    """A scan of the strip from one of the sim times ``starts`` at least keeps the body-rate and per-axis
    torque bounds (INVALID_SITE naming the scan speed and the least demand found)."""
    sc = valid.maneuver.problem.spacecraft
    demands = [tracking_demand(sc, valid.geometry, valid.strip, *valid.axes, float(t)) for t in np.atleast_1d(starts)]
    if any(rate <= valid.rate_max and torque <= sc.body_torque_max for rate, torque in demands):
        return
    rate, torque = min(demands, key=lambda d: max(d[0] / valid.rate_max, d[1] / sc.body_torque_max))
    speed = valid.strip.scan_speed_m_s
    when = "from the arrival" if len(demands) == 1 else "from any start where the strip's start is in view"
    if rate > valid.rate_max:
        raise RequestError(BAD, f"scan_speed_m_s: scanning the strip at {speed:.0f} m/s {when} asks a body rate of "
                                f"{math.degrees(rate):.2f} deg/s, beyond the bound of "
                                f"{math.degrees(valid.rate_max):.2f} deg/s")
    raise RequestError(BAD, f"scan_speed_m_s: scanning the strip at {speed:.0f} m/s {when} asks a body torque of "
                            f"{torque:.3g} N m, beyond the spacecraft's {sc.body_torque_max:.3g} N m per axis")


def plan_image(valid: ValidImage, tol: Tolerances = TOLERANCES, cone_padding: float = 0.0,
               runner: Callable = run_method) -> ImageOutcome:
    """Plan and verify the slew (:func:`att_planner.service.planning.plan_maneuver`), then check the
    image it leads to: seen above the minimum elevation from the arrival through the dwell or scan
    (SITE_NOT_VISIBLE), a strip's scan from the arrival within the bounds (INVALID_SITE)."""
    outcome = plan_maneuver(valid.maneuver, tol, cone_padding, runner)
    image = ImageOutcome(outcome.code, outcome.message, outcome.plan, outcome.stage, outcome.stages)
    if outcome.code != ErrorCode.OK:
        return image
    arrival = float(outcome.plan.t[-1] - outcome.plan.t[0])
    image.image_start, image.image_end = arrival, arrival + valid.duration
    start = valid.offset + arrival
    t = np.linspace(start, start + valid.duration,
                    min(IMAGE_SAMPLES, max(2, int(math.ceil(valid.duration / IMAGE_STEP_S)) + 1)))
    seen = elevation(valid.geometry, valid.sites_E(start, t), t)
    image.lowest_elevation = float(seen.min())
    try:
        if image.lowest_elevation < valid.min_elevation:
            k = int(np.argmin(seen))
            raise RequestError(ErrorCode.SITE_NOT_VISIBLE,
                               f"the slew arrives at {arrival:.1f} s; {t[k] - valid.offset:.1f} s after the start the "
                               f"{'strip' if valid.strip else 'site'} is {math.degrees(seen[k]):.1f} deg above its "
                               f"horizon, below the instrument's {math.degrees(valid.min_elevation):.1f} deg")
        if valid.strip is not None:
            check_tracking(valid, start)
    except RequestError as err:
        image.code, image.message = err.code, err.message
        return image
    image.pointing_after = valid.mode if valid.strip is None else strip_mode(valid.strip, *valid.axes, start)
    image.message = (f"{outcome.message}; {'scan' if valid.strip else 'dwell'} from {arrival:.1f} s to "
                     f"{image.image_end:.1f} s, seen at {math.degrees(image.lowest_elevation):.1f} deg or higher")
    return image
