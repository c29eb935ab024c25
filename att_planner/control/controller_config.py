"""The controller's gains and timing (its node's parameters, :mod:`.from_scenario`)."""
from __future__ import annotations

import math
from dataclasses import dataclass


@dataclass(frozen=True)
class ControllerConfig:
    """Gains and timing (the controller node's parameters)."""

    control_period: float = 0.1        # s of sim time between commands
    settle_time: float = 20.0          # s held on the final attitude after the plan ends
    tracking_kp: float = 0.4           # N m / rad, attitude feedback around the plan reference
    tracking_kd: float = 10.0          # N m s / rad
    kp: float = 2e5                    # magnetorquer PD-like law (Bruni & Celani)
    kd: float = 1e8
    m_max: float = math.inf            # A m² per coil (default: the spacecraft's dipole limit)
    safe_kd: float = 10.0              # N m s / rad, rate damping of the safe mode
    feedback_period: float = 0.5       # s of sim time between action feedbacks
    max_cached_plans: int = 50
    max_cache_bytes: int = 64 * 1024 * 1024   # serialized plans kept
    safe_rate_threshold: float = 0.005  # rad/s: found rotating faster at start, the controller damps (safe mode)
    dumping: bool = False              # magnetorquer momentum dumping
    dumping_gain: float = 1e-3         # 1/s: k of m = k (Δh × B)/|B|²
    null_space_gain: float = 0.05      # 1/s: wheel speeds' null-space component to its bias (more than 3 wheels)
    null_space_speed: float = 0.0      # rad/s: that bias, along each null-space direction
    safe_sun_axis: tuple = (0.0, 0.0, 1.0)   # body axis the safe mode points at the Sun once the rates are damped
    handover_blend: float = 60.0       # s: a plan ending at rest enters a moving pointing reference this smoothly

    @property
    def feedback_every(self) -> int:
        """Control steps between action feedbacks."""
        return max(1, round(self.feedback_period / self.control_period))
