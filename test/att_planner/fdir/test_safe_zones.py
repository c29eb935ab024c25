"""Safe mode among the zones (att_planner.fdir.safe_zones, .safe_flight): the rate from the momentum,
the zone barrier on a body spinning toward a zone, the Sun attitude chosen clear of the zones, the
rate-limited approach; and the keeper flown on a rigid body with wheels from hostile states."""
from __future__ import annotations

import math
from types import SimpleNamespace

import numpy as np
import pytest

from att_msgs_py.types import Zone
from att_planner.control.controller_config import ControllerConfig
from att_planner.fdir import safe_zones as sz
from att_planner.fdir.safe_flight import ZoneKeeper
from att_planner.zones import FittedZones
from att_sim.models import dynamics as dyn
from att_sim.models import rotations as rot

J = np.diag([3000.0, 4500.0, 6000.0])
S = 1.0 / math.sqrt(3.0)
C = math.sqrt(2.0 / 3.0)
PYRAMID = np.array([[C, 0.0, -C, 0.0], [0.0, C, 0.0, -C], [S, S, S, S]])    # leo_pyramid's wheel axes
SC = dyn.Spacecraft(J, PYRAMID, wheel_inertia=0.2, wheel_torque_max=0.3)
TORQUE_MAX = sz.torque_authority(PYRAMID, 0.3)
RATE = math.radians(0.45)                      # rad/s: the demo slew's top rate
SENSOR_B = np.array([0.0, 1.0, 0.0])


def zone(direction_N, half_angle_deg, sensor_B=SENSOR_B, keep_in=False, name="z"):
    return Zone(name, "inertial", np.asarray(sensor_B, float), math.radians(half_angle_deg), keep_in,
                np.asarray(direction_N, float) / np.linalg.norm(direction_N))


def test_the_rate_from_the_momentum_is_the_body_rate():
    rng = np.random.default_rng(1)
    q = rot.normalize(rng.normal(size=4))
    omega, h = rng.normal(size=3) * 1e-2, rng.normal(size=3)
    H = sz.momentum_N(q, omega, J, h)
    assert np.allclose(sz.rate_from_momentum(q, H, J, h), omega, atol=1e-15)
    turned = rot.multiply(q, rot.exp_map(np.array([0.3, -0.2, 0.1])))
    h2 = rot.dcm_BN(turned) @ H - J @ np.zeros(3)       # all the momentum on the wheels: the body at rest
    assert np.allclose(sz.rate_from_momentum(turned, H, J, h2), 0.0, atol=1e-15)


def test_the_margins_are_those_of_the_zones_module():
    rng = np.random.default_rng(2)
    zs = [zone(rng.normal(size=3), 20.0), zone(rng.normal(size=3), 35.0, (0, 0, 1), keep_in=True)]
    fitted = FittedZones(zs)
    q = rot.normalize(rng.normal(size=(5, 4)))
    axes, half = fitted.at(np.zeros(5), true=True)
    assert np.allclose(sz.margins(q, fitted.sensor_axes, axes, half, fitted.keep_in), fitted.margins(0.0, q),
                       atol=1e-12)


def test_the_torque_authority_is_what_every_wheel_can_give():
    assert sz.torque_authority(np.eye(3), 0.3) == pytest.approx(0.3)
    assert sz.torque_authority(PYRAMID[:, :2], 0.3) == 0.0
    G = PYRAMID
    rng = np.random.default_rng(3)
    for d in rng.normal(size=(50, 3)):
        tau = TORQUE_MAX * d / np.linalg.norm(d)
        assert np.abs(np.linalg.pinv(G) @ tau).max() <= 0.3 + 1e-12


def fly_rigid(q, omega, law, seconds: float, dt: float = 0.5, substeps: int = 5):
    """Rigid body with its wheels' momentum h_w (B axes): J ω̇ = τ − ω × (J ω + h_w), ḣ_w = −τ; ``law(t, q, ω, h)``
    the body torque; the attitudes flown."""
    h = np.zeros(3)
    out = [q]
    for k in range(int(seconds / dt)):
        tau = law(k * dt, q, omega, h)
        for _ in range(substeps):                                # sub-steps of the torque held
            omega = omega + dt / substeps * np.linalg.solve(J, tau - np.cross(omega, J @ omega + h))
            h = h - dt / substeps * tau
            q = rot.normalize(rot.propagate_constant_rate(q, omega, dt / substeps))
        out.append(q)
    return np.array(out), omega


