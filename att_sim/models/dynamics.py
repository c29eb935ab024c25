"""Rigid-body attitude dynamics with reaction wheels, magnetorquers and external torques.

This is the truth model of the simulator *and* the model the planner uses to verify every plan.

State ``x = [q (4, xyzw body-to-inertial), omega (3, rad/s body), wheel_speed (N, rad/s)]``.
Momentum model (Olivares & Staffetti 2018, generalised to a mounting matrix ``G`` (3×N) whose
columns are the wheel spin axes in body axes)::

    H_b   = J ω + G I_w Ω                       (J: I_s, everything but the wheels' spin inertia;
                                                 Ω: wheel spin rates in inertial space)
    J ω̇  = −ω × (J ω + G I_w Ω) − G u + τ_ext   (u: wheel motor torques, reaction on the body −G u)
    I_w Ω̇ = u
    q̇    = ½ q ⊗ [ω, 0]

A wheel at its speed limit cannot accelerate further: the motor torque pushing it beyond
``wheel_speed_max`` is cut (the same thing a wheel drive does). The limit applies to the speed the
drive sees, the wheel's speed *relative to the body* ``Ω − Gᵀω`` (Basilisk's ``Omega`` and
``Omega_max`` are relative speeds too), not to the inertial spin rate ``Ω`` of the state.
``τ_ext`` adds the direct body torque input, magnetorquer torque ``m × B_b`` and the
environment's torques (gravity gradient, solar pressure, drag, residual dipole).

Integration: classic RK4 (:func:`rk4`, the suite's one Runge–Kutta step) with quaternion
renormalisation after every step, see :func:`step`. Actuator inputs are held over a step
(zero-order hold: that is what a sampled controller commands); the environment — the field in body
axes and the external torques — is a function of ``(t, x)`` evaluated at every RK4 stage
(:data:`StageEnvironment`), so a magnetorquer run is fourth-order accurate in the step. Holding the
field fixed in body axes over a step instead (``Inputs.field_body``, kept for callers that evaluate
it themselves) is only first-order accurate: the body turns under the held field.
"""
from __future__ import annotations

import functools
import hashlib
from collections.abc import Callable
from dataclasses import dataclass, field
from functools import cached_property
from operator import mul

import numpy as np

from att_msgs_py.types import ControlKind, Interpolation
from att_sim.models import rotations as rot


@dataclass(frozen=True)
class Spacecraft:
    """Mass properties and actuator limits (SI units)."""

    inertia: np.ndarray                                   # (3, 3) kg m², I_s (see module docstring)
    wheel_axes: np.ndarray = field(default_factory=lambda: np.eye(3))  # (3, N) unit spin axes
    wheel_inertia: float = 0.0                            # kg m² about each spin axis
    wheel_torque_max: float = np.inf                      # N m per wheel
    wheel_speed_max: float = np.inf                       # rad/s per wheel
    body_torque_max: float = np.inf                       # N m per body axis (direct torque input)
    dipole_max: float = np.inf                            # A m² per magnetorquer

    def __post_init__(self):
        object.__setattr__(self, "inertia", np.asarray(self.inertia, dtype=float).reshape(3, 3))
        axes = np.asarray(self.wheel_axes, dtype=float).reshape(3, -1)
        object.__setattr__(self, "wheel_axes", axes)

    @property
    def n_wheels(self) -> int:
        return self.wheel_axes.shape[1]

    @cached_property
    def inertia_inv(self) -> np.ndarray:
        return np.linalg.inv(self.inertia)

    @cached_property
    def rows(self) -> tuple[list, list, list]:
        """``(J, J⁻¹, G)`` as nested lists of Python floats (:func:`derivative`'s arithmetic)."""
        return self.inertia.tolist(), self.inertia_inv.tolist(), self.wheel_axes.tolist()

    @cached_property
    def wheel_axes_pinv(self) -> np.ndarray:
        """``G⁺`` (N, 3): the least-norm wheel quantities that produce a body vector."""
        return np.linalg.pinv(self.wheel_axes)

    @cached_property
    def digest(self) -> str:
        """SHA-256 (hex) of every physical parameter: a plan names the configuration it was made
        for by this, and a controller of another configuration refuses it."""
        h = hashlib.sha256(b"att_suite.spacecraft.v1")
        for a in (self.inertia, self.wheel_axes, self.wheel_inertia, self.wheel_torque_max, self.wheel_speed_max,
                  self.body_torque_max, self.dipole_max):
            a = np.ascontiguousarray(a, dtype="<f8")
            h.update(str(a.shape).encode() + a.tobytes())
        return h.hexdigest()


