"""Hostile inputs to the controller core (no ROS): plans (cached or inline), states, modes.

Every plan below is signed by the test's planner key unless the case is about the signature, so
the field checks themselves are exercised: a valid signature never makes a bad plan flyable.
"""
from __future__ import annotations

import math
from dataclasses import replace
from datetime import UTC, datetime, timedelta

import numpy as np
import pytest
from cryptography.hazmat.primitives.asymmetric.ed25519 import Ed25519PrivateKey

from att_msgs_py import convert, signing, validation
from att_msgs_py.errors import ErrorCode
from att_msgs_py.types import Cone, ControlKind, ControlMode, Plan, Status, Verification, Zone
from att_planner.control.controller import Controller, ControllerConfig
from att_planner.methods.eigenaxis import plan_eigenaxis_smooth
from att_planner.problem import ManeuverProblem
from att_sim.models import rotations as rot
from att_sim.models import scenario
from att_sim.truth.simulation import Simulation
from helpers.signed_plans import KEY, context, issue

SWIFT = scenario.load("swift_demo")
GOAL = rot.from_axis_angle([0, 0, 1], 0.8)
BIG = validation.MAX_PLAN_SAMPLES + 1
EPOCH = datetime(2026, 12, 21, tzinfo=UTC)
SUN = Zone("sun", "sun", [1.0, 0, 0], 0.8)


def zoned(*zones, epoch=EPOCH):
    """A change of the plan: these zones (and the epoch of a real-sky plan)."""
    return lambda p: replace(p, zones=list(zones), epoch=epoch)


def verified(**fields) -> Verification:
    return Verification(0.0, 0.0, math.inf, [], 0.0, 0.0, 0.0, 101, **fields)


def good_plan() -> Plan:
    return plan_eigenaxis_smooth(ManeuverProblem(SWIFT.spacecraft, rot.IDENTITY, GOAL), samples=101)


@pytest.fixture
def core():
    c = Controller(context(), ControllerConfig(control_period=0.1), body_frame_id="body")
    sim = Simulation(SWIFT.spacecraft, SWIFT.orbit)
    assert c.accept_state(sim.state("eci", "body"), wall=0.0).refused is None
    return c


def n(plan: Plan) -> int:
    return len(plan.t)


def arr(plan: Plan, name: str, value):
    return replace(plan, **{name: value})


