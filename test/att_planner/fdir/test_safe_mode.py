"""Safe mode on what is left, against independent recomputations: the coils' torque is the part of the
demand normal to the field, B-dot dissipates the rotational energy, a dipole keeps its direction when
scaled, and the wheels take the demand while they span the body."""
from __future__ import annotations

import numpy as np
import pytest

from att_planner.fdir import safe_mode


def test_the_coils_make_the_part_of_the_torque_normal_to_the_field():
    rng = np.random.default_rng(2)
    for _ in range(50):
        tau, B = rng.normal(0, 1e-3, 3), rng.normal(0, 3e-5, 3)
        m = safe_mode.cross_product_dipole(tau, B, dipole_max=1e6)
        normal = tau - B * (B @ tau) / (B @ B)                  # the projection, computed apart
        assert np.allclose(np.cross(m, B), normal, atol=1e-15)


def test_a_dipole_over_the_limit_keeps_its_direction():
    m = safe_mode.cross_product_dipole([0.0, 0.0, 0.01], [3e-5, 0.0, 0.0], dipole_max=50.0)
    assert np.abs(m).max() == pytest.approx(50.0)
    assert np.allclose(m / np.linalg.norm(m), [0.0, -1.0, 0.0])
    assert np.array_equal(safe_mode.cross_product_dipole([1.0, 0, 0], np.zeros(3), 50.0), np.zeros(3))


def test_b_dot_dissipates_the_rotational_energy():
    """With the field fixed inertially over a step, Ḃ_B = −ω × B_B: the B-dot torque m × B has ω·τ ≤ 0."""
    rng = np.random.default_rng(5)
    for _ in range(100):
        omega, B = rng.normal(0, 1e-2, 3), rng.normal(0, 3e-5, 3)
        m = safe_mode.bdot_dipole(-np.cross(omega, B), gain=1e6, dipole_max=50.0)
        assert omega @ np.cross(m, B) <= 1e-18


def test_damping_uses_the_wheels_while_they_span_the_body_else_the_coils_else_b_dot():
    omega, B, B_dot = np.array([0.01, -0.02, 0.005]), np.array([2e-5, -1e-5, 3e-5]), np.array([1e-7, 0, 0])
    on_wheels = safe_mode.damping(omega, B, B_dot, kd=100.0, bdot_gain=1e5, dipole_max=50.0,
                                  wheels_controllable=True, gyro_trusted=True)
    assert on_wheels.on_wheels and np.allclose(on_wheels.torque_B, -100.0 * omega) and not on_wheels.dipole_B.any()
    on_coils = safe_mode.damping(omega, B, B_dot, 100.0, 1e5, 50.0, wheels_controllable=False, gyro_trusted=True)
    assert on_coils.law == "cross_product" and not on_coils.torque_B.any()
    assert np.allclose(on_coils.dipole_B, safe_mode.cross_product_dipole(-100.0 * omega, B, 50.0))
    blind = safe_mode.damping(None, B, B_dot, 100.0, 1e5, 50.0, wheels_controllable=True, gyro_trusted=False)
    assert blind.law == "b_dot" and np.allclose(blind.dipole_B, [-1e-2, 0.0, 0.0])
