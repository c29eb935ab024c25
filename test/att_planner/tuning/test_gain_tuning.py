"""Magnetorquer PD law, batch settling simulator and derivative-free min-max."""
import math

import numpy as np
import pytest
import yaml

from att_msgs_py.types import Status
from att_planner import tuning as gt
from att_planner.control.magnetorquer import control_torque, dipole_command
from att_planner.reference.bruni_celani import PUBLISHED_GAINS, PUBLISHED_ICS, robust_seeds
from att_planner.tools import config_cli
from att_planner.tools import tune as tune_cli
from att_planner.tools.monte_carlo.cluster import HTTP_ON_A_FREE_PORT
from att_planner.tuning.settling import _BatchModel
from att_sim.models import dynamics as dyn
from att_sim.models import environment as env
from att_sim.models import rotations as rot

CASE = gt.MagnetorquerCase()


# --------------------------------------------------------------------------------------- law


def test_law_matches_formula_saturates_and_is_pd_when_unsaturated():
    rng = np.random.default_rng(0)
    q = rot.normalize(rng.normal(size=(50, 4)))
    w = rng.uniform(-0.1, 0.1, (50, 3))
    b = rng.normal(size=(50, 3)) * 3e-5
    kp, kd = 2e5, 3e8
    m = dipole_command(q, w, b, kp, kd, 10.0)
    expected = -10.0 * np.clip(np.cross(b, kp * q[:, :3] + kd * w) / 10.0, -1, 1)
    np.testing.assert_allclose(m, expected, rtol=1e-12)
    assert np.all(np.abs(m) <= 10.0 + 1e-12) and np.any(np.abs(m) == 10.0)
    tau = control_torque(q, w, b, kp, kd, 10.0)
    np.testing.assert_allclose(np.einsum("ij,ij->i", tau, b), 0.0, atol=1e-18)   # m × B ⟂ B
    # small errors: no saturation, τ = −(|B|² I − B Bᵀ)(κp q_v + κd ω)
    qs, ws = q[:, :3] * 1e-4, w * 1e-4
    tau = control_torque(qs, ws, b, kp, kd, 10.0)
    a = kp * qs + kd * ws
    pd = -(np.sum(b * b, 1)[:, None] * a - b * np.sum(b * a, 1)[:, None])
    np.testing.assert_allclose(tau, pd, rtol=1e-9)
    # component-first layout and per-case gains give the same numbers
    m0 = dipole_command(q.T, w.T, b.T, np.full(50, kp), np.full(50, kd), 10.0, axis=0)
    np.testing.assert_allclose(m0.T, m, rtol=1e-12)


# ----------------------------------------------------------------------- batch model vs truth


def test_batch_right_hand_side_equals_truth_dynamics():
    """The batch RHS is the dynamics model's derivative with Inputs(dipole_B=m, field_B=B_b)."""
    rng = np.random.default_rng(1)
    n = 12
    h = gt.H_LOWER + rng.random((n, 7)) * (gt.H_UPPER - gt.H_LOWER)
    q0, w0, psi = gt.initial_states(h)
    kp, kd = 10 ** rng.uniform(4, 7, n), 10 ** rng.uniform(6, 9, n)
    model = _BatchModel(CASE, kp, kd, psi)
    x = np.concatenate([q0, w0], 1).T.copy()
    t = 1234.5
    d = model(t, x)
    sc = dyn.Spacecraft(inertia=np.diag(CASE.inertia), dipole_max=CASE.m_max)
    orbit = CASE.orbit
    for j in range(n):
        b_body = env.field_body(orbit, t, q0[j], psi[j])
        m = dipole_command(q0[j], w0[j], b_body, kp[j], kd[j], CASE.m_max)
        ref = dyn.derivative(sc, dyn.initial_state(sc, q0[j], w0[j]), dyn.Inputs(dipole_B=m, field_B=b_body))
        np.testing.assert_allclose(d[:, j], ref[:7], rtol=1e-9, atol=1e-15)


def test_initial_condition_parametrisation():
    q0, w0, psi = gt.initial_states(PUBLISHED_ICS["ic23"])
    np.testing.assert_allclose(np.linalg.norm(q0, axis=1), 1.0)
    np.testing.assert_allclose(q0[0, :3], 0.5 * np.array([math.sin(3 * math.pi / 4), 0.0, math.cos(3 * math.pi / 4)]))
    np.testing.assert_allclose(w0[0], [-0.1, 0.1, 0.1])
    assert psi[0] == pytest.approx(math.pi / 2)
    starts = gt.multistart_points()
    assert starts.shape == (8, 7) and len({tuple(r) for r in starts[:, 3:6]}) == 8


