"""Direct collocation toolkit: Hermite–Simpson transcription of multiphase optimal control (CasADi + IPOPT).

A *phase* is ``ẋ = f(x, u)`` on ``t ∈ [t0, t0 + T]`` with ``T`` a decision variable (free time) or
fixed by its bounds. Time is normalised per phase, ``τ = (t − t0)/T ∈ [0, 1]``, and discretised on a
mesh ``0 = τ_0 < … < τ_N = 1``. The transcription is Hermite–Simpson in separated form (Betts,
*Practical Methods for Optimal Control*, 2nd ed., §4.5): with ``h_k = T (τ_{k+1} − τ_k)``::

    x_m     = (x_k + x_{k+1})/2 + h_k/8 (f_k − f_{k+1})
    x_{k+1} = x_k + h_k/6 (f_k + 4 f_m + f_{k+1})

Two control representations, chosen so that a simulator reproduces the plan exactly:

* ``'constant'``: one control per interval, used in ``f_k, f_m, f_{k+1}`` of that interval —
  zero-order hold (the state is smooth inside each interval, so the 4th-order accuracy holds up
  to the switching instants of a bang-bang solution, which sit on mesh nodes).
* ``'linear'``: a control per node, ``u_m = (u_k + u_{k+1})/2`` — linear interpolation.

Path constraints ``g(x, u)`` or ``g(x, u, t)`` are imposed at nodes and midpoints, a time-dependent one
at the point's physical time ``t = t0 + T τ`` (``t0``: the sum of the earlier phases' durations),
an expression of the duration variables, so its derivatives with respect to them are exact (moving
keep-out zones); :mod:`~att_planner.methods.time_optimal.mesh` checks them between those points and
refines the mesh where they fail. A phase may give
the path constraints a last input ``w(τ)``, a known function of the mesh fraction (the ramp of a
tightening near the ends), evaluated at each point.

Phases are joined, bounded and scored through :class:`Transcription` (``add_constraint``,
``minimize``), so the same machinery serves a single free-time slew and a multiphase schedule.
"""
from __future__ import annotations

import copy
import time
from dataclasses import dataclass, field

import casadi as ca
import numpy as np

from att_planner.methods.time_optimal.anytime import DeadlineCallback

CONTROL_KINDS = ("constant", "linear")
# IPOPT options for MUMPS with the AMD ordering and without its own scalings (IPOPT scales the NLP):
# on the bang-bang slews the same iterates at a fifth to a third less CPU (swift's three exploration
# solves: 0.10 s, the defaults 0.12-0.17 s); not on the smooth ones, whose iterations they changed
# (earth_obs 28 -> 70, swift 25 -> 22)
MUMPS_OPTIONS = {"mumps_pivot_order": 0, "mumps_scaling": 0, "mumps_permuting_scaling": 0}


