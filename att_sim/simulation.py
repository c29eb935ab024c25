"""The simulator's numerics without ROS: state, actuator inputs, environment, one step at a time.

:class:`Simulation` holds the truth state of :mod:`att_sim.dynamics`, the latest accepted actuator
command and the orbit/field environment of :mod:`att_sim.environment`. The simulator node is a thin
adapter around it; tests drive it directly.
"""
from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from att_msgs_py.types import CONTROL_MODES, Command, ControlMode, State
from att_sim import dynamics as dyn
from att_sim import environment as env
from att_sim import rotations as rot


@dataclass
class Applied:
    """What actually acted on the body during the last step (after limits)."""

    wheel_torque: np.ndarray
    dipole: np.ndarray = field(default_factory=lambda: np.zeros(3))
    field_body: np.ndarray = field(default_factory=lambda: np.zeros(3))
    body_torque: np.ndarray = field(default_factory=lambda: np.zeros(3))   # total torque on the body


class Simulation:
    def __init__(self, sc: dyn.Spacecraft, orbit: env.OrbitParams, q0=rot.IDENTITY, omega0=(0, 0, 0),
                 wheel_speed0=None, gravity_gradient: bool = False):
        self.sc, self.orbit, self.gravity_gradient = sc, orbit, gravity_gradient
        self.t = 0.0
        self.arg0 = orbit.arg0
        self.x = dyn.initial_state(sc, q0, omega0, wheel_speed0)
        self.wheel_cmd = np.zeros(sc.n_wheels)
        self.dipole_cmd = np.zeros(3)
        self.body_cmd = np.zeros(3)
        self.command_timeout = False
        self.halted, self.halt_reason = False, ""
        self.applied = Applied(np.zeros(sc.n_wheels))

    def set_command(self, command: Command) -> str | None:
        """Accept a command (None) or say why it is rejected; a rejected command changes nothing."""
        if command.mode not in CONTROL_MODES:
            return f"mode {command.mode} is not one of {CONTROL_MODES}"
        wheel_torque = np.asarray(command.wheel_torques, float)
        if wheel_torque.size not in (0, self.sc.n_wheels):
            return f"wheel_torques has {wheel_torque.size} entries, the spacecraft has {self.sc.n_wheels} wheels"
        for name, v in (("wheel_torques", wheel_torque), ("dipole", command.dipole),
                        ("body_torque", command.body_torque)):
            if not np.all(np.isfinite(v)):
                return f"{name} contains NaN or Inf"
        idle = command.mode == ControlMode.IDLE
        self.wheel_cmd = np.zeros(self.sc.n_wheels) if idle or wheel_torque.size == 0 else wheel_torque
        self.dipole_cmd = np.zeros(3) if idle else np.asarray(command.dipole, float)
        self.body_cmd = np.zeros(3) if idle else np.asarray(command.body_torque, float)
        return None

    def reset(self, q, omega, wheel_speed, orbit_phase: float) -> str | None:
        q, omega = np.asarray(q, float), np.asarray(omega, float)
        wheel_speed = np.zeros(self.sc.n_wheels) if len(wheel_speed) == 0 else np.asarray(wheel_speed, float)
        if not (np.all(np.isfinite(q)) and np.all(np.isfinite(omega)) and np.all(np.isfinite(wheel_speed))
                and math.isfinite(orbit_phase)):
            return "reset values contain NaN or Inf"
        if abs(np.linalg.norm(q) - 1.0) > 1e-3:
            return f"attitude norm {np.linalg.norm(q):.6g} is not 1 (tolerance 1e-3)"
        if wheel_speed.size != self.sc.n_wheels:
            return f"wheel_speeds has {wheel_speed.size} entries, the spacecraft has {self.sc.n_wheels} wheels"
        self.x = dyn.initial_state(self.sc, q, omega, wheel_speed)
        self.arg0 = orbit_phase - self.orbit.mean_motion * self.t
        self.halted, self.halt_reason = False, ""
        return None

    def position(self) -> np.ndarray:
        return env.position(self.orbit, self.t, self.arg0)

    def state(self, frame_id: str = "", body_frame_id: str = "") -> State:
        """The truth state now, with what acted during the last step."""
        x, a = self.x, self.applied
        return State(t=self.t, q=x[:4].copy(), omega=x[4:7].copy(), wheel_speeds=x[7:].copy(),
                     wheel_torques=a.wheel_torque, field_body=a.field_body, dipole=a.dipole,
                     applied_torque=a.body_torque, position=self.position(), command_timeout=self.command_timeout,
                     frame_id=frame_id, body_frame_id=body_frame_id)

    def inputs(self) -> dyn.Inputs:
        """Inputs for the next step: limits applied, zero while the command watchdog is tripped."""
        q, ws = self.x[:4], self.x[7:]
        active = not self.command_timeout
        u = dyn.effective_wheel_torque(self.sc, ws, self.wheel_cmd if active else np.zeros_like(self.wheel_cmd))
        m = np.clip(self.dipole_cmd, -self.sc.dipole_max, self.sc.dipole_max) if active else np.zeros(3)
        tau = np.clip(self.body_cmd, -self.sc.body_torque_max, self.sc.body_torque_max) if active else np.zeros(3)
        b_body = env.field_body(self.orbit, self.t, q, self.arg0)
        gg = (env.gravity_gradient_torque(self.orbit, self.t, q, self.sc.inertia, self.arg0)
              if self.gravity_gradient else None)
        return dyn.Inputs(wheel_torque=u, body_torque=tau, dipole=m, field_body=b_body, gravity_gradient=gg)

    def advance(self, dt: float) -> None:
        """One RK4 step with the inputs held; a non-finite result halts the simulation."""
        inp = self.inputs()
        x_new = dyn.step(self.sc, self.x, inp, dt)
        if not np.all(np.isfinite(x_new)):
            self.halted = True
            self.halt_reason = f"state became non-finite at t = {self.t:.3f} s; propagation stopped"
            return
        tau = dyn.external_torque(self.sc, inp, self.x[:4]) - self.sc.wheel_axes @ inp.wheel_torque
        self.applied = Applied(inp.wheel_torque, inp.dipole, inp.field_body, tau)
        self.x = x_new
        self.t += dt
