"""Safe mode among the zones (no ROS, pure): the laws that bring the body to rest and to the Sun
without turning a sensor into its keep-out zone.

Each function is a pure function of its arguments; :class:`att_planner.fdir.recovery.SafeActuator`
keeps the little state the flight needs (the momentum at entry, the Sun attitude chosen) and calls
them at each control step. The zones are those of :mod:`att_planner.zones`: zone ``z`` has a body
sensor axis ``s_z``, an inertial axis ``a_z`` and a half-angle ``θ_z``; with the boresight
``b = [NB] s_z`` and ``γ = angle(b, a_z)`` its margin is ``γ − θ_z`` (keep-out) or ``θ_z − γ``
(keep-in), rad, ≥ 0 clear.

* **Rate without the gyro** (:func:`rate_from_momentum`): the angular momentum of body and wheels
  ``H_N = [NB](J ω + G I_w Ω)`` is constant without external torque, so with the wheels' speeds
  (their tachometers) and the attitude (the star trackers) the body rate is
  ``ω = J⁻¹([BN] H_N − G I_w Ω)``; ``H_N`` is taken once at the entry (:func:`momentum_N`).
  External torques (gravity gradient, drag, a few 10⁻⁵ N m) make it drift by their impulse.
* **The zone barrier** (:func:`barrier_torque`): a braking curve on each margin. The rotation that
  opens the margin of zone ``z`` is about ``u = ∓(b × a)/|b × a|`` (keep-out: −, keep-in: +); the
  margin rate is ``ṁ = ω·u`` (inertial axes). With ``α`` the angular acceleration the wheels give about
  ``u`` (``torque_max / |J u|``, halved for margin), the margin stops before the boundary's
  ``buffer`` as long as ``ṁ ≥ −√(2 α (m − buffer))``; inside the buffer the curve asks for opening
  (``ṁ ≥ rate_out · (buffer − m)/buffer``). Below the curve the barrier asks the acceleration
  ``gain · (ṁ_min − ṁ)`` about ``u`` (torque ``J u``·that), and the nominal law's torque against ``u`` is
  dropped (a safety filter in the spirit of control barrier functions: Ames et al. 2019; the braking
  curve is the velocity bound of a double integrator, as in Wie, *Space Vehicle Dynamics and
  Control*, 2008, §7.3 for constrained reorientation).
* **The Sun attitude** (:func:`sun_attitudes`, :func:`choose_sun_attitude`): body axis ``sun_axis_B``
  on the Sun leaves one rotation ``ψ`` about the Sun line free; it is chosen among ``count``
  candidates so that the worst margin over the zones' motion for the hold (samples of their axes,
  Earth limb included) and along the eigenaxis approach from the present attitude is the largest,
  the smallest rotation among those clear by ``buffer``.
* **The approach** (:func:`approach_torque`): ``τ = −K_d (ω − ω_ref)``, ``ω_ref = −(K_p/K_d) φ``
  limited to ``rate_max`` (``φ`` the rotation vector of the body relative to the target, body axes):
  the PD law about the target with the eigenaxis rate bounded, so that the barrier can always brake
  the body before a zone.
"""
from __future__ import annotations

import numpy as np

from att_sim.models import rotations as rot

BUFFER_RAD = np.radians(1.0)            # rad: margin the barrier keeps from each zone boundary
RATE_OUT_RAD_S = np.radians(0.05)       # rad/s: opening rate the barrier asks for at the boundary
BARRIER_GAIN_S = 0.5                    # 1/s: acceleration asked per rad/s below the braking curve
AUTHORITY_SHARE = 0.5                   # share of the wheels' acceleration the braking curve counts on
SLEW_RATE_RAD_S = np.radians(0.2)       # rad/s: largest eigenaxis rate of the approach to the Sun
RATE_DAMPED_RAD_S = np.radians(0.02)    # rad/s: the rate below which the Sun attitude is chosen
SUN_CANDIDATES = 72                     # rotations about the Sun line tried (5 deg apart)
PATH_POINTS = 33                        # attitudes checked along the approach


def momentum_N(q_BN, omega_BN_B, inertia_B, h_wheels_B) -> np.ndarray:
    """``H_N = [NB](J ω + h_w)`` (N m s), the angular momentum of body and wheels in inertial axes."""
    J = np.asarray(inertia_B, float).reshape(3, 3)
    return rot.dcm_NB(np.asarray(q_BN, float)) @ (J @ np.asarray(omega_BN_B, float) + np.asarray(h_wheels_B, float))


