"""The simulator's numerics without ROS: state, actuator inputs, environment, one step at a time.

:class:`Simulation` holds the truth state of :mod:`att_sim.models.dynamics`, the latest accepted actuator
command and the environment of :mod:`att_sim.models.world` (orbit, field, Sun, disturbances), which is
evaluated at every RK4 stage; the actuator command is held over a step. The published state carries
the field and position *at the published state* (its time and attitude). The simulator node is a
thin adapter around it; tests drive it directly. Its step and its sensor readings are those of a
:class:`att_sim.truth.batch.SimulationBatch` of one: the same functions advance the simulations of
many Monte Carlo runs in one step.

Every command and reset is checked field by field first (:class:`Checks`); a refused one changes
nothing and comes back as a :class:`Refusal` (an :class:`~att_msgs_py.errors.ErrorCode` and a
sentence naming the field). Commands are held to their publisher
(:class:`~att_msgs_py.source_hold.SourceHold`, :attr:`Simulation.command_source`): one from another
publisher is refused while the held one is in the ROS graph, however long it is silent. A command
within ``command_limit_factor`` × an actuator limit is clamped to the limit (saturation); beyond
it, it is a fault and refused.
"""
from __future__ import annotations

import math
from dataclasses import dataclass
from typing import NamedTuple

import numpy as np

from att_msgs_py import validation
from att_msgs_py.errors import ErrorCode, RequestError, clip
from att_msgs_py.source_hold import SourceHold
from att_msgs_py.types import CONTROL_MODES, Command, ControlMode, FaultSource, State
from att_sim.models import dynamics as dyn
from att_sim.models import environment as env
from att_sim.models import rotations as rot
from att_sim.models import world
from att_sim.models.actuator_specs import ActuatorSpecs
from att_sim.models.config_faults import PARAMETERS, FaultSpec, Hardware, fault_problem
from att_sim.models.config_faults import spec as fault_spec
from att_sim.models.orbit import CircularOrbit
from att_sim.models.sensor_specs import SensorSpecs
from att_sim.truth.actuators import Magnetorquers, WheelDrive
from att_sim.truth.batch import Applied, SimulationBatch
from att_sim.truth.faults import Faults
from att_sim.truth.sensors import Readings, SensorSuite, Taken, rng

DEFAULT_STEP = 0.05             # s: the simulator's RK4 step unless its parameter says otherwise
MAX_ORBIT_PHASE = 1e6          # rad: |orbit_phase| of a reset (beyond it the phase drowns in rounding)


class Refusal(NamedTuple):
    """Why a command or a reset was refused."""

    code: ErrorCode
    message: str


@dataclass(frozen=True)
class Checks:
    """What a command or reset must satisfy. The simulator node sets every field from its
    parameters; the defaults leave command stamps unchecked for cores driven directly (tests)."""

    command_limit_factor: float = 2.0   # a command beyond factor × its limit is refused (COMMAND_LIMIT)
    max_reset_rate: float = 1.0         # rad/s: largest ‖body_rate‖ of a reset
    body_frame_id: str = "body"         # a command's frame_id is "" or this
    stamp_ahead: float = math.inf       # s: a command stamped after t + stamp_ahead is refused (node: one step)
    stamp_age: float = math.inf         # s: one stamped before t − stamp_age is refused (node: command_timeout)


def _numbers(value, name: str, code: ErrorCode, shape: tuple) -> np.ndarray:
    """``value`` as a finite float array of ``shape`` (RequestError otherwise)."""
    try:
        return validation.finite_array(value, name, code, shape)
    except RequestError:
        raise
    except (TypeError, ValueError):
        raise RequestError(code, f"{name} is not made of numbers") from None


def _number(value, name: str, code: ErrorCode, low: float = -math.inf, high: float = math.inf) -> float:
    """``value`` as a finite float in [low, high] (RequestError otherwise)."""
    try:
        return validation.number(value, name, code, low, high)
    except RequestError:
        raise
    except (TypeError, ValueError):
        raise RequestError(code, f"{name} is not a number") from None


def _given(fault: FaultSpec) -> tuple:
    """The parameters of ``fault`` its kind takes (``factor``, ``bias_rad``, ``bias_rad_s``), None for the others."""
    wanted = PARAMETERS.get(fault.kind)
    return tuple(getattr(fault, name) if name == wanted else None for name in ("factor", "bias_rad", "bias_rad_s"))