@dataclass
class Inputs:
    """Actuator inputs held over one integration step (zero-order hold). ``field_body`` and
    ``gravity_gradient`` are the held-environment form; a :data:`StageEnvironment` replaces both."""

    wheel_torque: np.ndarray | None = None   # (N,) motor torques u
    body_torque: np.ndarray | None = None    # (3,) direct body torque, body axes
    dipole: np.ndarray | None = None         # (3,) A m², body axes
    field_body: np.ndarray | None = None     # (3,) T, body axes (needed with dipole), held
    gravity_gradient: np.ndarray | None = None  # (3,) N m, body axes, precomputed, held
    wheel_drive: Callable | None = None      # (u, ν) -> net wheel torques at relative speeds ν (friction,
                                             # envelope: att_sim.truth.actuators.WheelDrive); None: ideal motors


StageEnvironment = Callable[[float, np.ndarray], tuple[np.ndarray, np.ndarray]]
"""``(t, x) -> (B_b, τ_env)``: the geomagnetic field in body axes (T) and the external environment
torque (N m, body axes) at one RK4 stage's time and state (e.g. :meth:`att_sim.models.world.Environment.stage`)."""


def initial_state(sc: Spacecraft, q=rot.IDENTITY, omega=(0.0, 0.0, 0.0), wheel_speed=None) -> np.ndarray:
    ws = np.zeros(sc.n_wheels) if wheel_speed is None else np.asarray(wheel_speed, float)
    return np.concatenate([rot.normalize(np.asarray(q, float)), np.asarray(omega, float), ws])


def relative_wheel_speed(sc: Spacecraft, wheel_speed: np.ndarray, omega: np.ndarray) -> np.ndarray:
    """The wheels' speeds relative to the body ``Ω − Gᵀω`` (rad/s): what a wheel drive measures and limits."""
    return np.asarray(wheel_speed, float) - sc.wheel_axes.T @ np.asarray(omega, float)


def relative_wheel_speeds(axes_T: np.ndarray, x: np.ndarray) -> np.ndarray:
    """:func:`relative_wheel_speed` of each row of states ``x`` (rows of [q, ω, Ω]); ``axes_T``: the
    wheels × 3 matrix ``Gᵀ`` of all rows, or one per row (stacked products: each row's bits alone)."""
    return x[:, 7:] - np.matmul(axes_T, x[:, 4:7, None])[:, :, 0]


def relative_speeds(G, w, ws) -> list:
    """``Ω − Gᵀω`` component by component (:func:`rates`' arithmetic): ``G`` rows of components,
    ``w`` the body rate's, ``ws`` the wheels'."""
    w0, w1, w2 = w
    return [s - (a * w0 + b * w1 + c * w2) for s, a, b, c in zip(ws, *G)]


def through_wheels(G, u) -> list:
    """``G u``, the body vector of wheel quantities ``u``, component by component."""
    return [sum(map(mul, row, u)) for row in G]


def effective_wheel_torque(sc: Spacecraft, wheel_speed: np.ndarray, u: np.ndarray, omega: np.ndarray) -> np.ndarray:
    """Clip motor torques to their limit and cut those that would push a wheel beyond
    ``wheel_speed_max`` *relative to the body* (``Ω − Gᵀω``, ``Ω`` the state's inertial spin rate,
    ``ω`` the body rate) further."""
    relative = relative_wheel_speed(sc, wheel_speed, omega)
    return np.array(_limited(sc, np.asarray(u, float).tolist(), relative.tolist()))


