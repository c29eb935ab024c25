"""The step of the truth simulation on rows of runs: one simulation (n = 1) or a batch of Monte Carlo runs.

:class:`SimulationBatch` holds simulations at the same time, each with its own spacecraft, drives,
environment and random streams, and is the one implementation of their step:
:meth:`Simulation.advance <att_sim.truth.simulation.Simulation.advance>` and
:meth:`Simulation.sense <att_sim.truth.simulation.Simulation.sense>` are a batch of one's. A step:
every run's inputs (its watchdog, its drives' held torques and noise, the limits, the coils) on
rows, one RK4 step of all the states — :func:`att_sim.models.dynamics.rates` on the stacked
spacecraft (:class:`att_sim.models.dynamics.SpacecraftStack`), each run's environment at every stage
(:func:`att_sim.models.world.stages`) — then every run's applied torques, its sample of the
environment and its time. :meth:`SimulationBatch.sense` takes every run's sensor readings, the gyros
(:class:`att_sim.truth.sensors.gyro.Gyros`) and tachometers due measuring on rows. Each run's row
is computed by the same operations whatever the batch, so a run flown in a batch equals the same run
flown alone to rounding (test/att_sim/truth/test_batch.py).
"""
from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from att_msgs_py.types import WheelSpeedMeasurement
from att_sim.models import dynamics as dyn
from att_sim.models import rotations as rot
from att_sim.models import world
from att_sim.truth import faults as faulting
from att_sim.truth.actuators import Magnetorquers, WheelDrive
from att_sim.truth.sensors import Readings, Taken
from att_sim.truth.sensors.gyro import Gyros
from att_sim.truth.sensors.tachometer import measure as measure_tachometers


@dataclass
class Applied:
    """What actually acted on the body during the last step (after limits)."""

    wheel_torque: np.ndarray
    dipole: np.ndarray = field(default_factory=lambda: np.zeros(3))
    body_torque: np.ndarray = field(default_factory=lambda: np.zeros(3))   # total torque on the body, step mean


