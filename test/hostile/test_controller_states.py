"""Hostile spacecraft states and mode requests to the controller core (no ROS): a state that
fails a field, time or source check changes nothing; recovery from a new timeline; safe mode at start."""
from __future__ import annotations

import math
from dataclasses import replace

import numpy as np
import pytest
from cryptography.hazmat.primitives.asymmetric.ed25519 import Ed25519PrivateKey

from att_msgs.srv import SetControllerMode
from att_msgs_py import signing
from att_msgs_py.errors import ErrorCode
from att_msgs_py.types import ControlMode
from att_planner.control.controller import Controller, ControllerConfig
from att_planner.methods.eigenaxis import plan_eigenaxis_smooth
from att_planner.problem import ManeuverProblem
from att_sim.models import rotations as rot
from att_sim.models import scenario
from att_sim.truth.simulation import Simulation
from helpers.signed_plans import KEY, context, issue

SWIFT = scenario.load("swift_demo")
SIM_A, SIM_B = b"simulator-gid", b"intruder-gid"


@pytest.fixture
def loop():
    """A core that has accepted states at t = 0 .. 1 s from the simulator (wall time = sim time)."""
    core = Controller(context(), ControllerConfig(control_period=0.1), body_frame_id="body")
    sim = Simulation(SWIFT.spacecraft, SWIFT.orbit)
    for _ in range(21):
        assert core.accept_state(sim.state("eci", "body"), wall=sim.t, clock=sim.t, source=SIM_A).refused is None
        sim.advance(0.05)
    return core, sim


def base(sim):
    return sim.state("eci", "body")


FIELD_CASES = [
    ("NaN attitude", dict(q=np.array([np.nan, 0, 0, 1.0])), "state.attitude has NaN"),
    ("zero attitude", dict(q=np.zeros(4)), "zero quaternion"),
    ("attitude of norm 2", dict(q=np.array([0, 0, 0, 2.0])), "norm 2"),
    ("infinite rate", dict(omega=np.array([np.inf, 0, 0])), "state.body_rate has NaN or Inf"),
    ("rate of 100 rad/s", dict(omega=np.array([0, 100.0, 0])), "body_rate reaches 100"),
    ("two wheel speeds for three wheels", dict(wheel_speeds=np.zeros(2)), "wheel_speeds has 2 entries"),
    ("wheel speed of 1e30", dict(wheel_speeds=np.array([1e30, 0, 0])), "wheel_speeds reach"),
    ("NaN wheel speed", dict(wheel_speeds=np.array([np.nan, 0, 0])), "wheel_speeds has NaN"),
    ("field of 1 T", dict(field_body=np.array([1.0, 0, 0])), "magnetic_field_body is 1 T"),
    ("NaN field", dict(field_body=np.array([np.nan, 0, 0])), "magnetic_field_body has NaN"),
    ("another inertial frame", dict(frame_id="map"), "state frames 'map'"),
    ("another body frame", dict(body_frame_id="base_link"), "'base_link'"),
    ("negative stamp", dict(t=-1.0), "stamp -1.0"),
    ("NaN stamp", dict(t=math.nan), "stamp nan"),
]


@pytest.mark.parametrize("case, change, words", FIELD_CASES, ids=[c[0] for c in FIELD_CASES])
def test_a_state_with_a_bad_field_changes_nothing(loop, case, change, words):
    core, sim = loop
    before = core.state
    out = core.accept_state(replace(base(sim), **change), wall=sim.t, clock=sim.t, source=SIM_A)
    assert out.refused.code == ErrorCode.INVALID_STATE and words in out.refused.message, out.refused.message
    assert core.state is before


TIME_CASES = [
    ("stamp of 1e6 s", dict(t=1e6), ErrorCode.STATE_TIME_JUMP, "from the node's clock"),
    ("stamp backward", dict(t=0.5), ErrorCode.STATE_TIME_JUMP, "after 1"),
    ("stamp repeated", dict(t=1.0), ErrorCode.STATE_TIME_JUMP, "after 1"),
    ("stamp 100 s ahead", dict(t=101.0), ErrorCode.STATE_TIME_JUMP, "from the node's clock"),
]


@pytest.mark.parametrize("case, change, code, words", TIME_CASES, ids=[c[0] for c in TIME_CASES])
def test_a_state_out_of_time_changes_nothing_and_the_loop_goes_on(loop, case, change, code, words):
    core, sim = loop
    out = core.accept_state(replace(base(sim), **change), wall=sim.t, clock=sim.t, source=SIM_A)
    assert out.refused.code == code and words in out.refused.message, out.refused.message
    assert core.state.t == pytest.approx(1.0)
    assert core.accept_state(base(sim), wall=sim.t, clock=sim.t, source=SIM_A).refused is None   # the next real one
    assert core.state.t == pytest.approx(sim.t)


