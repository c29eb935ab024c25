"""Rigid-body attitude dynamics with reaction wheels, magnetorquers and external torques.

The one model of the motion, shared: the truth simulation integrates it with the dispersed spacecraft,
the planner's verification (its prediction model) with the nominal one.

Frames (Basilisk's names): N inertial, B body. State ``x = [q_BN (4, xyzw: B relative to N),
omega_BN_B (3, rad/s: rate of B relative to N in B axes), wheel_speed (N, rad/s: the wheels' spin
rates Ω in inertial space, one scalar per wheel about its spin axis)]``. Momentum model (Olivares &
Staffetti 2018, generalised to a mounting matrix ``G`` (3×N) whose columns are the wheel spin axes
in B axes; ``ω`` is ``omega_BN_B``)::

    h_B   = J ω + G I_w Ω                       (J: I_s about the centre of mass in B axes, everything
                                                 but the wheels' spin inertia)
    J ω̇  = −ω × (J ω + G I_w Ω) − G u + τ_B     (u: wheel motor torques, reaction on the body −G u)
    I_w Ω̇ = u
    q̇_BN = ½ q_BN ⊗ [ω, 0]

A wheel at its speed limit cannot accelerate further: the motor torque pushing it beyond
``wheel_speed_max`` is cut (the same thing a wheel drive does). The limit applies to the speed the
drive sees, the wheel's speed *relative to the body* ``Ω − Gᵀω`` (Basilisk's ``Omega`` and
``Omega_max`` are relative speeds too), not to the inertial spin rate ``Ω`` of the state.
``τ_B`` (B axes) adds the direct body torque input, magnetorquer torque ``m_B × B_B`` and the
environment's torques (gravity gradient, solar pressure, drag, residual dipole).

Integration: classic RK4 (:func:`rk4`, the suite's one Runge–Kutta step) with quaternion
renormalisation after every step, see :func:`step`. Actuator inputs are held over a step
(zero-order hold: that is what a sampled controller commands); the environment — the field in B
axes and the external torques — is a function of ``(t, x)`` evaluated at every RK4 stage
(:data:`StageEnvironment`), so a magnetorquer run is fourth-order accurate in the step. Holding the
field fixed in B axes over a step instead (``Inputs.field_B``, for callers that evaluate the field
themselves) is only first-order accurate: the body turns under the held field.

Every function works on a leading run axis: the states of n spacecraft as rows (n, 7 + N) and their
parameters stacked (:class:`SpacecraftStack`; n = 1 for one simulation, n runs for a Monte Carlo
batch, :mod:`att_sim.truth.batch`), each run's row computed by the same operations whatever n is.
"""
from __future__ import annotations

import functools
import hashlib
from collections.abc import Callable
from dataclasses import dataclass, field
from functools import cached_property

import numpy as np

from att_msgs_py.types import ControlKind, Interpolation
from att_sim.models import rotations as rot


@dataclass(frozen=True)
class Spacecraft:
    """Mass properties and actuator limits (SI units), in body (B) axes: the spacecraft file's values
    (its keys carry their units, :func:`att_sim.models.scenario.spacecraft_from_model`). ``inertia``
    is ``J`` (= I_s, see the module docstring) about the centre of mass in B axes, ``wheel_axes`` the
    mounting matrix ``G`` whose columns are the wheels' unit spin axes in B axes, ``body_torque_max``
    the direct torque limit per B axis."""

    inertia: np.ndarray                                   # (3, 3) kg m², J about the centre of mass, B axes
    wheel_axes: np.ndarray = field(default_factory=lambda: np.eye(3))  # (3, N) unit spin axes in B axes, G
    wheel_inertia: float = 0.0                            # kg m² about each spin axis
    wheel_torque_max: float = np.inf                      # N m per wheel
    wheel_speed_max: float = np.inf                       # rad/s per wheel
    body_torque_max: float = np.inf                       # N m per B axis (direct torque input)
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
    def stacked(self) -> SpacecraftStack:
        """This spacecraft as a :class:`SpacecraftStack` of one (n = 1: :func:`rates`' run axis)."""
        return stack([self])

    @cached_property
    def wheel_axes_pinv(self) -> np.ndarray:
        """``G⁺`` (N, 3): the least-norm wheel quantities that produce a vector in B axes."""
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


