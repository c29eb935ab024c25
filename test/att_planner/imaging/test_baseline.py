"""The accessible bound and the greedy baseline (a planning estimate): every planned image lies in
its site's window, each site once, each slew the rest-to-rest eigenaxis time the problem's own
bound gives, the choice the earliest-closing reachable window."""
from __future__ import annotations

import math

import numpy as np
import pytest

from att_planner.imaging import access, baseline, sites
from att_planner.problem import ManeuverProblem, rest_to_rest_time
from att_sim.models import rotations as rot
from att_sim.models import scenario as scen
from att_sim.models import world

AEOS = scen.load("aeos")
RATE_MAX = math.radians(5.0)
H_MAX = 50.0


def test_the_rest_to_rest_time_is_bang_bang_on_a_principal_axis_and_coasts_at_the_rate_bound():
    sc = AEOS.spacecraft
    phi = math.radians(30.0)
    alpha = sc.body_torque_max / sc.inertia[2, 2]
    assert rest_to_rest_time(sc, [0, 0, 1], phi)[0] == pytest.approx(2 * math.sqrt(phi / alpha))
    w = math.radians(1.0)
    assert rest_to_rest_time(sc, [0, 0, 1], phi, rate_max=w)[0] == pytest.approx(phi / w + w / alpha)
    assert rest_to_rest_time(sc, [[0, 0, 1], [1, 0, 0]], [0.0, 0.0]).tolist() == [0.0, 0.0]


def scalar_slew_time(sc, e, phi, rate_max, h_max):
    """The bang-bang-and-coast time written out for one slew (the reference of the vectorised one)."""
    J = sc.inertia
    alpha = sc.body_torque_max / np.max(np.abs(J @ e) + phi * np.abs(np.cross(e, J @ e)))
    w = min(math.sqrt(alpha * phi), rate_max / np.abs(e).max(), h_max / np.abs(sc.wheel_axes_pinv @ J @ e).max())
    return phi / w + w / alpha


def test_the_rest_to_rest_time_is_the_problems_slew_time_bound():
    sc = AEOS.spacecraft
    rng = np.random.default_rng(3)
    e_all, phi_all, expected = [], [], []
    for _ in range(20):
        q0, q1 = rot.normalize(rng.normal(size=4)), rot.normalize(rng.normal(size=4))
        e, phi = rot.to_axis_angle(rot.multiply(rot.conjugate(q0), q1))
        problem = ManeuverProblem(sc, q0, q1, rate_max=RATE_MAX, wheel_momentum_max=H_MAX)
        assert problem.slew_time_bound() == pytest.approx(scalar_slew_time(sc, e, phi, RATE_MAX, H_MAX), rel=1e-12)
        e_all.append(e), phi_all.append(phi), expected.append(problem.slew_time_bound())
    assert rest_to_rest_time(sc, np.array(e_all), np.array(phi_all), RATE_MAX, H_MAX) == pytest.approx(expected,
                                                                                                      rel=1e-12)


def test_rotation_between_recovers_the_eigenaxis_and_angle():
    rng = np.random.default_rng(4)
    q0 = rot.normalize(rng.normal(size=4))
    axes = rng.normal(size=(5, 3))
    axes /= np.linalg.norm(axes, axis=1, keepdims=True)
    angles = np.array([0.1, 1.0, 2.0, 3.0, math.pi - 1e-9])
    q1 = np.array([rot.multiply(q0, rot.from_axis_angle(a, x)) for a, x in zip(axes, angles)])
    axis, angle = baseline.rotation_between(rot.dcm_NB(q0), np.array([rot.dcm_NB(q) for q in q1]))
    assert angle == pytest.approx(angles, abs=1e-7)
    assert np.abs(np.abs(np.einsum("ij,ij->i", axis, axes)) - 1).max() < 1e-6


@pytest.fixture(scope="module")
def day():
    env = world.Environment.from_scenario(AEOS)
    s = sites.uniform(400, 11)
    w = access.access_windows(env, s, 0.0, AEOS.orbit_model.period)
    plan = baseline.greedy(env, AEOS.spacecraft, s, w, [0, 0, 1], rate_max=RATE_MAX, wheel_momentum_max=H_MAX,
                           dwell_s=2.0)
    return env, s, w, plan


