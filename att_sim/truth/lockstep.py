"""Simulations advanced together: one RK4 step of many runs at once (the runs of a Monte Carlo campaign).

:class:`Lockstep` holds simulations at the same time, each with its own spacecraft, drives,
environment and random streams, and advances them as :meth:`Simulation.advance
<att_sim.truth.simulation.Simulation.advance>` advances each: every run's inputs (its watchdog, its
drives' held torques and noise), then one RK4 step of all the states together — the derivative is
:func:`att_sim.models.dynamics.rates` on arrays of runs, the field of each run's environment in body axes
(:func:`att_sim.models.rotations.to_body`) at every stage — then every run's applied torques, its sample of
the environment and its time; :meth:`Lockstep.sense` takes every run's sensor readings, the gyros
measuring together. The arithmetic is the single run's, element by element, so each run
reaches the bits it reaches alone (test/att_sim/truth/test_lockstep.py), for about the cost of one run's step.
"""
from __future__ import annotations

import numpy as np

from att_msgs_py.types import WheelSpeedMeasurement
from att_sim.models import dynamics as dyn
from att_sim.models import rotations as rot
from att_sim.truth.actuators import DrivesOfRuns, MagnetorquersOfRuns
from att_sim.truth.sensors import Readings, Taken
from att_sim.truth.sensors.gyro import GyrosOfRuns
from att_sim.truth.sensors.tachometer import measure_together as measure_tachometers
from att_sim.truth.simulation import Applied, Simulation


def _by_run(matrices: list) -> list:
    """Equally shaped matrices (nested lists of floats), one per run, as rows of arrays of runs."""
    return [list(row) for row in np.moveaxis(np.array(matrices, float), 0, -1)]


