"""The typed schema of a mission file (``config/missions/``) and of a target list (``config/targets/``).

A mission names a target list, which names the scenario it is observed from: references by name,
resolved by the readers (:mod:`att_planner.mission.config`, :mod:`att_planner.mission.targets`) and
by ``att-config check``. Ranges and defaults are written once, here; units are in the key names.
"""
from __future__ import annotations

from typing import Annotated, ClassVar, Literal

import numpy as np
from pydantic import AfterValidator, ConfigDict, Discriminator, Field, Tag, field_validator, model_validator

from att_msgs_py.limits import MAX_TARGETS
from att_msgs_py.types import SECONDARY_KINDS
from att_sim.models.config_base import Name, Schema, Vector3, distinct_names, near_unit, number

AXIS_TOLERANCE = 1e-6          # |‖v‖ − 1| accepted for a mission's body axis
MAX_DWELL_S = 86_400.0


def _non_zero(v: list[float]) -> list[float]:
    if float(np.linalg.norm(v)) < 1e-9:
        raise ValueError("a non-zero 3-vector")
    return v


def _distinct_targets(items: list) -> list:
    return distinct_names(items, "target")


UnitAxis = Annotated[Vector3, AfterValidator(near_unit(AXIS_TOLERANCE))]
Secondary = Literal[tuple(k for k in SECONDARY_KINDS if k != "inertial")]


class Mission(Schema):
    """How a day of observations is flown."""

    renamed: ClassVar = {"rate_hz": "rate_Hz"}

    targets: Annotated[str, Field(min_length=1, max_length=4096)] = Field(
        description="the target list: a file stem under config/targets/, or a path to a *.yaml file")
    sensor_axis: UnitAxis = Field(description="body axis put on each target")
    horizon_s: float = number(ge=60.0, le=7 * 86_400.0, unit="s", meaning="sim time from the scenario's epoch")
    margin_deg: float = number(1.0, ge=0.0, le=30.0, unit="deg", meaning="visible this far outside every zone")
    rate_Hz: float = number(5.0, ge=0.5, le=50.0, unit="Hz", meaning="simulator step, state, control and estimate "
                                                                      "rate of the day")
    start_lead_s: float = number(240.0, ge=1.0, le=3600.0, unit="s", meaning="sim time from a slew's request to "
                                                                              "its start")
    time_budget_s: float = number(10.0, ge=0.05, le=600.0, unit="s", meaning="planner wall time per slew")
    method: Annotated[str, Field(max_length=64)] = Field("", description="planning method; empty: the planner's "
                                                                         "default")
    pointing_tolerance_deg: float = number(0.05, ge=1e-4, le=10.0, unit="deg", meaning="a dwell counts as "
                                                                                       "observed within this")
    momentum_dumping: bool = Field(True, description="magnetorquer dumping while a target is held")
    rate_max_deg_per_s: float | None = number(None, ge=1e-4, le=10.0, unit="deg/s", meaning="per body axis, the "
                                              "slews' rate bound; none: the gyroscopic rate limit")
    zones: list[Name] | None = Field(None, description="the scenario's zones kept, by name; none: all")
    secondary: Secondary = Field("velocity", description="ground sites: the direction the secondary axis is kept "
                                                         "nearest")
    secondary_axis: UnitAxis | None = Field(None, description="ground sites: that body axis; none: the axis "
                                                              "after the sensor's")
    site_arrival: Literal["on_law", "at_rest"] = Field(
        "on_law", description="ground sites: a slew ends on the site's law, its attitude and rate (on_law: an "
                              "agile spacecraft), or at rest on its attitude and the controller blends into the "
                              "law (at_rest: a spacecraft whose rate bound is below a pass's rate)")
    handover_blend_s: float = number(60.0, ge=0.0, le=3600.0, unit="s", meaning="ground sites: the controller's "
                                                                                 "blend into the site's law after "
                                                                                 "a slew that ends at rest")
    start_pointing: Literal["scenario", "nadir"] = Field(
        "scenario", description="the attitude the day starts at: the scenario's simulator initial_attitude, or "
                                "nadir: sensor_axis on the nadir and secondary_axis towards secondary")

    @field_validator("method")
    @classmethod
    def _printable(cls, method: str) -> str:
        if not method.isprintable():
            raise ValueError("a printable method name")
        return method

    @field_validator("zones")
    @classmethod
    def _distinct(cls, zones):
        if zones is not None and len(set(zones)) != len(zones):
            raise ValueError("distinct zone names")
        return zones

    @model_validator(mode="after")
    def _method_takes_the_rate_bound(self):
        from att_planner import methods

        if not self.method:
            return self
        if self.method not in methods.METHODS:
            raise ValueError(f"method: one of {', '.join(methods.METHODS)}, or empty for the planner's default")
        if self.rate_max_deg_per_s is not None and "rate_max" not in methods.get(self.method).options:
            takes = [m.name for m in methods.REGISTRY if "rate_max" in m.options]
            raise ValueError(f"method {self.method} takes no rate bound, and rate_max_deg_per_s asks one: a method "
                             f"that does ({', '.join(takes)}), or no rate_max_deg_per_s")
        return self

    @model_validator(mode="after")
    def _axes_apart(self):
        if self.secondary_axis is not None and np.linalg.norm(np.cross(self.sensor_axis, self.secondary_axis)) < 1e-3:
            raise ValueError("secondary_axis not parallel to sensor_axis")
        return self


