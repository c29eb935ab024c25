"""Which spacecraft states the controller acts on (no ROS): field checks, time and source.

Every state is checked field by field (finite, unit attitude, wheel count, magnitudes) and then
against time: its stamp must move forward from the last accepted state by at most
``max_state_gap`` s and, once the node's clock runs, lie within ``max_clock_skew`` s of it. A state
from a second publisher is ignored while the accepted one is alive. A discarded state changes
nothing, so no single message can stall or steer the loop; after ``resync_timeout`` s of wall
time without an accepted state (a restarted simulator, a replayed log), the next state that
passes the field and clock checks starts a new timeline, which the gate reports.
"""
from __future__ import annotations

import math
from dataclasses import dataclass

from att_msgs_py import validation
from att_msgs_py.errors import ErrorCode, RequestError
from att_msgs_py.types import State
from att_sim.models.dynamics import Spacecraft

MAX_BODY_RATE = 10.0          # rad/s, any axis
MAX_FIELD = 1e-3              # T (the geomagnetic field is below 7e-5 T)


@dataclass(frozen=True)
class GateConfig:
    max_state_gap: float = 5.0      # s of sim time between consecutive accepted states
    max_clock_skew: float = 5.0     # s between a stamp and the node's clock
    resync_timeout: float = 2.0     # s of wall time without an accepted state before a new timeline


@dataclass
class Admission:
    """What the gate made of one state: ``error`` when discarded, ``resynced`` when it starts a
    new timeline (the previous stamp is in ``previous_t``)."""

    state: State | None
    error: RequestError | None = None
    resynced: bool = False
    previous_t: float = math.nan


class StateGate:
    def __init__(self, spacecraft: Spacecraft, frame_id: str, body_frame_id: str, config: GateConfig = GateConfig()):
        self.spacecraft, self.frame_id, self.body_frame_id, self.config = spacecraft, frame_id, body_frame_id, config
        self.last: State | None = None
        self.last_wall = -math.inf
        self.source: bytes | None = None

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
        """Check ``s`` (received at monotonic ``wall`` s, node clock ``clock`` s or None before
        it runs, from publisher ``source``) and keep it as the latest when it passes."""
        c = self.config
        silent = wall - self.last_wall > c.resync_timeout
        try:
            s = self.check_fields(s)
            if source is not None and self.source is not None and source != self.source and not silent:
                raise RequestError(ErrorCode.INVALID_STATE, "state from a second publisher while the first one "
                                                            "is alive; ignored")
            if clock is not None and abs(s.t - clock) > c.max_clock_skew:
                raise RequestError(ErrorCode.STATE_TIME_JUMP, f"state stamp {s.t:.6g} s is {s.t - clock:+.6g} s from "
                                                              f"the node's clock (at most {c.max_clock_skew:g} s)")
            prev = self.last
            jump = prev is not None and not (0.0 < s.t - prev.t <= c.max_state_gap)
            if jump and not silent:
                raise RequestError(ErrorCode.STATE_TIME_JUMP,
                                   f"state stamp {s.t:.6g} s after {prev.t:.6g} s (it must move forward by at most "
                                   f"{c.max_state_gap:g} s); discarded")
        except RequestError as err:
            return Admission(None, err)
        admission = Admission(s, resynced=jump, previous_t=prev.t if prev is not None else math.nan)
        self.last, self.last_wall, self.source = s, wall, source if source is not None else self.source
        return admission