@dataclass(frozen=True, eq=False)
class SpacecraftStack:
    """The parameters of n spacecraft with the same number of wheels N on a leading run axis (the
    runs of a batch; n = 1: one spacecraft): the arrays :func:`rates` works on. Limits are columns
    (n, 1), so they broadcast over the wheels or axes of each row. Frames as in :class:`Spacecraft`
    (B axes), whose field names these are."""

    inertia: np.ndarray            # (n, 3, 3) kg m², J about the centre of mass, B axes
    inertia_inv: np.ndarray        # (n, 3, 3)
    wheel_axes: np.ndarray         # (n, 3, N) G, spin axes in B axes
    wheel_inertia: np.ndarray      # (n, 1) kg m², I_w
    wheel_torque_max: np.ndarray   # (n, 1) N m
    wheel_speed_max: np.ndarray    # (n, 1) rad/s
    body_torque_max: np.ndarray    # (n, 1) N m
    dipole_max: np.ndarray         # (n, 1) A m²
    momentum_map: np.ndarray       # (n, 3, 3 + N): h_B = [J, I_w G] [omega_BN_B; Ω]
    spinning: bool                 # the wheels have inertia (all rows alike)

    @property
    def n(self) -> int:
        return len(self.inertia)

    @property
    def n_wheels(self) -> int:
        return self.wheel_axes.shape[2]


def stack(spacecraft: list[Spacecraft]) -> SpacecraftStack:
    """The :class:`SpacecraftStack` of ``spacecraft`` (ValueError unless they have the same number of
    wheels, and all spinning wheels or none)."""
    if not spacecraft:
        raise ValueError("a stack needs at least one spacecraft")
    if len({sc.n_wheels for sc in spacecraft}) != 1 or len({sc.wheel_inertia > 0 for sc in spacecraft}) != 1:
        raise ValueError("stacked spacecraft share their number of wheels, and have all spinning wheels or none")
    G = np.array([sc.wheel_axes for sc in spacecraft])
    J = np.array([sc.inertia for sc in spacecraft])

    def column(name):
        return np.array([[float(getattr(sc, name))] for sc in spacecraft])
    wheel_inertia = column("wheel_inertia")
    return SpacecraftStack(J, np.array([sc.inertia_inv for sc in spacecraft]), G, wheel_inertia,
                           column("wheel_torque_max"), column("wheel_speed_max"), column("body_torque_max"),
                           column("dipole_max"), np.concatenate([J, wheel_inertia[:, :, None] * G], axis=2),
                           spacecraft[0].wheel_inertia > 0)


@dataclass
class Inputs:
    """Actuator inputs held over one integration step (zero-order hold), one row per run (or one
    vector (a run of one). ``field_B`` and ``gravity_gradient_B`` are the held-environment form; a
    :data:`StageEnvironment` replaces both."""

    wheel_torque: np.ndarray | None = None   # (n, N) motor torques u, one scalar per wheel
    torque_B: np.ndarray | None = None       # (n, 3) N m, direct body torque, B axes
    dipole_B: np.ndarray | None = None       # (n, 3) A m², magnetorquer dipole, B axes
    field_B: np.ndarray | None = None        # (n, 3) T, geomagnetic field, B axes (needed with dipole_B), held
    gravity_gradient_B: np.ndarray | None = None  # (n, 3) N m, environment torque, B axes, precomputed, held
    wheel_drive: Callable | None = None      # (u, ν) -> net wheel torques at relative speeds ν, rows (friction,
                                             # envelope: att_sim.truth.actuators.WheelDrive); None: ideal motors


