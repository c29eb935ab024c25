"""Simulator node: integrates the truth dynamics and publishes state and /clock.

One thread: the loop steps the dynamics and, between steps, lets the executor run the node's
callbacks (commands, reset) with ``spin_once``, so a command is handled the moment it arrives and
no lock or cross-thread wake-up sits in the control loop.

Subscribes ``/actuator/command`` (ActuatorCommand), publishes ``/spacecraft/state``
(SpacecraftState) at ``publish_rate`` and ``/clock`` at ``clock_rate`` (Hz of sim time), serves
``/simulator/reset``. Runs at ``real_time_factor`` × wall time (0: as fast as possible).
Parameters come from the scenario file (``scenario`` parameter), overridable by ROS parameters.

Safety: commands with NaN/Inf or of the wrong size are rejected and never integrated; when no
valid command arrived for ``command_timeout`` s of sim time the actuator inputs are zeroed and the
state says so; a non-finite state stops the propagation (reported, the node stays up).
"""
from __future__ import annotations

import time

import numpy as np
import rclpy
from rclpy.node import Node
from rosgraph_msgs.msg import Clock

from att_msgs.msg import ActuatorCommand, SpacecraftState
from att_msgs.srv import ResetSimulator
from att_msgs_py import convert, qos, topics
from att_msgs_py.errors import ErrorCode
from att_msgs_py.node_runner import parameter_reader, run_node, spin_until_shutdown
from att_sim import scenario as scen
from att_sim.simulation import Simulation