class Lockstep:
    """Simulations at one time, of spacecraft with the same number of wheels, advanced together."""

    def __init__(self, sims: list[Simulation]):
        if not sims:
            raise ValueError("a lockstep needs at least one simulation")
        first = sims[0]
        for s in sims[1:]:
            if s.t != first.t or s.sc.n_wheels != first.sc.n_wheels:
                raise ValueError("the simulations of a lockstep share their time and their number of wheels")
            if (s.wheel_drive is None) != (first.wheel_drive is None) \
                    or (s.sc.wheel_inertia > 0) != (first.sc.wheel_inertia > 0):
                raise ValueError("the simulations of a lockstep all have wheel drives (and spinning wheels) or none")
        self.sims = list(sims)
        for s in sims[1:]:
            s.environment.share_time_part(first.environment)
        self.rows = tuple(_by_run([s.sc.rows[k] for s in sims]) for k in range(3))
        self.wheel_inertia = np.array([s.sc.wheel_inertia for s in sims])
        self.spinning = first.sc.wheel_inertia > 0
        self.torque_max = np.array([s.sc.wheel_torque_max for s in sims])
        self.speed_max = np.array([s.sc.wheel_speed_max for s in sims])
        n = first.sc.n_wheels
        self.drives = None if first.wheel_drive is None else DrivesOfRuns([s.wheel_drive for s in sims], n)
        coils = [s.magnetorquers for s in sims]
        self.coils = MagnetorquersOfRuns(coils) if all(c is not None for c in coils) else None
        self.stacked_inputs = n > 0 and (self.coils is not None or all(c is None for c in coils))
        self.axes_T = np.array([s.sc.wheel_axes.T for s in sims])           # R × wheels × 3
        self.limits = {k: np.array([[getattr(s.sc, k)] for s in sims]) for k in ("dipole_max", "body_torque_max")}
        self.disturbed = any(s.environment.disturbed for s in sims)
        envs = [s.environment for s in sims]
        self.one_sky = all(e.shares_time_part(first.environment) for e in envs)   # one time-only part for all
        self.gyros: tuple[list, GyrosOfRuns] | None = None   # the runs whose gyros were due, and theirs

    def _limited(self, u: list, relative: list) -> list:
        return dyn.limited_runs(self.torque_max, self.speed_max, u, relative)

    def _stage(self, t: float, x: np.ndarray) -> tuple[list, list | None]:
        """Each run's ``(B_b, τ_env)`` at one stage (one array of runs per component)."""
        envs = [s.environment for s in self.sims]
        field_N = envs[0].field_inertial(t).tolist() if self.one_sky else \
            list(np.array([e.field_inertial(t) for e in envs]).T)
        field_b = rot.to_body(list(x[:4]), field_N)
        if not self.disturbed:
            return field_b, None
        columns = np.array(field_b).T
        torques = [e.disturbance(t, x[:4, i], columns[i]) for i, e in enumerate(envs)]
        return field_b, list(np.array([np.zeros(3) if tau is None else tau for tau in torques]).T)

    def advance(self, dt: float) -> None:
        """One step of ``dt`` of every simulation (a run whose step fails halts alone, as it would alone)."""
        sims = self.sims
        x = np.array([s.x for s in sims])
        inputs = self._inputs(x)
        x = x.T
        u = list(np.array([i.wheel_torque for i in inputs]).T)
        tau_body, dipole = (list(np.array([getattr(i, k) for i in inputs]).T) for k in ("body_torque", "dipole"))
        stages = []

        def f(t, state):
            field_b, tau_env = self._stage(t, state)
            stages.append((field_b, tau_env))
            torque = dyn.torque_sum(tau_body, dipole, field_b, tau_env)
            out = np.empty_like(state)
            for k, c in enumerate(dyn.rates(self.rows, self.wheel_inertia, list(state[:4]), list(state[4:7]),
                                            list(state[7:]), torque, u, self._limited, self.drives, self.spinning)):
                out[k] = c
            return out
        try:
            x_new = dyn.renormalised(dyn.rk4(f, sims[0].t, x, dt))
        except ValueError:              # some run's environment failed: each run alone, as it would be
            for s, inp in zip(sims, inputs):
                s.advance_with(inp, dt)
            return
        G = self.rows[2]
        motor = net = u
        if self.drives is not None:
            speed = dyn.relative_speeds(G, list(x[4:7]), list(x[7:]))
            motor, net = self.drives.motor(u, speed), self.drives(u, speed)
        mean = dyn.rk4_mean(*(dyn.torque_sum(tau_body, dipole, fb, te) for fb, te in stages))
        body = np.array([m - g for m, g in zip(mean, dyn.through_wheels(G, net))]).T
        motor = np.array(motor, float).reshape(len(u), len(sims)).T
        samples = self._samples(sims[0].t + dt, x_new)
        for i, (s, inp) in enumerate(zip(sims, inputs)):
            s.finish_step(x_new[:, i].copy(), dt, Applied(motor[i].copy(), inp.dipole, body[i].copy()), samples[i])

    def sense(self) -> list[Readings]:
        """Every run's :meth:`Simulation.sense <att_sim.truth.simulation.Simulation.sense>`, the gyros due
        measuring together (:class:`att_sim.truth.sensors.gyro.GyrosOfRuns`), the tachometers due too
        (:func:`att_sim.truth.sensors.tachometer.measure_together`)."""
        sims = self.sims
        if any(s.sensors is None for s in sims):
            return [s.sense() for s in sims]
        taken = [Taken(s.gyro_interval(rotation)) for s, rotation in zip(sims, self._gyro_rotations())]
        due = [i for i, got in enumerate(taken) if got.gyro_interval is not None]
        if due and (self.gyros is None or self.gyros[0] != due):
            self.gyros = (due, GyrosOfRuns([sims[i].sensors.gyro for i in due]))
        for i, rate in zip(due, self.gyros[1].measure([taken[i].gyro_interval for i in due]) if due else ()):
            taken[i].gyro_rate = rate
        due = [i for i, s in enumerate(sims) if s.sensors.tachometer_due(s.t)]
        if due:
            x = np.array([sims[i].x for i in due])
            measured = measure_tachometers([sims[i].sensors.tachometer for i in due],
                                           dyn.relative_wheel_speeds(self.axes_T[due], x))
            for i, speeds in zip(due, measured):
                taken[i].wheel_speeds = WheelSpeedMeasurement(sims[i].t, speeds, sims[i].sensors.body_frame_id)
        return [s.sense(got) for s, got in zip(sims, taken)]

    def _gyro_rotations(self) -> list:
        """Each run's rotation since its gyro's last sample, ``log(q_last* ⊗ q)``, on rows (None: no
        sample yet); used where the gyro is due (:meth:`SensorSuite.gyro_interval
        <att_sim.truth.sensors.SensorSuite.gyro_interval>`)."""
        sims = self.sims
        out = [None] * len(sims)
        since = [i for i, s in enumerate(sims) if s.sensors.gyro_last is not None]
        if since:
            last = np.array([sims[i].sensors.gyro_last[1] for i in since])
            rotations = rot.log_map(rot.multiply(rot.conjugate(last), np.array([sims[i].x[:4] for i in since])))
            for i, rotation in zip(since, rotations):
                out[i] = rotation
        return out

    def _inputs(self, x: np.ndarray) -> list[dyn.Inputs]:
        """Every run's :meth:`Simulation.inputs <att_sim.truth.simulation.Simulation.inputs>` at its state
        (a row of ``x``), on rows of runs: commands zeroed where the watchdog is tripped, the drives'
        hold, the torque and speed limits (:func:`att_sim.models.dynamics.limited_runs`), the dipole's and
        body torque's limits, the coils; run by run when some runs have coils and others not."""
        sims = self.sims
        if not self.stacked_inputs:
            return [s.inputs() for s in sims]
        active = [not s.command_timeout for s in sims]
        on = np.array(active)[:, None]
        u = np.where(on, np.array([s.wheel_cmd for s in sims]), 0.0)
        if self.drives is not None:
            u = self.drives.hold(u, active)
        relative = dyn.relative_wheel_speeds(self.axes_T, x)
        u = np.array(self._limited(list(u.T), list(relative.T))).T
        limit = self.limits["dipole_max"]
        m = np.where(on, np.minimum(np.maximum(np.array([s.dipole_cmd for s in sims]), -limit), limit), 0.0)
        if self.coils is not None:
            m = self.coils(m)
        limit = self.limits["body_torque_max"]
        tau = np.where(on, np.minimum(np.maximum(np.array([s.body_cmd for s in sims]), -limit), limit), 0.0)
        return [dyn.Inputs(wheel_torque=u[i], body_torque=tau[i], dipole=m[i], wheel_drive=s.wheel_drive)
                for i, s in enumerate(sims)]

    def _samples(self, t: float, x: np.ndarray) -> list:
        """Each run's :meth:`Environment.sample <att_sim.models.world.Environment.sample>` at ``t`` and its
        state (a column of ``x``), the field in body axes of all at once; Nones (each run samples
        alone) when an environment cannot be evaluated."""
        try:
            field_b, tau_env = self._stage(t, x)
        except ValueError:
            return [None] * len(self.sims)
        field_b = np.array(field_b).T
        tau_env = [None] * len(self.sims) if tau_env is None else np.array(tau_env).T
        return [s.environment.sample_of(t, b.copy(), None if tau is None else tau.copy())
                for s, b, tau in zip(self.sims, field_b, tau_env)]