StageEnvironment = Callable[[float, np.ndarray], tuple[np.ndarray, np.ndarray | None]]
"""``(t, x) -> (B_B, τ_env_B)``: the geomagnetic field in B axes (T) and the external environment
torque (N m, B axes; None: none) at one RK4 stage's time and states (rows, e.g.
:meth:`att_sim.models.world.Environment.stage`)."""


def initial_state(sc: Spacecraft, q_BN=rot.IDENTITY, omega_BN_B=(0.0, 0.0, 0.0), wheel_speed=None) -> np.ndarray:
    """The state ``[q_BN, omega_BN_B, wheel_speed]`` (7 + N,): the attitude normalised, the wheels'
    inertial spin rates ``Ω`` (rad/s; None: at rest in inertial space)."""
    ws = np.zeros(sc.n_wheels) if wheel_speed is None else np.asarray(wheel_speed, float)
    return np.concatenate([rot.normalize(np.asarray(q_BN, float)), np.asarray(omega_BN_B, float), ws])


def relative_wheel_speed(sc: Spacecraft | SpacecraftStack, wheel_speed: np.ndarray,
                         omega_BN_B: np.ndarray) -> np.ndarray:
    """The wheels' speeds relative to the body ``Ω − Gᵀω`` (rad/s; ``Ω`` the inertial spin rates
    ``wheel_speed``, ``ω`` = ``omega_BN_B``): what a wheel drive measures and limits. One
    spacecraft's vectors, or rows of runs (``omega_BN_B`` (n, 3), ``wheel_speed`` (n, N)) of one
    spacecraft or of a :class:`SpacecraftStack`."""
    omega_BN_B = np.asarray(omega_BN_B, float)
    return np.asarray(wheel_speed, float) - (omega_BN_B[..., None, :] @ sc.wheel_axes)[..., 0, :]


def limited(sc: Spacecraft | SpacecraftStack, u: np.ndarray, relative: np.ndarray) -> np.ndarray:
    """Motor torques ``u`` clipped to ``wheel_torque_max``, those that would push a wheel at its
    limit speed (``|ν| ≥ wheel_speed_max`` for the relative speed ``ν``) further cut (``u ν > 0``)."""
    limit, speed_max = sc.wheel_torque_max, sc.wheel_speed_max
    u = np.minimum(np.maximum(u, -limit), limit)
    return np.where((np.abs(relative) >= speed_max) & (u * relative > 0), 0.0, u)


def effective_wheel_torque(sc: Spacecraft | SpacecraftStack, wheel_speed: np.ndarray, u: np.ndarray,
                           omega_BN_B: np.ndarray) -> np.ndarray:
    """:func:`limited` at the state's relative wheel speeds ``Ω − Gᵀω`` (``Ω`` the state's inertial
    spin rates, ``ω`` = ``omega_BN_B`` the body rate): vectors of one spacecraft or rows of runs."""
    return limited(sc, np.asarray(u, float), relative_wheel_speed(sc, wheel_speed, omega_BN_B))


def external_torque(inputs: Inputs, stage: tuple | None = None) -> np.ndarray:
    """The external torque ``τ_B = torque_B + m_B × B_B + τ_env_B`` (N m, B axes; rows, or (3,) when
    every input is one vector): ``stage`` = ``(B_B, τ_env_B)`` of a :data:`StageEnvironment`, else the
    held ``inputs.field_B`` and ``inputs.gravity_gradient_B``."""
    field_B, tau_env_B = (inputs.field_B, inputs.gravity_gradient_B) if stage is None else stage
    tau = _ZERO3 if inputs.torque_B is None else inputs.torque_B
    if inputs.dipole_B is not None and field_B is not None:
        tau = tau + rot.cross(inputs.dipole_B, field_B)
    return tau if tau_env_B is None else tau + tau_env_B