# (case id, change of the plan before it is issued, expected code, words of the message)
PLAN_CASES = [
    ("rates shorter than times", lambda p: arr(p, "omega", p.omega[:-3]), ErrorCode.INVALID_PLAN, "rates has"),
    ("torques shorter than times", lambda p: arr(p, "torque", p.torque[:5]), ErrorCode.INVALID_PLAN, "torques has"),
    ("attitudes longer than times", lambda p: arr(p, "q", np.vstack([p.q, p.q[:2]])), ErrorCode.INVALID_PLAN,
     "attitudes has"),
    ("NaN time", lambda p: arr(p, "t", np.where(np.arange(n(p)) == 7, np.nan, p.t)), ErrorCode.INVALID_PLAN, "NaN"),
    ("NaN duration", lambda p: arr(p, "t", np.append(p.t[:-1], np.nan)), ErrorCode.INVALID_PLAN, "NaN"),
    ("1e308 duration", lambda p: arr(p, "t", np.append(p.t[:-1], 1e308)), ErrorCode.INVALID_PLAN, "duration"),
    ("a day and a second", lambda p: arr(p, "t", p.t * (86_401.0 / p.t[-1])), ErrorCode.INVALID_PLAN, "duration"),
    ("negative duration", lambda p: arr(p, "t", -p.t), ErrorCode.INVALID_PLAN, "do not increase"),
    ("start time not zero", lambda p: arr(p, "t", p.t + 5.0), ErrorCode.INVALID_PLAN, "starts at 0"),
    ("repeated time", lambda p: arr(p, "t", np.where(np.arange(n(p)) == 3, p.t[2], p.t)), ErrorCode.INVALID_PLAN,
     "do not increase"),
    ("one sample", lambda p: replace(p, t=p.t[:1], q=p.q[:1], omega=p.omega[:1], torque=p.torque[:1]),
     ErrorCode.INVALID_PLAN, "at least 2"),
    ("no samples", lambda p: replace(p, t=p.t[:0], q=p.q[:0], omega=p.omega[:0], torque=p.torque[:0]),
     ErrorCode.INVALID_PLAN, "at least 2"),
    ("too many samples", lambda p: replace(
        p, t=np.linspace(0, 10, BIG), q=np.tile(rot.IDENTITY, (BIG, 1)), omega=np.zeros((BIG, 3)),
        torque=np.zeros((BIG, 3))), ErrorCode.SIZE_LIMIT, "at most"),
    ("zero quaternion", lambda p: arr(p, "q", np.where(np.arange(n(p))[:, None] == 4, 0.0, p.q)),
     ErrorCode.INVALID_PLAN, "attitudes[4] has norm 0"),
    ("huge quaternion", lambda p: arr(p, "q", p.q * 1e150), ErrorCode.INVALID_PLAN, "attitudes[0] has norm"),
    ("quaternion of norm 1.1", lambda p: arr(p, "q", p.q * 1.1), ErrorCode.INVALID_PLAN, "unit quaternions"),
    ("NaN quaternion", lambda p: arr(p, "q", np.where(np.arange(n(p))[:, None] == 9, np.nan, p.q)),
     ErrorCode.INVALID_PLAN, "attitudes has NaN"),
    ("NaN rate", lambda p: arr(p, "omega", p.omega + np.nan), ErrorCode.INVALID_PLAN, "rates has NaN"),
    ("rate of 1e6 rad/s", lambda p: arr(p, "omega", p.omega + 1e6), ErrorCode.INVALID_PLAN, "rates reach"),
    ("torque twice the limit", lambda p: arr(p, "torque", np.full_like(p.torque, 0.2)), ErrorCode.INVALID_PLAN,
     "above the spacecraft's torque_max"),
    ("torque of 1e30", lambda p: arr(p, "torque", p.torque + 1e30), ErrorCode.INVALID_PLAN, "torques reach"),
    ("wheel torque above the wheel limit", lambda p: replace(p, control_kind=ControlKind.WHEEL_TORQUE,
                                                             torque=np.full_like(p.torque, 0.13)),
     ErrorCode.INVALID_PLAN, "wheel_torque_max"),
    ("infinite torque", lambda p: arr(p, "torque", p.torque - np.inf), ErrorCode.INVALID_PLAN, "torques has NaN"),
    ("unknown interpolation", lambda p: replace(p, interpolation="cubic"), ErrorCode.INVALID_PLAN,
     "interpolation 'cubic'"),
    ("empty interpolation", lambda p: replace(p, interpolation=""), ErrorCode.INVALID_PLAN, "interpolation ''"),
    ("unknown control kind", lambda p: replace(p, control_kind="warp"), ErrorCode.INVALID_PLAN, "control_kind 'warp'"),
    ("empty control kind", lambda p: replace(p, control_kind=""), ErrorCode.INVALID_PLAN, "control_kind ''"),
    ("status failed", lambda p: replace(p, status=Status.FAILED), ErrorCode.INVALID_PLAN, "status 'failed'"),
    ("unknown status", lambda p: replace(p, status="great"), ErrorCode.INVALID_PLAN, "status 'great'"),
    ("message with an escape", lambda p: replace(p, message="ok\x1b[2J"), ErrorCode.INVALID_TEXT, "plan.message"),
    ("overlong message", lambda p: replace(p, message="m" * 5000), ErrorCode.SIZE_LIMIT, "plan.message"),
    ("method with a newline", lambda p: replace(p, method="eigenaxis\nrm"), ErrorCode.INVALID_TEXT, "plan.method"),
    ("zero sensor axis", lambda p: replace(p, sensor_axis=np.zeros(3)), ErrorCode.INVALID_PLAN, "sensor_axis"),
    ("unknown moving goal", lambda p: replace(p, verification=verified(goal="sideways")), ErrorCode.INVALID_PLAN,
     "plan.verification.goal 'sideways'"),
    ("moving goal with an escape", lambda p: replace(p, verification=verified(goal="strip\x1b")),
     ErrorCode.INVALID_TEXT, "plan.verification.goal"),
    ("non-unit sensor axis", lambda p: replace(p, sensor_axis=np.array([2.0, 0, 0])), ErrorCode.INVALID_PLAN,
     "sensor_axis has norm"),
    ("cone half-angle of 2 rad", lambda p: replace(p, cones=[Cone([1.0, 0, 0], 2.0, "sun")]), ErrorCode.INVALID_PLAN,
     "half_angle"),
    ("NaN cone direction", lambda p: replace(p, cones=[Cone([np.nan, 0, 1.0], 0.3, "sun")]), ErrorCode.INVALID_PLAN,
     "direction"),
    ("seventeen cones", lambda p: replace(p, cones=[Cone([0, 0, 1.0], 0.1, f"c{i}") for i in range(17)]),
     ErrorCode.SIZE_LIMIT, "17 cones"),
    ("cone name with a control character", lambda p: replace(p, cones=[Cone([0, 0, 1.0], 0.1, "s\x07un")]),
     ErrorCode.INVALID_TEXT, "cones[0].name"),
    ("unknown zone body", zoned(SUN, replace(SUN, body="jupiter")), ErrorCode.INVALID_PLAN,
     "plan.zones[1] ('sun').body 'jupiter' is not one of inertial, sun, moon, earth_limb"),
    ("empty zone body", zoned(replace(SUN, body="")), ErrorCode.INVALID_PLAN, "body '' is not one of"),
    ("zone body with an escape", zoned(replace(SUN, body="sun\x1b")), ErrorCode.INVALID_TEXT, "zones[0].body"),
    ("zone name with a bell", zoned(replace(SUN, name="s\x07")), ErrorCode.INVALID_TEXT, "zones[0].name"),
    ("zone name of 300 characters", zoned(replace(SUN, name="z" * 300)), ErrorCode.SIZE_LIMIT, "zones[0].name"),
    ("zero zone sensor axis", zoned(replace(SUN, sensor_axis=np.zeros(3))), ErrorCode.INVALID_PLAN,
     "zones[0] ('sun').sensor_axis is the zero vector"),
    ("NaN zone sensor axis", zoned(replace(SUN, sensor_axis=[np.nan, 0, 1.0])), ErrorCode.INVALID_PLAN,
     "sensor_axis has NaN"),
    ("infinite zone sensor axis", zoned(replace(SUN, sensor_axis=[np.inf, 0, 0])), ErrorCode.INVALID_PLAN,
     "sensor_axis has NaN or Inf"),
    ("zone half-angle 0", zoned(replace(SUN, half_angle=0.0)), ErrorCode.INVALID_PLAN, "half_angle = 0.0 rad is "
                                                                                       "outside (0, pi)"),
    ("zone half-angle pi", zoned(replace(SUN, half_angle=math.pi)), ErrorCode.INVALID_PLAN, "outside (0, pi)"),
    ("NaN zone half-angle", zoned(replace(SUN, half_angle=np.nan)), ErrorCode.INVALID_PLAN, "half_angle = nan"),
    ("negative zone half-angle", zoned(replace(SUN, half_angle=-0.1)), ErrorCode.INVALID_PLAN, "half_angle = -0.1"),
    ("Earth-limb margin of 1.6 rad", zoned(Zone("e", "earth_limb", [0, 1.0, 0], 1.6)), ErrorCode.INVALID_PLAN,
     "outside [0, pi/2) (the margin beyond the Earth's limb)"),
    ("inertial zone without a direction", zoned(Zone("i", "inertial", [0, 1.0, 0], 0.3)), ErrorCode.INVALID_PLAN,
     "zones[0] ('i').direction is the zero vector; an inertial zone needs a unit direction"),
    ("inertial zone with a NaN direction", zoned(Zone("i", "inertial", [0, 1.0, 0], 0.3, False, [np.nan, 1.0, 0])),
     ErrorCode.INVALID_PLAN, "direction has NaN"),
    ("sun zone with a direction", zoned(replace(SUN, direction=[0, 0, 1.0])), ErrorCode.INVALID_PLAN,
     "only an inertial zone has one"),
    ("seventeen zones", zoned(*[replace(SUN, name=f"z{i}") for i in range(17)]), ErrorCode.SIZE_LIMIT,
     "plan.zones has 17 zones; at most 16"),
    ("a moving zone without an epoch", zoned(Zone("m", "moon", [1.0, 0, 0], 0.4), epoch=None),
     ErrorCode.INVALID_PLAN, "plan.zones[0] ('m') moves with the sky (body moon) but plan.epoch is zero"),
]