class SimulationBatch:
    """Simulations at one time, of spacecraft with the same number of wheels, advanced together
    (duck-typed :class:`att_sim.truth.simulation.Simulation` objects)."""

    def __init__(self, sims: list):
        if not sims:
            raise ValueError("a batch needs at least one simulation")
        first = sims[0]
        for s in sims[1:]:
            if s.t != first.t or s.sc.n_wheels != first.sc.n_wheels:
                raise ValueError("the simulations of a batch share their time and their number of wheels")
            if (s.wheel_drive is None) != (first.wheel_drive is None) \
                    or (s.sc.wheel_inertia > 0) != (first.sc.wheel_inertia > 0):
                raise ValueError("the simulations of a batch all have wheel drives (and spinning wheels) or none")
        self.sims = list(sims)
        for s in sims[1:]:
            s.environment.share_time_part(first.environment)
        self.spacecraft = first.sc.stacked if len(sims) == 1 else dyn.stack([s.sc for s in sims])
        self.drives = None if first.wheel_drive is None else \
            first.wheel_drive if len(sims) == 1 else WheelDrive.stack([s.wheel_drive for s in sims])
        self.coiled = [i for i, s in enumerate(sims) if s.magnetorquers is not None]
        coils = [sims[i].magnetorquers for i in self.coiled]
        self.coils = None if not coils else coils[0] if len(coils) == 1 else Magnetorquers.stack(coils)
        self.gyros: tuple[list, Gyros] | None = None   # the gyros that were due, and their model on rows

    def advance(self, dt: float) -> None:
        """One RK4 step of every simulation, the actuator inputs held and each environment evaluated at
        every stage; a run whose state becomes non-finite or whose environment cannot be evaluated
        (e.g. a decayed TLE) halts, alone. The applied body torque reported is the step's RK4-weighted mean."""
        for s in self.sims:
            s.faults.start_due(s.t)
        x = np.array([s.x for s in self.sims])
        self.advance_with(x, self.inputs(x), dt)

    def advance_with(self, x: np.ndarray, inputs: dyn.Inputs, dt: float) -> None:
        """:meth:`advance` from the states ``x`` (rows) with the step's inputs already taken (:meth:`inputs`)."""
        sims, sc = self.sims, self.spacecraft
        environments = [s.environment for s in sims]
        torques = []                    # the external torque of each stage: the step's mean is applied

        def f(t, state):
            torques.append(dyn.external_torque(inputs, world.stages(environments, t, state)))
            return dyn.rates(sc, state, torques[-1], inputs.wheel_torque, inputs.wheel_drive)
        try:
            x_new = dyn.rk4(f, sims[0].t, x, dt)
        except ValueError as err:       # some run's environment failed: each run alone, as it would be
            if len(sims) == 1:
                sims[0].halt_environment(err)
                return
            for i, s in enumerate(sims):
                alone = s.batch()
                alone.advance_with(x[i:i + 1], inputs_row(inputs, i, alone.drive()), dt)
            return
        dyn.renormalised(x_new.T)
        u = net = inputs.wheel_torque
        drive = inputs.wheel_drive
        if drive is not None:           # at the step's start: motor torque, and less friction
            speed = dyn.relative_wheel_speed(sc, x[:, 7:], x[:, 4:7])
            u, net = drive.motor(u, speed), drive(u, speed)
        body = dyn.rk4_mean(*torques) - (sc.wheel_axes @ net[:, :, None])[:, :, 0]
        samples = self._samples(sims[0].t + dt, x_new)
        for i, s in enumerate(sims):
            s.finish_step(x_new[i], dt, Applied(u[i], inputs.dipole_B[i], body[i]), samples[i])

    def inputs(self, x: np.ndarray) -> dyn.Inputs:
        """Every run's actuator inputs for the next step at its state (a row of ``x``), on rows: the
        commands zeroed where the watchdog is tripped (the drives draw no noise there), the drives'
        hold, the torque and speed limits (:func:`att_sim.models.dynamics.effective_wheel_torque`),
        the dipole's and body torque's limits, the coils of the runs that have them; each run's
        wheel and coil faults (:mod:`att_sim.truth.faults`: a wheel off or seized has no motor
        torque, an open coil no dipole)."""
        sims, sc = self.sims, self.spacecraft
        active = [not s.command_timeout for s in sims]
        on = np.array(active)[:, None]
        u = np.where(on, np.array([s.wheel_cmd for s in sims]), 0.0)
        if self.drives is not None:
            u = self.drives.hold(u, active)
        u = dyn.effective_wheel_torque(sc, x[:, 7:], u, x[:, 4:7])
        run_faults = [s.faults for s in sims]
        wheels = faulting.wheel_rows(run_faults)
        if wheels is not None:
            u = u * wheels.motor
        limit = sc.dipole_max
        m = np.where(on, np.minimum(np.maximum(np.array([s.dipole_cmd for s in sims]), -limit), limit), 0.0)
        m = faulting.open_coils(run_faults, m)
        if self.coils is not None:
            m[self.coiled] = self.coils(m[self.coiled])
        limit = sc.body_torque_max
        tau = np.where(on, np.minimum(np.maximum(np.array([s.body_cmd for s in sims]), -limit), limit), 0.0)
        return dyn.Inputs(wheel_torque=u, torque_B=tau, dipole_B=m, wheel_drive=self.drive(wheels))

    def drive(self, wheels: faulting.WheelRows | None = None):
        """The runs' wheel drives for the dynamics: the drives (None: ideal motors), through the runs'
        wheel faults when one has any (``wheels``: their rows, when stacked already)."""
        wheels = wheels or faulting.wheel_rows([s.faults for s in self.sims])
        return self.drives if wheels is None else faulting.FaultedDrive(self.drives, wheels)

    def _samples(self, t: float, x: np.ndarray) -> list:
        """Each run's :meth:`Environment.sample <att_sim.models.world.Environment.sample>` at ``t`` and its
        state (a row of ``x``); Nones (each run samples alone) when an environment cannot be evaluated."""
        environments = [s.environment for s in self.sims]
        try:
            field_b, tau_env = world.stages(environments, t, x)
        except ValueError:
            return [None] * len(self.sims)
        return [e.sample_of(t, field_b[i], None if tau_env is None else tau_env[i])
                for i, e in enumerate(environments)]

    def sense(self) -> list[Readings]:
        """Every run's sensor readings now (:meth:`SensorSuite.sample
        <att_sim.truth.sensors.SensorSuite.sample>`; nothing for a run without sensors), the gyros due
        measuring on rows, the tachometers due too."""
        sims = self.sims
        for s in sims:
            s.faults.start_due(s.t)
        suites = [i for i, s in enumerate(sims) if s.sensors is not None]
        taken = [Taken() for _ in sims]
        rotations = self._gyro_rotations(suites)
        for i in suites:
            taken[i].gyro_interval = sims[i].gyro_interval(rotations.get(i))
        due = [i for i in suites if taken[i].gyro_interval is not None]
        if due:
            units = [sims[i].sensors.gyro for i in due]
            if self.gyros is None or len(self.gyros[0]) != len(units) \
                    or any(a is not b for a, b in zip(self.gyros[0], units)):
                self.gyros = (units, Gyros(units))
            rotation = np.array([taken[i].gyro_interval[0] for i in due])[:, None, :]
            rates = self.gyros[1].measure(rotation, [taken[i].gyro_interval[1] for i in due])[:, 0]
            rates = faulting.gyro_rows([sims[i].faults for i in due], rates)
            for i, rate in zip(due, rates):
                taken[i].gyro_rate = rate
        due = [i for i in suites if sims[i].sensors.tachometer_due(sims[i].t)]
        if due:
            x = np.array([s.x for s in sims])
            relative = dyn.relative_wheel_speed(self.spacecraft, x[:, 7:], x[:, 4:7])[due]
            measured = faulting.tachometer_rows([sims[i].faults for i in due],
                                                measure_tachometers([sims[i].sensors.tachometer for i in due],
                                                                    relative))
            for i, speeds in zip(due, measured):
                taken[i].wheel_speeds = WheelSpeedMeasurement(sims[i].t, speeds, sims[i].sensors.body_frame_id)
        return [s.sense_taken(got) for s, got in zip(sims, taken)]

    def _gyro_rotations(self, suites: list[int]) -> dict:
        """The rotation of each run of ``suites`` whose gyro has sampled before since that sample,
        ``log(q_last* ⊗ q)``, on rows (used where the gyro is due: :meth:`SensorSuite.gyro_interval
        <att_sim.truth.sensors.SensorSuite.gyro_interval>`)."""
        sims = self.sims
        since = [i for i in suites if sims[i].sensors.gyro_last is not None]
        if not since:
            return {}
        last = np.array([sims[i].sensors.gyro_last[1] for i in since])
        rotations = rot.log_map(rot.multiply(rot.conjugate(last), np.array([sims[i].x[:4] for i in since])))
        return dict(zip(since, rotations))


def inputs_row(inputs: dyn.Inputs, i: int, drive: WheelDrive | None) -> dyn.Inputs:
    """Run ``i``'s inputs of a batch's (rows ``i:i+1``), its drive ``drive``."""
    def row(v):
        return None if v is None else v[i:i + 1]
    return dyn.Inputs(wheel_torque=row(inputs.wheel_torque), torque_B=row(inputs.torque_B),
                      dipole_B=row(inputs.dipole_B), wheel_drive=drive)
