"""The controller core built from a scenario and its parameters (no ROS).

:func:`controller_from_scenario` reads every parameter of the controller's core through ``param``
— the node's :class:`~att_msgs_py.node_runner.ParameterReader` (ROS parameters over the scenario's
``controller`` section) or a :class:`~att_msgs_py.parameters.SectionReader` (the section alone, for
the in-process closed loop), both over the declarations of
:data:`~att_planner.control.controller_parameters.CONTROLLER` — so the node and the in-process loop
fly the same controller. Each
bad value is one :class:`~att_msgs_py.errors.ConfigError` line.
"""
from __future__ import annotations

import math

import numpy as np

from att_msgs_py import signing
from att_msgs_py.errors import ConfigError, ErrorCode, clip
from att_planner.control.controller import Controller, ControllerConfig
from att_planner.control.maneuver import ZONE_FIT_WINDOW
from att_planner.control.measured_state import MeasuredState
from att_planner.control.plan_checks import PlanContext
from att_planner.control.state_gate import GateConfig
from att_planner.guidance.laws import PointingGeometry
from att_planner.zones import FittedZones
from att_sim.models import world
from att_sim.models.ephemeris import Ephemeris
from att_sim.models.scenario import Scenario


def public_key(param, name: str, load: bool = True):
    """The Ed25519 public key file of parameter ``name`` (default: the suite's key directory), read
    (``load``: else the parameter is read and checked, and None returned)."""
    path = param(name, str(signing.default_key_dir() / signing.PUBLIC_NAME))
    if not load:
        return None
    try:
        return signing.load_public_key(path)
    except (OSError, ValueError) as exc:
        raise ConfigError(ErrorCode.INVALID_CONFIG, f"parameter '{name}': no Ed25519 public key at "
                                                    f"'{clip(path, 200)}' ({clip(exc, 120)}): run att-keygen, or "
                                                    "copy the planner's plan_signing.pub") from None


def controller_config(param, scenario: Scenario) -> ControllerConfig:
    """The core's gains and timing from the parameters of :data:`CONTROLLER`."""
    tracking_kd = param("tracking_kd")
    return ControllerConfig(
        control_period=1.0 / param("control_rate_Hz"), settle_time=param("settle_time_s"),
        tracking_kp=param("tracking_kp"), tracking_kd=tracking_kd, kp=param("kp"), kd=param("kd"),
        m_max=param("m_max_Am2", scenario.spacecraft.dipole_max), safe_kd=param("safe_kd", tracking_kd),
        max_cached_plans=param("max_cached_plans"), max_cache_bytes=int(param("max_cache_MiB") * 2**20),
        safe_rate_threshold=param("safe_rate_threshold_rad_s"), dumping=param("momentum_dumping"),
        dumping_gain=param("dumping_gain"), null_space_gain=param("null_space_gain"),
        null_space_speed=param("null_space_speed_rad_s"), handover_blend=param("handover_blend_s"),
        safe_sun_axis=tuple(_unit_param(param, "safe_sun_axis")))


def _unit_param(param, name: str) -> np.ndarray:
    """A parameter that is a unit vector (3 numbers, norm within 1e-3 of 1), normalised."""
    v = np.asarray(param(name), float)
    norm = float(np.linalg.norm(v))
    if abs(norm - 1.0) > 1e-3:
        raise ConfigError(ErrorCode.INVALID_PARAMETER, f"parameter '{name}': expected a unit vector, got norm "
                                                       f"{norm:.6g}")
    return v / norm


def plan_context(param, scenario: Scenario, key=None) -> PlanContext:
    """What plans must match; ``key``: the planner's public key (default: parameter ``plan_public_key``)."""
    return PlanContext(
        scenario.spacecraft, scenario.name, scenario.frame_id, key or public_key(param, "plan_public_key"),
        max_start_attitude_error=math.radians(param("max_start_attitude_error_deg")),
        max_start_rate_error=param("max_start_rate_error_rad_s"),
        epoch=scenario.epoch,
        max_start_epoch_error=param("max_start_epoch_error_s"))


def gate_config(param) -> GateConfig:
    return GateConfig(max_state_gap=param("max_state_gap_s"), max_clock_skew=param("max_clock_skew_s"),
                      resync_timeout=param("resync_timeout_s"))


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
    source = param("state_source", "estimate" if scenario.sensors.gyro else "truth")
    wheels = scenario.actuators.wheels
    compensate = param("friction_compensation", bool(wheels and (wheels.coulomb_friction or wheels.viscous_friction)))
    sky = None if scenario.epoch is None else Ephemeris(scenario.epoch, scenario.orbit_model)
    mode = param("initial_mode")
    controller = Controller(plan_context(param, scenario, key), controller_config(param, scenario), mode,
                            scenario.body_frame_id, gate_config(param), sky, measured_state(source, scenario),
                            wheels.friction if compensate and wheels else None,
                            PointingGeometry.of(world.Environment.from_scenario(scenario)))
    controller.safe_zones = scenario_zones(scenario, sky)
    return controller


def scenario_zones(scenario: Scenario, sky: Ephemeris | None) -> FittedZones | None:
    """The scenario's zones on ``sky`` (those that move left out without one), the zones safe mode keeps
    clear of (:mod:`att_planner.fdir.safe_flight`); None when there are none."""
    zones = [z for z in scenario.zones if sky is not None or z.body == "inertial"]
    if not zones:
        return None
    moving = any(z.body != "inertial" for z in zones)
    return FittedZones(zones, sky if moving else None, window=ZONE_FIT_WINDOW)
