"""The attitude convention: body-to-inertial, [x, y, z, w], Hamilton product."""
import numpy as np
import pytest

from att_sim.models import rotations as rot

RNG = np.random.default_rng(7)


def random_quaternions(n):
    return rot.normalize(RNG.normal(size=(n, 4)))


def test_dcm_maps_body_to_inertial_and_composes_like_the_product():
    q = rot.from_axis_angle([0, 0, 1], np.pi / 2)
    assert rot.dcm_NB(q) @ np.array([1.0, 0, 0]) == pytest.approx([0, 1, 0], abs=1e-15)
    p, r = random_quaternions(2)
    assert np.allclose(rot.dcm_NB(rot.multiply(p, r)), rot.dcm_NB(p) @ rot.dcm_NB(r))


def test_dcm_BN_is_schaub_and_junkins_bn_and_the_transpose_of_dcm_NB():
    """A body frame turned by θ about the inertial 3-axis: Schaub & Junkins' [BN] = M3(θ) =
    [[c, s, 0], [−s, c, 0], [0, 0, 1]] (v_B = [BN] v_N), written out here."""
    theta = 0.7
    c, s = np.cos(theta), np.sin(theta)
    q_BN = rot.from_axis_angle([0, 0, 1], theta)
    np.testing.assert_allclose(rot.dcm_BN(q_BN), [[c, s, 0], [-s, c, 0], [0, 0, 1]], atol=1e-15)
    qs = random_quaternions(5)
    assert np.array_equal(rot.dcm_BN(qs), np.swapaxes(rot.dcm_NB(qs), -1, -2))
    v_N = RNG.normal(size=3)
    for q in qs:
        assert np.array_equal(rot.dcm_BN(q), rot.dcm_NB(q).T)
        np.testing.assert_allclose(rot.to_body(q.tolist(), v_N.tolist()), rot.dcm_BN(q) @ v_N, rtol=0, atol=1e-14)


def test_from_dcm_inverts_dcm_up_to_sign():
    for q in random_quaternions(50):
        back = rot.from_dcm_NB(rot.dcm_NB(q))
        assert min(np.linalg.norm(back - q), np.linalg.norm(back + q)) < 1e-12


def test_exp_map_matches_rodrigues_and_small_angles():
    phi = np.array([0.3, -0.2, 0.9])
    angle = np.linalg.norm(phi)
    K = rot.hat(phi / angle)
    rodrigues = np.eye(3) + np.sin(angle) * K + (1 - np.cos(angle)) * K @ K
    assert np.allclose(rot.expm_so3(phi), rodrigues)
    assert np.allclose(rot.exp_map([1e-12, 0, 0]), [5e-13, 0, 0, 1])


def test_kinematics_convention_q_dot_is_half_q_times_omega():
    q, w, dt = random_quaternions(1)[0], np.array([0.1, -0.3, 0.2]), 1e-6
    numeric = (rot.propagate_constant_rate(q, w, dt) - q) / dt
    assert np.allclose(numeric, 0.5 * rot.multiply(q, np.append(w, 0)), atol=1e-6)
    # R_dot = R hat(omega)
    R_dot = (rot.dcm_NB(rot.propagate_constant_rate(q, w, dt)) - rot.dcm_NB(q)) / dt
    assert np.allclose(R_dot, rot.dcm_NB(q) @ rot.hat(w), atol=1e-5)


def test_angle_between_is_sign_independent():
    q = random_quaternions(1)[0]
    r = rot.multiply(q, rot.from_axis_angle([1, 1, 0], 0.4))
    assert rot.angle_between(q, -r) == pytest.approx(0.4)
    assert np.allclose(rot.error_vector(-r, q), rot.error_vector(r, q))