def _limited(sc: Spacecraft, u: list, relative: list) -> list:
    """Torques ``u`` clipped to the limit, those pushing a wheel at its limit speed ``relative``
    further cut (u ν > 0: the same sign, neither zero); Python floats."""
    limit, speed_max = sc.wheel_torque_max, sc.wheel_speed_max
    return [0.0 if abs(v) >= speed_max and u_k * v > 0 else u_k
            for u_k, v in zip((min(max(u_k, -limit), limit) for u_k in u), relative)]


def limited_runs(limit, speed_max, u: list, relative: list) -> list:
    """:func:`_limited` of several runs at once: ``u`` and ``relative`` one array of runs per wheel
    (the same operations, so the same bits run by run)."""
    clipped = (np.minimum(np.maximum(u_k, -limit), limit) for u_k in u)
    return [np.where((np.abs(v) >= speed_max) & (u_k * v > 0), 0.0, u_k) for u_k, v in zip(clipped, relative)]


def torque_sum(tau_body, dipole, field_b, tau_env) -> list:
    """``τ_body + m × B_b + τ_env`` component by component (each a Python float, or an array of
    runs); ``dipole`` / ``field_b`` / ``tau_env`` None: absent."""
    tau = [0.0, 0.0, 0.0] if tau_body is None else list(tau_body)
    if dipole is not None and field_b is not None:
        tau = [a + b for a, b in zip(tau, rot.cross_floats(dipole, field_b))]
    if tau_env is not None:
        tau = [a + b for a, b in zip(tau, tau_env)]
    return tau


def _floats(v):
    return None if v is None else np.asarray(v, float).tolist()


def external_torque(inputs: Inputs, stage: tuple | None = None) -> list:
    """Body torque ``τ_body + m × B_b + τ_env`` (N m, body axes; three Python floats): ``stage`` =
    ``(B_b, τ_env)`` of a :data:`StageEnvironment`, else the held ``inputs.field_body`` and
    ``inputs.gravity_gradient``."""
    field_b, tau_env = (inputs.field_body, inputs.gravity_gradient) if stage is None else stage
    return torque_sum(_floats(inputs.body_torque), _floats(inputs.dipole), _floats(field_b), _floats(tau_env))


def rk4_mean(t1, t2, t3, t4) -> list:
    """The RK4-weighted mean ``(a + 2b + 2c + d)/6`` of four stages' values, component by component."""
    return [(a + 2 * b + 2 * c + d) / 6.0 for a, b, c, d in zip(t1, t2, t3, t4)]


def mean_external_torque(inputs: Inputs, stages: list) -> np.ndarray:
    """The RK4-weighted mean of :func:`external_torque` over a step's four ``stages`` (N m, body
    axes): the body torque a step applied."""
    return np.array(rk4_mean(*(external_torque(inputs, s) for s in stages)))


def derivative(sc: Spacecraft, x: np.ndarray, inputs: Inputs, stage: tuple | None = None) -> np.ndarray:
    """Time derivative of one state for actuator inputs held constant (see module docstring);
    ``stage``: the environment ``(B_b, τ_env)`` at this state (:func:`external_torque`). Evaluated
    on Python floats: on 3-vectors numpy's cost is its per-call overhead (the simulator's hot path)."""
    u = inputs.wheel_torque
    return np.array(rates(sc.rows, sc.wheel_inertia, x[:4].tolist(), x[4:7].tolist(), x[7:].tolist(),
                          external_torque(inputs, stage), None if u is None else _floats(u),
                          lambda v, nu: _limited(sc, v, nu), inputs.wheel_drive, sc.wheel_inertia > 0))