def test_published_ic20_figures_reproduce():
    """IC (20): trial gains ≈ 4.0 orbits, the paper's DIRECT optimum ≈ 1.77 (model as written)."""
    gains = [PUBLISHED_GAINS["trial"], PUBLISHED_GAINS["fixed_direct"]]
    res = gt.simulate_settling(CASE, [g[0] for g in gains], [g[1] for g in gains],
                               np.repeat(PUBLISHED_ICS["ic20"][None], 2, 0),
                               gt.SimSettings(dt=10.0, cap_orbits=6, quiet_orbits=0.25))
    assert np.all(res.status == gt.SETTLED)
    assert res.ts[0] == pytest.approx(4.002, abs=0.02)
    assert res.ts[1] == pytest.approx(1.775, abs=0.015)


def test_batch_integration_agrees_with_truth_dynamics_stepping():
    """Same gains and ICs through att_sim.models.dynamics.step with every input held over each 1 s step
    (a zero-order hold of the environment over each step) and through the batch RK4
    (inputs evaluated at the RK4 stages): after
    400 s of tumbling the states differ only by the hold's first-order effect (< 0.3°)."""
    rng = np.random.default_rng(3)
    h = gt.H_LOWER + rng.random((2, 7)) * (gt.H_UPPER - gt.H_LOWER)
    kp, kd = PUBLISHED_GAINS["robust_direct_direct"]
    batch = gt.propagate(CASE, kp, kd, h, 400.0, 1.0)
    sc = dyn.Spacecraft(inertia=np.diag(CASE.inertia), dipole_max=CASE.m_max)
    q0, w0, psi = gt.initial_states(h)
    for j in range(2):
        x = dyn.initial_state(sc, q0[j], w0[j])
        for k in range(400):
            b_body = env.field_body(CASE.orbit, float(k), x[:4], psi[j])
            m = dipole_command(x[:4], x[4:7], b_body, kp, kd, CASE.m_max)
            x = dyn.step(sc, x, dyn.Inputs(dipole_B=m, field_B=b_body), 1.0)
        assert rot.angle_between(x[:4], batch[j, :4]) < 5e-3
        np.testing.assert_allclose(x[4:7], batch[j, 4:7], atol=5e-5)


def test_cap_and_pruning_are_reported_not_hidden():
    settings = gt.SimSettings(dt=20.0, cap_orbits=0.4)
    h = np.repeat(PUBLISHED_ICS["ic22"][None], 3, 0)
    # κp = κd ≈ 0: nothing happens, the tumbling case never settles -> CAPPED at the cap
    res = gt.simulate_settling(CASE, [1e-9, 1e-9, 1e-9], [1e-9, 1e-9, 1e-9], h, settings)
    assert np.all(res.status == gt.CAPPED) and np.all(res.ts == 0.4)
    # stop_above: still above ν after 0.1 orbit -> ABOVE with a lower bound, its group DROPPED
    at_rest = np.zeros(7)                          # q = identity, ω = 0: never leaves |q_i| ≤ ν
    settings = gt.SimSettings(dt=20.0, cap_orbits=1.0, quiet_orbits=0.2)
    res = gt.simulate_settling(CASE, [1e-9, 2e5, 2e5, 2e5], [1e-9, 3e8, 3e8, 3e8],
                               np.vstack([h[:1], at_rest, PUBLISHED_ICS["ic20"], at_rest]),
                               settings, group=[0, 0, 1, 2], stop_above=0.1)
    assert res.status[0] == gt.ABOVE and 0.1 <= res.ts[0] <= 0.15
    assert res.status[1] == gt.DROPPED and res.ts[1] == 0.0
    assert res.status[2] == gt.ABOVE
    assert res.status[3] == gt.SETTLED and res.ts[3] == 0.0
    # race: the first complete group's value becomes the bound of the others
    res = gt.simulate_settling(CASE, [2e5, 2e5], [3e8, 3e8], np.vstack([at_rest, PUBLISHED_ICS["ic20"]]),
                               settings, race=True)
    assert list(res.status) == [gt.SETTLED, gt.ABOVE] and res.ts[1] < 0.3