class Phase:
    """A phase ``ẋ = f(x, u)`` on a mesh, with box bounds and optional path constraints.

    ``dynamics`` and ``path`` are CasADi Functions ``(x, u) -> ẋ`` and ``(x, u[, t][, w][, p]) -> g``
    (usable both symbolically and numerically): ``t`` the time (:attr:`timed`), ``w`` the value of
    ``path_weight(τ)`` at the point's mesh fraction, ``p`` the phase's ``path_parameters`` (the same
    at every point; parameters of a parametric :class:`Transcription`). Bounds are arrays (or
    scalars) broadcast to the sizes.
    """

    def __init__(self, dynamics: ca.Function, mesh, *, control: str = "constant",
                 state_bounds=(-np.inf, np.inf), control_bounds=(-np.inf, np.inf),
                 duration_bounds=(0.0, np.inf), path: ca.Function | None = None,
                 path_bounds=(-np.inf, 0.0), path_weight=None, name: str = "phase", path_parameters=()):
        if control not in CONTROL_KINDS:
            raise ValueError(f"control must be one of {CONTROL_KINDS}, not '{control}'")
        self.dynamics = dynamics
        self.n_state = dynamics.size1_in(0)
        self.n_control = dynamics.size1_in(1)
        self.mesh = np.asarray(mesh, float)
        if self.mesh[0] != 0.0 or self.mesh[-1] != 1.0 or np.any(np.diff(self.mesh) <= 0):
            raise ValueError("mesh must increase strictly from 0 to 1")
        self.control = control
        self.state_bounds = tuple(np.broadcast_to(np.asarray(b, float), (self.n_state,)).copy() for b in state_bounds)
        self.control_bounds = tuple(np.broadcast_to(np.asarray(b, float), (self.n_control,)).copy()
                                    for b in control_bounds)
        self.duration_bounds = (float(duration_bounds[0]), float(duration_bounds[1]))
        self.path = path
        n_path = path.size1_out(0) if path is not None else 0
        self.path_bounds = tuple(np.broadcast_to(np.asarray(b, float), (n_path,)).copy() for b in path_bounds)
        self.path_weight = path_weight
        self.name = name
        self.path_parameters = np.asarray(path_parameters, float).ravel()

    @property
    def timed(self) -> bool:
        """Whether the path constraints depend on time (an input ``t`` after ``x, u``)."""
        return self.path is not None and self.path.n_in() == (
            3 + (self.path_weight is not None) + bool(self.path_parameters.size))

    def path_args(self, x, u, t, tau) -> list:
        """The path function's inputs at points of mesh fractions ``tau``: ``x, u``, then the time
        ``t`` when :attr:`timed`, then ``path_weight(tau)`` when given, then the phase's
        ``path_parameters`` when there are any (one value for every point)."""
        args = [x, u] + ([t] if self.timed else [])
        if self.path_weight is not None:
            args.append(ca.DM(np.asarray(self.path_weight(np.asarray(tau, float)), float)).T)
        return args + ([self.path_parameters] if self.path_parameters.size else [])

    @property
    def intervals(self) -> int:
        return len(self.mesh) - 1

    @property
    def n_control_samples(self) -> int:
        return self.intervals if self.control == "constant" else self.intervals + 1

    def with_mesh(self, mesh) -> Phase:
        """The same phase on another mesh."""
        return Phase(self.dynamics, mesh, control=self.control, state_bounds=self.state_bounds,
                     control_bounds=self.control_bounds, duration_bounds=self.duration_bounds,
                     path=self.path, path_bounds=self.path_bounds, path_weight=self.path_weight,
                     name=self.name, path_parameters=self.path_parameters)


@dataclass
class PhaseVariables:
    """Symbolic decision variables of one phase (columns are nodes / midpoints / control samples)."""

    duration: ca.SX
    X: ca.SX        # (nx, N+1)
    Xm: ca.SX       # (nx, N)
    U: ca.SX        # (nu, N) or (nu, N+1)

    @property
    def x_start(self):
        return self.X[:, 0]

    @property
    def x_end(self):
        return self.X[:, -1]


@dataclass
class PhaseSolution:
    """Numeric solution of one phase; ``t`` are the node times from the phase start."""

    phase: Phase
    duration: float
    x: np.ndarray       # (N+1, nx)
    xm: np.ndarray      # (N, nx)
    u: np.ndarray       # (N, nu) constant, (N+1, nu) linear

    @property
    def t(self) -> np.ndarray:
        return self.duration * self.phase.mesh

    def control_samples(self) -> np.ndarray:
        """Controls at the node times ``t`` for the simulator: ZOH repeats the last interval."""
        return np.vstack([self.u, self.u[-1:]]) if self.phase.control == "constant" else self.u

    def control_at(self, tau: np.ndarray) -> np.ndarray:
        tau = np.atleast_1d(np.asarray(tau, float))
        mesh = self.phase.mesh
        if self.phase.control == "constant":
            k = np.clip(np.searchsorted(mesh, tau, side="right") - 1, 0, self.phase.intervals - 1)
            return self.u[k]
        return np.stack([np.interp(tau, mesh, self.u[:, j]) for j in range(self.u.shape[1])], axis=-1)

    def state_at(self, tau: np.ndarray) -> np.ndarray:
        """Hermite cubic interpolant of the states (the one Hermite–Simpson collocates)."""
        tau = np.atleast_1d(np.asarray(tau, float))
        mesh = self.phase.mesh
        k = np.clip(np.searchsorted(mesh, tau, side="right") - 1, 0, self.phase.intervals - 1)
        f = self.phase.dynamics
        u_left = self.u[k]
        u_right = self.u[k] if self.phase.control == "constant" else self.u[k + 1]
        fk = np.array(f(self.x[k].T, u_left.T)).T
        fk1 = np.array(f(self.x[k + 1].T, u_right.T)).T
        h = (self.duration * (mesh[k + 1] - mesh[k]))[:, None]
        s = ((tau - mesh[k]) / (mesh[k + 1] - mesh[k]))[:, None]
        h00, h10 = 2 * s**3 - 3 * s**2 + 1, s**3 - 2 * s**2 + s
        h01, h11 = -2 * s**3 + 3 * s**2, s**3 - s**2
        return h00 * self.x[k] + h10 * h * fk + h01 * self.x[k + 1] + h11 * h * fk1

    def resample(self, phase: Phase) -> PhaseGuess:
        """This solution as a warm start on another mesh (e.g. after ``mesh.refine_mesh``)."""
        mesh = phase.mesh
        mids = (mesh[:-1] + mesh[1:]) / 2
        u = self.control_at(mids if phase.control == "constant" else mesh)
        return PhaseGuess(self.duration, self.state_at(mesh), self.state_at(mids), u)


