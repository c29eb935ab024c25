"""The responses acted on (no ROS): the controller's allocation and safe mode, the estimator's exclusions.

:func:`act` takes :class:`~.responses.Responses` (a pure function of the monitor's active faults) and
sets what the controller and the estimator fly on, the same call for a node and for the in-process
closed loop:

* the controller's ``healthy`` mask (None with every wheel healthy): each wheel command, the batched
  tracking law included, is allocated on the healthy wheels
  (:func:`att_planner.control.wheels.wheel_command` with ``healthy=``);
* the estimator's ``excluded`` sensors;
* with ``safe_mode``, the controller switched to safe mode (a maneuver in flight is aborted); its
  actuation on what is left (:class:`SafeActuator`) when the healthy wheels no longer span the body
  or the gyro is not trusted, the controller's own safe law otherwise; with zones known (those of the
  maneuver safe mode interrupted, else the controller's ``safe_zones``: the scenario's) and wheels
  that span the body, safe mode among those zones (:class:`~.safe_flight.ZoneKeeper`).
"""
from __future__ import annotations

import numpy as np

from att_msgs_py.types import ControlMode, ManeuverResult
from att_planner.fdir import safe_mode
from att_planner.fdir.responses import Responses
from att_planner.fdir.safe_flight import ZoneKeeper


class SafeActuator:
    """Safe mode's actuation on what is left (:func:`.safe_mode.damping`): ``−K_d ω`` on the healthy
    wheels or, when they do not span the body, on the coils by the cross-product law; B-dot on the
    coils when the gyro is not trusted. The B-dot gain is ``K_d / |B|²`` (the damping ``K_d`` the
    cross-product law gives about the axes normal to the field, since ``m × B = −k (B × (ω × B))``)
    and ``Ḃ_B`` the difference of the last two fields the controller held. Returns None where the
    controller's own safe law (wheels, then Sun pointing) applies. With a ``keeper``
    (:class:`~.safe_flight.ZoneKeeper`: the zones are known) and wheels that span the body, the
    keeper flies safe mode among the zones, with the gyro or without it."""

    def __init__(self, kd: float, dipole_max: float, wheels_controllable: bool, gyro_trusted: bool,
                 keeper: ZoneKeeper | None = None):
        self.kd, self.dipole_max = kd, dipole_max
        self.controllable, self.gyro_trusted = wheels_controllable, gyro_trusted
        self.keeper = keeper
        self.last: tuple[float, np.ndarray] | None = None     # (t, field_B) of the previous call

    def __call__(self, state) -> safe_mode.SafeActuation | None:
        field = np.asarray(state.field_body, float)
        rate = np.zeros(3)
        if self.last is not None and state.t > self.last[0] and field.size == 3:
            rate = (field - self.last[1]) / (state.t - self.last[0])
        if field.size == 3:
            self.last = (float(state.t), field.copy())
        if self.controllable and self.keeper is not None:
            return self.keeper(state, self.gyro_trusted)
        if self.controllable and self.gyro_trusted:
            return None
        b2 = float(field @ field) if field.size == 3 else 0.0
        gain = self.kd / b2 if b2 > 0.0 else 0.0
        return safe_mode.damping(state.omega, field if field.size == 3 else np.zeros(3), rate, self.kd, gain,
                                 self.dipole_max, self.controllable, self.gyro_trusted)


def act(r: Responses, controller, estimator=None) -> ManeuverResult | None:
    """Fly ``controller`` (and ``estimator``, when given; a controller None: the estimator alone, as in
    the estimator node) on the responses ``r`` (module docstring); the result of a maneuver that safe
    mode aborted."""
    if estimator is not None:
        estimator.excluded = set(r.excluded_sensors)
    if controller is None:
        return None
    controller.healthy = None if all(r.healthy_wheels) else tuple(r.healthy_wheels)
    ended = None
    if r.safe_mode:
        flown = controller.maneuver.zones if controller.maneuver is not None else None   # before the abort
        zones = flown if flown is not None else getattr(controller, "safe_zones", None)
        if controller.mode != ControlMode.SAFE:
            _, _, ended = controller.set_mode(ControlMode.SAFE)
        actuator = controller.safe_actuation
        if actuator is None or (actuator.controllable, actuator.gyro_trusted) != (r.wheels_controllable,
                                                                                  r.gyro_trusted):
            keeper = actuator.keeper if actuator is not None else None
            if keeper is None and zones is not None and r.wheels_controllable:
                keeper = ZoneKeeper(zones, controller.spacecraft, controller.guidance_sky, controller.config,
                                    r.healthy_wheels)
            controller.safe_actuation = SafeActuator(controller.config.safe_kd, controller.m_max,
                                                     r.wheels_controllable, r.gyro_trusted, keeper)
    else:
        controller.safe_actuation = None
    return ended