def rate_from_momentum(q_BN, momentum_N_Nms, inertia_B, h_wheels_B) -> np.ndarray:
    """``ω_BN_B = J⁻¹([BN] H_N − h_w)`` (rad/s): the body rate the momentum leaves to the body."""
    J = np.asarray(inertia_B, float).reshape(3, 3)
    H_B = rot.dcm_BN(np.asarray(q_BN, float)) @ np.asarray(momentum_N_Nms, float)
    return np.linalg.solve(J, H_B - np.asarray(h_wheels_B, float))


def torque_authority(wheel_axes, wheel_torque_max_Nm: float) -> float:
    """A body torque norm (N m) the wheels ``wheel_axes`` (3 x N, the healthy ones) give in any direction
    within ``wheel_torque_max_Nm`` each: ``T sigma_min(G)`` (the least-norm allocation ``G+ tau`` has
    ``|G+ tau|_inf <= |tau| / sigma_min``); 0 when they do not span the body."""
    G = np.asarray(wheel_axes, float).reshape(3, -1)
    if G.shape[1] < 3:
        return 0.0
    return float(wheel_torque_max_Nm * np.linalg.svd(G, compute_uv=False)[-1])


def margins(q_BN, sensor_axes_B, axes_N, half_angles, keep_in) -> np.ndarray:
    """Margins (rad, ≥ 0 clear) of the attitude(s) ``q_BN`` ((4,) or (K, 4)) to the zones: sensor axes
    (Z, 3), inertial axes ((Z, 3) or (K, Z, 3)), half-angles ((Z,) or (K, Z)), keep-in flags (Z,)."""
    q = np.asarray(q_BN, float)
    s = np.asarray(sensor_axes_B, float).reshape(-1, 3)
    s = s / np.linalg.norm(s, axis=-1, keepdims=True)
    a = np.asarray(axes_N, float)
    a = a / np.linalg.norm(a, axis=-1, keepdims=True)
    b = np.einsum("...ij,zj->...zi", rot.dcm_NB(q), s)                 # (..., Z, 3) boresights
    gamma = np.arccos(np.clip(np.sum(b * a, axis=-1), -1.0, 1.0))
    m = gamma - np.asarray(half_angles, float)
    return np.where(np.asarray(keep_in, bool), -m, m)


def barrier_torque(q_BN, omega_BN_B, nominal_torque_B, sensor_axes_B, axes_N, half_angles, keep_in, inertia_B,
                   torque_max_Nm: float, drift_rad_s=None, buffer_rad: float = BUFFER_RAD,
                   rate_out_rad_s: float = RATE_OUT_RAD_S, gain_s: float = BARRIER_GAIN_S
                   ) -> tuple[np.ndarray, np.ndarray]:
    """The nominal body torque filtered by the zone barrier (module docstring): the torque (N m, body
    axes, scaled as a whole to the norm ``torque_max_Nm``, a torque the healthy wheels give in any
    direction: :func:`torque_authority`) and a flag per zone (Z,) whether its barrier acts.
    ``drift_rad_s`` (Z,): each margin's rate at a fixed attitude, the zones' own motion (the Earth limb
    turning with the orbit; None: zones at rest), added to the margin rate the body's turn makes."""
    J = np.asarray(inertia_B, float).reshape(3, 3)
    R = rot.dcm_NB(np.asarray(q_BN, float))
    omega_N = R @ np.asarray(omega_BN_B, float)
    tau = np.asarray(nominal_torque_B, float).copy()
    s = np.asarray(sensor_axes_B, float).reshape(-1, 3)
    a = np.asarray(axes_N, float).reshape(-1, 3)
    m = margins(q_BN, s, a, half_angles, keep_in)
    keep_in = np.asarray(keep_in, bool).reshape(-1)
    drift = np.zeros(len(m)) if drift_rad_s is None else np.asarray(drift_rad_s, float).reshape(-1)
    push, active = np.zeros(3), np.zeros(len(m), bool)
    for z in range(len(m)):
        b = R @ (s[z] / np.linalg.norm(s[z]))
        n = np.cross(b, a[z] / np.linalg.norm(a[z]))
        if np.linalg.norm(n) < 1e-9:      # on the axis: any rotation normal to the boresight opens (closes) it
            n = np.cross(b, rot.orthonormal_basis(b)[0])
        u_N = (n if keep_in[z] else -n) / np.linalg.norm(n)
        u_B = R.T @ u_N
        alpha = AUTHORITY_SHARE * torque_max_Nm / np.linalg.norm(J @ u_B)
        rate = float(omega_N @ u_N) + float(drift[z])
        floor = (-np.sqrt(2.0 * alpha * (m[z] - buffer_rad)) if m[z] >= buffer_rad
                 else rate_out_rad_s * min(1.0, (buffer_rad - m[z]) / buffer_rad))
        if rate >= floor:
            continue
        active[z] = True
        against = float(tau @ u_B)
        if against < 0.0:
            tau -= against * u_B
        push += J @ u_B * (gain_s * (floor - rate))
    tau = tau + push
    norm = float(np.linalg.norm(tau))
    return (tau * (torque_max_Nm / norm) if norm > torque_max_Nm else tau), active


