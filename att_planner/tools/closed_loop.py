"""The simulator, estimator and controller cores wired as their nodes wire them, in one process.

:class:`ClosedLoop` runs :class:`att_sim.truth.simulation.Simulation`, the
:class:`~att_planner.estimation.estimator.Estimator` and the
:class:`~att_planner.control.controller.Controller` of a scenario — built by the same functions as
the nodes (:func:`~att_planner.control.controller_from_scenario.controller_from_scenario`,
:func:`~att_planner.estimation.estimator_from_scenario.estimator_from_scenario`) from the scenario's sections, with
``overrides`` on top — and passes what the nodes would publish, in the order the simulator publishes
it: each step the sensors' readings, then the state; the estimator's estimate (or the truth state)
to the controller; its command, at each control instant, back to the simulator. With a fault table
(``fault_table=``) a :class:`~att_planner.fdir.monitor.FaultMonitor` watches what the nodes publish
(:class:`~att_planner.fdir.tap.MonitorTap`) and its responses are acted on before each control step
(:func:`att_planner.fdir.recovery.act`: allocation on the healthy wheels, the estimator's exclusions,
safe mode), and ``recovery`` is called when the healthy wheels change. No DDS: tests, the
benchmarks and Monte Carlo campaigns fly thousands of maneuvers this way. Plans are signed with the
loop's own key, as the planner would sign them.

:class:`Trace` records, at every control instant, the truth, the estimate and what was commanded.
"""
from __future__ import annotations

import math
from typing import NamedTuple

import numpy as np
from cryptography.hazmat.primitives.asymmetric.ed25519 import Ed25519PrivateKey

from att_msgs_py import convert, signing, topics
from att_msgs_py.errors import ConfigError, ErrorCode, RequestError
from att_msgs_py.parameters import SectionReader
from att_msgs_py.types import Health, ManeuverResult, Plan, PointingMode
from att_planner.control.controller_from_scenario import controller_from_scenario
from att_planner.control.controller_parameters import CONTROLLER
from att_planner.estimation.estimator import Estimator
from att_planner.estimation.estimator_from_scenario import estimator_from_scenario
from att_planner.estimation.estimator_parameters import ESTIMATOR
from att_planner.service.planner_parameters import PLANNER
from att_sim.models import dynamics as dyn
from att_sim.models import rotations as rot
from att_sim.models.scenario import Scenario
from att_sim.truth.sensors import Readings
from att_sim.truth.simulation import Checks, Simulation
from att_sim.truth.simulator_parameters import SIMULATOR


class Reprocessing(NamedTuple):
    """An estimator's reprocessing from snapshot ``start`` (:meth:`ClosedLoop.exchange_steps`)."""

    estimator: Estimator
    start: int


class Trace:
    """What happened at each control instant: one row per instant while running (:meth:`append`),
    columns by :meth:`arrays` — the truth (attitude, rate, wheel speeds relative to the body from
    the state vector and the wheel axes), the controller's attitude (estimate or truth), the
    estimate's attitude covariance and gyro bias (NaN without one), the truth's gyro bias, the
    health, the latest tracker sample's status, the commanded wheel torques, dipole and mode, and
    the attitude error to the controller's reference (its status)."""

    FIELDS = ("t", "q_true", "omega_true", "q_est", "attitude_covariance", "bias_true", "bias_est", "health",
              "tracker_status", "wheel_speeds", "wheel_torques", "dipole", "mode", "attitude_error")
    _ROW = ("t", "x", "q_est", "attitude_covariance", "bias_est", "bias_true", "health", "tracker_status",
            "wheel_torques", "dipole", "mode", "attitude_error")

    def __init__(self, sc: dyn.Spacecraft):
        self.sc = sc                    # its wheel axes: relative speeds ν = Ω − Gᵀω
        self.rows: list[tuple] = []

    def append(self, t: float, x: np.ndarray, q_est: np.ndarray, attitude_covariance: np.ndarray,
               bias_est: np.ndarray, bias_true: np.ndarray, health: int, tracker_status: int,
               wheel_torques: np.ndarray, dipole: np.ndarray, mode: int, attitude_error: float) -> None:
        """One instant (``x``: the simulation's state vector [q, ω, Ω]); the arrays are kept as given."""
        self.rows.append((t, x, q_est, attitude_covariance, bias_est, bias_true, health, tracker_status,
                          wheel_torques, dipole, mode, attitude_error))

    def arrays(self, *names: str) -> dict[str, np.ndarray]:
        """The fields ``names`` (default every one of :data:`FIELDS`) as arrays, one row per instant."""
        columns = dict(zip(self._ROW, zip(*self.rows))) if self.rows else {}
        x = np.array(columns.get("x", ()), float).reshape(-1, 7 + self.sc.n_wheels)
        derived = {"q_true": lambda: x[:, :4], "omega_true": lambda: x[:, 4:7],
                   "wheel_speeds": lambda: dyn.relative_wheel_speed(self.sc, x[:, 7:], x[:, 4:7])}
        return {k: derived[k]() if k in derived else np.asarray(columns.get(k, ())) for k in names or self.FIELDS}


