"""The real sky of a request (no ROS): its epoch, orbit and zones, checked into what a problem needs.

* **Epoch** (``builtin_interfaces/Time``, UTC seconds since 1970): the request's, or when it is zero
  the scenario's ``epoch``; within the ephemeris span of :mod:`att_sim.models.epoch` (1900-2050) and the
  wire's int32 seconds (before 2038-01-19T03:14:07Z), since the plan carries it back
  (INVALID_EPOCH). Without one anywhere the request may only have inertial zones.
* **Orbit**: the request's TLE (both lines; :class:`att_sim.models.orbit.TLEOrbit` at the request's
  epoch, checked column by column and by its checksum: INVALID_ORBIT), or when both lines are
  empty the scenario's orbit (:class:`att_sim.models.ephemeris.Ephemeris` maps its time zero onto the epoch).
  It must stay above :data:`MIN_ALTITUDE` over the whole zone window (ORBIT_TOO_LOW; an SGP4
  failure, i.e. a decayed TLE, too).
* **Zones**: at most :data:`MAX_ZONES`, each checked field by field
  (:func:`att_msgs_py.validation.zone`: INVALID_ZONE). The sky (Sun, Moon, Earth) is built when
  a zone moves or a TLE is given; only a moving zone puts it into the problem.
"""
from __future__ import annotations

from dataclasses import dataclass
from datetime import datetime

from att_msgs_py import validation
from att_msgs_py.errors import ErrorCode, RequestError
from att_msgs_py.limits import MAX_TLE_LENGTH, MAX_ZONES
from att_msgs_py.types import Zone
from att_sim.models import epoch as epochs
from att_sim.models import orbit as orbits
from att_sim.models.ephemeris import Ephemeris
from att_sim.models.scenario import Scenario

MIN_ALTITUDE = 150e3           # m (att_sim.models.orbit.check_altitude's default)


@dataclass(frozen=True)
class RequestGeometry:
    """What a request's epoch, orbit and zones add to its problem: the epoch of t = 0 (None: none),
    the checked zones, and the ephemeris seen from the spacecraft (None unless an orbit is given or a
    zone moves; ``moving``: a zone moves, the problem gets the ephemeris)."""

    epoch: datetime | None
    zones: list[Zone]
    sky: Ephemeris | None
    moving: bool


def check_zones(raw: list) -> list[Zone]:
    """At most :data:`MAX_ZONES` zones, each checked and normalised (unnamed ones become ``zone<i>``)."""
    if len(raw) > MAX_ZONES:
        raise RequestError(ErrorCode.SIZE_LIMIT, f"{len(raw)} zones given; at most {MAX_ZONES} are accepted")
    zones = []
    for i, z in enumerate(raw):
        z = validation.zone(z, f"zones[{i}]")
        zones.append(z if z.name else Zone(f"zone{i}", z.body, z.sensor_axis, z.half_angle, z.keep_in, z.direction))
    return zones


def resolve_epoch(sec: int, nanosec: int, scenario: Scenario) -> datetime | None:
    """The request's epoch, or the scenario's when it is zero; None when neither has one."""
    requested = validation.wire_epoch(sec, nanosec, "epoch")
    epoch, label = (requested, "epoch") if requested is not None else (scenario.epoch, f"scenario '{scenario.name}' "
                                                                                        "epoch")
    if epoch is None:
        return None
    try:
        epoch = epochs.parse_epoch(epoch, label)
    except ValueError as err:
        raise RequestError(ErrorCode.INVALID_EPOCH, str(err)) from None
    return validation.sendable_epoch(epoch, label)


def check_tle(line1: str, line2: str) -> tuple[str, str] | None:
    """The request's TLE lines (text, :data:`MAX_TLE_LENGTH`), both or neither; None for neither."""
    validation.text(line1, "tle_line1", max_length=MAX_TLE_LENGTH)
    validation.text(line2, "tle_line2", max_length=MAX_TLE_LENGTH)
    if not line1 and not line2:
        return None
    if not (line1 and line2):
        empty = "tle_line1" if not line1 else "tle_line2"
        raise RequestError(ErrorCode.INVALID_ORBIT, f"{empty} is empty; give both TLE lines (both empty: the "
                                                    "scenario's orbit)")
    return line1, line2


def resolve_orbit(tle: tuple[str, str] | None, epoch: datetime, scenario: Scenario) -> orbits.Orbit:
    """The request's TLE propagated from ``epoch``, or the scenario's orbit."""
    if tle is None:
        return scenario.orbit_model
    try:
        return orbits.TLEOrbit(epoch, *tle)
    except ValueError as err:
        raise RequestError(ErrorCode.INVALID_ORBIT, f"tle_line1/tle_line2: {err}") from None


def check_orbit_window(sky: Ephemeris, window: float) -> None:
    """The spacecraft stays above :data:`MIN_ALTITUDE` from the epoch to ``window`` s after it."""
    t0 = sky.orbit_offset
    try:
        orbits.check_altitude(sky.orbit, t0, t0 + window, MIN_ALTITUDE)
    except ValueError as err:
        raise RequestError(ErrorCode.ORBIT_TOO_LOW, f"orbit over the {window:.0f} s maneuver window from "
                                                    f"{epochs.format_epoch(sky.epoch)}: {err}") from None


def resolve_sky(sec: int, nanosec: int, raw_zones: list, tle_line1: str, tle_line2: str,
                scenario: Scenario) -> RequestGeometry:
    """Check the real-sky fields of a request against ``scenario`` (module docstring; the orbit's
    altitude over the window is :func:`check_orbit_window`'s, once the window is known)."""
    zones = check_zones(list(raw_zones))
    tle = check_tle(tle_line1, tle_line2)
    epoch = resolve_epoch(sec, nanosec, scenario)
    moving = next((z for z in zones if z.body != "inertial"), None)
    if epoch is None and (moving is not None or tle is not None):
        needs = f"zone '{moving.name}' (body {moving.body}) moves with the sky" if moving else "a TLE is given"
        raise RequestError(ErrorCode.INVALID_EPOCH, f"epoch is zero and scenario '{scenario.name}' has none, but "
                                                    f"{needs}: give the maneuver's start epoch")
    sky = None if moving is None and tle is None else Ephemeris(epoch, resolve_orbit(tle, epoch, scenario))
    return RequestGeometry(epoch, zones, sky, moving is not None)
