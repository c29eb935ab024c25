"""Zones that move: the sensor zones of a problem as functions of time.

Zone ``z`` (:class:`att_msgs_py.types.Zone`) has a body sensor axis ``s_z``, a unit inertial axis
``a_z(t)`` and a half-angle ``θ_z(t)``: ``inertial`` a fixed direction and half-angle (a keep-out
cone), ``sun`` / ``moon`` the direction from the spacecraft (:class:`att_sim.models.ephemeris.Ephemeris`),
``earth_limb`` the nadir −r̂(t) with ``asin(R_E/|r(t)|) + half_angle``. Its margin at attitude ``q``
is, with the boresight ``b = R(q) s_z / |s_z|`` and ``γ = angle(b, a_z)``::

    keep-out: m = γ − θ_z        keep-in: m = θ_z − γ        (m ≥ 0: clear; rad)

The motion over ``[0, window]`` is represented by Chebyshev series in ``x = (2t − a − b)/(b − a)``
on pieces ``[a, b]`` (one piece unless a degree above :data:`MAX_DEGREE` would be needed),
interpolated at the Chebyshev points of the first kind (Trefethen, *Approximation Theory and
Approximation Practice*, 2013, ch. 3-4) with the degree raised until the error against the sky on a
fine grid is at most half of :data:`FIT_TOLERANCE` (axis: |a_fit − a_true|, an angle bound;
half-angle: |θ_fit − θ_true|), checked when the FittedZones is built: the grid has at least 8 points
per oscillation of the error of a degree-40 fit, so the error between its points stays within the
tolerance. The series are summed by Clenshaw's
recurrence, the same arithmetic in numpy and in CasADi (:meth:`FittedZones.casadi`), so that
collocation and SQP constraints are exact functions of a symbolic time; their derivatives are those
of the series (exact, not finite differences). A fitted axis is unit to within the tolerance
(margins use angles, which do not depend on its length). Outside ``[0, window]`` a moving FittedZones
refuses numpy evaluation (ValueError); symbolic users must bound their time by ``window``.
Verification does not use the fit: :meth:`FittedZones.true_axes` and :meth:`FittedZones.true_half_angles`
come straight from the sky, at any time.
"""
from __future__ import annotations

import numpy as np

from att_msgs_py.types import ZONE_BODIES, Cone, Zone
from att_sim.models import rotations as rot

FIT_TOLERANCE = 1e-8          # rad: largest error of the fitted axes and half-angles against the sky
DEGREES = (4, 8, 12, 16, 24, 32, 40)   # degrees tried on a piece, in order
MAX_DEGREE = DEGREES[-1]      # above it the piece is halved
MAX_PIECES = 256              # beyond this the sky is not smooth enough to fit (ValueError)
CHECK_POINTS = 8 * (MAX_DEGREE + 1)    # points of the fine grid the fit is checked on, per piece


def zones_from_cones(cones: list[Cone], sensor_axis) -> list[Zone]:
    """A problem's keep-out cones as inertial keep-out zones of the one sensor ``sensor_axis``."""
    return [Zone(c.name, "inertial", np.asarray(sensor_axis, float), c.half_angle, False, c.direction)
            for c in cones]


def same_axis(a, b) -> bool:
    """Whether two sensor axes are the same direction (to 1e-12)."""
    a, b = np.asarray(a, float), np.asarray(b, float)
    return bool(np.allclose(a / np.linalg.norm(a), b / np.linalg.norm(b), rtol=0.0, atol=1e-12))


def clenshaw(x, rows):
    """``Σ_j c_j T_j(x)`` by Clenshaw's recurrence for the coefficient vectors ``rows`` (c_0 first);
    ``x`` a numpy column (K, 1) or a CasADi scalar (the rows then CasADi columns)."""
    b1 = b2 = 0.0
    for c in rows[:0:-1]:
        b1, b2 = c + 2.0 * x * b1 - b2, b1
    return rows[0] + x * b1 - b2


def _chebyshev_interpolant(values: np.ndarray) -> np.ndarray:
    """Coefficients (n+1, m) of the degree-n interpolant of ``values`` (n+1, m) taken at the
    Chebyshev points of the first kind ``x_k = cos(π (k + ½)/(n + 1))`` (discrete cosine transform)."""
    n1 = len(values)
    k = np.arange(n1) + 0.5
    coef = 2.0 / n1 * np.cos(np.pi * np.outer(np.arange(n1), k) / n1) @ values
    coef[0] /= 2.0
    return coef