class ClosedLoop:
    def __init__(self, scenario: Scenario, *, overrides: dict | None = None, seed: int | None = None,
                 q0=rot.IDENTITY, omega0=(0.0, 0.0, 0.0), wheel_speed0=None, simulation: Simulation | None = None,
                 key: Ed25519PrivateKey | None = None, fault_table=None):
        """``overrides``: ``{node: {parameter: value}}`` over the scenario's sections (simulator
        ``step_s``/``publish_rate_Hz``, every controller and estimator parameter); ``seed``: the noise
        seed (default the scenario's); ``simulation``: a prepared one (e.g. a dispersed truth);
        ``key``: the plan-signing key (default a new one; loops sharing one can share issued plans);
        ``fault_table``: a fault table (:class:`att_planner.fdir.table.FaultTable` or its file path)
        watched and acted on (None: the controller's ``fault_table`` parameter, empty by default: no fault
        handling)."""
        overrides = overrides or {}
        unknown = sorted(set(overrides) - {"simulator", "controller", "estimator"})
        if unknown:
            raise ConfigError(ErrorCode.INVALID_PARAMETER, f"overrides of unknown node(s) {', '.join(unknown)}; "
                                                           "known: simulator, controller, estimator")
        sections = scenario.node_params
        sim_param = SectionReader(SIMULATOR, sections.get("simulator", {}), str(scenario.node_params_path),
                                  overrides.get("simulator"))
        self.step = sim_param("step_s")
        self.publish_period = 1.0 / sim_param("publish_rate_Hz", min(10.0, 1.0 / self.step),
                                                high=(1 + 1e-9) / self.step)
        sim_param.refuse_unknown()
        self.key = key or Ed25519PrivateKey.generate()
        ctl_param = SectionReader(CONTROLLER, sections.get("controller", {}), str(scenario.node_params_path),
                                  overrides.get("controller"))
        self.controller = controller_from_scenario(ctl_param, scenario, key=self.key.public_key())
        table_param = ctl_param("fault_table")
        ctl_param.refuse_unknown()
        self.estimator = None
        if self.controller.measured is not None:
            est_param = SectionReader(ESTIMATOR, sections.get("estimator", {}), str(scenario.node_params_path),
                                      overrides.get("estimator"))
            self.estimator = estimator_from_scenario(est_param, scenario)
            table_param = table_param or est_param("fault_table")      # one monitor in process runs both sides'
            est_param.refuse_unknown()
        self.scenario = scenario
        self.sim = simulation or Simulation.for_scenario(
            scenario, q0=q0, omega0=omega0, wheel_speed0=wheel_speed0, seed=seed,
            checks=Checks(body_frame_id=scenario.body_frame_id))
        self.trace = Trace(self.sim.sc)
        self.tracker_status = 0                 # of the latest tracker measurement (TrackerStatus)
        self.tracker_valid: dict[str, list[float]] = {}   # tracker name -> the instants of its valid measurements
        self.refusals: list[RequestError] = []
        self.next_state = 0.0
        self.result: ManeuverResult | None = None
        self.tap = None     # optional (topic, t, mirror object) of everything the nodes would publish: a log
        self.monitor = self.monitor_tap = self.onboard = None
        self.recovery = None  # optional (loop, healthy before, healthy after) when the healthy wheels change
        if fault_table is None and table_param:
            from att_planner.fdir.onboard import load_table
            fault_table = load_table(table_param)
        if fault_table is not None:
            self._watch(fault_table)

    def _watch(self, fault_table) -> None:
        from att_planner.fdir import table as fault_tables
        from att_planner.fdir.onboard import Onboard

        ft = fault_table if isinstance(fault_table, fault_tables.FaultTable) else fault_tables.read(fault_table)
        self.onboard = Onboard(ft, self.scenario, self.controller, self.estimator)
        self.monitor, self.monitor_tap = self.onboard.monitor, self.onboard.tap

    def _emit(self, topic: str, t: float, m) -> None:
        if self.monitor_tap is not None:
            self.monitor_tap(topic, t, m)
        if self.tap is not None:
            self.tap(topic, t, m)

    def respond(self) -> None:
        """Act on the monitor's responses when it reported something new
        (:meth:`att_planner.fdir.onboard.Onboard.respond`)."""
        if self.onboard is None:
            return
        before = self.controller.healthy
        ended, changed = self.onboard.respond()
        if ended is not None:
            self.result = ended
        if changed and self.recovery is not None:
            self.recovery(self, before, self.controller.healthy)

    # -- plans ------------------------------------------------------------------------------------
    def issue(self, plan: Plan, plan_id: str = "plan") -> tuple[Plan, bytes]:
        """``plan`` with the context a planner fills, signed with the loop's key: (received plan, payload)."""
        plan.plan_id, plan.spacecraft, plan.frame_id = plan_id, self.scenario.name, self.scenario.frame_id
        plan.spacecraft_digest = self.scenario.spacecraft.digest
        msg = convert.plan_msg(plan)
        signing.sign(msg, self.key)
        return convert.plan_from_msg(msg), signing.payload(msg)

    def execute(self, plan: Plan, plan_id: str = "plan", after: PointingMode | None = None,
                issued: tuple[Plan, bytes] | None = None) -> RequestError | None:
        """Start flying ``plan`` now, handing over to the pointing mode ``after`` at its end (why
        not, when it cannot start); ``issued``: what :meth:`issue` made of it already (loops of one
        key flying one plan share it)."""
        received, payload = issued or self.issue(plan, plan_id)
        resolved, refused = self.controller.resolve(received.plan_id, received, payload)
        return refused or self.controller.start(resolved, after)

    # -- the loop ---------------------------------------------------------------------------------
    def tick(self) -> None:
        """One simulator step: readings and state out, the controller's command (when due) in, advance."""
        self.exchange()
        self.sim.advance(self.step)

    def exchange(self) -> None:
        """A step's messages without the advance: readings and state out, the command (when due) in."""
        for job in self.exchange_steps():
            if isinstance(job, Reprocessing):
                job.estimator.reprocess(job.start)

    def exchange_steps(self, readings: Readings | None = None):
        """:meth:`exchange` as a generator: it yields each :class:`Reprocessing` the estimator needs
        before the exchange goes on (:meth:`Estimator.reprocess
        <att_planner.estimation.estimator.Estimator.reprocess>`), which the caller does — at once,
        or for many loops together (:func:`~att_planner.tools.monte_carlo.run.fly_batch`, which
        also senses for them: ``readings``, the simulation's now) — and the controller when it is
        about to step, to which the caller may send its :class:`StepOutput
        <att_planner.control.controller.StepOutput>`
        (:func:`~att_planner.control.controller.step_controllers` of many loops; None: it steps alone)."""
        sim, ctl, est = self.sim, self.controller, self.estimator
        readings = sim.sense() if readings is None else readings
        t = sim.t
        state_due = t >= self.next_state - 1e-9
        if state_due:
            self.next_state = t + self.publish_period
        tapped = self.tap is not None or self.monitor_tap is not None
        if tapped:
            self._tap_readings(t, readings, state_due)
        outcome = None
        if est is not None:
            for m in readings.star_trackers:
                self.tracker_status = int(m.status)
                if m.valid:
                    self.tracker_valid.setdefault(m.name, []).append(m.t)
                self._guard(est.take_star_tracker, m)
            if readings.magnetometer is not None:
                self._guard(est.take_magnetometer, readings.magnetometer)
                self._guard(ctl.measured.on_magnetometer, readings.magnetometer)
            if readings.sun_sensors is not None:
                self._guard(est.take_sun_sensors, readings.sun_sensors)
            if readings.wheel_speeds is not None:
                self._guard(ctl.measured.on_wheel_speeds, readings.wheel_speeds)
            omega = self._guard(est.take_gyro, readings.gyro) if readings.gyro is not None else None
            if omega is not None:
                yield Reprocessing(est, est.newest)
                estimate = est.publish(readings.gyro.t, omega)
                if estimate is not None:
                    if tapped:
                        self._emit(topics.ESTIMATE, t, estimate)
                    outcome = ctl.accept_estimate(estimate)
        elif state_due:
            outcome = ctl.accept_state(sim.state(self.scenario.frame_id, self.scenario.body_frame_id))
        if outcome is not None:
            self._outcome(outcome)
            self.respond()
            if ctl.due():
                out = yield ctl
                out = ctl.step() if out is None else out
                if out.result is not None:
                    self.result = out.result
                if tapped:
                    self._emit(topics.COMMAND, t, out.command)
                    self._emit(topics.CONTROLLER_STATUS, t, out.status)
                refused = sim.set_command(out.command)
                if refused is not None:
                    self.refusals.append(RequestError(refused.code, refused.message))
                if est is not None:
                    est.on_dipole_command(out.command.t, out.command.dipole)
                self._record(out)

    def run(self, duration: float) -> None:
        """Tick for ``duration`` s of sim time (stops early if the simulation halts)."""
        end = self.sim.t + duration - 1e-9
        while self.sim.t < end and not self.sim.halted:
            self.tick()

    def fly(self, plan: Plan, settle: float | None = None) -> ManeuverResult:
        """Execute ``plan`` now and run until the controller ends it (its duration + settle time);
        a plan that cannot start comes back as an unsuccessful result with its code."""
        refused = self.execute(plan)
        if refused is not None:
            return ManeuverResult(False, int(refused.code), refused.message)
        self.result = None
        limit = self.sim.t + plan.duration + (self.controller.config.settle_time if settle is None else settle) + 10
        while self.result is None and self.sim.t < limit and not self.sim.halted:
            self.tick()
        return self.result or ManeuverResult(False, 305, "the maneuver did not end in time")

    def _guard(self, call, arg):
        try:
            return call(arg)
        except RequestError as err:
            self.refusals.append(err)
            return None

    def _outcome(self, outcome) -> None:
        if outcome.refused is not None:
            self.refusals.append(outcome.refused)
        if outcome.ended is not None:
            self.result = outcome.ended

    def _tap_readings(self, t: float, readings, state_due: bool) -> None:
        """Hand the tap what the simulator publishes now: the sensors' readings, the faults the truth
        started (each at its onset), then the state."""
        for topic, m in ((topics.IMU, readings.gyro), (topics.MAGNETOMETER, readings.magnetometer),
                         (topics.SUN_SENSORS, readings.sun_sensors), (topics.WHEEL_SPEEDS, readings.wheel_speeds),
                         (topics.SENSOR_TRUTH, readings.truth), *((topics.STAR_TRACKER, m) for m in
                                                                  readings.star_trackers)):
            if m is not None:
                self._emit(topic, t, m)
        for event in self.sim.faults.take_events():
            self._emit(topics.SIM_FAULTS, event.t, event)
        if state_due:
            self._emit(topics.STATE, t, self.sim.state(self.scenario.frame_id, self.scenario.body_frame_id))

    def _record(self, out) -> None:
        sim, est, command = self.sim, self.estimator, out.command
        filtered = est is not None and est.state is not None
        self.trace.append(
            sim.t, sim.x.copy(), self.controller.state.q.copy(),
            est.state.P[:3, :3].copy() if filtered else np.full((3, 3), math.nan),
            est.state.bias_B.copy() if filtered else np.full(3, math.nan),
            sim.sensors.gyro.bias.copy() if sim.sensors and sim.sensors.gyro else np.zeros(3),
            int(est.health(sim.t)) if est is not None else int(Health.CONVERGED), self.tracker_status,
            np.array(command.wheel_torques, float), np.array(command.dipole, float), int(command.mode),
            float(out.status.attitude_error))