class SimulatorNode(Node):
    def __init__(self):
        super().__init__("simulator")
        name = self.declare_parameter("scenario", "swift_demo").value
        self.scenario = scen.load(name)
        param = parameter_reader(self, self.scenario.node_params.get("simulator", {}))
        self.step = float(param("step", 0.05))
        self.publish_period = 1.0 / float(param("publish_rate", 10.0))
        self.clock_period = 1.0 / float(param("clock_rate", 50.0))
        self.real_time_factor = float(param("real_time_factor", 1.0))
        self.command_timeout = float(param("command_timeout", 1.0))
        self.end_time = float(param("end_time", 0.0))      # s of sim time; 0: run until stopped
        # Hold sim time at zero until this many subscribers (recorder, controller) see the state,
        # so that no run starts before it is recorded and controlled; at most start_timeout s.
        self.wait_for_subscribers = int(param("wait_for_subscribers", 0))
        self.start_timeout = float(param("start_timeout", 60.0))
        # Lockstep: after each published state, wait (up to lockstep_timeout s of wall time) for
        # the command that answers it, so the loop stays closed at any speed and under CPU load.
        self.lockstep = bool(param("lockstep", True))
        self.lockstep_timeout = float(param("lockstep_timeout", 0.5))
        self.answered = False
        self.awaited_stamp = 0.0
        self.sim = Simulation(
            self.scenario.spacecraft, self.scenario.orbit,
            q0=param("initial_attitude", [0.0, 0.0, 0.0, 1.0]),
            omega0=param("initial_rate", [0.0, 0.0, 0.0]),
            gravity_gradient=bool(param("gravity_gradient", False)))
        self.last_command_time = -np.inf
        self.rejected_commands = 0

        self.state_pub = self.create_publisher(SpacecraftState, topics.STATE, qos.STREAM_QOS)
        self.clock_pub = self.create_publisher(Clock, topics.CLOCK, qos.CLOCK_QOS)
        self.create_subscription(ActuatorCommand, topics.COMMAND, self.on_command, qos.STREAM_QOS)
        self.create_service(ResetSimulator, topics.RESET_SIMULATOR, self.on_reset)
        self.get_logger().info(
            f"scenario '{self.scenario.name}', step {self.step} s, RTF "
            f"{self.real_time_factor or 'max'}, {self.scenario.spacecraft.n_wheels} wheels")

    # -- callbacks: translate messages to Simulation calls -------------------------------------
    def on_command(self, msg: ActuatorCommand):
        command = convert.command_from_msg(msg)
        error = self.sim.set_command(command)
        if error is None:
            self.last_command_time = self.sim.t
            if command.t >= self.awaited_stamp - 1e-9:
                self.answered = True
        else:
            self.rejected_commands += 1
            self.get_logger().warning(f"command rejected ({self.rejected_commands} so far): {error}",
                                      throttle_duration_sec=1.0)

    def on_reset(self, request: ResetSimulator.Request, response: ResetSimulator.Response):
        q = convert.from_quaternion(request.attitude)
        w = convert.from_vector3(request.body_rate)
        error = self.sim.reset(q, w, np.asarray(request.wheel_speeds, float), request.orbit_phase)
        response.success = error is None
        response.error_code = 0 if error is None else int(ErrorCode.INVALID_RESET)
        response.message = "state reset" if error is None else error
        return response

    # -- loop ----------------------------------------------------------------------------------
    def run(self, executor) -> None:
        """Step, publish /clock every ``clock_every`` steps and the state every ``state_every``
        steps (rates rounded to whole steps, counted in steps so they never drift), pace to the
        real-time factor, and in lockstep wait for the command answering each state; callbacks
        run through ``executor.spin_once`` in between (``executor`` is also ``self.executor``,
        set when the node was added to it)."""
        state_every = max(1, round(self.publish_period / self.step))
        clock_every = max(1, round(self.clock_period / self.step))
        give_up = time.monotonic() + self.start_timeout
        while self.state_pub.get_subscription_count() < self.wait_for_subscribers:
            if time.monotonic() > give_up:
                self.get_logger().warning(f"starting with {self.state_pub.get_subscription_count()} of "
                                          f"{self.wait_for_subscribers} expected state subscribers")
                break
            executor.spin_once(timeout_sec=0.05)
        wall0, sim0, k = time.monotonic(), self.sim.t, 0
        self.publish(k, state_every, clock_every)
        while rclpy.ok():
            if self.end_time > 0 and self.sim.t >= self.end_time - 1e-9:
                self.get_logger().info(f"end_time reached at t = {self.sim.t:.3f} s; propagation stopped")
                spin_until_shutdown(executor)
                return
            if self.sim.halted:
                executor.spin_once(timeout_sec=0.1)
                continue
            self.sim.command_timeout = self.sim.t - self.last_command_time > self.command_timeout
            self.sim.advance(self.step)
            if self.sim.halted:
                self.get_logger().error(f"propagation stopped: {self.sim.halt_reason}")
                continue
            k += 1
            self.publish(k, state_every, clock_every)
            executor.spin_once(timeout_sec=0.0)
            if self.real_time_factor > 0:
                self.spin_until(lambda: False, wall0 + (self.sim.t - sim0) / self.real_time_factor)

    def spin_until(self, done, deadline: float) -> None:
        """Run callbacks until ``done()`` or the monotonic ``deadline``."""
        while not done():
            remaining = deadline - time.monotonic()
            if remaining <= 0:
                return
            self.executor.spin_once(timeout_sec=remaining)

    def publish(self, k: int, state_every: int, clock_every: int):
        t = self.sim.t
        if k % clock_every == 0:
            self.clock_pub.publish(Clock(clock=convert.time_msg(t)))
        if k % state_every == 0:
            self.answered, self.awaited_stamp = False, t
            self.state_pub.publish(self.state_message())
            if self.lockstep:
                self.spin_until(lambda: self.answered, time.monotonic() + self.lockstep_timeout)

    def state_message(self) -> SpacecraftState:
        return convert.state_msg(self.sim.state(self.scenario.frame_id, self.scenario.body_frame_id))


def main(args=None):
    run_node(SimulatorNode, args, loop=lambda node, executor: node.run(executor))


if __name__ == "__main__":
    main()
