"""Simulator node: integrates the truth dynamics and publishes state and /clock.

One thread: the loop steps the dynamics and, between steps, lets the executor run the node's
callbacks (commands, reset) with ``spin_once``, so a command is handled the moment it arrives and
no lock or cross-thread wake-up sits in the control loop.

Subscribes ``/actuator/command`` (ActuatorCommand), publishes ``/spacecraft/state``
(SpacecraftState) at ``publish_rate_Hz`` and ``/clock`` at ``clock_rate_Hz`` (sim time), serves
``/simulator/reset``. The 3D view (:mod:`att_sim.models.scene`): ``/tf`` (tf2_msgs/TFMessage: the
body frame ``body_frame_id`` under the inertial ``frame_id``, attitude only, the view centred on the
spacecraft) and ``/simulator/zone_margins`` (att_msgs/ZoneMargins: each zone's truth margin) at
``tf_rate_Hz``, and ``/simulator/markers`` (visualization_msgs/MarkerArray: the zones as
cones where they are now, the sensor boresights, the Sun/Moon/Earth directions) at ``marker_rate_Hz``;
a rate of 0 switches either off. With the scenario's sensors it also publishes what they measure,
each at its own rate (:class:`att_sim.truth.sensors.SensorSuite`): ``/sensors/imu`` (sensor_msgs/Imu),
``/sensors/star_tracker`` (att_msgs/StarTracker), ``/sensors/magnetometer``
(sensor_msgs/MagneticField), ``/sensors/sun_sensors`` (att_msgs/CoarseSunSensors),
``/sensors/wheel_speeds`` (sensor_msgs/JointState) and, for evaluation only,
``/simulator/sensor_truth`` (the gyro's actual bias); every noise source is drawn from the ``seed``
parameter (default: the scenario's ``sensors.seed``). With ``campaign`` (a Monte Carlo campaign file
of this scenario) and ``run_seed`` it flies the dispersed truth of that run (:mod:`att_sim.truth.dispersions`:
mass properties, wheels, drives, initial attitude and rate, every noise from the run seed), so a
campaign's run can be watched through the nodes. The world is the scenario's
(:meth:`att_sim.truth.simulation.Simulation.for_scenario`:
orbit, field model, disturbances, epoch = sim time zero); the state's position is in the scenario's
``frame_id`` (GCRS with an epoch) and its field is the one at the published state. Runs at
``real_time_factor`` × wall time (0: as fast as possible).
Parameters come from the scenario file (``scenario`` parameter), overridable by ROS parameters;
each is type- and range-checked, and a bad one stops the node with one line on stderr (exit 2).

Faults (:mod:`att_sim.truth.faults`): the scenario's ``faults`` start at their onset, and
``/simulator/inject_fault`` (att_msgs/InjectFault) schedules one more when the scenario sets
``allow_fault_injection`` (else it answers FAULT_INJECTION_DISABLED); a refused request changes nothing
and the simulator keeps running. Every fault started is published, latched, on ``/simulator/faults``
(att_msgs/FaultEvent, stamped with its onset), for evaluation only.

Safety: a command or reset above the size caps of :mod:`att_msgs_py.limits` is refused (SIZE_LIMIT)
before it is read; every command and reset is checked by :class:`~att_sim.truth.simulation.Simulation` (sizes,
NaN/Inf, magnitude against ``command_limit_factor`` × the limits, stamp, frame, text); a refused one
is never integrated and is logged at most once a second with the running count. Commands are held
to their publisher (:class:`~att_msgs_py.source_hold.SourceHold`): one from a second publisher is
refused while the held one is in the ROS graph, however long it is silent; a restarted controller
is followed once the old one has left the graph (at once after a clean stop, when its DDS lease
expires after a crash). When no valid
command arrived for ``command_timeout_s`` of sim time the actuator inputs are zeroed and the state
says so. In lockstep, a state that no command answers within ``lockstep_timeout_s`` of wall time
ends the waiting: the simulator free-runs at its real-time factor with zero inputs
(``command_timeout`` set) until a command answers again; with a real-time factor of 0 (as fast
as possible) it free-runs at real time. A controller that lives but fell behind (after a stall of
the estimator chain on a loaded machine) shows itself by commands too old to apply: such a command
from the publisher of the last accepted one puts the simulator back to waiting, so the chain
catches up and the lockstep resumes instead of the simulator drowning it in states. A non-finite
state stops the propagation (reported, the node stays up).

Holding sim time: ``/simulator/hold`` (std_srvs/SetBool) with ``data: true`` stops the propagation
after the current step (callbacks keep running, nothing is published) until ``data: false`` or
``max_hold_s`` of wall time, whichever comes first; the real-time pacing counts from the release.
A driver that must not race the simulator (a mission planning its next slew at ``real_time_factor``
0) holds it while it waits, so what it flies never depends on how fast the machine is.
"""
from __future__ import annotations