def rates(rows: tuple, wheel_inertia, q, w, ws, torque, u, limited, drive, spinning: bool) -> list:
    """The state derivative component by component — each component a Python float (one run) or an
    array of runs, with the same operations either way: ``rows`` = (J, J⁻¹, G) nested sequences of
    such components, ``torque`` the external body torque, ``u`` the held motor torques (None: no
    motor input), ``limited(u, ν)`` the speed-limit cut (:func:`_limited`), ``drive(u, ν)`` the
    imperfect drives' net torques (None: ideal), ``spinning``: the wheels have inertia."""
    J, J_inv, G = rows
    w0, w1, w2 = w
    h = [r[0] * w0 + r[1] * w1 + r[2] * w2 for r in J]
    wheel_rates = [0.0] * len(ws)
    if ws:
        spin = [wheel_inertia * s for s in ws]
        h = [h_i + s for h_i, s in zip(h, through_wheels(G, spin))]
        if u is not None:
            relative = relative_speeds(G, w, ws)
            u = limited(u, relative)
            if drive is not None:
                u = drive(u, relative)
            torque = [t - g for t, g in zip(torque, through_wheels(G, u))]
            if spinning:
                wheel_rates = [u_k / wheel_inertia for u_k in u]
    net = [t - c for t, c in zip(torque, rot.cross_floats(w, h))]
    w_dot = [r[0] * net[0] + r[1] * net[1] + r[2] * net[2] for r in J_inv]
    return [*quaternion_rate(q, w), *w_dot, *wheel_rates]


def quaternion_rate(q, w) -> tuple:
    """``q̇ = ½ q ⊗ [ω, 0]`` component by component, for floats and CasADi scalars alike."""
    qx, qy, qz, qw = q
    wx, wy, wz = w
    return (0.5 * (qw * wx + qy * wz - qz * wy), 0.5 * (qw * wy + qz * wx - qx * wz),
            0.5 * (qw * wz + qx * wy - qy * wx), -0.5 * (qx * wx + qy * wy + qz * wz))


def rk4(f: Callable, t, x, dt, work: tuple | None = None):
    """One classic Runge–Kutta step of ``x' = f(t, x)``. Plain arithmetic on ``x``, so the same
    step serves numpy states, batches of states and CasADi expressions.

    ``work`` (numpy, large batches): five arrays shaped like ``x`` (``k1..k4`` and a stage state);
    ``f`` is then called as ``f(t, x, out)`` writing the derivative into ``out``, and ``x`` is
    advanced in place — the same operations, in the same order, without temporaries."""
    if work is None:
        k1 = f(t, x)
        k2 = f(t + 0.5 * dt, x + 0.5 * dt * k1)
        k3 = f(t + 0.5 * dt, x + 0.5 * dt * k2)
        k4 = f(t + dt, x + dt * k3)
        return x + dt / 6.0 * (k1 + 2 * k2 + 2 * k3 + k4)
    k1, k2, k3, k4, stage = work
    f(t, x, k1)
    f(t + 0.5 * dt, np.add(x, np.multiply(0.5 * dt, k1, out=stage), out=stage), k2)
    f(t + 0.5 * dt, np.add(x, np.multiply(0.5 * dt, k2, out=stage), out=stage), k3)
    f(t + dt, np.add(x, np.multiply(dt, k3, out=stage), out=stage), k4)
    total = np.add(k1, np.multiply(2, k2, out=k2), out=k2)
    total = np.add(total, np.multiply(2, k3, out=k3), out=k2)
    total = np.add(total, k4, out=k2)
    return np.add(x, np.multiply(dt / 6.0, total, out=k2), out=x)


def renormalised(x: np.ndarray) -> np.ndarray:
    """The state with its quaternion (first four rows) scaled back to unit norm, in place."""
    x[:4] /= np.linalg.norm(x[:4], axis=0)
    return x


def step(sc: Spacecraft, x: np.ndarray, inputs: Inputs, dt: float,
         environment: StageEnvironment | None = None, t: float = 0.0) -> np.ndarray:
    """Advance the state from time ``t`` by ``dt`` with the actuator inputs held (ZOH): RK4, then the
    quaternion renormalised. ``environment(t, x)`` is evaluated at each of the four stages (the
    stage's time and state); without it the field and torque held in ``inputs`` act over the step."""
    if environment is None:
        return renormalised(rk4(lambda _t, s: derivative(sc, s, inputs), t, x, dt))
    return renormalised(rk4(lambda tt, s: derivative(sc, s, inputs, environment(tt, s)), t, x, dt))


