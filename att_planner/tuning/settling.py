"""The settling-time problem of Bruni & Celani: its data, and the settling time of many
(gain, initial condition) cases integrated as one batch (the batch simulator), with the truth-path
check of one case through :mod:`att_sim.models.dynamics`."""
from __future__ import annotations

import math
import time
from dataclasses import dataclass

import numpy as np

from att_planner.control.magnetorquer import dipole_command
from att_sim.models import dynamics as dyn
from att_sim.models import environment as env

# ---------------------------------------------------------------------------------------------
# Problem data
# ---------------------------------------------------------------------------------------------


@dataclass(frozen=True)
class MagnetorquerCase:
    """Spacecraft, orbit and settling threshold of the study (defaults: Bruni & Celani's case)."""

    inertia: tuple = (27.0, 17.0, 25.0)           # kg m², principal (diagonal) inertia
    m_max: float = 10.0                           # A m² per coil (m*)
    orbit: env.OrbitParams = env.OrbitParams()    # 450 km, 87°, RAAN 0 (ψ is per case)
    dipole: env.DipoleModel = env.DEFAULT_DIPOLE
    nu: float = 0.05                              # settling threshold on each |q_i|

    @property
    def period(self) -> float:
        return self.orbit.period


# Gain box of the paper (sensor resolutions) and the log box the searches use: the DIRECT optimum
# of the paper sits at κ_p/κ_p,max ≈ 2e-3, so a linear box wastes almost every sample.
LOG_GAIN_BOUNDS = ((3.0, 8.0), (5.0, 9.0))        # log10 κ_p, log10 κ_d

# Initial-condition parameters h = (ρ, φ, θ, ω1, ω2, ω3, ψ) and the box H.
H_NAMES = ("rho", "phi", "theta", "w1", "w2", "w3", "psi")
H_LOWER = np.array([0.0, 0.0, 0.0, -0.1, -0.1, -0.1, 0.0])
H_UPPER = np.array([1.0, 2 * np.pi, np.pi, 0.1, 0.1, 0.1, 2 * np.pi])


def multistart_points() -> np.ndarray:
    """The paper's 8 SDBOX starts: extreme rates ±0.1 with ρ = 0.5, φ = π, θ = π/2, ψ = π."""
    signs = np.array([[a, b, c] for a in (-1, 1) for b in (-1, 1) for c in (-1, 1)], float)
    base = np.array([0.5, np.pi, np.pi / 2, 0.0, 0.0, 0.0, np.pi])
    pts = np.repeat(base[None], 8, 0)
    pts[:, 3:6] = 0.1 * signs
    return pts