class Source(Schema):
    """An inertial target: J2000 right ascension and declination."""

    name: Name
    ra_deg: float = number(ge=0.0, le=360.0, unit="deg", meaning="right ascension, J2000")
    dec_deg: float = number(ge=-90.0, le=90.0, unit="deg", meaning="declination, J2000")
    dwell_s: float = number(ge=0.0, le=MAX_DWELL_S, unit="s", meaning="time held on the target")


class Site(Schema):
    """A ground target: geodetic latitude, longitude and altitude; a site tracked for ``dwell_s``, or a
    strip from there to its end scanned at ``scan_speed_m_s`` (its dwell is its scan)."""

    name: Name
    lat_deg: float = number(ge=-90.0, le=90.0, unit="deg", meaning="geodetic latitude (a strip: its start's)")
    lon_deg: float = number(ge=-180.0, le=360.0, unit="deg", meaning="longitude, east (a strip: its start's)")
    alt_m: float = number(0.0, ge=-500.0, le=9000.0, unit="m", meaning="altitude above the ellipsoid")
    dwell_s: float | None = number(None, ge=0.0, le=MAX_DWELL_S, unit="s", meaning="time the site is tracked "
                                                                                    "(a site's; none for a strip)")
    end_lat_deg: float | None = number(None, ge=-90.0, le=90.0, unit="deg", meaning="a strip: its end's geodetic "
                                                                                     "latitude")
    end_lon_deg: float | None = number(None, ge=-180.0, le=360.0, unit="deg", meaning="a strip: its end's "
                                                                                       "longitude, east")
    scan_speed_m_s: float | None = number(None, gt=0.0, le=20_000.0, unit="m/s", meaning="a strip: the ground "
                                                                                         "speed of its scan")

    @model_validator(mode="after")
    def _site_or_strip(self):
        strip = (self.end_lat_deg, self.end_lon_deg, self.scan_speed_m_s)
        if all(v is None for v in strip):
            if self.dwell_s is None:
                raise ValueError("dwell_s: a site's time tracked (or end_lat_deg, end_lon_deg and scan_speed_m_s: "
                                 "a strip)")
            return self
        if any(v is None for v in strip):
            raise ValueError("a strip needs end_lat_deg, end_lon_deg and scan_speed_m_s, all three")
        if self.dwell_s is not None:
            raise ValueError("dwell_s: a strip's dwell is its scan (its length / scan_speed_m_s): give none")
        return self


class InertialTargets(Schema):
    kind: Literal["inertial"]
    scenario: Name = Field(description="the scenario the targets are observed from")
    roll_reference: Annotated[Vector3, AfterValidator(_non_zero)] = Field(
        [0.0, 0.0, 1.0], description="inertial direction the roll axis is kept nearest")
    targets: Annotated[list[Source], Field(min_length=1, max_length=MAX_TARGETS), AfterValidator(_distinct_targets)]


class GroundTargets(Schema):
    kind: Literal["ground"]
    scenario: Name = Field(description="the scenario the sites are observed from")
    min_elevation_deg: float = number(0.0, ge=0.0, le=89.0, unit="deg", meaning="a site is observable while the "
                                                                                "spacecraft is this high in its sky")
    targets: Annotated[list[Site], Field(min_length=1, max_length=MAX_TARGETS), AfterValidator(_distinct_targets)]


def _kind(value) -> str | None:
    return value.get("kind") if isinstance(value, dict) else None


TargetList = Annotated[Annotated[InertialTargets, Tag("inertial")] | Annotated[GroundTargets, Tag("ground")],
                       Discriminator(_kind)]


class TargetListKind(Schema):
    """What a target list must say first: its kind (the rest is checked by that kind's model)."""

    model_config = ConfigDict(extra="allow", frozen=True, strict=True)

    kind: Literal["inertial", "ground"] = Field(description="inertial: sources on the sky; ground: sites")


def target_list_model(data: dict) -> type[Schema]:
    """The model of a target list's root mapping, chosen by its ``kind``."""
    return {"inertial": InertialTargets, "ground": GroundTargets}.get(_kind(data), TargetListKind)
