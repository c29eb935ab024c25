"""Which spacecraft states the controller acts on (no ROS): field checks, time and source.

Every state is checked field by field (finite, unit attitude, wheel count, magnitudes), then for
its source and then against time. Source: the states are held to one publisher
(:class:`~att_msgs_py.source_hold.SourceHold`); a state from another publisher is ignored while the
held one is in the ROS graph, however long it is silent, and is taken (a new source: a restarted
simulator or estimator) only once the held one has left the graph. Time: a stamp must move forward
from the last accepted state by at most ``max_state_gap`` s and, when the node has a clock from
the state's own DDS participant (:class:`ParticipantClocks`), lie within ``max_clock_skew`` s of
it. A discarded state changes nothing, so no single message can stall or steer the loop. A new
timeline starts (the gate reports it) at a change of source, whatever its stamps, and when the
held publisher's stamps jump after ``resync_timeout`` s of wall time without an accepted state (a
controller starved while a fast simulator ran on).
"""
from __future__ import annotations

import math
from dataclasses import dataclass

from att_msgs_py import validation
from att_msgs_py.errors import ErrorCode, RequestError
from att_msgs_py.source_hold import SourceHold, Verdict
from att_msgs_py.types import State
from att_sim.models.dynamics import Spacecraft

MAX_BODY_RATE = 10.0          # rad/s, any axis
MAX_FIELD = 1e-3              # T (the geomagnetic field is below 7e-5 T)


@dataclass(frozen=True)
class GateConfig:
    max_state_gap: float = 5.0      # s of sim time between consecutive accepted states
    max_clock_skew: float = 5.0     # s between a stamp and the node's clock
    resync_timeout: float = 2.0     # s of wall time without an accepted state: the held publisher may jump


@dataclass
class Admission:
    """What the gate made of one state: ``error`` when discarded, ``resynced`` when it starts a
    new timeline (the previous stamp is in ``previous_t``), ``handover`` when it comes from a new
    publisher after the held one left the ROS graph."""

    state: State | None
    error: RequestError | None = None
    resynced: bool = False
    previous_t: float = math.nan
    handover: bool = False


class ParticipantClocks:
    """The latest /clock of each DDS participant that sent one (at most ``size``, the oldest
    forgotten first): a state is compared with the clock of its own participant only, so another
    participant's clock, frozen or hostile, can never make the held source's states fail."""

    def __init__(self, size: int = 16):
        self.size, self.latest = size, {}

    def hear(self, participant: bytes | None, t: float) -> None:
        if participant is None or not (math.isfinite(t) and t >= 0):
            return
        self.latest.pop(participant, None)
        if len(self.latest) >= self.size:
            self.latest.pop(next(iter(self.latest)))
        self.latest[participant] = t

    def of(self, participant: bytes | None) -> float | None:
        """The latest clock of ``participant`` (None: none heard)."""
        return None if participant is None else self.latest.get(participant)


class StateGate:
    def __init__(self, spacecraft: Spacecraft, frame_id: str, body_frame_id: str, config: GateConfig = GateConfig()):
        self.spacecraft, self.frame_id, self.body_frame_id, self.config = spacecraft, frame_id, body_frame_id, config
        self.last: State | None = None
        self.last_wall = -math.inf
        self.hold = SourceHold()        # the node gives it the graph (hold.live)
        self.clocks = ParticipantClocks()

    def check_fields(self, s: State) -> State:
        """``s`` with its attitude normalised; raises RequestError (INVALID_STATE)."""
        code, sc = ErrorCode.INVALID_STATE, self.spacecraft
        if s.frame_id != self.frame_id or s.body_frame_id != self.body_frame_id:
            raise RequestError(code, f"state frames '{s.frame_id[:64]}'/'{s.body_frame_id[:64]}' are not "
                                     f"'{self.frame_id}'/'{self.body_frame_id}'")
        if not math.isfinite(s.t) or s.t < 0:
            raise RequestError(code, f"state stamp {s.t!r} is not a finite time >= 0")
        q = validation.unit_quaternion(s.q, "state.attitude", code)
        omega = validation.finite_array(s.omega, "state.body_rate", code, (3,))
        if validation.peak(omega) > MAX_BODY_RATE:
            raise RequestError(code, f"state.body_rate reaches {validation.peak(omega):.6g} rad/s; at most "
                                     f"{MAX_BODY_RATE}")
        wheels = validation.finite_array(s.wheel_speeds, "state.wheel_speeds", code, (-1,))
        if wheels.size != sc.n_wheels:
            raise RequestError(code, f"state.wheel_speeds has {wheels.size} entries; the spacecraft has "
                                     f"{sc.n_wheels} wheels")
        if validation.peak(wheels) > 2 * sc.wheel_speed_max:
            raise RequestError(code, f"state.wheel_speeds reach {validation.peak(wheels):.6g} rad/s, twice above "
                                     f"the limit {sc.wheel_speed_max:g}")
        b = validation.finite_array(s.field_body, "state.magnetic_field_body", code, (3,))
        field = math.sqrt(sum(c * c for c in b.tolist()))
        if field > MAX_FIELD:
            raise RequestError(code, f"state.magnetic_field_body is {field:.3g} T; at most {MAX_FIELD} T")
        s.q, s.omega, s.wheel_speeds, s.field_body = q, omega, wheels, b
        return s

    def admit(self, s: State, wall: float, clock: float | None = None, source: bytes | None = None) -> Admission:
        """Check ``s`` (received at monotonic ``wall`` s from publisher ``source``, with ``clock`` the
        latest /clock of that publisher's participant, None when there is none) and keep it as the
        latest when it passes."""
        c = self.config
        silent = wall - self.last_wall > c.resync_timeout
        try:
            s = self.check_fields(s)
            verdict = self.hold.check(source)
            if not verdict.admitted:
                raise RequestError(ErrorCode.INVALID_STATE, self.hold.refusal("state"))
            if clock is not None and abs(s.t - clock) > c.max_clock_skew:
                raise RequestError(ErrorCode.STATE_TIME_JUMP, f"state stamp {s.t:.6g} s is {s.t - clock:+.6g} s from "
                                                              f"the node's clock (at most {c.max_clock_skew:g} s)")
            prev = self.last
            handover = verdict is Verdict.HANDOVER
            jump = prev is not None and not (0.0 < s.t - prev.t <= c.max_state_gap)
            if jump and not (silent or handover):
                raise RequestError(ErrorCode.STATE_TIME_JUMP,
                                   f"state stamp {s.t:.6g} s after {prev.t:.6g} s (it must move forward by at most "
                                   f"{c.max_state_gap:g} s); discarded")
        except RequestError as err:
            return Admission(None, err)
        admission = Admission(s, resynced=jump or handover, previous_t=prev.t if prev is not None else math.nan,
                              handover=handover)
        self.last, self.last_wall = s, wall
        self.hold.take(source)
        return admission