@pytest.mark.parametrize("case, change, code, words", PLAN_CASES, ids=[c[0] for c in PLAN_CASES])
@pytest.mark.parametrize("route", ["inline", "published"])
def test_a_bad_plan_is_refused_signed_or_not(core, case, change, code, words, route):
    plan, payload = issue(change(good_plan()), core.context, "bad")
    if route == "inline":
        flown, refused = core.resolve("", plan, payload)
        assert flown is None
    else:
        refused = core.receive_plan(plan, payload)
        later = core.resolve("bad")[1]           # executing it later says why it was refused
        assert "bad" not in core.plans and later.code == code and "refused when it arrived" in later.message
    assert refused.code == code and words in refused.message, refused.message
    assert core.maneuver is None and core.mode == ControlMode.IDLE


def test_a_plan_with_checked_zones_and_epoch_is_kept_normalised(core):
    zones = [SUN, Zone("e", "earth_limb", [0, 1.0, 0], 0.0, True), Zone("i", "inertial", [0, 0, 1.0], 0.2, False,
                                                                         [0, 0.6, 0.8])]
    plan, payload = issue(zoned(*zones)(good_plan()), core.context, "z")
    assert core.receive_plan(plan, payload) is None
    kept = core.plans["z"].plan
    assert kept.epoch == EPOCH and [z.body for z in kept.zones] == ["sun", "earth_limb", "inertial"]
    assert kept.zones[1].keep_in and np.allclose(kept.zones[2].direction, [0, 0.6, 0.8])


