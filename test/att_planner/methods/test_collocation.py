"""The Hermite–Simpson collocation toolkit on problems with known answers."""
import casadi as ca
import numpy as np
import pytest

from att_planner.methods.time_optimal import collocation as col
from att_planner.methods.time_optimal import mesh as meshes


def _double_integrator(control, intervals=10, max_iter=1000):
    x, u = ca.SX.sym("x", 2), ca.SX.sym("u", 1)
    f = ca.Function("f", [x, u], [ca.vertcat(x[1], u)])
    phase = col.Phase(f, meshes.uniform_mesh(intervals), control=control, control_bounds=(-1, 1),
                      duration_bounds=(0.1, 10))
    tr = col.Transcription([phase])
    tr.bound_state(0, 0, [0, 0])
    tr.bound_state(0, -1, [1, 0])
    tr.minimize(tr.variables(0).duration)
    tr.build(max_iter=max_iter)
    guess = col.guess_from_functions(phase, 3.0, lambda t: np.stack([t / 3, np.full_like(t, 1 / 3)], -1),
                                     lambda t: np.zeros((len(t), 1)))
    return tr, tr.solve(tr.pack([guess]))


def test_collocation_double_integrator_minimum_time_is_exact_with_zoh_control():
    # rest-to-rest over a unit distance with |u| ≤ 1: t_f = 2 sqrt(1) = 2, switch at mid-time
    tr, res = _double_integrator("constant")
    assert res.success
    sol = tr.phase_solution(res.w)
    assert sol.duration == pytest.approx(2.0, abs=1e-6)
    assert np.allclose(sol.u[:5], 1.0, atol=1e-5) and np.allclose(sol.u[5:], -1.0, atol=1e-5)
    # the Hermite interpolant reproduces x = t²/2 on the first half
    assert sol.state_at(np.array([0.25]))[0, 0] == pytest.approx(0.5 * 0.5**2, abs=1e-9)


def test_collocation_linear_control_cannot_beat_the_bang_bang_bound():
    tr, res = _double_integrator("linear")
    assert res.success
    assert 2.0 - 1e-6 <= tr.phase_solution(res.w).duration < 2.1


def test_an_unconverged_solve_keeps_its_feasible_iterate_of_least_time():
    # stopped after 3 IPOPT iterations no iterate meets the constraints; after 5 and 6 one does, and its
    # zero-order-hold torques, integrated exactly, bring the double integrator to rest at x = 1
    assert _double_integrator("constant", max_iter=3)[1].incumbent is None
    for max_iter in (5, 6):
        tr, res = _double_integrator("constant", max_iter=max_iter)
        assert not res.success and res.incumbent is not None
        sol = tr.phase_solution(res.incumbent)
        x = v = 0.0
        for h, u in zip(np.diff(sol.phase.mesh) * sol.duration, sol.u[:, 0]):
            x, v = x + v * h + 0.5 * u * h**2, v + u * h
        assert x == pytest.approx(1.0, abs=1e-3) and v == pytest.approx(0.0, abs=1e-9)
        assert 2.0 - 1e-6 <= sol.duration < 2.001
    assert _double_integrator("constant")[1].incumbent is None        # converged: the answer itself