def test_a_body_spinning_toward_a_zone_is_stopped_before_it():
    half, omega0 = 30.0, np.array([RATE, 0.0, 0.0])     # sensor +y turning about +x toward the zone
    u = np.array([-1.0, 0.0, 0.0])                  # the rotation opening the margin
    alpha = sz.AUTHORITY_SHARE * TORQUE_MAX / np.linalg.norm(J @ u)
    stop = RATE ** 2 / (2 * alpha)
    margin = sz.BUFFER_RAD + stop + math.radians(0.5)          # just outside the braking curve
    a_N = rot.dcm_NB(rot.from_axis_angle(np.array([1.0, 0.0, 0.0]), margin + math.radians(half))) @ SENSOR_B
    zs = FittedZones([zone(a_N, half)])
    axes, halves = zs.at(np.zeros(1), true=True)
    hostile = TORQUE_MAX * np.array([1.0, 0.0, 0.0])            # a nominal law driving into the zone

    def barrier(t, q, w, h):
        return sz.barrier_torque(q, w, hostile, zs.sensor_axes, axes[0], halves[0], zs.keep_in, J, TORQUE_MAX)[0]

    q, _ = fly_rigid(rot.IDENTITY, omega0, barrier, 400.0, dt=1.0, substeps=4)
    m = sz.margins(q, zs.sensor_axes, axes[0], halves[0], zs.keep_in)
    assert m.min() >= 0.0 and m[-1] > m.min()
    bare, _ = fly_rigid(rot.IDENTITY, omega0, lambda t, q, w, h: hostile, 400.0, dt=1.0, substeps=4)
    assert sz.margins(bare, zs.sensor_axes, axes[0], halves[0], zs.keep_in).min() < 0.0   # the barrier's doing


def test_a_zone_moving_toward_a_body_at_rest_is_kept_out():
    rate = math.radians(0.06)                       # rad/s: the Earth limb's motion in a low orbit
    half = 30.0
    start = math.radians(half) + 2 * sz.BUFFER_RAD

    def axis(t):                                    # the zone's axis turning about +x toward the sensor +y
        return rot.dcm_NB(rot.from_axis_angle(np.array([1.0, 0.0, 0.0]), start - rate * t)) @ SENSOR_B

    def barrier(t, q, w, h):
        a = axis(t)[None]
        drift = (sz.margins(q, [SENSOR_B], axis(t + 1.0)[None], [math.radians(half)], [False])
                 - sz.margins(q, [SENSOR_B], a, [math.radians(half)], [False]))
        return sz.barrier_torque(q, w, np.zeros(3), [SENSOR_B], a, [math.radians(half)], [False], J, TORQUE_MAX,
                                 drift)[0]

    q, _ = fly_rigid(rot.IDENTITY, np.zeros(3), barrier, 400.0, dt=1.0, substeps=4)
    t = np.arange(len(q)) * 1.0
    m = np.array([sz.margins(qk, [SENSOR_B], axis(tk)[None], [math.radians(half)], [False])[0]
                  for qk, tk in zip(q, t)])
    assert m.min() >= 0.0
    still = np.array([sz.margins(rot.IDENTITY, [SENSOR_B], axis(tk)[None], [math.radians(half)], [False])[0]
                      for tk in t])
    assert still.min() < 0.0                        # at rest it would have been entered


def test_a_keep_in_zone_is_kept():
    zs = FittedZones([zone(SENSOR_B, 10.0, keep_in=True)])
    axes, halves = zs.at(np.zeros(1), true=True)

    def barrier(t, q, w, h):
        return sz.barrier_torque(q, w, np.zeros(3), zs.sensor_axes, axes[0], halves[0], zs.keep_in, J, TORQUE_MAX)[0]

    q, _ = fly_rigid(rot.IDENTITY, np.array([math.radians(0.05), 0.0, 0.0]), barrier, 400.0, dt=1.0, substeps=4)
    assert sz.margins(q, zs.sensor_axes, axes[0], halves[0], zs.keep_in).min() >= 0.0