# epochs no wire message can carry (its int32 seconds span 1901-2038): the core still refuses them
@pytest.mark.parametrize("epoch, words", [
    (datetime(1850, 1, 1, tzinfo=UTC), "plan.epoch must be an ISO 8601 UTC time"),
    (datetime(2051, 6, 1, tzinfo=UTC), "2051-06-01T00:00:00.000000Z"),
    (datetime(2026, 12, 21), "naive times are refused"),
    ("2026-12-21T00:00:00Z", "plan.epoch must be a UTC datetime or none, got str"),
])
def test_an_epoch_outside_the_ephemeris_span_is_refused(core, epoch, words):
    plan, payload = issue(zoned(SUN)(good_plan()), core.context, "e")
    plan.epoch = epoch
    flown, refused = core.resolve("", plan, payload)
    assert flown is None and refused.code == ErrorCode.INVALID_PLAN and words in refused.message, refused.message


# (case id, message fields changed after the context is filled, the key, expected code, words)
CONTEXT_CASES = [
    ("unsigned", {}, None, ErrorCode.PLAN_NOT_AUTHENTIC, "not signed"),
    ("signed by another key", {}, Ed25519PrivateKey.generate(), ErrorCode.PLAN_NOT_AUTHENTIC,
     "not with the configured"),
    ("another spacecraft", {"spacecraft": "bruni_celani"}, KEY, ErrorCode.WRONG_SPACECRAFT, "'bruni_celani'"),
    ("same name, other physics", {"spacecraft_digest": "0" * 64}, KEY, ErrorCode.WRONG_SPACECRAFT, "digest"),
    ("empty spacecraft", {"spacecraft": ""}, KEY, ErrorCode.WRONG_SPACECRAFT, "made for spacecraft ''"),
    ("another frame", {"header": convert.plan_msg(Plan()).header}, KEY, ErrorCode.INVALID_FRAME, "frame"),
    ("empty plan id", {"plan_id": ""}, KEY, ErrorCode.INVALID_PLAN, "plan_id is empty"),
    ("plan id with a control character", {"plan_id": "p\x01"}, KEY, ErrorCode.INVALID_TEXT, "plan.plan_id"),
    ("plan id of 200 characters", {"plan_id": "p" * 200}, KEY, ErrorCode.SIZE_LIMIT, "plan.plan_id"),
]