_ZERO3 = np.zeros(3)


def rk4_mean(k1, k2, k3, k4) -> np.ndarray:
    """The RK4-weighted mean ``(a + 2b + 2c + d)/6`` of four stages' values."""
    return (k1 + 2 * k2 + 2 * k3 + k4) / 6.0


def rates(sc: SpacecraftStack, x: np.ndarray, torque_B: np.ndarray, u: np.ndarray | None = None,
          drive: Callable | None = None) -> np.ndarray:
    """Time derivative of the states ``x`` (n, 7 + N), one row per spacecraft of the stack, for
    inputs held constant (see module docstring): ``torque_B`` the external torque in B axes (rows, or
    one (3,) for all), ``u`` the held motor torques (n, N) (None: no motor input), cut at the speed
    limit (:func:`limited`) and, with ``drive(u, ν)``, made the imperfect drives' net torques."""
    out = np.empty_like(x)
    w = x[:, 4:7]
    if len(x) == 1:                 # one run: the same formula on Python floats (the same bits, cheaper)
        out[0, :4] = quaternion_rate(x[0, :4].tolist(), x[0, 4:7].tolist())
    else:
        out.T[:4] = quaternion_rate(x.T[:4], w.T)
    h = (sc.momentum_map @ x[:, 4:, None])[:, :, 0]
    if u is not None and sc.n_wheels:
        relative = relative_wheel_speed(sc, x[:, 7:], w)
        u = limited(sc, u, relative)
        if drive is not None:
            u = drive(u, relative)
        torque_B = torque_B - (sc.wheel_axes @ u[:, :, None])[:, :, 0]
        out[:, 7:] = u / sc.wheel_inertia if sc.spinning else 0.0
    else:
        out[:, 7:] = 0.0
    out[:, 4:7] = (sc.inertia_inv @ (torque_B - rot.cross(w, h))[:, :, None])[:, :, 0]
    return out


def derivative(sc: Spacecraft | SpacecraftStack, x: np.ndarray, inputs: Inputs,
               stage: tuple | None = None) -> np.ndarray:
    """:func:`rates` of one spacecraft's state (7 + N,) or of a stack's rows, the inputs' ``wheel_torque``
    one vector or rows; ``stage``: the environment ``(B_B, τ_env_B)`` there (:func:`external_torque`)."""
    x = np.asarray(x, float)
    u = inputs.wheel_torque
    if u is not None:
        u = np.asarray(u, float)
        u = u if u.ndim == 2 else u[None]
    out = rates(sc.stacked if isinstance(sc, Spacecraft) else sc, x if x.ndim == 2 else x[None],
                external_torque(inputs, stage), u, inputs.wheel_drive)
    return out if x.ndim == 2 else out[0]


def quaternion_rate(q_BN, omega_BN_B) -> tuple:
    """``q̇_BN = ½ q_BN ⊗ [omega_BN_B, 0]`` component by component, for floats, arrays of runs and CasADi
    scalars alike."""
    qx, qy, qz, qw = q_BN
    wx, wy, wz = omega_BN_B
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
    """The state with its quaternion (first four entries; of each column of states whose components
    are rows, e.g. the transpose of rows of runs) scaled back to unit norm, in place."""
    x[:4] /= np.linalg.norm(x[:4], axis=0)
    return x


def step(sc: Spacecraft | SpacecraftStack, x: np.ndarray, inputs: Inputs, dt: float,
         environment: StageEnvironment | None = None, t: float = 0.0) -> np.ndarray:
    """Advance the state (or the rows of a stack's states) from time ``t`` by ``dt`` with the actuator
    inputs held (ZOH): RK4, then the quaternions renormalised. ``environment(t, x)`` is evaluated at
    each of the four stages (the stage's time and states); without it the field and torque held in
    ``inputs`` act over the step."""
    if environment is None:
        x_new = rk4(lambda _t, s: derivative(sc, s, inputs), t, x, dt)
    else:
        x_new = rk4(lambda tt, s: derivative(sc, s, inputs, environment(tt, s)), t, x, dt)
    renormalised(x_new.T)
    return x_new