def test_the_sun_attitudes_put_the_axis_on_the_sun():
    sun = np.array([0.3, -0.5, 0.8])
    qs = sz.sun_attitudes(sun, [0.0, 0.0, 1.0], 12)
    assert qs.shape == (12, 4)
    assert np.allclose(rot.dcm_NB(qs) @ np.array([0.0, 0.0, 1.0]), sun / np.linalg.norm(sun), atol=1e-12)
    assert len({round(float(rot.angle_between(qs[0], q)), 6) for q in qs}) == 7        # 0, 30, ..., 180 deg
    with pytest.raises(ValueError, match="non-zero"):
        sz.sun_attitudes([0.0, 0.0, 0.0], [0.0, 0.0, 1.0])


def test_the_sun_attitude_is_chosen_clear_of_a_zone_near_the_sun():
    sun = np.array([1.0, 0.0, 0.0])
    # a zone 60 deg off the Sun, half-angle 45 deg: the sensor (normal to the Sun axis) clears it for some ψ only
    a_N = np.array([math.cos(math.radians(60.0)), math.sin(math.radians(60.0)), 0.0])
    zs = FittedZones([zone(a_N, 45.0)])
    on_sun = rot.from_axis_angle(np.array([0.0, 1.0, 0.0]), math.radians(90.0))      # body z on the Sun, y on +y
    turned = rot.from_axis_angle(np.array([0.0, 0.0, 1.0]), math.radians(30.0))
    flipped = rot.from_axis_angle(np.array([1.0, 0.0, 0.0]), math.pi)
    q0 = rot.multiply(turned, rot.multiply(flipped, on_sun))       # z 30 deg off the Sun, the sensor clear
    assert sz.margins(q0, zs.sensor_axes, a_N[None], [math.radians(45.0)], [False])[0] > 0.0
    cands = sz.sun_attitudes(sun, [0.0, 0.0, 1.0])
    axes, halves = zs.at(np.zeros(sz.PATH_POINTS), true=True)
    held = sz.margins(cands, zs.sensor_axes, axes[0], halves[0], zs.keep_in)[:, 0]
    assert held.min() < 0.0 < held.max()                          # some rotations about the Sun line enter
    q, worst = sz.choose_sun_attitude(q0, cands, zs.sensor_axes, axes, halves, axes[:1], halves[:1], zs.keep_in)
    assert worst >= sz.BUFFER_RAD
    path = rot.slerp(q0, q, np.linspace(0, 1, 200))
    assert sz.margins(path, zs.sensor_axes, axes[0], halves[0], zs.keep_in).min() >= sz.BUFFER_RAD - 1e-3


def test_the_approach_is_the_pd_law_near_the_target_and_rate_limited_far():
    target = rot.IDENTITY
    near = rot.from_axis_angle(np.array([0.0, 0.0, 1.0]), 0.01)
    tau = sz.approach_torque(near, np.zeros(3), target, 20.0, 480.0)
    assert np.allclose(tau, -20.0 * rot.log_map(near), rtol=1e-9)
    far = rot.from_axis_angle(np.array([0.0, 0.0, 1.0]), 2.0)
    tau = sz.approach_torque(far, np.zeros(3), target, 20.0, 480.0)
    assert np.allclose(tau, [0.0, 0.0, -480.0 * sz.SLEW_RATE_RAD_S])
    assert np.allclose(sz.approach_torque(target, np.zeros(3), target, 20.0, 480.0), 0.0)


class Geometry(SimpleNamespace):
    pass