@pytest.mark.parametrize("case, fields, key, code, words", CONTEXT_CASES, ids=[c[0] for c in CONTEXT_CASES])
def test_plans_out_of_context_or_unauthenticated_are_refused(core, case, fields, key, code, words):
    plan, payload = issue(good_plan(), core.context, "p1", key=key, fields=fields)
    refused = core.receive_plan(plan, payload)
    assert refused is not None and refused.code == code and words in refused.message, refused and refused.message
    assert core.resolve("", plan, payload)[1].code == code


def tampered(core, how):
    plan, payload = issue(good_plan(), core.context, "p1")
    msg = convert.plan_msg(plan)
    signing.sign(msg, KEY)
    how(msg)
    return convert.plan_from_msg(msg), signing.payload(msg)


@pytest.mark.parametrize("case, how, words", [
    ("a flipped signature bit", lambda m: setattr(m, "signature", bytes([m.signature[0] ^ 1]) + bytes(m.signature[1:])),
     "does not verify"),
    ("times changed after signing", lambda m: setattr(m, "times", [t * 0.5 for t in m.times]), "does not verify"),
    ("a torque changed after signing", lambda m: m.torques[10].__setattr__("x", 0.05), "does not verify"),
    ("a truncated signature", lambda m: setattr(m, "signature", bytes(m.signature[:32])), "has 32 bytes"),
    ("a spoofed key id", lambda m: setattr(m, "key_id", "0123456789abcdef"), "signed with key '0123456789abcdef'"),
    ("the stamp changed", lambda m: m.header.stamp.__setattr__("sec", 99), "does not verify"),
])
def test_a_plan_altered_after_signing_is_refused(core, case, how, words):
    plan, payload = tampered(core, how)
    refused = core.receive_plan(plan, payload)
    assert refused.code == ErrorCode.PLAN_NOT_AUTHENTIC and words in refused.message, refused.message


def test_a_plan_id_is_never_taken_by_a_different_plan(core):
    real, payload = issue(good_plan(), core.context, "p1")
    assert core.receive_plan(real, payload) is None
    assert core.receive_plan(real, payload) is None             # the same plan again: harmless
    other = plan_eigenaxis_smooth(ManeuverProblem(SWIFT.spacecraft, rot.IDENTITY, rot.from_axis_angle([1, 0, 0], 1.5)))
    forged, forged_payload = issue(other, core.context, "p1")   # even signed with the planner's key
    assert core.receive_plan(forged, forged_payload).code == ErrorCode.PLAN_ID_REUSED
    assert core.resolve("", forged, forged_payload)[1].code == ErrorCode.PLAN_ID_REUSED
    kept, _ = core.resolve("p1")
    assert np.allclose(kept.q[-1], real.q[-1])