def test_without_a_clock_the_previous_state_bounds_a_forward_jump(loop):
    core, sim = loop
    out = core.accept_state(replace(base(sim), t=30.0), wall=sim.t, source=SIM_A)
    assert out.refused.code == ErrorCode.STATE_TIME_JUMP and "at most 5 s" in out.refused.message


def graph(core, *gids):
    """Give the core's state gate a ROS graph listing ``gids`` as the state's publishers (a set to edit)."""
    live = set(gids)
    core.gate.hold.live = lambda: live
    return live


def test_a_second_publisher_is_ignored_while_the_first_is_in_the_graph_however_long_it_is_silent(loop):
    core, sim = loop
    graph(core, SIM_A, SIM_B)
    out = core.accept_state(base(sim), wall=sim.t, clock=sim.t, source=SIM_B)
    assert out.refused.code == ErrorCode.INVALID_STATE and "second publisher" in out.refused.message
    sim.advance(30.0)                       # the first publisher silent (paused) for 30 s: still in the graph
    assert core.accept_state(base(sim), wall=sim.t, clock=sim.t, source=SIM_B).refused.code == \
        ErrorCode.INVALID_STATE
    assert core.state.t == pytest.approx(1.0) and core.gate.hold.held == SIM_A


def test_a_second_publisher_takes_over_once_the_first_has_left_the_graph(loop):
    core, sim = loop
    live = graph(core, SIM_A, SIM_B)
    live.discard(SIM_A)                     # the first publisher stopped
    out = core.accept_state(base(sim), wall=sim.t, clock=sim.t, source=SIM_B)
    assert out.refused is None and "new source" in out.note
    assert core.gate.hold.held == SIM_B


def test_a_spoofer_flooding_while_the_real_source_pauses_is_never_acted_on_and_the_real_one_goes_on(loop):
    """The real simulator paused 3 s while an intruder publishes plausible states at 1 kHz (current
    attitude, stamps following the sim clock, a small body rate) and its own, then frozen, /clock:
    nothing of the intruder is taken, and the real source's next state is."""
    core, sim = loop
    live = graph(core, SIM_A, SIM_B)
    clock_A, clock_B = SIM_A[:12], SIM_B[:12]
    core.gate.clocks.hear(clock_A, sim.t)
    for k in range(3000):
        wall = sim.t + 0.001 * (k + 1)
        fake = replace(base(sim), t=sim.t + 0.001 * (k + 1), omega=np.array([0.002, 0.0, 0.0]))
        core.gate.clocks.hear(clock_B, 1.0)                   # the intruder's clock, frozen
        out = core.accept_state(fake, wall=wall, clock=core.gate.clocks.of(clock_B), source=SIM_B)
        assert out.refused is not None and "second publisher" in out.refused.message
    live.discard(SIM_B)                                       # the intruder stops
    sim.advance(0.05)
    core.gate.clocks.hear(clock_A, sim.t)
    out = core.accept_state(base(sim), wall=sim.t + 3.0, clock=core.gate.clocks.of(clock_A), source=SIM_A)
    assert out.refused is None and out.note is None          # the same timeline, no restart
    assert core.state.t == pytest.approx(sim.t) and not np.any(core.state.omega == 0.002)


def test_another_participants_clock_never_fails_the_held_sources_states(loop):
    core, sim = loop
    core.gate.clocks.hear(SIM_A[:12], sim.t)
    core.gate.clocks.hear(SIM_B[:12], 500.0)                 # a hostile clock from another participant
    assert core.gate.clocks.of(SIM_A[:12]) == pytest.approx(sim.t)
    assert core.accept_state(base(sim), wall=sim.t, clock=core.gate.clocks.of(SIM_A[:12]),
                             source=SIM_A).refused is None
    for k in range(40):                                      # a flood of participants forgets the oldest only
        core.gate.clocks.hear(bytes([k]) * 12, 1.0)
    assert core.gate.clocks.of(SIM_A[:12]) is None and len(core.gate.clocks.latest) == 16


def test_the_held_source_whose_stamps_jump_after_a_starved_while_starts_a_new_timeline(loop):
    core, sim = loop
    sim.advance(8.0)                                         # the controller was busy 2.5 s; the simulator ran on
    out = core.accept_state(base(sim), wall=1.0 + 2.5, clock=sim.t, source=SIM_A)
    assert out.refused is None and "timeline restarted" in out.note and core.gate.hold.held == SIM_A