def angular_momentum_inertial(sc: Spacecraft, x: np.ndarray) -> np.ndarray:
    h_b = sc.inertia @ x[4:7] + sc.wheel_axes @ (sc.wheel_inertia * x[7:])
    return rot.dcm_NB(x[:4]) @ h_b


def kinetic_energy(sc: Spacecraft, x: np.ndarray) -> float:
    """Rotational kinetic energy ``½ ωᵀ J ω + ½ I_w |Ω|²`` of body and wheels (Ω measured in
    inertial space, as in the momentum model); conserved when no torque acts and motors are idle."""
    w, ws = x[4:7], x[7:]
    return 0.5 * w @ sc.inertia @ w + 0.5 * sc.wheel_inertia * ws @ ws


# ---------------------------------------------------------------------------------------------
# Profiles: integrate a sampled control history (used by plan verification and benchmarks)
# ---------------------------------------------------------------------------------------------

@dataclass
class Trajectory:
    t: np.ndarray          # (K,)
    q: np.ndarray          # (K, 4)
    omega: np.ndarray      # (K, 3)
    wheel_speed: np.ndarray  # (K, N)


STEPS_PER_CALL = 2048      # RK4 steps per call of the compiled body-torque stepper (a verification: one)


@functools.cache
def _body_torque_stepper():
    """``(x0, U, dU, h, p) -> X``: :data:`STEPS_PER_CALL` RK4 steps of the rigid body from ``x0`` = (q, ω)
    under the body torque ``U_i + dU_i τ`` (τ from the step's start: ZOH with ``dU = 0``, linear
    interpolation), step ``h_i`` (0: the state is kept), quaternion renormalised after each step, as
    :func:`step` does; ``p`` = (J, J⁻¹, G I_w Ω) column-major, the wheels' momentum constant (no motor
    torque). CasADi code, compiled once into the cache (:mod:`att_sim.models.codegen`)."""
    import casadi as ca

    from att_sim.models.codegen import compiled

    x, u, du, h, p = ca.SX.sym("x", 7), ca.SX.sym("u", 3), ca.SX.sym("du", 3), ca.SX.sym("h"), ca.SX.sym("p", 21)
    J, J_inv, h_wheels = ca.reshape(p[:9], 3, 3), ca.reshape(p[9:18], 3, 3), p[18:]

    def f(tau, s):
        w = s[4:]
        w_dot = ca.mtimes(J_inv, u + du * tau - ca.cross(w, ca.mtimes(J, w) + h_wheels))
        return ca.vertcat(*quaternion_rate(ca.vertsplit(s[:4]), ca.vertsplit(w)), w_dot)

    x_next = rk4(f, 0.0, x, h)
    steps = ca.Function("body_torque_step", [x, u, du, h, p], [ca.vertcat(x_next[:4] / ca.norm_2(x_next[:4]),
                                                                           x_next[4:])])
    steps = steps.mapaccum("body_torque_steps", STEPS_PER_CALL)
    xs, us, dus, hs, ps = (ca.MX.sym(n, k, m) for n, k, m in (("x", 7, 1), ("u", 3, STEPS_PER_CALL),
                                                               ("du", 3, STEPS_PER_CALL), ("h", 1, STEPS_PER_CALL),
                                                               ("p", 21, 1)))
    return compiled(ca.Function("body_torque_profile", [xs, us, dus, hs, ps],
                                [steps(xs, us, dus, hs, ca.repmat(ps, 1, STEPS_PER_CALL))]))