def test_the_bound_counts_the_sites_with_a_window(day):
    _, s, w, plan = day
    bound = baseline.accessible_bound(w, s)
    assert bound.sites == len(set(w.site.tolist())) > 0
    assert bound.priority == pytest.approx(sum(s.priority[i] for i in set(w.site.tolist())))
    assert 0 < len(plan) <= bound.sites and plan.priority <= bound.priority


def test_every_planned_image_is_in_its_window_once_after_its_slew(day):
    env, s, w, plan = day
    assert len({i.site for i in plan.images}) == len(plan)
    pointing = baseline.Pointing(env, access.SkyGeometry(env, s), [0, 0, 1])
    previous_t, previous = w.t0_s - 2.0, pointing.nadir(w.t0_s)
    for image in plan.images:
        assert w.site[image.window] == image.site
        assert w.open_s[image.window] <= image.time_s <= w.close_s[image.window]
        target = pointing.dcm_NB(np.array([image.site]), np.array([image.time_s]))[0]
        e, phi = rot.to_axis_angle(rot.multiply(rot.conjugate(rot.from_dcm_NB(previous)), rot.from_dcm_NB(target)))
        slew = ManeuverProblem(AEOS.spacecraft, rot.from_dcm_NB(previous), rot.from_dcm_NB(target), rate_max=RATE_MAX,
                               wheel_momentum_max=H_MAX).slew_time_bound()
        assert phi == pytest.approx(image.slew_angle_rad, abs=1e-7)
        # the arrival is the slew's end (a fixed point to the second), or the window's opening
        assert image.time_s >= previous_t + 2.0 + slew - 0.05 or image.time_s == w.open_s[image.window]
        assert image.time_s == pytest.approx(max(w.open_s[image.window], previous_t + 2.0 + slew), abs=0.05)
        # the imager's boresight on the site: the spacecraft at >= 58 deg in the site's sky
        r = access.SkyGeometry(env, s).pairs(np.array([image.site]), np.array([image.time_s]))[0]
        assert r >= math.sin(math.radians(access.MIN_ELEVATION_DEG)) - 1e-9
        r_N = env.orbit.position(np.array([image.time_s]))[0]
        site_N = env.field.itrs_rotation(np.array([image.time_s]))[0].T @ pointing.geometry.sites_itrs[image.site]
        los = (site_N - r_N) / np.linalg.norm(site_N - r_N)
        assert np.linalg.norm(np.cross(target @ [0.0, 0.0, 1.0], los)) < 1e-9 and target[:, 2] @ los > 0
        assert image.slew_s == pytest.approx(slew, rel=1e-9)
        previous_t, previous = image.time_s, target


def test_the_choice_is_the_earliest_closing_reachable_window():
    """Windows made by hand: site 0 opens at once but closes before any slew can reach it (dropped);
    sites 1 and 2 open together and 2 closes first: 2 is imaged, then 1. Looking one window ahead,
    the policy takes 1 (the next to open) first."""
    env = world.Environment.from_scenario(AEOS)
    s = sites.uniform(3, 0)
    w = access.AccessWindows(3, 0.0, 1000.0, math.radians(58.0), np.array([0, 1, 2]), np.array([0.0, 100.0, 100.0]),
                             np.array([0.5, 900.0, 400.0]))
    plan = baseline.greedy(env, AEOS.spacecraft, s, w, [0, 0, 1], rate_max=RATE_MAX, wheel_momentum_max=H_MAX)
    assert [i.site for i in plan.images] == [2, 1] and plan.images[0].time_s >= 100.0
    assert plan.priority == pytest.approx(s.priority[1] + s.priority[2])
    one = baseline.greedy(env, AEOS.spacecraft, s, w, [0, 0, 1], rate_max=RATE_MAX, wheel_momentum_max=H_MAX,
                          lookahead=1)
    assert [i.site for i in one.images][:1] == [1]


@pytest.mark.parametrize("kwargs, words", [({"lookahead": 0}, "lookahead"), ({"dwell_s": -1.0}, "dwell_s"),
                                           ({"dwell_s": math.nan}, "dwell_s")])
def test_bad_policy_settings_are_refused(day, kwargs, words):
    env, s, w, _ = day
    with pytest.raises(ValueError, match=words):
        baseline.greedy(env, AEOS.spacecraft, s, w, [0, 0, 1], **kwargs)
