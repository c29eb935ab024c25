"""The controller's state when it flies on measurements (``state_source: estimate``, no ROS).

:class:`MeasuredState` keeps the latest wheel tachometer sample and the latest *clean* magnetometer
sample (taken while the magnetorquers were off: :class:`~att_planner.estimation.inputs.DipoleLog`),
each checked like every input, and composes them with an attitude estimate into the
:class:`~att_msgs_py.types.State` the controller's laws take: attitude and rate from the estimate,
inertial wheel spin rates ``Ω = ν + Gᵀω`` from the measured relative speeds ``ν``, the field in
body axes from the magnetometer. It also plans the magnetometer's blanking: the controller
commands no dipole over the control period that ends at a magnetometer sample.

The estimate's rate is the gyro's, less its bias: the mean body rate over the gyro's interval
ending at the stamp (:mod:`att_sim.truth.sensors.gyro`), to first order the rate half an interval
earlier. The state's rate is the rate at the stamp: the mean advanced by half the interval
``Δt`` (since the previous estimate flown, the estimator publishing one per gyro sample) with the body
acceleration of the latest command, held over that interval (Euler's equation with the wheels)::

    ω(t) = ω̄ + (Δt / 2) J⁻¹ (−G u + m × B − ω̄ × (J ω̄ + G J_s Ω))

``u`` the commanded wheel motor torques, ``m`` the commanded dipole, ``B`` the measured field, the
disturbances left out. Without that, a rate-feedback gain ``K_d`` reads a changing rate half an
interval late: an error ``K_d ω̇ Δt / 2`` of torque at every step, which at a few hertz is the
largest error of an agile slew. No advance over the first estimate, a gap longer than
:data:`MAX_ADVANCE_INTERVAL` or without a command within it.
"""
from __future__ import annotations

import math

import numpy as np

from att_msgs_py import validation
from att_msgs_py.errors import ErrorCode, RequestError
from att_msgs_py.types import AttitudeEstimate, Health, MagnetometerMeasurement, State, WheelSpeedMeasurement
from att_planner.estimation.inputs import DipoleLog, InputChecks
from att_sim.models import rotations as rot
from att_sim.models.dynamics import Spacecraft
from att_sim.models.sensor_specs import SensorSpecs

BAD = ErrorCode.INVALID_MEASUREMENT
HEALTHS = tuple(Health)
MAX_ADVANCE_INTERVAL = 1.0     # s: a longer gap between estimates is not a gyro interval (no advance)


class MeasuredState:
    def __init__(self, spacecraft: Spacecraft, specs: SensorSpecs, frame_id: str, body_frame_id: str):
        self.spacecraft, self.specs, self.body_frame_id = spacecraft, specs, body_frame_id
        self.checks = InputChecks(specs, frame_id, body_frame_id)
        self.dipoles = DipoleLog()
        self.wheel_speeds: np.ndarray | None = None     # relative to the body, rad/s
        self.field_B = np.zeros(3)                      # T, body axes: the latest clean sample
        self.magnetometer_period = 1.0 / specs.magnetometer.rate if specs.magnetometer else None
        self.command: tuple | None = None               # (t, wheel torques, dipole) the latest command

    def record_command(self, t: float, wheel_torques, dipole_B) -> None:
        """The command issued at ``t`` (held until the next): what turns the body until the next estimate."""
        self.command = (float(t), np.array(wheel_torques, float), np.array(dipole_B, float))

    def on_wheel_speeds(self, m: WheelSpeedMeasurement) -> None:
        sc = self.spacecraft
        if not (isinstance(m.t, float | int) and math.isfinite(m.t)):
            raise RequestError(BAD, f"wheel speed stamp {m.t!r} is not finite")
        if m.frame_id != self.body_frame_id:
            raise RequestError(BAD, f"wheel speed header.frame_id '{str(m.frame_id)[:64]}' is not "
                                    f"'{self.body_frame_id}'")
        speeds = validation.finite_array(m.speeds, "wheel speed velocity", BAD, (sc.n_wheels,))
        if validation.peak(speeds) > 2 * sc.wheel_speed_max:
            raise RequestError(BAD, f"wheel speed velocity reaches {validation.peak(speeds):.6g} rad/s, more than "
                                    f"twice the limit {sc.wheel_speed_max:g}")
        self.wheel_speeds = speeds

    def on_magnetometer(self, m: MagnetometerMeasurement) -> None:
        field = self.checks.magnetometer(m)
        if self.dipoles.clean(m.t):
            self.field_B = field

    def blank(self, t: float, period: float) -> bool:
        """Whether a magnetometer sample falls in the control period (t, t + period]: the coils
        stay off over it, so that sample is clean."""
        p = self.magnetometer_period
        if p is None:
            return False
        return (math.floor(t / p + 1e-9) + 1) * p <= t + period + 1e-9

    def rate_at_stamp(self, t: float, omega_mean_B: np.ndarray, previous: float | None) -> np.ndarray:
        """The body rate at the estimate's stamp ``t`` from its rate, the gyro's mean over the interval
        ending there since ``previous``, the stamp of the estimate flown before (module docstring)."""
        command = self.command
        if previous is None or command is None or not 0.0 < t - previous <= MAX_ADVANCE_INTERVAL \
                or not 0.0 < t - command[0] <= MAX_ADVANCE_INTERVAL:
            return omega_mean_B
        sc, (_, u, m_B) = self.spacecraft, command
        w = omega_mean_B
        torque_B = rot.cross(m_B, self.field_B) if m_B.size else np.zeros(3)
        if sc.n_wheels and self.wheel_speeds is not None and u.size == sc.n_wheels:
            spin = self.wheel_speeds + sc.wheel_axes.T @ w
            torque_B = torque_B - sc.wheel_axes @ u - rot.cross(w, sc.wheel_axes @ (sc.wheel_inertia * spin))
        omega_dot = np.linalg.solve(sc.inertia, torque_B - rot.cross(w, sc.inertia @ w))
        return w + 0.5 * (t - previous) * omega_dot

    def compose(self, estimate: AttitudeEstimate, previous: float | None = None) -> State:
        """The state of ``estimate`` with the measured wheel speeds (made inertial) and field, its rate
        at its stamp (``previous``: the stamp of the estimate flown before, None for none); an
        estimate of a health the message does not define is refused (310)."""
        if estimate.health not in HEALTHS:
            raise RequestError(ErrorCode.INVALID_STATE, f"estimate health {estimate.health!r} is not one of "
                                                        f"{[int(h) for h in Health]}")
        n = self.spacecraft.n_wheels
        if n and self.wheel_speeds is None:
            raise RequestError(ErrorCode.NO_STATE, "no wheel speed measurement yet")
        omega = self.rate_at_stamp(estimate.t, np.asarray(estimate.omega, float), previous)
        relative = self.wheel_speeds if n else np.zeros(0)
        inertial = relative + self.spacecraft.wheel_axes.T @ omega if n else relative
        return State(t=estimate.t, q=np.asarray(estimate.q, float), omega=omega, wheel_speeds=inertial,
                     field_body=self.field_B.copy(), frame_id=estimate.frame_id, body_frame_id=estimate.body_frame_id)