def test_one_quaternion_fast_paths_agree_with_the_stacked_forms():
    """dcm_NB, exp_map and to_axis_angle take Python-float paths for one quaternion or vector (the
    loops' hot path); each row of a stack goes through numpy's: the same values to the last ulps."""
    qs = random_quaternions(20)
    stacked = rot.dcm_NB(qs)
    for q, R in zip(qs, stacked):
        assert np.array_equal(rot.dcm_NB(q), R)
    phis = np.vstack([RNG.normal(size=(10, 3)), RNG.normal(size=(5, 3)) * 1e-9, np.zeros((1, 3))])
    # a unit quaternion: each path rounds its norm, sin(θ/2)/θ, cos and products to a few ulps of 1 in
    # its own order (libm's scalar sin against numpy's vector one), so the two agree to 8 eps absolute
    # (the largest of 10^6 random vectors: 4 eps); a relative bound fails on components near zero
    for phi, q in zip(phis, rot.exp_map(phis)):
        assert np.max(np.abs(rot.exp_map(phi) - q)) <= 8.0 * np.finfo(float).eps
    for q in qs:
        axis, angle = rot.to_axis_angle(q)
        assert np.allclose(rot.from_axis_angle(axis, angle), q if q[3] >= 0 else -q, rtol=0, atol=4e-16)


def test_log_map_of_rows_gives_each_row_its_bits_alone():
    """A batch's gyros take the rotations of all runs as rows: each row is the one quaternion's
    log map bit for bit — small and zero rotations, w < 0, unnormalised, zero and non-finite rows."""
    qs = np.vstack([random_quaternions(200) * RNG.uniform(1e-3, 1e3, (200, 1)),
                    [[1e-12, -2e-13, 3e-14, -1.0], [0.0, 0.0, 0.0, 1.0], [0.0, 0.0, 0.0, 0.0],
                     [np.nan, 0.0, 0.0, 1.0], [0.6, 0.8, 0.0, 0.0]]])
    rows = rot.log_map(qs)
    for q, row in zip(qs, rows):
        assert rot.log_map(q).tobytes() == row.tobytes()
    assert np.allclose(rot.exp_map(rows[:200]), rot.normalize(qs[:200]) * np.sign(qs[:200, 3:]), atol=1e-12)


def test_to_body_on_rows_is_the_transposed_dcm_of_each_row():
    """Rows of quaternions, unit or not (an RK4 stage's), each against ``dcm(q)ᵀ v`` computed alone;
    one vector for every row or one per row; one quaternion; a stack of rows."""
    qs = random_quaternions(50) * RNG.uniform(0.9, 1.1, (50, 1))
    vs = RNG.normal(size=(50, 3))

    def rounding(q, v):
        """The two evaluation orders of one sum differ by a few ulps of its largest term (|q|^2 |v|
        per product, about 8 products per component, rounded at most twice each)."""
        return 16 * np.finfo(float).eps * (1.0 + q @ q) * np.abs(v).sum()

    for v, rows in ((vs, rot.to_body(qs, vs)), (vs[0], rot.to_body(qs, vs[0]))):
        for i, (q, row) in enumerate(zip(qs, rows)):
            vi = v if v.ndim == 1 else v[i]
            np.testing.assert_allclose(row, rot.dcm_BN(q) @ vi, rtol=0, atol=rounding(q, vi))
    np.testing.assert_allclose(rot.to_body(qs[3], vs[3]), rot.dcm_BN(qs[3]) @ vs[3], rtol=0,
                               atol=rounding(qs[3], vs[3]))
    stacked = rot.to_body(qs.reshape(5, 10, 4), vs.reshape(5, 10, 3))
    np.testing.assert_array_equal(stacked.reshape(50, 3), rot.to_body(qs, vs))


def test_cross_of_one_pair_is_the_rows_formula_bit_for_bit():
    """One pair of vectors (shaped (3,), (1, 3) or component-first (3, 1)) takes the products on
    Python floats: the same bits as the pair inside a stack."""
    rng = np.random.default_rng(4)
    a, b = rng.normal(size=(50, 3)) * 1e3, rng.normal(size=(50, 3)) * 1e-5
    rows = rot.cross(a, b)
    for k in range(50):
        np.testing.assert_array_equal(rot.cross(a[k], b[k]), rows[k])
        np.testing.assert_array_equal(rot.cross(a[k:k + 1], b[k:k + 1]), rows[k:k + 1])
        np.testing.assert_array_equal(rot.cross(a[k][:, None], b[k][:, None], axis=0), rows[k][:, None])
    np.testing.assert_allclose(rows, np.cross(a, b), rtol=1e-12, atol=1e-18)