class Simulation:
    """Truth state, held actuator command and environment. Give ``orbit`` (a circular orbit with the
    tilted dipole and optional ``gravity_gradient``) or a :class:`att_sim.models.world.Environment`
    (:meth:`for_scenario` builds the scenario's). ``sensors`` and ``actuators``: the
    datasheets of the sensors :meth:`sense` samples and of the imperfect wheel drives and
    magnetorquers; ``seed`` (default: the sensors' ``seed``) makes every random stream of the run;
    ``faults``: the hardware faults (:class:`~att_sim.models.config_faults.FaultSpec`) the scenario
    schedules (:meth:`inject` adds more; :meth:`request_fault` when ``allow_fault_injection``)."""

    def __init__(self, sc: dyn.Spacecraft, orbit: env.OrbitParams | None = None, q0=rot.IDENTITY,
                 omega0=(0, 0, 0), wheel_speed0=None, gravity_gradient: bool = False, checks: Checks = Checks(),
                 environment: world.Environment | None = None, sensors: SensorSpecs | None = None,
                 actuators: ActuatorSpecs | None = None, seed: int | None = None,
                 frame_id: str = "", body_frame_id: str = "", faults: tuple = (),
                 allow_fault_injection: bool = False):
        if (orbit is None) == (environment is None):
            raise ValueError("Simulation needs either orbit parameters or an environment, not both")
        self.sc, self.checks = sc, checks
        self.environment = world.Environment.circular(sc, orbit, gravity_gradient) if environment is None \
            else environment
        self.t = 0.0
        self.x = dyn.initial_state(sc, q0, omega0, wheel_speed0)
        self.wheel_cmd = np.zeros(sc.n_wheels)
        self.dipole_cmd = np.zeros(3)
        self.body_cmd = np.zeros(3)
        self.command_timeout = False
        self.command_source = SourceHold()     # the publisher whose commands are applied (the node gives the graph)
        self.halted, self.halt_reason = False, ""
        self.applied = Applied(np.zeros(sc.n_wheels))
        self.now = self.environment.sample(self.t, self.x[:4])
        self.arg0 = self._arg0()
        sensors, actuators = sensors or SensorSpecs(), actuators or ActuatorSpecs()
        self.seed = sensors.seed if seed is None else int(seed)
        self.hardware = Hardware.of(sc.n_wheels, sensors)
        self.faults = Faults(self.hardware, body_frame_id)
        self.allow_fault_injection = allow_fault_injection      # :meth:`request_fault` schedules (else refuses)
        for fault in faults:
            self.inject(fault, FaultSource.SCENARIO)
        self.sensors = SensorSuite(sensors, self.seed, frame_id, body_frame_id, self.faults) if sensors else None
        self.wheel_drive = (WheelDrive(actuators.wheels, rng(self.seed, "wheel_drive"), sc.n_wheels)
                            if actuators.wheels else None)
        self.magnetorquers = (Magnetorquers(actuators.magnetorquers, rng(self.seed, "magnetorquers"))
                              if actuators.magnetorquers else None)
        self._batch: tuple[tuple, SimulationBatch] | None = None

    def _arg0(self) -> float | None:
        """A circular orbit's argument of latitude at t = 0 (rad; None for an orbit of elements or a TLE)."""
        orbit = self.environment.orbit
        return orbit.params.arg0 if isinstance(orbit, CircularOrbit) else None

    @classmethod
    def for_scenario(cls, scenario, q0=rot.IDENTITY, omega0=(0, 0, 0), wheel_speed0=None,
                     gravity_gradient: bool | None = None, checks: Checks = Checks(),
                     seed: int | None = None, dispersed_faults: tuple = ()) -> Simulation:
        """The simulation of a :class:`att_sim.models.scenario.Scenario` in its environment, with its
        sensors and actuators (``gravity_gradient`` and ``seed``, when given, override the scenario's),
        its faults and the ``dispersed_faults`` a Monte Carlo run drew (:mod:`att_sim.truth.dispersions`)."""
        sim = cls(scenario.spacecraft, q0=q0, omega0=omega0, wheel_speed0=wheel_speed0, checks=checks,
                  environment=world.Environment.from_scenario(scenario, gravity_gradient),
                  sensors=scenario.sensors, actuators=scenario.actuators, seed=seed, frame_id=scenario.frame_id,
                  body_frame_id=scenario.body_frame_id, faults=scenario.faults,
                  allow_fault_injection=scenario.allow_fault_injection)
        for fault in dispersed_faults:
            sim.faults.schedule(fault, FaultSource.DISPERSION)
        return sim

    def inject(self, fault: FaultSpec, source: FaultSource = FaultSource.SERVICE) -> Refusal | None:
        """Schedule ``fault`` (its onset at or before now: at the next step) or say why it cannot be
        (INVALID_FAULT: a component, index, kind or parameter this spacecraft's hardware cannot have)."""
        problem = fault_problem(fault.component, fault.index, fault.kind, *_given(fault), t_s=fault.t_s,
                                hardware=self.hardware)
        if problem:
            return Refusal(ErrorCode.INVALID_FAULT, problem.sentence())
        self.faults.schedule(fault, source)
        return None

    def request_fault(self, component, index, kind, factor, bias_rad, bias_rad_s, t_s) -> Refusal | None:
        """Schedule the fault of a ``/simulator/inject_fault`` request (its fields as received) or say why
        not: FAULT_INJECTION_DISABLED unless :attr:`allow_fault_injection`; INVALID_TEXT, INVALID_FAULT
        naming the field otherwise. A parameter its kind does not take is 0 (``bias_rad`` empty); an
        onset before now starts at the next step."""
        if not self.allow_fault_injection:
            return Refusal(ErrorCode.FAULT_INJECTION_DISABLED, "fault injection is off: the scenario does not set "
                                                              "allow_fault_injection: true")
        bad = ErrorCode.INVALID_FAULT
        try:
            component = validation.text(component, "component")
            kind = validation.text(kind, "kind")
            factor = _number(factor, "factor", bad)
            bias_rad = _numbers(bias_rad, "bias_rad", bad, (-1,))
            bias_rad_s = _number(bias_rad_s, "bias_rad_s", bad)
            t_s = _number(t_s, "t_s", bad, 0.0)
        except RequestError as err:
            return Refusal(err.code, err.message)
        if isinstance(index, bool) or not isinstance(index, (int, np.integer)):
            return Refusal(bad, f"index: expected a whole number; found {clip(repr(index), 40)}")
        given = (factor if factor != 0.0 else None, bias_rad.tolist() if bias_rad.size else None,
                 bias_rad_s if bias_rad_s != 0.0 else None)
        problem = fault_problem(component, int(index), kind, *given, t_s=t_s, hardware=self.hardware)
        if problem:
            return Refusal(bad, problem.sentence())
        self.faults.schedule(fault_spec(component, int(index), kind, *given, t_s=max(t_s, self.t)),
                             FaultSource.SERVICE)
        return None

    def set_command(self, command: Command, source: bytes | None = None) -> Refusal | None:
        """Accept a command from publisher ``source`` (None: unnamed) or say why it is refused; a
        refused command changes nothing."""
        if not self.command_source.check(source).admitted:
            return Refusal(ErrorCode.INVALID_COMMAND, self.command_source.refusal("command"))
        try:
            wheel_torque, dipole, body_torque = self.check_command(command)
        except RequestError as err:
            return Refusal(err.code, err.message)
        self.command_source.take(source)
        idle = command.mode == ControlMode.IDLE
        self.wheel_cmd = np.zeros(self.sc.n_wheels) if idle or wheel_torque.size == 0 else wheel_torque
        self.dipole_cmd = np.zeros(3) if idle else dipole
        self.body_cmd = np.zeros(3) if idle else body_torque
        return None

    def check_command(self, command: Command, late_ok: bool = False) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """The command's wheel torques, dipole and body torque, checked (RequestError otherwise):
        mode, sizes, finiteness, magnitude against the limits, stamp (``late_ok``: however old),
        frame and plan id."""
        bad, c = ErrorCode.INVALID_COMMAND, self.checks
        if isinstance(command.mode, bool) or not isinstance(command.mode, (int, np.integer)) \
                or command.mode not in CONTROL_MODES:
            raise RequestError(bad, f"mode {clip(repr(command.mode), 40)} is not one of {CONTROL_MODES}")
        n = self.sc.n_wheels
        wheel_torque = _numbers(command.wheel_torques, "wheel_torques", bad, (-1,))
        if wheel_torque.size not in (0, n):
            raise RequestError(bad, f"wheel_torques has {wheel_torque.size} entries, the spacecraft has {n} wheels "
                                    f"(or give none)")
        dipole = _numbers(command.dipole, "dipole", bad, (3,))
        body_torque = _numbers(command.body_torque, "body_torque", bad, (3,))
        for name, value, limit, limit_name in (
                ("wheel_torques", wheel_torque, self.sc.wheel_torque_max, "wheel_torque_max"),
                ("dipole", dipole, self.sc.dipole_max, "dipole_max"),
                ("body_torque", body_torque, self.sc.body_torque_max, "torque_max")):
            peak = validation.peak(value)
            if peak > c.command_limit_factor * limit:
                ratio = f"{peak / limit:.3g} x" if limit > 0 else "above"
                raise RequestError(ErrorCode.COMMAND_LIMIT,
                                   f"{name} reaches {peak:.6g}, {ratio} its limit {limit_name} = {limit:g}; more "
                                   f"than {c.command_limit_factor:g} x the limit is refused")
        t = _number(command.t, "header.stamp", bad)
        if t > self.t + c.stamp_ahead + 1e-9:
            raise RequestError(bad, f"header.stamp t = {t:.6g} s is ahead of the simulation (t = {self.t:.6g} s, at "
                                    f"most {c.stamp_ahead:g} s ahead)")
        if t < self.t - c.stamp_age - 1e-9 and not late_ok:
            raise RequestError(bad, f"header.stamp t = {t:.6g} s is older than the simulation's t = {self.t:.6g} s "
                                    f"by more than command_timeout = {c.stamp_age:g} s")
        frame = validation.text(command.frame_id, "header.frame_id", bad)
        if frame not in ("", c.body_frame_id):
            raise RequestError(bad, f"header.frame_id '{frame}' is not the body frame '{c.body_frame_id}' (or empty)")
        validation.text(command.plan_id, "plan_id")
        return wheel_torque, dipole, body_torque

    def late_only(self, command: Command) -> bool:
        """Whether ``command`` is refused only for being older than ``stamp_age`` (a late answer:
        every other field passes)."""
        try:
            self.check_command(command, late_ok=True)
        except RequestError:
            return False
        return command.t < self.t - self.checks.stamp_age

    def reset(self, q, omega, wheel_speed, orbit_phase: float) -> Refusal | None:
        """Reset attitude, rate, wheel speeds (empty: zeros) and orbit phase, or say why not (a
        refused reset changes nothing); sim time keeps running. ``orbit_phase`` is the argument of
        latitude now (rad) of a circular orbit; an orbit given by elements or a TLE is fixed by them
        and its epoch, so there it must be 0 (keep the orbit)."""
        try:
            x, environment = self.check_reset(q, omega, wheel_speed, orbit_phase)
        except RequestError as err:
            return Refusal(err.code, err.message)
        self.x, self.environment = x, environment
        self.halted, self.halt_reason = False, ""
        if self.sensors is not None:
            self.sensors.gyro_last = None       # a reset is no motion the gyro could have measured
        self.now, self.arg0 = self.environment.sample(self.t, self.x[:4]), self._arg0()
        return None

    def check_reset(self, q, omega, wheel_speed, orbit_phase: float) -> tuple[np.ndarray, world.Environment]:
        """The state vector and environment a reset asks for (RequestError otherwise)."""
        bad, sc = ErrorCode.INVALID_RESET, self.sc
        with np.errstate(over="ignore"):                 # a 1e308 attitude has norm inf: refused below
            q = validation.unit_quaternion(_numbers(q, "attitude", bad, (4,)), "attitude", bad)
        omega = _numbers(omega, "body_rate", bad, (3,))
        rate = float(np.linalg.norm(omega))
        if rate > self.checks.max_reset_rate:
            raise RequestError(bad, f"body_rate has norm {rate:.6g} rad/s, above max_reset_rate_rad_s = "
                                    f"{self.checks.max_reset_rate:g} rad/s")
        wheel_speed = _numbers(wheel_speed, "wheel_speeds", bad, (-1,))
        if wheel_speed.size == 0:
            wheel_speed = np.zeros(sc.n_wheels)
        if wheel_speed.size != sc.n_wheels:
            raise RequestError(bad, f"wheel_speeds has {wheel_speed.size} entries, the spacecraft has {sc.n_wheels} "
                                    f"wheels (or give none)")
        relative = dyn.relative_wheel_speed(sc, wheel_speed, omega)
        if relative.size and np.max(np.abs(relative)) > sc.wheel_speed_max:
            i = int(np.argmax(np.abs(relative)))
            raise RequestError(bad, f"wheel_speeds[{i}] = {wheel_speed[i]:.6g} rad/s is {relative[i]:.6g} rad/s "
                                    f"relative to the body, beyond wheel_speed_max = {sc.wheel_speed_max:g} rad/s")
        phase = _number(orbit_phase, "orbit_phase", bad, -MAX_ORBIT_PHASE, MAX_ORBIT_PHASE)
        environment = self.environment
        if isinstance(environment.orbit, CircularOrbit):
            environment = environment.with_phase(self.t, phase)
        elif phase != 0.0:
            raise RequestError(bad, f"orbit_phase must be 0 on this {type(environment.orbit).__name__}: its elements "
                                    f"and epoch fix where the spacecraft is (only a circular orbit takes a phase)")
        return dyn.initial_state(sc, q, omega, wheel_speed), environment

    def position(self) -> np.ndarray:
        """Spacecraft position now (m, inertial: GCRS with an epoch)."""
        return self.now.position

    def state(self, frame_id: str = "", body_frame_id: str = "") -> State:
        """The truth state now — field and position at this time and attitude — with what acted
        during the last step (motor torques, dipole, mean body torque)."""
        x, a = self.x, self.applied
        return State(t=self.t, q=x[:4].copy(), omega=x[4:7].copy(), wheel_speeds=x[7:].copy(),
                     wheel_torques=a.wheel_torque, field_body=self.now.field_B.copy(), dipole=a.dipole,
                     applied_torque=a.body_torque, position=self.now.position.copy(),
                     command_timeout=self.command_timeout, frame_id=frame_id, body_frame_id=body_frame_id)

    def batch(self) -> SimulationBatch:
        """This simulation as a :class:`~att_sim.truth.batch.SimulationBatch` of one (kept while its
        spacecraft, drives and coils are the same objects)."""
        key = (self.sc, self.wheel_drive, self.magnetorquers)
        if self._batch is None or any(a is not b for a, b in zip(self._batch[0], key)):
            self._batch = (key, SimulationBatch([self]))
        return self._batch[1]

    def inputs(self) -> dyn.Inputs:
        """Actuator inputs for the next step (rows of one run): limits applied, zero while the command
        watchdog is tripped; through the imperfect drives and coils when the scenario has them."""
        return self.batch().inputs(self.x[None])

    def sense(self) -> Readings:
        """What the sensors output now (nothing without sensors): see :class:`att_sim.truth.sensors.SensorSuite`."""
        return self.batch().sense()[0]

    def sense_taken(self, taken: Taken) -> Readings:
        """:meth:`sense` with the gyro's and tachometer's measurements taken already
        (:meth:`SimulationBatch.sense <att_sim.truth.batch.SimulationBatch.sense>`)."""
        if self.sensors is None:
            return Readings()
        x = self.x
        return self.sensors.sample(self.t, x[:4], x[4:7], None, self.now.field_B, self.applied.dipole,
                                   lambda: self.environment.bodies(self.t), taken)

    def gyro_interval(self, rotation: np.ndarray | None = None) -> tuple[np.ndarray, float] | None:
        """The gyro's interval now (:meth:`SensorSuite.gyro_interval <att_sim.truth.sensors.SensorSuite.gyro_interval>`,
        ``rotation`` its; None without sensors)."""
        return None if self.sensors is None else self.sensors.gyro_interval(self.t, self.x[:4], self.x[4:7], rotation)

    def advance(self, dt: float) -> None:
        """One RK4 step, the actuator inputs held and the environment evaluated at every stage; a
        non-finite result or an environment that cannot be evaluated (e.g. a decayed TLE) halts the
        simulation. The applied body torque reported is the step's RK4-weighted mean."""
        self.batch().advance(dt)

    def finish_step(self, x_new: np.ndarray, dt: float, applied: Applied, sample: world.Sample | None = None) -> None:
        """Take the state ``x_new`` a step of ``dt`` reached and what acted over it, or halt: a
        non-finite state, an environment that cannot be evaluated there. ``sample``: the
        environment's sample there, when it is known already."""
        try:
            values = x_new.tolist()
            finite = math.isfinite(sum(values)) or all(map(math.isfinite, values))   # a finite sum: all are
            if finite and sample is None:
                sample = self.environment.sample(self.t + dt, x_new[:4])
            now = sample if finite else None
        except ValueError as err:
            self.halt_environment(err)
            return
        if now is None:
            self.halted = True
            self.halt_reason = f"state became non-finite at t = {self.t:.3f} s; propagation stopped"
            return
        self.applied = applied
        self.x, self.now = x_new, now
        self.t += dt

    def halt_environment(self, err: ValueError) -> None:
        """Stop: the environment could not be evaluated (``err`` says why)."""
        self.halted = True
        self.halt_reason = f"environment failed at t = {self.t:.3f} s: {err}; propagation stopped"
