"""Safe mode flown among the zones on the healthy wheels (no ROS): the state the laws of
:mod:`.safe_zones` need from one control step to the next.

:class:`ZoneKeeper` is called at each control step of safe mode with the controller's state (the
estimate) while the healthy wheels span the body and the zones of the maneuver safe mode interrupted
are known:

1. the body rate: the estimate's with the gyro trusted; else the rate the angular momentum leaves to
   the body (:func:`.safe_zones.rate_from_momentum`), the momentum taken at the first step without
   the gyro from the estimate of that step (a gyro fault is isolated within seconds of its onset);
2. rate damping ``τ = −K_d ω`` (``safe_kd``) until the rate is below
   :data:`.safe_zones.RATE_DAMPED_RAD_S`, then the approach (:func:`.safe_zones.approach_torque`, the
   tracking gains) to the Sun attitude chosen once at that moment
   (:func:`.safe_zones.choose_sun_attitude`: ``safe_sun_axis`` on the Sun, the free rotation about
   the Sun line keeping the zones clear along the approach and for :data:`HOLD_HORIZON_S` of hold);
   without a Sun to see the body is kept at rest;
3. every torque through the zone barrier (:func:`.safe_zones.barrier_torque`) with the zones where
   they are at that step and their own drift (over :data:`DRIFT_STEP_S`), within the torque the
   healthy wheels give in any direction (:func:`.safe_zones.torque_authority`).
"""
from __future__ import annotations

import numpy as np

from att_planner.fdir import safe_zones as sz
from att_planner.fdir.safe_mode import SafeActuation

HOLD_HORIZON_S = 6000.0       # s of hold the Sun attitude is checked over (a low Earth orbit and more)
HOLD_STEP_S = 60.0            # s between the checked instants of the hold
DRIFT_STEP_S = 1.0            # s: the zones' own margin rate is their difference over this step


class ZoneKeeper:
    """Safe mode among ``zones`` (:class:`att_planner.zones.FittedZones`; their sky at any time) for
    ``spacecraft`` on its wheels ``healthy`` (mask, None: all), the Sun from ``geometry``
    (:class:`att_planner.guidance.laws.PointingGeometry`, None: no Sun), the gains of ``config``
    (:class:`att_planner.control.controller_config.ControllerConfig`); module docstring."""

    def __init__(self, zones, spacecraft, geometry, config, healthy=None):
        self.zones, self.spacecraft, self.geometry, self.config = zones, spacecraft, geometry, config
        mask = np.ones(spacecraft.n_wheels, bool) if healthy is None else np.asarray(healthy, bool)
        self.torque_max = sz.torque_authority(spacecraft.wheel_axes[:, mask], spacecraft.wheel_torque_max)
        if not self.torque_max > 0.0:
            raise ValueError("the healthy wheels do not span the body: safe mode among the zones needs them")
        self.momentum_N: np.ndarray | None = None       # N m s, taken at the first step without the gyro
        self.target: np.ndarray | None = None           # q_BN of the Sun attitude, once chosen
        self.target_margin = np.nan                     # rad, its worst margin when chosen
        self.active = np.zeros(len(zones.zones), bool)  # the zones whose barrier acted at the last step

    def rate(self, state, gyro_trusted: bool) -> np.ndarray:
        """The body rate safe mode flies on (module docstring, 1)."""
        sc = self.spacecraft
        h_wheels_B = sc.wheel_axes @ (sc.wheel_inertia * np.asarray(state.wheel_speeds, float))
        if gyro_trusted:
            return np.asarray(state.omega, float)
        if self.momentum_N is None:
            self.momentum_N = sz.momentum_N(state.q, state.omega, sc.inertia, h_wheels_B)
        return sz.rate_from_momentum(state.q, self.momentum_N, sc.inertia, h_wheels_B)

    def sun_target(self, state) -> None:
        """Choose the Sun attitude from the state's attitude (module docstring, 2)."""
        sun = self.geometry.sun_N(state.t) if self.geometry is not None and self.geometry.sun_N is not None else None
        if sun is None:
            return
        t = float(state.t)
        q = np.asarray(state.q, float)
        candidates = sz.sun_attitudes(sun, self.config.safe_sun_axis)
        approach_s = np.pi / sz.SLEW_RATE_RAD_S + 120.0        # the longest approach, and its settling
        path_axes, path_half = self.zones.at(t + np.linspace(0.0, approach_s, sz.PATH_POINTS), true=True)
        hold_axes, hold_half = self.zones.at(t + np.arange(0.0, HOLD_HORIZON_S + HOLD_STEP_S, HOLD_STEP_S), true=True)
        self.target, self.target_margin = sz.choose_sun_attitude(
            q, candidates, self.zones.sensor_axes, path_axes, path_half, hold_axes, hold_half, self.zones.keep_in)

    def __call__(self, state, gyro_trusted: bool) -> SafeActuation:
        c = self.config
        omega = self.rate(state, gyro_trusted)
        if self.target is None and float(np.linalg.norm(omega)) <= sz.RATE_DAMPED_RAD_S:
            self.sun_target(state)
        if self.target is None:
            nominal, law = -c.safe_kd * omega, "wheels_among_zones"
        else:
            nominal, law = sz.approach_torque(state.q, omega, self.target, c.tracking_kp, c.tracking_kd), \
                "sun_among_zones"
        t = float(state.t)
        axes, half = self.zones.at(np.array([t, t + DRIFT_STEP_S]), true=True)
        now, later = (sz.margins(state.q, self.zones.sensor_axes, axes[k], half[k], self.zones.keep_in) for k in (0, 1))
        tau, self.active = sz.barrier_torque(state.q, omega, nominal, self.zones.sensor_axes, axes[0], half[0],
                                             self.zones.keep_in, self.spacecraft.inertia, self.torque_max,
                                             (later - now) / DRIFT_STEP_S)
        return SafeActuation(True, tau, np.zeros(3), law)