# --------------------------------------------------------------------------- search blocks


def branin(x):
    x = np.atleast_2d(x)
    a, b = x[:, 0], x[:, 1]
    return (b - 5.1 / (4 * np.pi**2) * a**2 + 5 / np.pi * a - 6) ** 2 + 10 * (1 - 1 / (8 * np.pi)) * np.cos(a) + 10


def test_direct_batch_matches_scipy_direct():
    lo, hi = [-5.0, 0.0], [10.0, 15.0]
    ours = gt.direct_batch(branin, lo, hi, maxfun=300)
    ref = gt.direct_scipy(lambda x: branin(x)[0], lo, hi, maxfun=300)
    assert ours.fun == pytest.approx(0.397887, abs=1e-3)
    assert ours.fun == pytest.approx(ref.fun, abs=1e-6)
    np.testing.assert_allclose(ours.x, ref.x, atol=1e-6)
    # the uniform start is a valid DIRECT partition too
    grid = gt.direct_batch(branin, lo, hi, maxfun=300, initial_level=2)
    assert grid.X.shape[0] >= 81 and grid.fun == pytest.approx(0.397887, abs=2e-3)


def test_sdbox_batch_reaches_box_constrained_minimum_from_several_starts():
    target = np.array([0.3, 0.7, 1.4, -0.2])        # last two outside [−1, 1] x [0, 1]
    lo, hi = np.array([0.0, 0.0, -1.0, 0.0]), np.array([1.0, 1.0, 1.0, 1.0])

    def f(x):
        return np.sum((np.atleast_2d(x) - target) ** 2, 1)

    res = gt.sdbox_batch(f, lo, hi, [[0.9, 0.1, 0.0, 0.5], [0.1, 0.9, -0.9, 0.9]], maxfun=3000, alpha_tol=1e-4)
    np.testing.assert_allclose(res.x, [0.3, 0.7, 1.0, 0.0], atol=1e-3)
    assert res.status == Status.OPTIMAL and res.nfev <= 3000


class AnalyticEvaluator:
    """Stands in for BatchEvaluator: t_s(κ, h) = 1 + |log κp − 5 − 0.5 u(ρ)| + 0.1 |log κd − 8| with
    u = 1 − |ρ − 0.6|/0.6 ∈ [0, 1] (worst cases inside the box): the min-max is κp = 10^5.25, κd = 1e8."""

    def __init__(self):
        self.evaluations, self.case_steps, self.batches = 0, 0, 0
        self.settings = gt.SimSettings()

    def settling(self, kp, kd, h, *, group=None, stop_above=None, race=False):
        h = np.atleast_2d(h)
        kp = np.broadcast_to(kp, (len(h),))
        kd = np.broadcast_to(kd, (len(h),))
        self.evaluations += len(h)
        u = 1.0 - np.abs(h[:, 0] - 0.6) / 0.6
        ts = 1.0 + np.abs(np.log10(kp) - 5.0 - 0.5 * u) + 0.1 * np.abs(np.log10(kd) - 8.0)
        return gt.SettlingResult(ts, np.full(len(h), gt.SETTLED), 0, 0, 0.0)


def analytic_worst(kp, kd):
    lk = math.log10(kp)
    return 1.0 + max(abs(lk - 5.0), abs(lk - 5.5)) + 0.1 * abs(math.log10(kd) - 8.0)


@pytest.mark.parametrize("inner, maxfun, tol", [("direct", 600, 0.1), ("sdbox", 300, 0.01),
                                                ("sdbox-multistart", 1500, 0.01)])
def test_inner_worst_case_searches(inner, maxfun, tol):
    ev = AnalyticEvaluator()
    wc = gt.worst_case(ev, 10**5.0, 1e8, method=inner, maxfun=maxfun)
    # DIRECT samples cell centres (ρ = 0.5 here at this budget), SDBOX converges onto ρ = 0.6
    assert wc.ts == pytest.approx(1.5, abs=tol) and wc.h[0] == pytest.approx(0.6, abs=tol + 0.01)
    assert wc.nfev <= maxfun + 200 and len(wc.T) == len(wc.X)


