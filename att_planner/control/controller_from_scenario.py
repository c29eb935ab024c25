"""The controller core built from a scenario and its parameters (no ROS).

:func:`controller_from_scenario` reads every parameter of the controller's core through ``param``
— the node's :class:`~att_msgs_py.node_runner.ParameterReader` (ROS parameters over the scenario's
``controller`` section) or a :class:`~att_msgs_py.parameters.SectionReader` (the section alone, for
the in-process closed loop) — so the node and the in-process loop fly the same controller. Each
bad value is one :class:`~att_msgs_py.errors.ConfigError` line.
"""
from __future__ import annotations

import math

import numpy as np

from att_msgs_py import signing
from att_msgs_py.errors import ConfigError, ErrorCode, clip
from att_msgs_py.types import ControlMode
from att_planner.control.controller import Controller, ControllerConfig
from att_planner.control.measured_state import MeasuredState
from att_planner.control.plan_checks import PlanContext
from att_planner.control.state_gate import GateConfig
from att_planner.guidance.laws import PointingGeometry
from att_sim.models import world
from att_sim.models.ephemeris import Ephemeris
from att_sim.models.scenario import Scenario

STATE_SOURCES = ("truth", "estimate")


def public_key(param, name: str):
    """The Ed25519 public key file of parameter ``name`` (default: the suite's key directory)."""
    path = param(name, str(signing.default_key_dir() / signing.PUBLIC_NAME))
    try:
        return signing.load_public_key(path)
    except (OSError, ValueError) as exc:
        raise ConfigError(ErrorCode.INVALID_CONFIG, f"parameter '{name}': no Ed25519 public key at "
                                                    f"'{clip(path, 200)}' ({clip(exc, 120)}): run att-keygen, or "
                                                    "copy the planner's plan_signing.pub") from None


def controller_config(param, scenario: Scenario) -> ControllerConfig:
    d = ControllerConfig()
    tracking_kd = param("tracking_kd", d.tracking_kd, 0.0)
    m_max = param("m_max", scenario.spacecraft.dipole_max)
    if not m_max > 0:
        raise ConfigError(ErrorCode.INVALID_PARAMETER, f"parameter 'm_max': expected a dipole > 0 A m², got {m_max}")
    return ControllerConfig(
        control_period=1.0 / param("control_rate", 1.0 / d.control_period, 0.0, 1000.0, low_open=True),
        settle_time=param("settle_time", d.settle_time, 0.0, 86_400.0),
        tracking_kp=param("tracking_kp", d.tracking_kp, 0.0), tracking_kd=tracking_kd,
        kp=param("kp", d.kp, 0.0), kd=param("kd", d.kd, 0.0), m_max=m_max,
        safe_kd=param("safe_kd", tracking_kd, 0.0),
        max_cached_plans=param("max_cached_plans", d.max_cached_plans, 1, 10_000),
        max_cache_bytes=int(param("max_cache_mb", d.max_cache_bytes / 2**20, 0.0, 4096.0, low_open=True) * 2**20),
        safe_rate_threshold=param("safe_rate_threshold", d.safe_rate_threshold, 0.0, 10.0, low_open=True),
        dumping=param("momentum_dumping", d.dumping),
        dumping_gain=param("dumping_gain", d.dumping_gain, 0.0, 10.0, low_open=True),
        null_space_gain=param("null_space_gain", d.null_space_gain, 0.0, 10.0),
        null_space_speed=param("null_space_speed", d.null_space_speed, -1e4, 1e4),
        handover_blend=param("handover_blend", d.handover_blend, 0.0, 3600.0),
        safe_sun_axis=tuple(_unit_param(param, "safe_sun_axis", list(d.safe_sun_axis))))


def _unit_param(param, name: str, default: list) -> np.ndarray:
    """A parameter that is a unit vector (3 numbers, norm within 1e-3 of 1), normalised."""
    v = np.asarray(param(name, default, -1.0, 1.0, length=3), float)
    norm = float(np.linalg.norm(v))
    if abs(norm - 1.0) > 1e-3:
        raise ConfigError(ErrorCode.INVALID_PARAMETER, f"parameter '{name}': expected a unit vector, got norm "
                                                       f"{norm:.6g}")
    return v / norm


def plan_context(param, scenario: Scenario, key=None) -> PlanContext:
    """What plans must match; ``key``: the planner's public key (default: parameter ``plan_public_key``)."""
    return PlanContext(
        scenario.spacecraft, scenario.name, scenario.frame_id, key or public_key(param, "plan_public_key"),
        max_start_attitude_error=math.radians(param("max_start_attitude_error_deg", 5.0, 0.0, 180.0, low_open=True)),
        max_start_rate_error=param("max_start_rate_error", 0.01, 0.0, 10.0, low_open=True),
        epoch=scenario.epoch,
        max_start_epoch_error=param("max_start_epoch_error", 10.0, 0.0, 86_400.0, low_open=True))


def gate_config(param) -> GateConfig:
    d = GateConfig()
    return GateConfig(max_state_gap=param("max_state_gap", d.max_state_gap, 0.0, 3600.0, low_open=True),
                      max_clock_skew=param("max_clock_skew", d.max_clock_skew, 0.0, 3600.0, low_open=True),
                      resync_timeout=param("resync_timeout", d.resync_timeout, 0.0, 3600.0, low_open=True))


def measured_state(source: str, scenario: Scenario) -> MeasuredState | None:
    """What the controller flies on with ``state_source: estimate`` (None: the truth)."""
    if source == "truth":
        return None
    if scenario.spacecraft.n_wheels and scenario.sensors.tachometer is None:
        raise ConfigError(ErrorCode.INVALID_PARAMETER, "parameter 'state_source': estimate needs the wheel speeds: "
                                                       "the scenario has no sensors.wheel_tachometer")
    return MeasuredState(scenario.spacecraft, scenario.sensors, scenario.frame_id, scenario.body_frame_id)


def controller_from_scenario(param, scenario: Scenario, key=None) -> Controller:
    """The controller core of ``scenario`` with its parameters: ``state_source`` (default
    ``estimate`` when the scenario has a gyro), ``friction_compensation`` (default: on when its wheel
    drives have friction), gains, start tolerances, the state gate and the plan key."""
    source = param("state_source", "estimate" if scenario.sensors.gyro else "truth", choices=list(STATE_SOURCES))
    wheels = scenario.actuators.wheels
    compensate = param("friction_compensation", bool(wheels and (wheels.coulomb_friction or wheels.viscous_friction)))
    sky = None if scenario.epoch is None else Ephemeris(scenario.epoch, scenario.orbit_model)
    mode = param("initial_mode", int(ControlMode.IDLE),
                 choices=[int(m) for m in ControlMode if m not in (ControlMode.PLAN_TRACKING, ControlMode.POINTING)])
    return Controller(plan_context(param, scenario, key), controller_config(param, scenario), mode,
                      scenario.body_frame_id, gate_config(param), sky, measured_state(source, scenario),
                      wheels.friction if compensate and wheels else None,
                      PointingGeometry.of(world.Environment.from_scenario(scenario)))