def plan_in_process(scenario: Scenario, q0, qf, sensor_axis, cones=(), zones=(), method: str = "",
                    time_budget: float = 30.0, epoch: tuple = (0, 0), wheel_speeds=(),
                    end_pointing: PointingMode | None = None, spacecraft: dyn.Spacecraft | None = None) -> Plan:
    """A verified plan as the planner service makes it (same validation, padding, method, fallback and
    verification; the planner's ``cone_padding_deg`` and ``default_method`` of the scenario), in this
    process; ``spacecraft``: the model planned for instead of the scenario's (the envelope of its healthy
    wheels, :func:`att_planner.fdir.envelope.planning_spacecraft`). RequestError when there is none."""
    from att_planner import methods
    from att_planner.service.planning import plan_maneuver
    from att_planner.service.requests import ManeuverRequest, validate_maneuver

    planner = SectionReader(PLANNER, scenario.node_params.get("planner", {}), str(scenario.node_params_path))
    request = ManeuverRequest(scenario.frame_id, np.asarray(q0, float), np.asarray(qf, float),
                              np.asarray(sensor_axis, float),
                              [(c.direction, c.half_angle, c.name) for c in cones], method=method,
                              time_budget=time_budget, spacecraft=scenario.name, epoch=epoch, zones=list(zones),
                              wheel_speeds=list(wheel_speeds), end_pointing=end_pointing)
    valid = validate_maneuver(request, frame_id=scenario.frame_id, default_spacecraft=scenario.name,
                              default_method=planner("default_method") or methods.REGISTRY[0].name,
                              default_budget=time_budget)
    if spacecraft is not None:
        valid.problem.spacecraft = spacecraft
    outcome = plan_maneuver(valid, cone_padding=math.radians(planner("cone_padding_deg")))
    if outcome.code != 0:
        raise RequestError(outcome.code, outcome.message)
    return outcome.plan