def sun_attitudes(sun_N, sun_axis_B, count: int = SUN_CANDIDATES) -> np.ndarray:
    """``count`` attitudes ``q_BN`` (count, 4) with body axis ``sun_axis_B`` on ``sun_N``, the rotation
    about the Sun line ``ψ = 2πk/count``."""
    if count < 1:
        raise ValueError(f"count = {count} attitudes: expected at least 1")
    s_N = np.asarray(sun_N, float)
    s_B = np.asarray(sun_axis_B, float)
    if not (np.linalg.norm(s_N) > 0 and np.linalg.norm(s_B) > 0):
        raise ValueError(f"sun_N = {s_N} and sun_axis_B = {s_B}: expected non-zero vectors")
    s_N, s_B = s_N / np.linalg.norm(s_N), s_B / np.linalg.norm(s_B)
    p_B = rot.orthonormal_basis(s_B)[0]
    body = np.column_stack([s_B, p_B, np.cross(s_B, p_B)])
    e1, e2 = rot.orthonormal_basis(s_N)
    out = np.empty((count, 4))
    for k, psi in enumerate(2.0 * np.pi * np.arange(count) / count):
        p_N = np.cos(psi) * e1 + np.sin(psi) * e2
        out[k] = rot.from_dcm_NB(np.column_stack([s_N, p_N, np.cross(s_N, p_N)]) @ body.T)
    return out


def choose_sun_attitude(q_BN, candidates, sensor_axes_B, path_axes_N, path_half_angles, hold_axes_N,
                        hold_half_angles, keep_in, buffer_rad: float = BUFFER_RAD,
                        path_points: int = PATH_POINTS) -> tuple[np.ndarray, float]:
    """The candidate (4,) the body goes to from ``q_BN`` and its worst margin (rad): along the eigenaxis
    path (``path_points`` attitudes, the zones at ``path_axes_N`` (P, Z, 3) / ``path_half_angles``
    (P, Z), P = ``path_points``, as they move during the approach) and held (the zones at the
    samples ``hold_axes_N`` (T, Z, 3) / ``hold_half_angles`` (T, Z)). The smallest rotation among the
    candidates clear by ``buffer_rad`` everywhere; without one, the largest worst margin."""
    cands = np.asarray(candidates, float).reshape(-1, 4)
    q = np.asarray(q_BN, float)
    fractions = np.linspace(0.0, 1.0, path_points)
    worst = np.empty(len(cands))
    for k, c in enumerate(cands):
        path = rot.slerp(q, c, fractions)
        along = margins(path, sensor_axes_B, path_axes_N, path_half_angles, keep_in)
        held = margins(np.broadcast_to(c, (len(hold_axes_N), 4)), sensor_axes_B, hold_axes_N, hold_half_angles,
                       keep_in)
        worst[k] = min(float(along.min(initial=np.inf)), float(held.min(initial=np.inf)))
    angles = np.array([rot.angle_between(q, c) for c in cands])
    clear = np.flatnonzero(worst >= buffer_rad)
    k = int(clear[np.argmin(angles[clear])]) if clear.size else int(np.argmax(worst))
    return cands[k], float(worst[k])


def approach_torque(q_BN, omega_BN_B, q_RN, kp: float, kd: float, rate_max_rad_s: float = SLEW_RATE_RAD_S
                    ) -> np.ndarray:
    """``τ_B = −K_d (ω − ω_ref)`` with ``ω_ref = −(K_p/K_d) φ`` limited to ``rate_max_rad_s`` (``φ``: the
    rotation vector of the body relative to the target ``q_RN``, body axes; N m)."""
    phi = rot.log_map(rot.multiply(rot.conjugate(np.asarray(q_RN, float)), np.asarray(q_BN, float)))
    ref = -(kp / kd) * phi
    norm = float(np.linalg.norm(ref))
    if norm > rate_max_rad_s:
        ref *= rate_max_rad_s / norm
    return -kd * (np.asarray(omega_BN_B, float) - ref)