import time

import numpy as np
import rclpy
from rosgraph_msgs.msg import Clock
from sensor_msgs.msg import Imu, JointState, MagneticField
from std_srvs.srv import SetBool
from tf2_msgs.msg import TFMessage
from visualization_msgs.msg import MarkerArray

from att_msgs.msg import (
    ActuatorCommand,
    CoarseSunSensors,
    FaultEvent,
    SensorTruth,
    SpacecraftState,
    StarTracker,
    ZoneMargins,
)
from att_msgs.srv import InjectFault, ResetSimulator
from att_msgs_py import convert, limits, markers, memory, qos, topics, validation
from att_msgs_py.errors import ConfigError, ErrorCode, RequestError, clip
from att_msgs_py.node_runner import (
    ParameterReader,
    live_publishers,
    publisher_of,
    read_scenario,
    run_node,
    spin_until_shutdown,
)
from att_msgs_py.suite_node import SuiteNode
from att_sim.models import scenario as scen
from att_sim.models import scene
from att_sim.truth import dispersions
from att_sim.truth.simulation import Checks, Refusal, Simulation
from att_sim.truth.simulator_parameters import SIMULATOR

FREE_RUN_PACE = 1.0        # real-time factor of a free-running simulator whose real_time_factor is 0 (max)


class SimulatorNode(SuiteNode):
    def __init__(self):
        super().__init__("simulator")
        self.scenario = scen.load_checked(read_scenario(self))
        param = self.read_parameters()
        self.answered = False
        self.awaited_stamp = 0.0
        self.free_running = False      # lockstep suspended: no command answered a state in time
        self.pace = (0.0, 0.0)         # (wall, sim) time the real-time pacing counts from
        self.last_command_time = -np.inf
        self.refused = {"command": 0, "reset": 0, "fault": 0}
        self.held_until = None         # monotonic deadline of a /simulator/hold, None: not held
        try:
            truth = param["truth"] or dispersions.Truth(self.scenario, param["initial_attitude"],
                                                        param["initial_rate_rad_s"], param["seed"])
            self.sim = Simulation.for_scenario(
                truth.scenario, q0=truth.q0, omega0=truth.omega0, gravity_gradient=param["gravity_gradient"],
                checks=Checks(command_limit_factor=param["command_limit_factor"],
                              max_reset_rate=param["max_reset_rate_rad_s"],
                              body_frame_id=self.scenario.body_frame_id,
                              stamp_ahead=self.step, stamp_age=self.command_timeout), seed=truth.seed,
                dispersed_faults=truth.faults)
        except ValueError as err:        # the environment cannot start (e.g. a TLE that fails at t = 0)
            raise ConfigError(ErrorCode.INVALID_CONFIG, f"scenario '{self.scenario.name}': {clip(err, 300)}") from None

        self.state_pub = self.create_publisher(SpacecraftState, topics.STATE, qos.STREAM_QOS)
        self.clock_pub = self.create_publisher(Clock, topics.CLOCK, qos.CLOCK_QOS)
        self.tf_pub = self.create_publisher(TFMessage, topics.TF, qos.STREAM_QOS) if self.tf_rate else None
        self.margin_pub = (self.create_publisher(ZoneMargins, topics.ZONE_MARGINS, qos.STREAM_QOS)
                           if self.tf_rate else None)
        self.marker_pub = (self.create_publisher(MarkerArray, topics.SIM_MARKERS, qos.STREAM_QOS)
                           if self.marker_rate else None)
        self.sensor_pubs = self.sensor_publishers()
        self.sim.command_source.live = live_publishers(self, topics.COMMAND)
        self.create_subscription(ActuatorCommand, topics.COMMAND, self.on_command, qos.STREAM_QOS)
        self.create_service(ResetSimulator, topics.RESET_SIMULATOR, self.on_reset)
        self.create_service(SetBool, topics.HOLD_SIMULATOR, self.on_hold)
        self.fault_pub = self.create_publisher(FaultEvent, topics.SIM_FAULTS, qos.MISSION_QOS)
        self.create_service(InjectFault, topics.INJECT_FAULT, self.on_inject_fault)
        e = self.sim.environment
        self.get_logger().info(
            f"scenario '{self.scenario.name}', step {self.step} s, RTF "
            f"{self.real_time_factor or 'max'}, {self.scenario.spacecraft.n_wheels} wheels, "
            f"{type(e.orbit).__name__}, field {e.field.model}, torques "
            f"{', '.join(e.torques(0.0, self.sim.x[:4])) or 'none'}")

    def read_parameters(self) -> dict:
        """Read and check every parameter (ConfigError naming the first bad one); the timing ones
        become attributes, the rest (initial state, checks) are returned."""
        section = self.scenario.node_params.get("simulator", {})
        param = ParameterReader(self, SIMULATOR, section, source=str(self.scenario.node_params_path))
        self.step = param("step_s")
        top = (1 + 1e-9) / self.step
        self.publish_period = 1.0 / param("publish_rate_Hz", min(10.0, 1.0 / self.step), high=top)
        self.clock_period = 1.0 / param("clock_rate_Hz", min(50.0, 1.0 / self.step), high=top)
        # the 3D view: /tf (default: with every state) and the markers, in Hz of sim time; 0: off
        self.tf_rate = param("tf_rate_Hz", 1.0 / self.publish_period, high=top)
        self.marker_rate = param("marker_rate_Hz", min(1.0, 1.0 / self.step), high=top)
        self.real_time_factor = param("real_time_factor")
        self.max_hold = param("max_hold_s")
        self.command_timeout = param("command_timeout_s")
        self.end_time = param("end_time_s")      # s of sim time; 0: run until stopped
        # Hold sim time at zero until this many subscribers (recorder, controller) see the state,
        # so that no run starts before it is recorded and controlled; at most start_timeout_s.
        self.wait_for_subscribers = param("wait_for_subscribers")
        self.start_timeout = param("start_timeout_s")
        # Lockstep: after each published state, wait (up to lockstep_timeout_s of wall time) for
        # the command that answers it, so the loop stays closed at any speed and under CPU load.
        self.lockstep = param("lockstep")
        self.lockstep_timeout = param("lockstep_timeout_s")
        values = {name: param(name) for name in ("command_limit_factor", "max_reset_rate_rad_s", "initial_attitude",
                                                 "initial_rate_rad_s", "campaign", "run_seed")}
        values["gravity_gradient"] = param("gravity_gradient", bool(self.scenario.environment.get("gravity_gradient")))
        values["seed"] = param("seed", self.scenario.sensors.seed)
        try:
            values["initial_attitude"] = validation.unit_quaternion(
                values["initial_attitude"], "parameter 'initial_attitude'", ErrorCode.INVALID_PARAMETER)
        except RequestError as err:
            raise ConfigError(err.code, err.message) from None
        rate = float(np.linalg.norm(values["initial_rate_rad_s"]))
        if rate > values["max_reset_rate_rad_s"]:
            limit = values["max_reset_rate_rad_s"]
            raise ConfigError(ErrorCode.INVALID_PARAMETER, f"parameter 'initial_rate_rad_s' has norm {rate:g} rad/s, "
                                                           f"above max_reset_rate_rad_s = {limit:g} rad/s")
        param.refuse_unknown()
        values["truth"] = self.dispersed_truth(values)
        return values

    def dispersed_truth(self, values: dict) -> dispersions.Truth | None:
        """The truth of run ``run_seed`` of the Monte Carlo ``campaign`` (a campaign file of this
        scenario; the nominal start is ``initial_attitude``/``initial_rate_rad_s``; the run seed is the
        sensors' seed too), None without a campaign; ConfigError naming the parameter."""
        path, seed = values["campaign"], values["run_seed"]
        if not path and seed < 0:
            return None
        if not path or seed < 0:
            raise ConfigError(ErrorCode.INVALID_PARAMETER, "parameters 'campaign' and 'run_seed' go together: a "
                                                           "dispersed truth is the run of that seed of that campaign")
        try:
            campaign = dispersions.load_campaign(path)
            if scen.find(campaign.scenario).resolve() != self.scenario.path.resolve():
                raise ValueError(f"its scenario '{campaign.scenario}' is not this simulator's "
                                 f"'{self.scenario.name}' ({self.scenario.path})")
            truth, _ = dispersions.seed_truth(campaign, self.scenario, seed, values["initial_attitude"],
                                              values["initial_rate_rad_s"])
        except (KeyError, ValueError) as err:
            raise ConfigError(ErrorCode.INVALID_PARAMETER, f"parameter 'campaign': {clip(err, 300)}") from None
        return truth

    def sensor_publishers(self) -> dict:
        """Publishers of the sensors the scenario has, by :class:`att_sim.truth.sensors.Readings` field."""
        s = self.scenario.sensors
        wanted = {"gyro": (s.gyro, Imu, topics.IMU),
                  "star_trackers": (s.star_trackers, StarTracker, topics.STAR_TRACKER),
                  "magnetometer": (s.magnetometer, MagneticField, topics.MAGNETOMETER),
                  "sun_sensors": (s.sun_sensors, CoarseSunSensors, topics.SUN_SENSORS),
                  "wheel_speeds": (s.tachometer, JointState, topics.WHEEL_SPEEDS),
                  "truth": (s.gyro, SensorTruth, topics.SENSOR_TRUTH)}
        return {name: self.create_publisher(kind, topic, qos.STREAM_QOS)
                for name, (present, kind, topic) in wanted.items() if present}

    # -- callbacks: translate messages to Simulation calls -------------------------------------
    # (``info`` has no default: rclpy passes the message info only to two-argument callbacks)
    def on_command(self, msg: ActuatorCommand, info: dict):
        if (oversized := limits.issue(msg, limits.ACTUATOR_COMMAND)) is not None:
            return self.report("command", Refusal(oversized.code, oversized.message))
        command = convert.command_from_msg(msg)
        source = publisher_of(info)
        refusal = self.sim.set_command(command, source)
        if refusal is not None:
            self.report("command", refusal)
            if self.free_running and source is not None and source == self.sim.command_source.held and \
                    self.sim.late_only(command):
                self.free_running = False        # the controller lives but lags: wait for it to catch up
                self.get_logger().info(f"a late command (t = {command.t:.3f} s) from the controller at t = "
                                       f"{self.sim.t:.3f} s: waiting for it to catch up", throttle_duration_sec=1.0)
            return
        self.last_command_time = self.sim.t
        if command.t >= self.awaited_stamp - 1e-9:
            self.answered = True
        if self.free_running:
            self.free_running = False
            self.get_logger().info(f"a command answers the state again at t = {self.sim.t:.3f} s: lockstep resumed",
                                   throttle_duration_sec=1.0)

    def on_reset(self, request: ResetSimulator.Request, response: ResetSimulator.Response):
        def reset():
            q = convert.from_quaternion(request.attitude)
            w = convert.from_vector3(request.body_rate)
            return self.sim.reset(q, w, np.asarray(request.wheel_speeds, float), request.orbit_phase)
        return self.answer("reset", request, limits.RESET_SIMULATOR, reset, response, lambda: "state reset")

    def on_hold(self, request: SetBool.Request, response: SetBool.Response):
        t = self.sim.t
        if request.data:
            self.held_until = time.monotonic() + self.max_hold
            response.message = f"sim time held at t = {t:.3f} s (at most {self.max_hold:g} s of wall time)"
        else:
            response.message = (f"sim time released at t = {t:.3f} s" if self.held_until is not None
                                else f"sim time was not held (t = {t:.3f} s)")
            self.release()
        response.success = True
        self.get_logger().info(response.message)
        return response

    def held(self) -> bool:
        """Whether a /simulator/hold stops the propagation now (one that outlived ``max_hold_s`` is
        released with a warning)."""
        if self.held_until is not None and time.monotonic() > self.held_until:
            self.get_logger().warning(f"sim time held for more than max_hold_s = {self.max_hold:g} s of wall time: "
                                      f"released at t = {self.sim.t:.3f} s")
            self.release()
        return self.held_until is not None

    def release(self) -> None:
        if self.held_until is not None:
            self.held_until = None
            self.pace = (time.monotonic(), self.sim.t)

    def on_inject_fault(self, request: InjectFault.Request, response: InjectFault.Response):
        def inject():
            return self.sim.request_fault(request.component, request.index, request.kind, request.factor,
                                          np.asarray(request.bias_rad, float), request.bias_rad_s, request.t_s)
        return self.answer("fault", request, limits.INJECT_FAULT, inject, response,
                           lambda: f"{request.component}[{request.index}] {request.kind} scheduled at t = "
                                   f"{max(request.t_s, self.sim.t):.3f} s")

    def answer(self, what: str, request, size_limit, act, response, done):
        """Answer a service request: refused above ``size_limit`` (SIZE_LIMIT) or by ``act()`` (a
        ``Refusal`` or None); a refusal is reported and answered with its code and sentence, a success
        with ``done()``."""
        refusal = limits.issue(request, size_limit)
        refusal = act() if refusal is None else Refusal(refusal.code, refusal.message)
        if refusal is not None:
            self.report(what, refusal)
        response.success = refusal is None
        response.error_code = 0 if refusal is None else int(refusal.code)
        response.message = done() if refusal is None else refusal.message
        return response

    def report(self, what: str, refusal: Refusal) -> None:
        """Log a refused command, reset or fault injection: at most one line a second for each (a flood
        of commands cannot hide a refused reset), with the running count."""
        self.refused[what] += 1
        if refusal.code == ErrorCode.SIZE_LIMIT:
            memory.trim()                # the refused message's deserialised copy goes back to the system
        name = {"command": "actuator command", "reset": "reset", "fault": "fault injection"}[what]
        line = clip(f"{name} rejected [{int(refusal.code)} {refusal.code.name}] ({self.refused[what]} so far): "
                    f"{refusal.message}")
        if what == "command":            # one call site each: rclpy throttles each call site separately
            self.get_logger().warning(line, throttle_duration_sec=1.0)
        elif what == "reset":
            self.get_logger().warning(line, throttle_duration_sec=1.0)
        else:
            self.get_logger().warning(line, throttle_duration_sec=1.0)

    # -- loop ----------------------------------------------------------------------------------
    def run(self, executor) -> None:
        """Step, publish /clock every ``clock_every`` steps and the state every ``state_every``
        steps (rates rounded to whole steps, counted in steps so they never drift), pace to the
        real-time factor, and in lockstep wait for the command answering each state; callbacks
        run through ``executor.spin_once`` in between (``executor`` is also ``self.executor``,
        set when the node was added to it)."""
        self.view_every = tuple(max(1, round(1.0 / (rate * self.step))) if rate else 0
                                for rate in (self.tf_rate, self.marker_rate))
        state_every = max(1, round(self.publish_period / self.step))
        clock_every = max(1, round(self.clock_period / self.step))
        give_up = time.monotonic() + self.start_timeout
        while self.listeners() < self.wait_for_subscribers:
            if time.monotonic() > give_up:
                self.get_logger().warning(f"starting with {self.listeners()} of {self.wait_for_subscribers} "
                                          "expected subscribers")
                break
            executor.spin_once(timeout_sec=0.05)
        k = 0
        self.pace = (time.monotonic(), self.sim.t)
        self.publish(k, state_every, clock_every)
        while rclpy.ok():
            if self.end_time > 0 and self.sim.t >= self.end_time - 1e-9:
                self.get_logger().info(f"end_time reached at t = {self.sim.t:.3f} s; propagation stopped")
                spin_until_shutdown(executor)
                return
            if self.sim.halted:
                executor.spin_once(timeout_sec=0.1)
                continue
            if self.held():
                executor.spin_once(timeout_sec=0.05)
                continue
            self.sim.command_timeout = (self.free_running
                                        or self.sim.t - self.last_command_time > self.command_timeout)
            self.sim.advance(self.step)
            if self.sim.halted:
                self.get_logger().error(f"propagation stopped: {self.sim.halt_reason}")
                continue
            k += 1
            self.publish(k, state_every, clock_every)
            executor.spin_once(timeout_sec=0.0)
            pace = self.real_time_factor or (FREE_RUN_PACE if self.free_running else 0.0)
            if pace > 0:
                wall0, sim0 = self.pace
                self.spin_until(lambda: False, wall0 + (self.sim.t - sim0) / pace)

    def listeners(self) -> int:
        """Subscriptions to the state, plus the nodes that listen only to the sensors (the estimator,
        and the controller flying on the estimate): recorder and controller, and the estimator."""
        def nodes(topic):
            return {(i.node_namespace, i.node_name) for i in self.get_subscriptions_info_by_topic(topic)}
        sensor_nodes = set().union(*(nodes(p.topic_name) for p in self.sensor_pubs.values()))
        return self.state_pub.get_subscription_count() + len(sensor_nodes - nodes(self.state_pub.topic_name))

    def spin_until(self, done, deadline: float) -> None:
        """Run callbacks until ``done()`` or the monotonic ``deadline``."""
        while not done():
            remaining = deadline - time.monotonic()
            if remaining <= 0:
                return
            self.executor.spin_once(timeout_sec=remaining)

    def publish(self, k: int, state_every: int, clock_every: int):
        t = self.sim.t
        self.publish_readings()
        for event in self.sim.faults.take_events():
            self.fault_pub.publish(convert.fault_event_msg(event))
            self.get_logger().warning(f"fault injected at t = {event.t:.3f} s ({event.source}): {event.component}"
                                      f"[{event.index}] {event.kind}")
        if k % clock_every == 0:
            self.clock_pub.publish(Clock(clock=convert.time_msg(t)))
        if k % state_every == 0:
            self.answered, self.awaited_stamp = False, t
            self.state_pub.publish(self.state_message())
            self.publish_view(k)            # while the estimator and the controller answer the state
            if self.lockstep and not self.free_running:
                self.wait_for_answer()
        else:
            self.publish_view(k)

    def wait_for_answer(self) -> None:
        """Lockstep: run callbacks until a command answers the state just published; after
        ``lockstep_timeout_s`` stop waiting and free-run at the real-time factor, paced from now."""
        self.spin_until(lambda: self.answered, time.monotonic() + self.lockstep_timeout)
        if not self.answered:
            self.free_running = True
            self.pace = (time.monotonic(), self.sim.t)
            self.get_logger().warning(
                f"no command answered the state at t = {self.awaited_stamp:.3f} s within {self.lockstep_timeout:g} s: "
                f"free-running at RTF {self.real_time_factor or 'max'} with zero actuator inputs until one does",
                throttle_duration_sec=1.0)

    def publish_readings(self) -> None:
        """What the sensors measure now (before the state: the estimator's gyro sample must be out
        before the lockstep waits for the command that answers the state)."""
        r = self.sim.sense()
        for name, make in (("gyro", convert.gyro_msg), ("magnetometer", convert.magnetometer_msg),
                           ("sun_sensors", convert.sun_sensors_msg), ("wheel_speeds", convert.wheel_speeds_msg),
                           ("truth", convert.sensor_truth_msg)):
            reading = getattr(r, name)
            if reading is not None:
                self.sensor_pubs[name].publish(make(reading))
        for m in r.star_trackers:
            self.sensor_pubs["star_trackers"].publish(convert.star_tracker_msg(m))

    def publish_view(self, k: int) -> None:
        """The 3D view at step ``k``: /tf and the zones' margins, and the markers, when their rates say so."""
        tf_every, marker_every = self.view_every
        t, frame_N, frame_B = self.sim.t, self.scenario.frame_id, self.scenario.body_frame_id
        zones, q_BN = self.scenario.zones, self.sim.x[:4]
        if tf_every and k % tf_every == 0:
            frames = [markers.transform_msg(t, frame_N, frame_B, q_BN)]
            if self.scenario.epoch is not None:         # the Earth-fixed frame, the Earth's centre at -r
                q_EN, origin = scene.earth_fixed(self.sim.environment, t, self.sim.position())
                frames.append(markers.transform_msg(t, frame_N, scene.EARTH_FIXED_FRAME, q_EN, origin))
            self.tf_pub.publish(markers.tf_msg(frames))
            views = scene.zone_views(zones, self.sim.environment.bodies(t))
            self.margin_pub.publish(markers.zone_margins_msg(t, frame_N, [v.name for v in views],
                                                             [v.keep_in for v in views],
                                                             scene.zone_margins(zones, views, q_BN)))
        if marker_every and k % marker_every == 0:
            shapes = scene.sky_shapes(zones, self.sim.environment.bodies(t), frame_N, frame_B)
            self.marker_pub.publish(markers.marker_array(shapes, t, frame_N))

    def state_message(self) -> SpacecraftState:
        return convert.state_msg(self.sim.state(self.scenario.frame_id, self.scenario.body_frame_id))


def main(args=None):
    memory.reexec_with_c_allocator()
    run_node(SimulatorNode, args, loop=lambda node, executor: node.run(executor))


if __name__ == "__main__":
    main()