def keeper_flight(zs, sun_N, q0, omega0, gyro_trusted, seconds, momentum_error=(0.0, 0.0, 0.0)):
    """The keeper flown on the rigid body with wheels (the state's wheel speeds from their momentum);
    its gyro, when not trusted, read once with ``momentum_error`` (rad/s) at the entry."""
    config = ControllerConfig(safe_kd=480.0, tracking_kp=20.0, tracking_kd=480.0)
    keeper = ZoneKeeper(zs, SC, Geometry(sun_N=lambda t: sun_N), config)
    laws = []

    def law(t, q, w, h):
        speeds = np.linalg.pinv(PYRAMID) @ h / SC.wheel_inertia
        read = w + (np.asarray(momentum_error) if t == 0.0 else 0.0)
        state = SimpleNamespace(t=t, q=q, omega=read, wheel_speeds=speeds)
        act = keeper(state, gyro_trusted)
        laws.append(act.law)
        return act.torque_B

    q, omega = fly_rigid(q0, omega0, law, seconds, dt=2.0, substeps=8)
    return q, omega, laws, keeper


@pytest.mark.parametrize("gyro_trusted", [True, False])
def test_the_keeper_stops_a_body_spinning_toward_a_zone_and_points_at_the_sun_clear_of_it(gyro_trusted):
    u = np.array([-1.0, 0.0, 0.0])
    alpha = TORQUE_MAX / np.linalg.norm(J @ u)
    margin = RATE ** 2 / (2 * alpha * sz.AUTHORITY_SHARE) + 2 * sz.BUFFER_RAD
    a_N = rot.dcm_NB(rot.from_axis_angle(np.array([1.0, 0.0, 0.0]), margin + math.radians(30.0))) @ SENSOR_B
    sun = np.array([0.2, -0.3, 1.0])
    zs = FittedZones([zone(a_N, 30.0, name="moon"), zone(sun, 45.0, name="sun")])
    q, omega, laws, keeper = keeper_flight(zs, sun / np.linalg.norm(sun), rot.IDENTITY, np.array([RATE, 0, 0]),
                                           gyro_trusted, 1200.0, np.array([1e-4, 0.0, 0.0]))
    axes, halves = zs.at(np.zeros(1), true=True)
    m = sz.margins(q, zs.sensor_axes, axes[0], halves[0], zs.keep_in)
    assert m.min() >= 0.0
    assert laws[0] == "wheels_among_zones" and laws[-1] == "sun_among_zones"
    z_N = rot.dcm_NB(q[-1]) @ np.array([0.0, 0.0, 1.0])
    assert math.degrees(math.acos(np.clip(z_N @ sun / np.linalg.norm(sun), -1, 1))) < 0.5
    assert np.linalg.norm(omega) < math.radians(0.01)


def test_the_keeper_goes_to_the_sun_around_a_zone_beside_it():
    sun = np.array([1.0, 0.0, 0.0])
    a_N = np.array([math.cos(math.radians(60.0)), math.sin(math.radians(60.0)), 0.0])
    zs = FittedZones([zone(a_N, 45.0)])
    # the body at rest, z 90 deg off the Sun, the sensor clear of the zone but the shortest way to the
    # Sun attitudes nearest in ψ runs through it
    q0 = rot.from_axis_angle(np.array([0.0, 0.0, 1.0]), math.radians(-100.0))
    axes, halves = zs.at(np.zeros(1), true=True)
    assert sz.margins(q0, zs.sensor_axes, axes[0], halves[0], zs.keep_in)[0] > 0.0
    q, omega, laws, keeper = keeper_flight(zs, sun, q0, np.zeros(3), False, 1500.0)
    m = sz.margins(q, zs.sensor_axes, axes[0], halves[0], zs.keep_in)
    assert m.min() >= 0.0 and keeper.target_margin >= sz.BUFFER_RAD
    z_N = rot.dcm_NB(q[-1]) @ np.array([0.0, 0.0, 1.0])
    assert math.degrees(math.acos(np.clip(z_N @ sun, -1, 1))) < 0.5


def test_the_keeper_refuses_wheels_that_do_not_span_the_body():
    zs = FittedZones([zone([1.0, 0.0, 0.0], 10.0)])
    with pytest.raises(ValueError, match="do not span"):
        ZoneKeeper(zs, SC, None, ControllerConfig(), healthy=(True, True, False, False))