@pytest.mark.parametrize("inner", gt.INNER_METHODS)
def test_min_max_on_an_analytic_problem(inner):
    ev = AnalyticEvaluator()
    res = gt.tune_robust(ev, seeds=robust_seeds(), inner=inner, outer_iterations=6, inner_maxfun=1500, max_cycles=6,
                         tol=0.01)
    truth = analytic_worst(res.kp, res.kd)
    assert res.ts <= truth + 1e-12                  # the reported worst case was really reached
    assert res.stats["cycles"] >= 1 and res.nfev == ev.evaluations
    if inner == "sdbox-multistart":
        # it finds both local maxima (u = 0 and u = 1): the true min-max κp = 10^5.25, value 1.25
        assert math.log10(res.kp) == pytest.approx(5.25, abs=0.02)
        assert res.ts == pytest.approx(1.25, abs=0.02) and truth < 1.27
        assert res.status == Status.OPTIMAL and res.hard_set.shape[0] > 11


# ------------------------------------------------------------------------- executors / CLI


def test_process_executor_splits_batches_with_the_same_results():
    h = np.repeat(PUBLISHED_ICS["ic20"][None], 4, 0)
    kp, kd = [2e5, 2e5, 1e5, 1e5], [3e8, 1e8, 3e8, 1e8]
    settings = gt.SimSettings(dt=20.0, cap_orbits=0.5)
    serial = gt.BatchEvaluator(CASE, settings).settling(kp, kd, h)
    ex = gt.make_executor(2)
    try:
        par = gt.BatchEvaluator(CASE, settings, ex, min_chunk=1).settling(kp, kd, h, group=[0, 0, 1, 1])
    finally:
        ex.close()
    np.testing.assert_array_equal(par.ts, serial.ts)
    np.testing.assert_array_equal(par.status, serial.status)


def test_dask_executor_on_a_local_two_worker_cluster():
    distributed = pytest.importorskip("distributed")
    h = np.repeat(PUBLISHED_ICS["ic20"][None], 4, 0)
    kp, kd = [2e5, 2e5, 1e5, 1e5], [3e8, 1e8, 3e8, 1e8]
    settings = gt.SimSettings(dt=20.0, cap_orbits=0.5)
    serial = gt.BatchEvaluator(CASE, settings).settling(kp, kd, h)
    # in-process workers start in a second instead of ~20 s on a loaded machine; the client path
    # (map, gather, scheduler address) is the one a remote cluster uses
    with distributed.LocalCluster(n_workers=2, threads_per_worker=1, processes=False, dashboard_address=None,
                                  scheduler_kwargs=HTTP_ON_A_FREE_PORT) as cluster:
        ex = gt.make_executor(scheduler=cluster.scheduler_address)
        try:
            assert ex.workers == 2
            par = gt.BatchEvaluator(CASE, settings, ex, min_chunk=1).settling(kp, kd, h)
        finally:
            ex.close()
    np.testing.assert_array_equal(par.ts, serial.ts)


def test_write_gains_replaces_the_old_dipole_key(tmp_path):
    path = tmp_path / "controller_gains.yaml"
    path.write_text(yaml.safe_dump({"controller": {"ros__parameters": {"kp": 1.0, "kd": 2.0, "m_max": 3.0}}}))
    tune_cli.write_gains(str(path), 4.0, 5.0, 6.0)
    assert yaml.safe_load(path.read_text())["controller"]["ros__parameters"] == {"kp": 4.0, "kd": 5.0,
                                                                                  "m_max_Am2": 6.0}
    assert config_cli.check_file(path, "parameters")[1] == []


def test_write_gains_keeps_other_keys_and_progress_line(tmp_path):
    path = tmp_path / "controller_gains.yaml"
    path.write_text(yaml.safe_dump({"controller": {"ros__parameters": {"state_timeout": 0.5}}, "other": {"a": 1}}))
    tune_cli.write_gains(str(path), 205493.83, 117283950.62, 10.0)
    doc = yaml.safe_load(path.read_text())
    p = doc["controller"]["ros__parameters"]
    assert p == {"state_timeout": 0.5, "kp": 205493.83, "kd": 117283950.62, "m_max_Am2": 10.0}
    assert doc["other"] == {"a": 1}
    line = tune_cli.ProgressBar(width=10).line(0.5, "best 1.3")
    assert line.startswith("[#####-----]  50%") and "ETA" in line and line.endswith("best 1.3")
    with pytest.raises(ValueError):
        gt.make_executor(0)
    with pytest.raises(ValueError):
        gt.worst_case(AnalyticEvaluator(), 1e5, 1e8, method="nelder-mead")