def angular_momentum_N(sc: Spacecraft, x: np.ndarray) -> np.ndarray:
    """``h_N = [NB] h_B``, ``h_B = J omega_BN_B + G I_w Ω``: the angular momentum of body and wheels in
    N axes (N m s), conserved when no external torque acts."""
    h_B = sc.inertia @ x[4:7] + sc.wheel_axes @ (sc.wheel_inertia * x[7:])
    return rot.dcm_NB(x[:4]) @ h_B


def kinetic_energy(sc: Spacecraft, x: np.ndarray) -> float:
    """Rotational kinetic energy ``½ ωᵀ J ω + ½ I_w |Ω|²`` of body and wheels (``ω`` = ``omega_BN_B``,
    Ω measured in inertial space, as in the momentum model); conserved when no torque acts and motors
    are idle."""
    w, ws = x[4:7], x[7:]
    return 0.5 * w @ sc.inertia @ w + 0.5 * sc.wheel_inertia * ws @ ws


# ---------------------------------------------------------------------------------------------
# Profiles: integrate a sampled control history (used by plan verification and benchmarks)
# ---------------------------------------------------------------------------------------------

@dataclass
class Trajectory:
    """The states along an integrated profile, one row per time."""

    t: np.ndarray            # (K,) s
    q_BN: np.ndarray         # (K, 4) attitude of B relative to N, xyzw
    omega_BN_B: np.ndarray   # (K, 3) rad/s, rate of B relative to N in B axes
    wheel_speed: np.ndarray  # (K, N) rad/s, the wheels' inertial spin rates Ω


STEPS_PER_CALL = 2048      # RK4 steps per call of the compiled body-torque stepper (a verification: one)


@functools.cache
def _body_torque_stepper():
    """``(x0, U, dU, h, p) -> X``: :data:`STEPS_PER_CALL` RK4 steps of the rigid body from ``x0`` =
    (q_BN, omega_BN_B) under the body torque (B axes) ``U_i + dU_i τ`` (τ from the step's start: ZOH
    with ``dU = 0``, linear interpolation), step ``h_i`` (0: the state is kept), quaternion
    renormalised after each step, as :func:`step` does; ``p`` = (J, J⁻¹, G I_w Ω) column-major, the
    wheels' momentum constant (no motor torque). CasADi code, compiled once into the cache
    (:mod:`att_sim.models.codegen`)."""
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

    ``kind`` is 'body_torque' (values are body torques in B axes, (K, 3)) or 'wheel_torque' (motor
    torques, (K, N)). ZOH profiles are integrated with steps aligned to the knots (exact input switching);
    each knot interval is split into substeps no longer than ``max_step`` (default: 1/400 of the
    duration; every interval gets at least one step). Returns the state at every substep. Body
    torques take the compiled stepper (:func:`_body_torque_stepper`: the same RK4 of the same
    equations, the wheels' momentum held, as :func:`step` without motor torques), motor torques
    :func:`rk4` of :func:`rates` on a row of one.
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
    kind = str(ControlKind(kind))           # body torques (B axes) or motor torques
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
        stack, row, u, slope = sc.stacked, x[None], u[:, None], slope[:, None]      # motor torques: rows of one
        X = [x]
        for u_i, du_i, h_i in zip(u, slope, h):
            row = rk4(lambda tau, s, u_i=u_i, du_i=du_i: rates(stack, s, _ZERO3, u_i + du_i * tau), 0.0, row, h_i)
            renormalised(row.T)
            X.append(row[0])
        X = np.array(X)
    return Trajectory(np.concatenate([grid[:1], t0 + h]), X[:, :4], X[:, 4:7], X[:, 7:])