def test_a_hand_published_far_stamp_before_the_clock_runs_stalls_nothing_once_its_publisher_is_gone():
    core = Controller(context(), ControllerConfig(), body_frame_id="body")
    live = graph(core, SIM_B, SIM_A)
    sim = Simulation(SWIFT.spacecraft, SWIFT.orbit)
    assert core.accept_state(replace(base(sim), t=1e6), wall=0.0, source=SIM_B).refused is None  # the first one
    assert core.accept_state(base(sim), wall=0.05, source=SIM_A).refused is not None
    live.discard(SIM_B)                      # `ros2 topic pub --once` ends
    out = core.accept_state(base(sim), wall=0.1, source=SIM_A)
    assert out.refused is None and "timeline restarted" in out.note


def test_a_new_timeline_aborts_the_running_maneuver(loop):
    core, sim = loop
    plan, payload = issue(plan_eigenaxis_smooth(ManeuverProblem(SWIFT.spacecraft, rot.IDENTITY,
                                                                rot.from_axis_angle([0, 0, 1], 0.5))), core.context)
    assert core.start(core.resolve("", plan, payload)[0]) is None
    restarted = Simulation(SWIFT.spacecraft, SWIFT.orbit)          # a restarted simulator: t = 0 again
    graph(core, SIM_B)                                              # the first one has left the graph
    out = core.accept_state(base(restarted), wall=sim.t + 0.05, clock=0.0, source=SIM_B)
    assert out.refused is None and "timeline restarted" in out.note
    assert out.ended.error_code == ErrorCode.ABORTED and core.maneuver is None and core.mode == ControlMode.SAFE


@pytest.mark.parametrize("rate, mode", [(0.02, ControlMode.SAFE), (0.001, ControlMode.IDLE)])
def test_a_controller_that_starts_on_a_spinning_spacecraft_damps_it(rate, mode):
    core = Controller(context(), ControllerConfig(safe_rate_threshold=0.005), body_frame_id="body")
    sim = Simulation(SWIFT.spacecraft, SWIFT.orbit, omega0=[rate, -rate, 0.0])
    out = core.accept_state(base(sim))
    assert core.mode == mode and (("safe mode" in out.note) if mode == ControlMode.SAFE else out.note is None)
    w0 = np.linalg.norm(sim.x[4:7])
    for _ in range(400):
        sim.advance(0.05)
        core.accept_state(base(sim), wall=sim.t)
        if core.due():
            assert sim.set_command(core.step().command) is None
    assert (np.linalg.norm(sim.x[4:7]) < 0.3 * w0) == (mode == ControlMode.SAFE)


@pytest.mark.parametrize("mode, code", [(255, ErrorCode.INVALID_MODE), (5, ErrorCode.INVALID_MODE),
                                        (int(ControlMode.PLAN_TRACKING), ErrorCode.INVALID_MODE),
                                        (int(ControlMode.POINTING), ErrorCode.INVALID_POINTING)])   # no pointing mode
def test_bad_mode_requests_are_refused(loop, mode, code):
    core, _ = loop
    assert core.set_mode(mode)[0] == code and core.mode == ControlMode.IDLE


def mode_request(mode, sequence, key=KEY, tamper=None):
    request = SetControllerMode.Request(mode=mode, sequence=sequence)
    if key is not None:
        signing.sign(request, key)
    if tamper:
        tamper(request)
    return signing.payload(request), bytes(request.signature), request.key_id, int(request.sequence)


@pytest.mark.parametrize("case, request_, words", [
    ("unsigned", lambda: mode_request(1, 10, key=None), "not signed"),
    ("another key", lambda: mode_request(1, 10, key=Ed25519PrivateKey.generate()), "not with the configured"),
    ("mode changed after signing", lambda: mode_request(1, 10, tamper=lambda r: setattr(r, "mode", 3)),
     "does not verify"),
    ("sequence changed after signing", lambda: mode_request(1, 10, tamper=lambda r: setattr(r, "sequence", 11)),
     "does not verify"),
    ("replayed", lambda: mode_request(1, 5), "not above the last accepted 5"),
    ("older", lambda: mode_request(1, 4), "not above the last accepted 5"),
])
def test_signed_mode_requests_when_required(loop, case, request_, words):
    core, _ = loop
    core.mode_key = KEY.public_key()
    assert core.authorize_mode(*mode_request(3, 5)) is None and core.mode_sequence == 5
    refused = core.authorize_mode(*request_())
    assert refused.code == ErrorCode.MODE_NOT_AUTHENTIC and words in refused.message, refused.message
    assert core.mode_sequence == 5
    assert core.authorize_mode(*mode_request(1, 6)) is None


def test_mode_requests_need_no_signature_unless_required(loop):
    core, _ = loop
    assert core.mode_key is None and core.authorize_mode(*mode_request(1, 0, key=None)) is None