def _body_torque_steps(sc: Spacecraft, x0: np.ndarray, u: np.ndarray, du: np.ndarray, h: np.ndarray) -> np.ndarray:
    """The states (S, 7 + N) after each of the S steps ``(u_i, du_i, h_i)`` of the compiled stepper."""
    stepper = _body_torque_stepper()
    p = np.concatenate([sc.inertia.ravel("F"), sc.inertia_inv.ravel("F"),
                        sc.wheel_axes @ (sc.wheel_inertia * x0[7:]) if sc.n_wheels else np.zeros(3)])
    S = len(h)
    pad = -S % STEPS_PER_CALL
    u, du = (np.vstack([a, np.zeros((pad, 3))]).T for a in (u, du))
    h = np.concatenate([h, np.zeros(pad)])[None]
    x = x0[:7]
    out = []
    for k in range(0, S + pad, STEPS_PER_CALL):
        block = np.asarray(stepper(x, u[:, k:k + STEPS_PER_CALL], du[:, k:k + STEPS_PER_CALL],
                                   h[:, k:k + STEPS_PER_CALL], p))
        out.append(block.T)
        x = block[:, -1]
    states = np.concatenate(out)[:S]
    return np.hstack([states, np.broadcast_to(x0[7:], (S, len(x0) - 7))])


def simulate_profile(
    sc: Spacecraft,
    x0: np.ndarray,
    t_knots: np.ndarray,
    values: np.ndarray,
    *,
    kind: str = ControlKind.BODY_TORQUE,
    interpolation: str = Interpolation.ZOH,
    max_step: float | None = None,
    t_end: float | None = None,
) -> Trajectory:
    """Integrate a sampled control history through :func:`derivative`.

    ``kind`` is 'body_torque' (values are body torques, (K, 3)) or 'wheel_torque' (motor torques,
    (K, N)). ZOH profiles are integrated with steps aligned to the knots (exact input switching);
    each knot interval is split into substeps no longer than ``max_step`` (default: 1/400 of the
    duration; every interval gets at least one step). Returns the state at every substep. Body
    torques take the compiled stepper (:func:`_body_torque_stepper`: the same RK4 of the same
    equations, the wheels' momentum held, as :func:`step` without motor torques), motor torques
    :func:`step`'s loop.
    """
    t_knots = np.asarray(t_knots, float)
    values = np.asarray(values, float).reshape(len(t_knots), -1)
    t_end = t_knots[-1] if t_end is None else t_end
    grid = np.unique(np.concatenate([t_knots[t_knots <= t_end], [t_end]]))
    if max_step is None:
        dts = np.diff(grid)
        max_step = max((grid[-1] - grid[0]) / 400.0, 1e-6) if len(dts) else 1.0
    if interpolation not in tuple(Interpolation):
        raise ValueError(f"unknown interpolation '{interpolation}' (use 'zoh' or 'linear')")
    kind = str(ControlKind(kind))           # the Inputs field the values go to
    n = np.maximum(1, np.ceil(np.diff(grid) / max_step - 1e-9).astype(int))      # steps per knot interval
    h = np.repeat(np.diff(grid) / n, n)
    t0 = np.repeat(grid[:-1], n) + (np.arange(n.sum()) - np.repeat(np.cumsum(n) - n, n)) * h   # each step's start
    k = np.minimum(np.searchsorted(t_knots, np.repeat(grid[:-1], n), side="right") - 1, len(t_knots) - 1)
    slope = np.zeros((len(k), values.shape[1]))
    if interpolation == Interpolation.LINEAR:       # the input evaluated at the RK4 stage times
        inner = k + 1 < len(t_knots)
        slope[inner] = (values[k[inner] + 1] - values[k[inner]]) / (t_knots[k[inner] + 1] - t_knots[k[inner]])[:, None]
    u = values[k] + slope * (t0 - t_knots[k])[:, None]          # the input at each step's start
    x = np.array(x0, float)
    if kind == ControlKind.BODY_TORQUE:
        X = np.vstack([x, _body_torque_steps(sc, x, u, slope, h)])
    else:
        X = [x.copy()]
        for u_i, du_i, h_i in zip(u, slope, h):
            x = renormalised(rk4(lambda tau, s, u_i=u_i, du_i=du_i:
                                 derivative(sc, s, Inputs(**{kind: u_i + du_i * tau})), 0.0, x, h_i))
            X.append(x.copy())
        X = np.array(X)
    return Trajectory(np.concatenate([grid[:1], t0 + h]), X[:, :4], X[:, 4:7], X[:, 7:])
