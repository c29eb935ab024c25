"""TRIAD and QUEST (Shuster & Oh 1981) on exact and noisy vectors, the 180° case QUEST's sequential
rotations exist for, and the coarse sun vector from cosine detectors."""
from __future__ import annotations

import math

import numpy as np
import pytest
from scipy.stats import chi2

from att_planner.estimation.attitude_determination import quest, sun_vector, triad
from att_sim.models import rotations as rot

RNG = np.random.default_rng(2026)


def random_unit(n: int) -> np.ndarray:
    v = RNG.normal(size=(n, 3))
    return v / np.linalg.norm(v, axis=1, keepdims=True)


@pytest.mark.parametrize("angle", [0.0, 1e-9, 0.3, 2.0, math.pi - 1e-6, math.pi])
def test_exact_vectors_give_the_attitude_to_rounding(angle):
    for _ in range(20):
        q = rot.from_axis_angle(random_unit(1)[0], angle)
        r = random_unit(4)
        b = r @ rot.dcm_NB(q)                      # rows R(q)ᵀ r: the body measurements
        assert rot.angle_between(triad(b[0], b[1], r[0], r[1]), q) < 1e-7
        q_quest, _ = quest(b, r, np.ones(4))
        assert rot.angle_between(q_quest, q) < 1e-7


def test_quest_on_noisy_vectors_is_consistent_with_its_covariance():
    """NEES of QUEST's attitude over 400 noisy cases, against its own covariance: chi-square, 3 dof."""
    sigmas = np.array([1e-3, 5e-3, 2e-2])
    nees, triad_errors, quest_errors = [], [], []
    for _ in range(400):
        q = rot.from_axis_angle(random_unit(1)[0], RNG.uniform(0, math.pi))
        r = random_unit(3)
        b = []
        for ri, s in zip(r, sigmas):
            v = rot.dcm_BN(q) @ ri + RNG.normal(0, s, 3)
            b.append(v / np.linalg.norm(v))
        b = np.array(b)
        q_hat, P = quest(b, r, 1.0 / sigmas**2)
        e = 2 * rot.error_vector(q, q_hat)                  # true attitude from the estimate, body axes
        nees.append(e @ np.linalg.solve(P, e))
        quest_errors.append(rot.angle_between(q_hat, q))
        triad_errors.append(rot.angle_between(triad(b[0], b[1], r[0], r[1]), q))
    lo, hi = chi2.ppf([0.025, 0.975], 3 * 400) / 400
    assert lo <= np.mean(nees) <= hi, np.mean(nees)
    # optimal weighting beats TRIAD, which trusts its second vector blindly
    assert np.mean(quest_errors) < np.mean(triad_errors)


def test_parallel_observations_are_refused():
    r = np.array([[1.0, 0.0, 0.0], [2.0, 0.0, 0.0]])
    with pytest.raises(ValueError):
        triad(r[0], r[1], r[0], r[1])
    with pytest.raises(ValueError):
        quest(r, r, [1.0, 1.0])
    with pytest.raises(ValueError):
        quest(r[:1], r[:1], [1.0])


def test_sun_vector_from_cosine_detectors():
    normals = np.vstack([np.eye(3), -np.eye(3)])
    s = np.array([0.6, -0.48, 0.64])
    values = np.maximum(normals @ s, 0.0)
    assert sun_vector(values, normals, 0.05) == pytest.approx(s / np.linalg.norm(s))
    pyramid = np.array([[1, 1, 1], [1, -1, 1], [-1, 1, 1], [-1, -1, 1], [0, 0, -1.0]])
    pyramid /= np.linalg.norm(pyramid, axis=1, keepdims=True)
    up = np.array([0.1, 0.2, 0.97])
    assert sun_vector(np.maximum(pyramid @ up, 0), pyramid, 0.05) == pytest.approx(up / np.linalg.norm(up))
    assert sun_vector(np.zeros(6), normals, 0.05) is None                   # eclipse
    assert sun_vector(np.array([0.9, 0, 0, 0, 0, 0]), normals, 0.05) is None  # one lit detector: no vector