@dataclass
class PhaseGuess:
    duration: float
    x: np.ndarray       # (N+1, nx)
    xm: np.ndarray      # (N, nx)
    u: np.ndarray       # (N or N+1, nu)


def guess_from_functions(phase: Phase, duration: float, state, control) -> PhaseGuess:
    """Warm start from callables ``state(t) -> (K, nx)`` and ``control(t) -> (K, nu)`` (phase time)."""
    mesh = phase.mesh
    mids = (mesh[:-1] + mesh[1:]) / 2
    t_u = mids if phase.control == "constant" else mesh
    return PhaseGuess(duration, np.asarray(state(duration * mesh)), np.asarray(state(duration * mids)),
                      np.asarray(control(duration * t_u)))


@dataclass
class NlpResult:
    """Outcome of one IPOPT solve (the suite's result fields, scipy-like; ``status`` is IPOPT's)."""

    w: np.ndarray
    objective: float
    success: bool             # IPOPT converged (to the requested or the acceptable tolerance)
    status: str               # IPOPT return status
    nit: int                  # IPOPT iterations
    wall_time: float          # s
    constraint_violation: float
    nfev: int = 0             # objective evaluations
    lam_g: np.ndarray = field(repr=False, default=None)
    lam_x: np.ndarray = field(repr=False, default=None)
    incumbent: np.ndarray | None = field(repr=False, default=None)   # see :meth:`Transcription.solve`


def _phase_constraints(p: int, ph: Phase, v: PhaseVariables, Tk, mesh, path_p, t_start):
    """``(rows, (lower, upper))`` of phase ``p``: the Hermite–Simpson defects (vectorised over the
    intervals with ``map``), then the path constraints at the nodes and midpoints; ``Tk`` the
    intervals' durations (or T), ``mesh`` and ``path_p`` the mesh fractions and path parameters."""
    X, Xm, U, N, nx = v.X, v.Xm, v.U, ph.intervals, ph.n_state
    h = Tk * (mesh[1:] - mesh[:-1])                          # (1, N)
    U_left = U if ph.control == "constant" else U[:, :-1]
    U_right = U if ph.control == "constant" else U[:, 1:]
    U_mid = U if ph.control == "constant" else (U_left + U_right) / 2
    fmap = ph.dynamics.map(N)
    Fk, Fk1, Fm = fmap(X[:, :-1], U_left), fmap(X[:, 1:], U_right), fmap(Xm, U_mid)
    H = ca.repmat(h, nx, 1)
    mid_defect = Xm - (X[:, :-1] + X[:, 1:]) / 2 - H / 8 * (Fk - Fk1)
    simpson_defect = X[:, 1:] - X[:, :-1] - H / 6 * (Fk + 4 * Fm + Fk1)
    out = [(ca.vec(mid_defect), (0.0, 0.0)), (ca.vec(simpson_defect), (0.0, 0.0))]
    if ph.path is not None:
        # Nodes see the control of the interval they start (the last node: the last one).
        U_nodes = ca.horzcat(U, U[:, -1]) if ph.control == "constant" else U
        times = weights = ()
        if ph.timed:
            T_nodes = ca.horzcat(Tk, Tk[-1]) if Tk.shape[1] > 1 else Tk
            times = (t_start + T_nodes * mesh, t_start + Tk * (mesh[:-1] + mesh[1:]) / 2)
        if ph.path_weight is not None:          # of the phase's own mesh (a weighted path is not parametric)
            weights = tuple(ca.DM(np.asarray(ph.path_weight(tau), float)).T
                            for tau in (ph.mesh, (ph.mesh[:-1] + ph.mesh[1:]) / 2))
        shared = [2 + ph.timed + len(weights[:1])] if ph.path_parameters.size else []   # p: one value for all
        extra = (path_p,) if shared else ()
        Gn = ph.path.map(f"path_nodes{p}", "serial", N + 1, shared, [])(X, U_nodes, *times[:1], *weights[:1], *extra)
        Gm = ph.path.map(f"path_mids{p}", "serial", N, shared, [])(Xm, U_mid, *times[1:], *weights[1:], *extra)
        out += [(ca.vec(Gn), (np.tile(ph.path_bounds[0], N + 1), np.tile(ph.path_bounds[1], N + 1))),
                (ca.vec(Gm), (np.tile(ph.path_bounds[0], N), np.tile(ph.path_bounds[1], N)))]
    return out