def test_forged_plans_never_evict_the_real_one_and_the_flown_plan_stays(core):
    real, payload = issue(good_plan(), core.context, "real")
    core.receive_plan(real, payload)
    for i in range(200):                                    # unsigned or wrongly signed: never cached
        core.receive_plan(*issue(good_plan(), core.context, f"forged{i}", key=None if i % 2 else
                                 Ed25519PrivateKey.generate()))
    assert list(core.plans) == ["real"]
    assert core.start(core.resolve("real")[0]) is None
    for i in range(core.config.max_cached_plans + 10):      # genuine plans: the flown one is kept
        core.receive_plan(*issue(good_plan(), core.context, f"g{i}"))
    assert "real" in core.plans and len(core.plans) == core.config.max_cached_plans


@pytest.mark.parametrize("case, state_change, words", [
    ("132 deg away", {"q": rot.from_axis_angle([0, 1, 0], math.radians(132))}, "132.00 deg"),
    ("6 deg away", {"q": rot.from_axis_angle([0, 1, 0], math.radians(6))}, "6.00 deg"),
    ("spinning", {"omega": np.array([0.0, 0.05, 0.0])}, "rate"),
])
def test_a_plan_far_from_the_current_state_does_not_start(case, state_change, words):
    c = Controller(context(), ControllerConfig(safe_rate_threshold=1.0), body_frame_id="body")
    sim = Simulation(SWIFT.spacecraft, SWIFT.orbit, q0=state_change.get("q", rot.IDENTITY),
                     omega0=state_change.get("omega", np.zeros(3)))
    c.accept_state(sim.state("eci", "body"))
    plan, payload = issue(good_plan(), c.context)
    refused = c.start(c.resolve("", plan, payload)[0])
    assert refused.code == ErrorCode.PLAN_CONTEXT and words in refused.message and c.maneuver is None


@pytest.mark.parametrize("offset, zone, words", [
    (0.0, SUN, None), (-8.0, SUN, None),
    (-600.0, SUN, "2026-12-20T23:50:00.000000Z, but it would start at 2026-12-21T00:00:00.000000Z, 600.0 s later"),
    (30.0, Zone("limb", "earth_limb", [0, 1.0, 0], 0.1),
     "30.0 s earlier (at most 10 s, parameter max_start_epoch_error_s)"),
    (-600.0, Zone("i", "inertial", [0, 1.0, 0], 0.1, False, [0, 0, 1.0]), None),     # a fixed zone: no matter
])
def test_a_plan_for_moving_zones_at_another_instant_does_not_start(offset, zone, words):
    """The plan's epoch against the scenario's epoch + sim time (here 0): its moving zones would be
    elsewhere."""
    c = Controller(context(epoch=EPOCH), ControllerConfig(), body_frame_id="body")
    c.accept_state(Simulation(SWIFT.spacecraft, SWIFT.orbit).state("eci", "body"))
    plan, refused = c.resolve("", *issue(zoned(zone, epoch=EPOCH + timedelta(seconds=offset))(good_plan()), c.context))
    assert refused is None
    refused = c.start(plan)
    if words is None:
        assert refused is None and c.maneuver is not None
    else:
        assert refused.code == ErrorCode.PLAN_CONTEXT and words in refused.message and c.maneuver is None, refused


def test_oversized_plan_messages_are_refused(core):
    plan, payload = issue(good_plan(), core.context)
    refused = core.receive_plan(plan, payload + bytes(validation.MAX_PLAN_BYTES))
    assert refused.code == ErrorCode.SIZE_LIMIT


@pytest.mark.parametrize("plan_id, code", [("x" * 300, ErrorCode.SIZE_LIMIT), ("p\x00\x01", ErrorCode.INVALID_TEXT),
                                           ("nope", ErrorCode.UNKNOWN_PLAN)])
def test_execute_by_a_bad_id_is_refused(core, plan_id, code):
    assert core.resolve(plan_id)[1].code == code