class FittedZones:
    """The zones of a problem over ``[0, window]`` s, their motion fitted by Chebyshev series
    (module docstring).

    ``zones``: list of Zone (cones first when built by the problem); ``sky``: an ephemeris
    (:class:`att_sim.models.ephemeris.Ephemeris`) or any object with
    ``sun_direction(t)``, ``moon_direction(t)``, ``nadir(t)`` and ``earth_angular_radius(t)``
    (vectorised, t seconds past the epoch), needed when a zone is not inertial. Attributes:
    ``moving`` (a zone is not inertial), ``names``, ``keep_in`` (Z,), ``sensor_axes`` (Z, 3),
    ``pieces`` (breakpoints), ``degree`` (highest degree used), ``fit_error`` (rad, measured at build).
    """

    def __init__(self, zones: list[Zone], sky=None, window: float = 600.0, tolerance: float = FIT_TOLERANCE):
        window = float(window)
        if not np.isfinite(window) or window <= 0:
            raise ValueError(f"zone window = {window} s must be finite and > 0")
        self.zones, self.sky, self.window, self.tolerance = list(zones), sky, window, float(tolerance)
        for i, z in enumerate(self.zones):
            if z.body not in ZONE_BODIES:
                raise ValueError(f"zones[{i}].body = '{z.body}' is not one of {', '.join(ZONE_BODIES)}")
        self.names = [z.name or str(i) for i, z in enumerate(self.zones)]
        self.keep_in = np.array([z.keep_in for z in self.zones], bool)
        self.sensor_axes = np.array([z.sensor_axis for z in self.zones], float).reshape(-1, 3)
        self._moving = np.array([i for i, z in enumerate(self.zones) if z.body != "inertial"], int)
        self.moving = bool(self._moving.size)
        if self.moving and sky is None:
            z = self.zones[self._moving[0]]
            raise ValueError(f"zone '{self.names[self._moving[0]]}' (body {z.body}) needs a sky: an epoch and an orbit")
        Z = len(self.zones)
        self._axes0 = np.zeros((Z, 3))
        self._half0 = np.array([z.half_angle for z in self.zones], float)
        for i, z in enumerate(self.zones):
            if z.body == "inertial":
                self._axes0[i] = z.direction
        # boresight groups: zones sharing one sensor axis (inertial ones as in att_planner.cones)
        groups: dict[bytes, list[int]] = {}
        for i in range(Z):
            groups.setdefault(self.sensor_axes[i].tobytes(), []).append(i)
        self._groups = [(self.sensor_axes[g[0]], np.array([i for i in g if i not in self._moving], int),
                         np.array([i for i in g if i in self._moving], int)) for g in groups.values()]
        self.pieces, self._coef, self._dcoef = np.array([0.0, window]), [], []
        self.degree, self.fit_error = 0, 0.0
        if self.moving:
            self._fit()

    # ------------------------------------------------------------------ the truth, from the sky
    def _moving_truth(self, t: np.ndarray) -> np.ndarray:
        """(K, 4M): the moving zones' true axes (3M, zone-major) then half-angles (M), at times (K,)."""
        cache = {}
        for body in {self.zones[i].body for i in self._moving}:
            if body == "sun":
                cache[body] = (self.sky.sun_direction(t), 0.0)
            elif body == "moon":
                cache[body] = (self.sky.moon_direction(t), 0.0)
            else:
                cache[body] = (self.sky.nadir(t), self.sky.earth_angular_radius(t))
        axes = [np.broadcast_to(cache[self.zones[i].body][0], t.shape + (3,)) for i in self._moving]
        half = [np.broadcast_to(cache[self.zones[i].body][1] + self._half0[i], t.shape) for i in self._moving]
        out = np.concatenate([np.stack(axes, -2).reshape(len(t), -1), np.stack(half, -1)], axis=-1)
        bad = ~np.isfinite(out).all(axis=-1)
        if bad.any():
            raise ValueError(f"the sky is not finite at t = {t[bad][0]:.6g} s (an orbit that decayed or left "
                             f"its model's span): no zone can be placed there")
        return out

    def _fit(self):
        todo, done = [(0.0, self.window)], []
        while todo:
            a, b = todo.pop(0)
            fitted = self._fit_piece(a, b)
            if fitted is not None:
                done.append((a, b) + fitted)
                continue
            if len(done) + len(todo) + 2 > MAX_PIECES:
                raise ValueError(f"the zones' motion cannot be fitted to {self.tolerance:.1e} rad over "
                                 f"{self.window} s with {MAX_PIECES} Chebyshev pieces: the sky is not smooth")
            todo += [(a, 0.5 * (a + b)), (0.5 * (a + b), b)]
        done.sort(key=lambda p: p[0])
        self.pieces = np.array([p[0] for p in done] + [self.window])
        self._coef = [p[2] for p in done]
        self._dcoef = [np.polynomial.chebyshev.chebder(p[2], axis=0) * (2.0 / (p[1] - p[0])) for p in done]
        self.degree = max(len(c) - 1 for c in self._coef)
        self.fit_error = max(p[3] for p in done)

    def _fit_piece(self, a: float, b: float):
        """(coefficients, error) of the lowest degree of :data:`DEGREES` within the tolerance on
        [a, b], else None."""
        xg = np.linspace(-1.0, 1.0, CHECK_POINTS)
        truth = self._moving_truth(a + (xg + 1.0) * (b - a) / 2)
        for n in DEGREES:
            x = np.cos(np.pi * (np.arange(n + 1) + 0.5) / (n + 1))
            coef = _chebyshev_interpolant(self._moving_truth(a + (x + 1.0) * (b - a) / 2))
            error = self._error(clenshaw(xg[:, None], coef), truth)
            if error <= 0.5 * self.tolerance:
                return coef, error
        return None

    def _error(self, fit: np.ndarray, truth: np.ndarray) -> float:
        M = len(self._moving)
        d = (fit - truth)
        axis_err = np.linalg.norm(d[:, :3 * M].reshape(len(d), M, 3), axis=-1)
        return float(max(axis_err.max(), np.abs(d[:, 3 * M:]).max()))

    # ------------------------------------------------------------------ the fit
    def _series(self, t: np.ndarray, derivative: bool) -> np.ndarray:
        """(K, 4M) fitted values (or their time derivatives) at times (K,) inside the window."""
        slack = 1e-9 * self.window
        if t.size and (t.min() < -slack or t.max() > self.window + slack):
            bad = t.min() if t.min() < -slack else t.max()
            raise ValueError(f"t = {bad:.6g} s is outside the zones' window [0, {self.window:.6g}] s "
                             f"(build the FittedZones over the whole maneuver)")
        out = np.empty((len(t), 4 * len(self._moving)))
        piece = np.clip(np.searchsorted(self.pieces, t, side="right") - 1, 0, len(self._coef) - 1)
        for p, (coef, dcoef) in enumerate(zip(self._coef, self._dcoef)):
            mask = piece == p
            if mask.any():
                a, b = self.pieces[p], self.pieces[p + 1]
                x = ((2.0 * t[mask] - (a + b)) / (b - a))[:, None]
                out[mask] = clenshaw(x, dcoef) if derivative else clenshaw(x, coef)
        return out

    def _assemble(self, t, values, rates: bool):
        t = np.asarray(t, float)
        flat = t.reshape(-1)
        K, Z, M = len(flat), len(self.zones), len(self._moving)
        axes = np.zeros((K, Z, 3)) if rates else np.broadcast_to(self._axes0, (K, Z, 3)).copy()
        half = np.zeros((K, Z)) if rates else np.broadcast_to(self._half0, (K, Z)).copy()
        if M:
            v = values(flat)
            axes[:, self._moving] = v[:, :3 * M].reshape(K, M, 3)
            half[:, self._moving] = v[:, 3 * M:]
        return axes.reshape(t.shape + (Z, 3)), half.reshape(t.shape + (Z,))

    def at(self, t, true: bool = False) -> tuple[np.ndarray, np.ndarray]:
        """``(axes, half_angles)`` at ``t`` in one evaluation: the fit, or with ``true`` the sky."""
        return self._assemble(t, self._moving_truth if true else lambda s: self._series(s, False), False)

    def rates_at(self, t) -> tuple[np.ndarray, np.ndarray]:
        """``(d a_z/dt, d θ_z/dt)`` of the fit at ``t`` in one evaluation."""
        return self._assemble(t, lambda s: self._series(s, True), True)

    def axes(self, t) -> np.ndarray:
        """Fitted unit inertial axes ``a_z(t)``, shape ``t.shape + (Z, 3)``."""
        return self._assemble(t, lambda s: self._series(s, False), False)[0]

    def half_angles(self, t) -> np.ndarray:
        """Fitted half-angles ``θ_z(t)`` (rad), shape ``t.shape + (Z,)``."""
        return self._assemble(t, lambda s: self._series(s, False), False)[1]

    def axes_rate(self, t) -> np.ndarray:
        """``d a_z/dt`` of the fit (1/s), shape ``t.shape + (Z, 3)``."""
        return self._assemble(t, lambda s: self._series(s, True), True)[0]

    def half_angles_rate(self, t) -> np.ndarray:
        """``d θ_z/dt`` of the fit (rad/s), shape ``t.shape + (Z,)``."""
        return self._assemble(t, lambda s: self._series(s, True), True)[1]

    def true_axes(self, t) -> np.ndarray:
        """Axes straight from the sky (any t), shape ``t.shape + (Z, 3)``."""
        return self._assemble(t, self._moving_truth, False)[0]

    def true_half_angles(self, t) -> np.ndarray:
        """Half-angles straight from the sky (any t), shape ``t.shape + (Z,)``."""
        return self._assemble(t, self._moving_truth, False)[1]

    def series(self, z: int) -> list[np.ndarray]:
        """The fit of moving zone ``z``: per piece (:attr:`pieces`) its Chebyshev coefficients
        (degree + 1, 4), the axis' three then the half-angle's, summed by :func:`clenshaw`."""
        j, M = int(np.flatnonzero(self._moving == z)[0]), len(self._moving)
        return [c[:, [3 * j, 3 * j + 1, 3 * j + 2, 3 * M + j]] for c in self._coef]

    def casadi(self, t):
        """``(axes, half_angles)``: Z CasADi 3-vectors and Z scalars, functions of the CasADi scalar
        ``t`` (SX or MX) by the same Clenshaw sums as :meth:`axes` (pieces chosen by ``if_else``).
        Exact inside ``[0, window]`` only: the caller must keep ``t`` there."""
        import casadi as ca
        Z, M = len(self.zones), len(self._moving)
        axes = [ca.DM(self._axes0[i]) for i in range(Z)]
        half = [ca.DM(self._half0[i]) for i in range(Z)]
        if not M:
            return axes, half
        values = None
        for p in range(len(self._coef) - 1, -1, -1):
            a, b = self.pieces[p], self.pieces[p + 1]
            v = clenshaw((2.0 * t - (a + b)) / (b - a), [ca.DM(c) for c in self._coef[p]])
            values = v if values is None else ca.if_else(t < b, v, values)
        for j, i in enumerate(self._moving):
            axes[i] = values[3 * j:3 * j + 3]
            half[i] = values[3 * M + j]
        return axes, half

    def casadi_constraints(self, t, R, margin=0.0) -> list:
        """``g_z(t, R) ≤ 0`` for every zone with the CasADi DCM ``R`` (body to inertial) at the CasADi
        time ``t``: keep-out ``a·b − cos(θ + margin)``, keep-in ``cos(θ − margin) − a·b``, b = R s_z;
        ``margin`` one for all zones or one (number or CasADi expression) per zone."""
        import casadi as ca
        axes, half = self.casadi(t)
        margins = margin if isinstance(margin, (list, tuple)) else [margin] * len(self.zones)
        g = []
        for z, (a, th, margin) in enumerate(zip(axes, half, margins)):
            s = self.sensor_axes[z] / np.linalg.norm(self.sensor_axes[z])
            c = ca.dot(a, ca.mtimes(R, ca.DM(s)))
            g.append(ca.cos(th - margin) - c if self.keep_in[z] else c - ca.cos(th + margin))
        return g

    # ------------------------------------------------------------------ margins
    def margins(self, t, q, true: bool = False) -> np.ndarray:
        """Margins (rad, ≥ 0 clear) of attitudes ``q`` (K, 4) at times ``t`` (K,), (K, Z); either may be
        a single one (broadcast): the fitted zones, or with ``true`` the zones straight from the sky."""
        q, t = np.asarray(q, float).reshape(-1, 4), np.asarray(t, float).reshape(-1)
        K = max(len(q), len(t))
        q, t = np.broadcast_to(q, (K, 4)), np.broadcast_to(t, (K,))
        Z = len(self.zones)
        out = np.zeros((len(q), Z))
        if not Z:
            return out
        R = rot.dcm_NB(q)
        A, theta = self.at(t, true) if self.moving else (None, None)
        for s, static, moving in self._groups:
            b = R @ s
            b = b / np.linalg.norm(b, axis=-1, keepdims=True)
            if static.size:   # exactly att_planner.cones.direction_margins
                out[:, static] = np.arccos(np.clip(b @ self._axes0[static].T, -1.0, 1.0)) - self._half0[static]
            if moving.size:
                a = A[:, moving]
                cos = np.einsum("kj,kzj->kz", b, a) / np.linalg.norm(a, axis=-1)
                out[:, moving] = np.arccos(np.clip(cos, -1.0, 1.0)) - theta[:, moving]
        out[:, self.keep_in] *= -1.0
        return out

    # ------------------------------------------------------------------ the frozen baseline
    def frozen_zones(self) -> list[Zone]:
        """Every zone as it is at t = 0 (true position and size) as an inertial zone."""
        a0, th0 = self.at(0.0, true=True)
        return [z if z.body == "inertial" else Zone(z.name, "inertial", z.sensor_axis, float(th0[i]), z.keep_in, a0[i])
                for i, z in enumerate(self.zones)]

    def frozen(self) -> FittedZones:
        """The zones frozen at t = 0 (:meth:`frozen_zones`), same window."""
        return FittedZones(self.frozen_zones(), None, self.window, self.tolerance)
