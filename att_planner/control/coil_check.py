"""The active magnetorquer check (no ROS, pure): a known dipole on each coil in turn, read back by the
magnetometer, its torque fed forward to the wheels.

A coil that is never commanded cannot be seen to have failed (:mod:`att_planner.fdir.coils`), and
the momentum dumping's smooth dipole cannot be told from the disturbances within 30 s. So, as on a
commissioning or periodic health check of the attitude control system, the controller pulses each
coil in turn with a known dipole and lets the magnetometer read it back: the magnetometer measures
the spacecraft's own dipole with it, ``B̃ = B + k m_applied`` (``k``: the coupling of the datasheet,
T per A m², along the applied dipole; :mod:`att_sim.truth.sensors.magnetometer`), which is why the
controller otherwise keeps the coils off over the control period that ends at a magnetometer sample
(blanking, :meth:`att_planner.control.measured_state.MeasuredState.blank`). The check takes one
magnetometer sample every ``period_s`` (a *check sample*, the ``n``-th since the epoch) out of the
blanking: over the ``dwell_s`` before it the dipole commanded is

    ``m = s_n a m_max e_c(n)``,  ``c(n) = n mod 3``,  ``s_n = +1`` for ``⌊n/3⌋`` even, else ``−1``,

coil ``c(n)`` alone at the fraction ``a`` of the coils' limit, each coil's sign alternating from one
visit to the next (a ± square wave per coil, a visit every ``3 period_s``): zero mean, so the pattern
is orthogonal to a constant and nearly so to a line (the field's slow drift, the magnetometer bias).
Every other dipole (the momentum dumping's) stays off over those steps. The magnetic torque
``m × B̂`` (``B̂`` the last clean field measured) is fed forward to the wheels, ``δu = A (m × B̂)``
(``A`` the allocation on the healthy wheels, :func:`att_planner.control.wheels.healthy_allocation`):
a healthy coil leaves the attitude untouched to the field's and the coil's errors (a 0.2 % field
error and a 0.5 deg coil misalignment leave 1 % of ``a m_max |B|``, a few 1e-6 N m, for ``dwell_s``);
an open coil kicks the body by ``a m_max |B| dwell_s`` (under 1e-4 N m s) per visit. The sample is
not clean for the controller's and the estimator's field (their :class:`DipoleLog
<att_planner.estimation.inputs.DipoleLog>` sees the dipole commanded): they keep the previous one.
Nothing is checked in safe mode, in magnetorquer modes or without a field measured (zero).
"""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from att_sim.models import rotations as rot


@dataclass(frozen=True)
class CoilCheck:
    """The check's pattern (module docstring): ``period_s`` between two check samples, ``fraction`` of
    the coils' limit commanded, ``dwell_s`` the dipole is held before each, for a magnetometer sampled
    every ``magnetometer_period_s``."""

    period_s: float
    fraction: float
    dwell_s: float
    magnetometer_period_s: float

    @property
    def every(self) -> int:
        """Magnetometer samples between two check samples (at least 1)."""
        return max(int(round(self.period_s / self.magnetometer_period_s)), 1)

    def dipole(self, t: float, control_period_s: float, m_max: float) -> np.ndarray | None:
        """The check's dipole (A m², body axes) commanded at the control step ``t`` (in force over
        ``(t, t + control_period_s]``), or None when no check sample follows within the dwell."""
        p = self.magnetometer_period_s
        n = math.floor(t / p + 1e-9) + 1                    # the next magnetometer sample after t
        n += (-n) % self.every                              # the next check sample
        s = n * p
        if not s - t < self.dwell_s + control_period_s - 1e-9:
            return None
        visit = n // self.every
        m = np.zeros(3)
        m[visit % 3] = (1.0 if (visit // 3) % 2 == 0 else -1.0) * self.fraction * m_max
        return m


def feedforward(dipole_B, field_B, allocation) -> np.ndarray:
    """``δu = A (m × B)`` (N m per wheel): the wheel torques that take the magnetic torque ``m × B``
    back off the body (``allocation``: N × 3, the wheels' motor torque per body torque, negated)."""
    return np.asarray(allocation, float) @ rot.cross(np.asarray(dipole_B, float), np.asarray(field_B, float))