class Transcription:
    """Hermite–Simpson NLP over one or more phases.

    Usage: create with phases, read their symbolic variables (:meth:`variables`), fix or bound
    boundary states (:meth:`bound_state`), add boundary / linkage constraints
    (:meth:`add_constraint`), set the objective (:meth:`minimize`), :meth:`build` once, then
    :meth:`solve` from as many initial guesses as wanted (the IPOPT instance is reused).
    ``symbolic='MX'`` keeps the mapped dynamics as function calls (builds in tens of ms);
    ``'SX'`` inlines them (faster evaluations, but a build grows to ~1 s at 60 intervals).

    ``parametric``: every phase's mesh fractions and ``path_parameters``, and ``extra_parameters``
    more values (:attr:`extra`, for the caller's own constraints), are parameters of the NLP rather
    than constants, taken from :attr:`phases` and :attr:`extra_values` at each :meth:`solve`: one
    built NLP serves every mesh of its interval counts and every parameter value (:meth:`copy`).
    """

    def __init__(self, phases: list[Phase], symbolic: str = "MX", duration_copies: bool = False,
                 parametric: bool = False, extra_parameters: int = 0):
        if symbolic not in ("SX", "MX"):
            raise ValueError("symbolic must be 'SX' or 'MX'")
        sym = ca.SX.sym if symbolic == "SX" else ca.MX.sym
        self.parametric = parametric
        self.extra = sym("extra", extra_parameters)
        self.extra_values = np.zeros(extra_parameters)
        params = []
        self.phases = list(phases)
        self._vars: list[PhaseVariables] = []
        self._slices: list[dict] = []
        w, lbw, ubw = [], [], []
        g, lbg, ubg = [], [], []
        offset = 0
        t_start = 0.0       # the phase's start time: the earlier phases' durations
        for p, ph in enumerate(self.phases):
            nx, nu, N = ph.n_state, ph.n_control, ph.intervals
            T = sym(f"T{p}")
            X = sym(f"X{p}", nx, N + 1)
            Xm = sym(f"Xm{p}", nx, N)
            U = sym(f"U{p}", nu, ph.n_control_samples)
            self._vars.append(PhaseVariables(T, X, Xm, U))
            copies = N - 1 if duration_copies else 0
            Tc = sym(f"Tc{p}", copies)
            sizes = {"T": 1, "X": nx * (N + 1), "Xm": nx * N, "U": nu * ph.n_control_samples, "Tc": copies}
            sl = {}
            for key, n in sizes.items():
                sl[key] = slice(offset, offset + n)
                offset += n
            self._slices.append(sl)
            w += [T, ca.vec(X), ca.vec(Xm), ca.vec(U), Tc]
            for bounds, side in ((lbw, 0), (ubw, 1)):
                bounds += [[ph.duration_bounds[side]], np.tile(ph.state_bounds[side], 2 * N + 1),
                           np.tile(ph.control_bounds[side], ph.n_control_samples), [ph.duration_bounds[side]] * copies]
            # the duration of each interval: T, or its own copy of T chained to the next (a banded KKT system)
            Tk = ca.vertcat(T, Tc).T if copies else T                   # (1, N) or scalar
            if copies:
                g.append((Tk[1:] - Tk[:-1]).T)
                lbg.append(np.zeros(copies))
                ubg.append(np.zeros(copies))
            mesh = sym(f"mesh{p}", 1, N + 1) if parametric else ca.DM(ph.mesh).T       # (1, N + 1)
            path_p = sym(f"path{p}", ph.path_parameters.size) if parametric else ca.DM(ph.path_parameters)
            if parametric:
                params += [mesh.T, path_p]
            for rows, bound in _phase_constraints(p, ph, self._vars[-1], Tk, mesh, path_p, t_start):
                g.append(rows)
                lbg.append(np.broadcast_to(bound[0], rows.shape[0]))
                ubg.append(np.broadcast_to(bound[1], rows.shape[0]))
            t_start = t_start + T
        self._p = ca.vertcat(*params, self.extra)
        self._w = ca.vertcat(*w)
        self.lbw = np.concatenate([np.ravel(v) for v in lbw]).astype(float)
        self.ubw = np.concatenate([np.ravel(v) for v in ubw]).astype(float)
        self._g = g
        self._lbg = [np.asarray(v, float).ravel() for v in lbg]
        self._ubg = [np.asarray(v, float).ravel() for v in ubg]
        self._objective = None
        self._solver = None
        self._callback = None

    # -- problem definition --------------------------------------------------------------------
    def variables(self, phase: int = 0) -> PhaseVariables:
        return self._vars[phase]

    def bound_state(self, phase: int, node: int, lower, upper=None):
        """Bound (or with ``upper=None`` fix) the state at one node (``-1``: the last)."""
        ph = self.phases[phase]
        node = node % (ph.intervals + 1)
        sl = self._slices[phase]["X"]
        idx = np.arange(sl.start, sl.stop).reshape(ph.intervals + 1, ph.n_state)[node]
        lower = np.broadcast_to(np.asarray(lower, float), (ph.n_state,))
        upper = lower if upper is None else np.broadcast_to(np.asarray(upper, float), (ph.n_state,))
        self.lbw[idx], self.ubw[idx] = lower, upper

    def add_constraint(self, expr, lower, upper):
        n = expr.shape[0]
        self._g.append(ca.vec(expr))
        self._lbg.append(np.broadcast_to(np.asarray(lower, float), (n,)).copy())
        self._ubg.append(np.broadcast_to(np.asarray(upper, float), (n,)).copy())

    def minimize(self, expr):
        self._objective = expr

    def build(self, *, tol: float = 1e-7, max_iter: int = 1000, ipopt_options: dict | None = None,
              nlpsol_options: dict | None = None, incumbents: bool = True):
        """Create the IPOPT instance (once per mesh; every :meth:`solve` reuses it).

        ``ipopt_options`` are IPOPT's own (e.g. ``linear_solver``); ``nlpsol_options`` CasADi's
        (e.g. ``expand``); ``incumbents``: keep the best feasible iterate of each solve (:meth:`solve`),
        else only the deadline is watched."""
        if self._objective is None:
            raise ValueError("set an objective with minimize() before build()")
        g = ca.vertcat(*self._g)
        self.lbg, self.ubg = np.concatenate(self._lbg), np.concatenate(self._ubg)
        self._callback = DeadlineCallback(self._w.shape[0], g.shape[0], incumbents)
        opts = {"ipopt.print_level": 0, "ipopt.sb": "yes", "print_time": False,
                "ipopt.tol": tol, "ipopt.acceptable_tol": 10 * tol, "ipopt.max_iter": max_iter,
                "ipopt.constr_viol_tol": 1e-8, "ipopt.acceptable_constr_viol_tol": 1e-6,
                "ipopt.mu_strategy": "adaptive", "iteration_callback": self._callback,
                "iteration_callback_ignore_errors": False}
        opts.update({f"ipopt.{k}": v for k, v in (ipopt_options or {}).items()})
        opts.update(nlpsol_options or {})
        self._solver = ca.nlpsol("hermite_simpson", "ipopt", {"x": self._w, "p": self._p, "f": self._objective,
                                                              "g": g}, opts)
        return self

    def copy(self, mesh=None, path_parameters=None, extra_values=None) -> Transcription:
        """A built parametric NLP for another problem of its shape: the same solver, its own bounds,
        phase 0 on ``mesh`` (as many intervals) with ``path_parameters``, and ``extra_values``."""
        if not self.parametric or self._solver is None:
            raise ValueError("only a built parametric Transcription is copied")
        out = copy.copy(self)
        out.lbw, out.ubw, out.lbg, out.ubg = self.lbw.copy(), self.ubw.copy(), self.lbg.copy(), self.ubg.copy()
        phase = self.phases[0]
        mesh = phase.mesh if mesh is None else np.asarray(mesh, float)
        if len(mesh) != len(phase.mesh):
            raise ValueError(f"a mesh of {len(mesh) - 1} intervals for an NLP of {phase.intervals}")
        out.phases = [phase.with_mesh(mesh)] + self.phases[1:]
        if path_parameters is not None:
            out.phases[0].path_parameters = np.asarray(path_parameters, float).ravel()
        out.extra_values = self.extra_values if extra_values is None else np.asarray(extra_values, float).ravel()
        return out

    def set_duration_bounds(self, phase: int, lower: float, upper: float) -> None:
        """Bounds of a phase's duration (and of its copies)."""
        for key in ("T", "Tc"):
            sl = self._slices[phase][key]
            self.lbw[sl], self.ubw[sl] = lower, upper

    # -- solving ----------------------------------------------------------------------------
    def pack(self, guesses: list[PhaseGuess]) -> np.ndarray:
        """Flat initial-guess vector from one guess per phase (clipped into the variable bounds)."""
        parts = []
        for ph, gs in zip(self.phases, guesses):
            copies = self._slices[len(parts) // 5]["Tc"]
            parts += [[gs.duration], np.asarray(gs.x, float).ravel(), np.asarray(gs.xm, float).ravel(),
                      np.asarray(gs.u, float).reshape(ph.n_control_samples, ph.n_control).ravel(),
                      np.full(copies.stop - copies.start, gs.duration)]
        w0 = np.concatenate([np.ravel(p) for p in parts])
        return np.clip(w0, self.lbw, self.ubw)

    def solve(self, w0: np.ndarray, *, deadline: float | None = None, lam_g0=None, lam_x0=None) -> NlpResult:
        """Run IPOPT from ``w0``; stops at ``deadline`` (a ``time.monotonic()`` instant). An answer
        that did not converge carries in ``incumbent`` the iterate of least objective that met the
        constraints within :data:`.anytime.INCUMBENT_VIOLATION` (None if none did): an anytime candidate that
        its caller must still verify."""
        if self._solver is None:
            self.build()
        self._callback.deadline = deadline
        self._callback.bounds, self._callback.incumbent = (self.lbg, self.ubg), None
        args = dict(x0=w0, lbx=self.lbw, ubx=self.ubw, lbg=self.lbg, ubg=self.ubg)
        if self.parametric:
            args["p"] = np.concatenate([np.concatenate([ph.mesh, ph.path_parameters]) for ph in self.phases]
                                       + [self.extra_values])
        elif self.extra_values.size:
            raise ValueError("extra parameters need a parametric Transcription")
        if lam_g0 is not None:
            args["lam_g0"] = lam_g0
        if lam_x0 is not None:
            args["lam_x0"] = lam_x0
        start = time.monotonic()
        try:
            out = self._solver(**args)
        except RuntimeError as exc:      # evaluation errors surface here; report, never raise
            return NlpResult(np.asarray(w0, float), np.inf, False, f"error: {exc}", 0,
                             time.monotonic() - start, np.inf)
        stats = self._solver.stats()
        w = np.array(out["x"]).ravel()
        g = np.array(out["g"]).ravel()
        viol = float(max(np.max(self.lbg - g, initial=0.0), np.max(g - self.ubg, initial=0.0)))
        status = stats.get("return_status", "unknown")
        success = status in ("Solve_Succeeded", "Solved_To_Acceptable_Level")
        incumbent = None if success or self._callback.incumbent is None else self._callback.incumbent[1]
        return NlpResult(w, float(out["f"]), success, status, int(stats.get("iter_count", 0)),
                         time.monotonic() - start, viol, int(stats.get("n_call_nlp_f", 0)),
                         np.array(out["lam_g"]).ravel(), np.array(out["lam_x"]).ravel(), incumbent)

    def phase_solution(self, w: np.ndarray, phase: int = 0) -> PhaseSolution:
        ph, sl = self.phases[phase], self._slices[phase]
        N, nx, nu = ph.intervals, ph.n_state, ph.n_control
        return PhaseSolution(ph, float(w[sl["T"]][0]), w[sl["X"]].reshape(N + 1, nx),
                             w[sl["Xm"]].reshape(N, nx), w[sl["U"]].reshape(ph.n_control_samples, nu))