def initial_states(h: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """``(q0 (N,4) [x,y,z,w], ω0 (N,3), ψ (N,))`` of parameter rows ``h`` (N, 7)."""
    h = np.atleast_2d(np.asarray(h, float))
    rho, phi, theta = h[:, 0], h[:, 1], h[:, 2]
    qv = rho[:, None] * np.stack([np.sin(theta) * np.cos(phi), np.sin(theta) * np.sin(phi), np.cos(theta)], -1)
    q4 = np.sqrt(np.clip(1.0 - np.sum(qv * qv, -1), 0.0, None))
    return np.concatenate([qv, q4[:, None]], -1), h[:, 3:6].copy(), h[:, 6].copy()


# ---------------------------------------------------------------------------------------------
# Batch settling-time simulator
# ---------------------------------------------------------------------------------------------


@dataclass(frozen=True)
class SimSettings:
    """Integration and settling-detection settings (docs/decisions/settling-simulator-settings.md).

    ``dt``: fixed RK4 step (s). Convergence study (64 random ICs of H, published robust gains,
    against dt = 1.25 s): median |Δt_s| 0.0009 / 0.0035 / 0.011 / 0.081 orbits at dt = 2.5 / 5 /
    10 / 20 s. t_s is discontinuous (a peak of |q_i| just touching ν moves it by a fraction of an
    orbit), so per-case agreement never becomes exact; the searches use 10 s with a 2 % margin on ν
    (their optimum then survives step changes) and every reported figure is re-measured at 5 s and
    through the truth path. ``cap_orbits``: horizon; a case not confirmed settled by then is
    reported CAPPED with ``t_s = cap`` (a lower bound, flagged, never silently clipped).
    Early retirement (``retire``): a case is confirmed settled once, for ``quiet_orbits``, it has had
    no |q_i| above ``quiet_fraction·ν`` and no rate above ``quiet_rate`` (checked every
    ``check_orbits``); its last exit above ν is then its settling time.
    """

    dt: float = 10.0
    cap_orbits: float = 12.0
    retire: bool = True
    quiet_orbits: float = 0.5
    quiet_fraction: float = 0.5
    quiet_rate: float = 2e-3
    check_orbits: float = 0.02


SETTLED, CAPPED, ABOVE, DROPPED = 0, 1, 2, 3
STATUS_NAMES = {SETTLED: "settled", CAPPED: "capped", ABOVE: "above_bound", DROPPED: "dropped"}


@dataclass
class SettlingResult:
    """Per-case settling times (orbits) and how each was obtained.

    ``status``: SETTLED (exact ``ts``), CAPPED (not settled within the cap, ``ts = cap``), ABOVE
    (still above ν after ``stop_above``: ``ts`` is a lower bound), DROPPED (another case of the same
    group went ABOVE; ``ts`` is the lower bound reached so far). ``wall_time`` in s.
    """

    ts: np.ndarray
    status: np.ndarray
    case_steps: int            # Σ over steps of the cases integrated (the work done)
    steps: int
    wall_time: float

    @property
    def exact(self) -> np.ndarray:
        return self.status == SETTLED


class _BatchModel:
    """Right-hand side ``f(t, x)`` of the Bruni–Celani closed loop for a batch, component-first ``(7, N)``.

    State rows ``[q_x, q_y, q_z, q_w, ω_x, ω_y, ω_z]``; every operation is on whole rows so one
    call advances all cases. Field: :func:`att_sim.models.environment.dipole_field_components`; law:
    the expression of :func:`att_planner.control.magnetorquer.dipole_command` written out per row
    (``m × B_b`` with ``m = −m* sat(B_b × (κ_p q_v + κ_d ω)/m*)``).
    """

    def __init__(self, case: MagnetorquerCase, kp, kd, psi):
        self.case = case
        self.n = case.orbit.mean_motion
        self.set_cases(np.asarray(kp, float), np.asarray(kd, float), np.asarray(psi, float))
        jx, jy, jz = case.inertia
        self.euler = ((jy - jz) / jx, (jz - jx) / jy, (jx - jy) / jz)
        self.m_over_j = (case.m_max / jx, case.m_max / jy, case.m_max / jz)
        self.plane = case.orbit.plane_matrix().tolist()

    def set_cases(self, kp, kd, psi):
        self.kp, self.kd = kp / self.case.m_max, kd / self.case.m_max
        self.cpsi, self.spsi = np.cos(psi), np.sin(psi)

    def take(self, keep: np.ndarray):
        self.kp, self.kd, self.cpsi, self.spsi = self.kp[keep], self.kd[keep], self.cpsi[keep], self.spsi[keep]

    def __call__(self, t: float, x: np.ndarray, out: np.ndarray | None = None) -> np.ndarray:
        """``ẋ`` at ``t``, written into ``out`` when given (the work-array path of
        :func:`att_sim.models.dynamics.rk4`)."""
        case = self.case
        qx, qy, qz, qw, wx, wy, wz = x
        c, s = math.cos(self.n * t), math.sin(self.n * t)
        cu = c * self.cpsi - s * self.spsi
        su = s * self.cpsi + c * self.spsi
        r_hat = env.direction(case.orbit, cu, su, self.plane)
        bx, by, bz = env.dipole_field_components(case.orbit, r_hat, case.dipole.axis_at(t), case.dipole)
        # B_b = C(q) B_i = B − 2 q_w (q_v × B) + 2 q_v × (q_v × B)
        tx, ty, tz = 2.0 * (qy * bz - qz * by), 2.0 * (qz * bx - qx * bz), 2.0 * (qx * by - qy * bx)
        bx = bx - qw * tx + (qy * tz - qz * ty)
        by = by - qw * ty + (qz * tx - qx * tz)
        bz = bz - qw * tz + (qx * ty - qy * tx)
        # saturated demand  s = sat(B_b × (κ_p q_v + κ_d ω) / m*)
        ax, ay, az = self.kp * qx + self.kd * wx, self.kp * qy + self.kd * wy, self.kp * qz + self.kd * wz
        sx, sy, sz = by * az - bz * ay, bz * ax - bx * az, bx * ay - by * ax
        for v in (sx, sy, sz):
            np.minimum(np.maximum(v, -1.0, out=v), 1.0, out=v)
        # J ω̇ = −ω × Jω + m × B_b,  m × B_b = −m* (s × B_b)
        ex, ey, ez = self.euler
        gx, gy, gz = self.m_over_j
        out = np.empty_like(x) if out is None else out
        np.subtract(ex * wy * wz, gx * (sy * bz - sz * by), out=out[4])
        np.subtract(ey * wz * wx, gy * (sz * bx - sx * bz), out=out[5])
        np.subtract(ez * wx * wy, gz * (sx * by - sy * bx), out=out[6])
        # q̇_v = ½ (q_v × ω + q_w ω),  q̇_w = −½ q_vᵀ ω
        np.multiply(0.5, qy * wz - qz * wy + qw * wx, out=out[0])
        np.multiply(0.5, qz * wx - qx * wz + qw * wy, out=out[1])
        np.multiply(0.5, qx * wy - qy * wx + qw * wz, out=out[2])
        np.multiply(-0.5, qx * wx + qy * wy + qz * wz, out=out[3])
        return out


def _work(x: np.ndarray) -> tuple:
    """Work arrays of :func:`att_sim.models.dynamics.rk4` for the batch ``x``."""
    return tuple(np.empty_like(x) for _ in range(5))


def _step(model: _BatchModel, t: float, x: np.ndarray, dt: float, work: tuple) -> np.ndarray:
    """The batch advanced in place by one :func:`att_sim.models.dynamics.rk4` step, quaternions renormalised."""
    return dyn.renormalised(dyn.rk4(model, t, x, dt, work))


def propagate(case: MagnetorquerCase, kp, kd, h, t_end: float, dt: float) -> np.ndarray:
    """States ``(N, 7)`` ``[q, ω]`` at ``t_end`` of the batch closed loop (same step as the
    settling simulator); used to check it against :mod:`att_sim.models.dynamics`."""
    h = np.atleast_2d(np.asarray(h, float))
    q0, w0, psi = initial_states(h)
    n = h.shape[0]
    model = _BatchModel(case, np.broadcast_to(kp, (n,)).astype(float), np.broadcast_to(kd, (n,)).astype(float), psi)
    x = np.concatenate([q0, w0], 1).T.copy()
    work = _work(x)
    for k in range(int(round(t_end / dt))):
        _step(model, k * dt, x, dt, work)
    return x.T.copy()


class _SettlingBatch:
    """The cases of one :func:`simulate_settling` call: the ones still integrated (columns of
    ``x``, original indices ``alive``) with their last exit above ν and last loud time (s), the
    outcome of every case, and the group bookkeeping of the pruning (``stop_above``, ``race``)."""

    def __init__(self, case: MagnetorquerCase, settings: SimSettings, kp, kd, h: np.ndarray, group, stop_above):
        n_cases = h.shape[0]
        q0, w0, psi = initial_states(h)
        self.case, self.settings, self.period = case, settings, case.period
        self.group = np.unique(np.arange(n_cases) if group is None else np.asarray(group),
                               return_inverse=True)[1].ravel()
        n_groups = int(self.group.max()) + 1 if n_cases else 0
        self.group_left = np.bincount(self.group, minlength=n_groups)    # cases not yet settled
        self.group_max = np.zeros(n_groups)           # latest exit of the settled cases (s)
        self.group_out = np.zeros(n_groups, bool)     # pruned: no longer a candidate
        self.incumbent = np.inf                       # best complete group (s), race only
        self.bound = np.full(n_cases, np.inf) if stop_above is None else np.broadcast_to(
            np.asarray(stop_above, float), (n_cases,)).astype(float) * self.period
        self.ts = np.zeros(n_cases)
        self.status = np.full(n_cases, CAPPED)
        self.alive = np.arange(n_cases)
        self.x = np.concatenate([q0, w0], 1).T.copy()     # (7, N)
        self.last_exit = np.where(np.any(np.abs(q0[:, :3]) > case.nu, 1), 0.0, -np.inf)
        self.last_loud = np.zeros(n_cases)
        self.model = _BatchModel(case, kp, kd, psi)
        self.work = _work(self.x)

    def _close(self, which: np.ndarray, status: int):
        """Record the live cases ``which`` (mask) as ``status`` with their last exit as ``t_s``."""
        self.status[self.alive[which]] = status
        self.ts[self.alive[which]] = np.maximum(self.last_exit[which], 0.0) / self.period

    def prune(self, t: float, exceeding: np.ndarray) -> np.ndarray:
        """Stop the cases still above ν after their bound (ABOVE) and the rest of their groups
        (DROPPED); returns the mask of the cases stopped."""
        above = exceeding & (t > np.minimum(self.bound, self.incumbent))
        done = above.copy()
        if above.any():
            self.status[self.alive[above]] = ABOVE
            self.ts[self.alive[above]] = t / self.period
            out_groups = np.unique(self.group[self.alive[above]])
            self.group_out[out_groups] = True
            drop = np.isin(self.group[self.alive], out_groups) & ~above
            self._close(drop, DROPPED)
            done |= drop
        return done

    def retire(self, t: float, qmax: np.ndarray, done: np.ndarray, race: bool) -> np.ndarray:
        """Confirm settled the cases quiet for ``quiet_orbits`` (see :class:`SimSettings`); in a
        race a group complete with them makes its worst case the incumbent. Returns their mask."""
        settings, x = self.settings, self.x
        loud = (qmax > settings.quiet_fraction * self.case.nu) | (
            np.einsum("ij,ij->j", x[4:], x[4:]) > settings.quiet_rate**2)
        self.last_loud[loud] = t
        quiet = ~done & (t - self.last_loud >= settings.quiet_orbits * self.period)
        self._close(quiet, SETTLED)
        if race and quiet.any():
            g = self.group[self.alive[quiet]]
            np.maximum.at(self.group_max, g, np.maximum(self.last_exit[quiet], 0.0))
            np.subtract.at(self.group_left, g, 1)
            complete = (self.group_left == 0) & ~self.group_out
            if complete.any():
                self.incumbent = min(self.incumbent, float(self.group_max[complete].min()))
        return quiet

    def keep(self, keep: np.ndarray):
        """Shrink the integrated batch to the cases ``keep`` (mask)."""
        self.alive, self.bound = self.alive[keep], self.bound[keep]
        self.x = np.ascontiguousarray(self.x[:, keep])   # x[:, mask] is column-major; the model works on rows
        self.last_exit, self.last_loud = self.last_exit[keep], self.last_loud[keep]
        self.model.take(keep)
        self.work = _work(self.x)

    def close_at_cap(self, t: float):
        """Cases still integrated at the cap: settled only if no exit above ν in the last quiet window."""
        if self.alive.size:
            ok = (t - self.last_exit) >= self.settings.quiet_orbits * self.period
            self._close(ok, SETTLED)
            self.ts[self.alive[~ok]] = self.settings.cap_orbits


def simulate_settling(case: MagnetorquerCase, kp, kd, h, settings: SimSettings = SimSettings(), *,
                      group=None, stop_above=None, race: bool = False) -> SettlingResult:
    """Settling times (orbits) of N cases ``(κ_p[j], κ_d[j], h[j])`` integrated together.

    ``kp``, ``kd`` broadcast against the N parameter rows ``h``. ``t_s`` is the last step time at
    which some ``|q_i| > ν`` (0 if never). ``stop_above`` (orbits, per case or per ``group``):
    a case still exceeding ν after that time cannot beat it, so it stops (ABOVE) and, when
    ``group`` labels are given, so does its whole group (DROPPED) — the pruning the min-max uses.
    ``race``: the groups compete for the smallest ``max t_s``; as soon as a group is complete its
    value becomes the bound for all the others (a minimisation needs nothing more of them).
    """
    start = time.perf_counter()
    h = np.atleast_2d(np.asarray(h, float))
    n_cases = h.shape[0]
    kp = np.broadcast_to(np.asarray(kp, float), (n_cases,)).copy()
    kd = np.broadcast_to(np.asarray(kd, float), (n_cases,)).copy()
    batch = _SettlingBatch(case, settings, kp, kd, h, group, stop_above)
    dt = float(settings.dt)
    n_steps = int(math.ceil(settings.cap_orbits * case.period / dt - 1e-9))
    check_every = max(1, int(round(settings.check_orbits * case.period / dt)))
    case_steps, t, step = 0, 0.0, 0
    for step in range(1, n_steps + 1):
        _step(batch.model, t, batch.x, dt, batch.work)
        t = step * dt
        case_steps += batch.x.shape[1]
        qmax = np.abs(batch.x[:3]).max(0)
        exceeding = qmax > case.nu
        batch.last_exit[exceeding] = t
        if step % check_every and step != n_steps:
            continue
        done = batch.prune(t, exceeding)
        if settings.retire:
            done |= batch.retire(t, qmax, done, race)
        if done.any():
            batch.keep(~done)
            if batch.alive.size == 0:
                break
    batch.close_at_cap(t)
    return SettlingResult(batch.ts, batch.status, case_steps, step, time.perf_counter() - start)


def truth_settling_time(case: MagnetorquerCase, kp: float, kd: float, h, *, dt: float = 1.0,
                        settings: SimSettings = SimSettings()) -> tuple[float, int]:
    """Settling time (orbits) and status of one case through the simulator's truth path.

    :func:`att_sim.models.dynamics.step` like the simulator node: the dipole ``m`` of
    :func:`att_planner.control.magnetorquer.dipole_command` (from the field at the step's start, as a
    sampled controller sees it) held over the step, the field ``B_b`` of
    :func:`att_sim.models.environment.field_body` evaluated at every RK4 stage — none of the batch code. The
    same settling rule as :func:`simulate_settling` (cap, quiet window).
    """
    q0, w0, psi = initial_states(h)
    sc = dyn.Spacecraft(inertia=np.diag(case.inertia), dipole_max=case.m_max)
    x = dyn.initial_state(sc, q0[0], w0[0])
    period = case.period
    last_exit = 0.0 if np.any(np.abs(q0[0, :3]) > case.nu) else -np.inf
    last_loud, t = 0.0, 0.0
    quiet_q, quiet_time = settings.quiet_fraction * case.nu, settings.quiet_orbits * period
    def field(tt, s):
        return env.field_body(case.orbit, tt, s[:4], psi[0], case.dipole), None
    for k in range(1, int(math.ceil(settings.cap_orbits * period / dt)) + 1):
        m = dipole_command(x[:4], x[4:7], field(t, x)[0], kp, kd, case.m_max)
        x = dyn.step(sc, x, dyn.Inputs(dipole_B=m), dt, field, t)
        t = k * dt
        qmax = np.max(np.abs(x[:3]))
        if qmax > case.nu:
            last_exit = t
        if qmax > quiet_q or x[4:7] @ x[4:7] > settings.quiet_rate**2:
            last_loud = t
        if settings.retire and t - last_loud >= quiet_time:
            return max(last_exit, 0.0) / period, SETTLED
    if t - last_exit >= quiet_time:
        return max(last_exit, 0.0) / period, SETTLED
    return settings.cap_orbits, CAPPED
