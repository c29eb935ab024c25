"""The spacecraft and scenario models: ranges, defaults, physical checks, renames."""
from __future__ import annotations

import math

import numpy as np
import pytest
from pydantic import ValidationError

from att_sim.models import config_actuators, config_sensors
from att_sim.models import config_schema as cs
from att_sim.models.actuator_specs import WheelDriveSpec
from att_sim.models.sensor_specs import GyroSpec, MagnetometerSpec, StarTrackerSpec, TachometerSpec

CRAFT = {"inertia_kg_m2": [100.0, 100.0, 100.0], "wheel_inertia_kg_m2": 0.01}


def craft(**changes):
    return cs.Spacecraft.model_validate({**CRAFT, **changes})


def test_defaults_are_no_limits_and_three_body_wheels():
    sc = craft()
    assert sc.torque_max_Nm == sc.wheel_torque_max_Nm == sc.dipole_max_Am2 == math.inf
    assert np.array_equal(np.reshape(sc.wheel_axes, (3, 3)), np.eye(3))


@pytest.mark.parametrize("inertia, words", [
    ([1.0, 2.0, 4.0], "triangle inequality"),
    ([-1.0, 2.0, 2.0], "positive definite"),
    ([1.0, 0.5, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0], "symmetric"),
    ([1.0, 2.0], "3 principal or 9"),
    ([1.0, float("nan"), 1.0], "finite"),
])
def test_non_physical_inertia_refused(inertia, words):
    with pytest.raises(ValidationError, match=words):
        craft(inertia_kg_m2=inertia)


def test_triangle_inequality_boundary_accepted():
    assert craft(inertia_kg_m2=[1.0, 1.0, 2.0]).inertia_kg_m2 == [1.0, 1.0, 2.0]


def test_wheels_need_inertia_and_unit_axes():
    with pytest.raises(ValidationError, match="wheel_inertia_kg_m2 > 0"):
        craft(wheel_inertia_kg_m2=0.0)
    assert craft(wheel_axes=[], wheel_inertia_kg_m2=0.0).wheel_axes == []
    with pytest.raises(ValidationError, match="vector 1 has norm 2"):
        craft(wheel_axes=[1.0, 0.0, 0.0, 0.0, 2.0, 0.0])


def test_sensor_defaults_match_the_datasheet_types():
    """The file's defaults and the SI datasheets' agree (one figure, two units)."""
    assert config_sensors.Gyro().rate_Hz == GyroSpec.rate
    assert config_sensors.Magnetometer().rate_Hz == MagnetometerSpec.rate
    assert config_sensors.WheelTachometer().rate_Hz == TachometerSpec.rate
    st = StarTrackerSpec()
    assert math.isclose(config_sensors.StarTracker(name="a").cross_boresight_arcsec * math.pi / 648000,
                        st.cross_boresight)
    assert config_actuators.WheelDrives().friction_speed_rad_s == WheelDriveSpec.friction_speed


def test_sky_needs_an_epoch():
    shared = {"spacecraft": CRAFT, "zones": [{"name": "sun", "body": "sun", "sensor_axis": [1, 0, 0],
                                              "half_angle_deg": 40}]}
    with pytest.raises(ValidationError, match="an epoch .* zone sun"):
        cs.Shared.model_validate(shared)
    assert cs.Shared.model_validate({**shared, "epoch": "2026-12-21T00:00:00Z"}).zones[0].name == "sun"
    with pytest.raises(ValidationError, match="epoch must carry"):
        cs.Shared.model_validate({**shared, "epoch": "2026-12-21T00:00:00"})


def test_zone_and_orbit_checks():
    base = {"spacecraft": CRAFT}
    bad_zone = {"name": "z", "body": "inertial", "sensor_axis": [1, 0, 0], "half_angle_deg": 180}
    with pytest.raises(ValidationError, match="half-angle in \\(0, 180\\)"):
        cs.Shared.model_validate({**base, "zones": [{**bad_zone, "direction": [0, 0, 1]}]})
    with pytest.raises(ValidationError, match="direction"):
        cs.Shared.model_validate({**base, "zones": [{**bad_zone, "half_angle_deg": 10}]})
    assert cs.Shared.model_validate(base).orbit.altitude_m == 450e3
    with pytest.raises(ValidationError, match="greater than 6378137"):
        cs.Shared.model_validate({**base, "epoch": "2026-01-01T00:00:00Z", "orbit": {
            "type": "kepler", "semi_major_axis_m": 6e6, "eccentricity": 0.0, "inclination_deg": 0.0,
            "raan_deg": 0.0, "arg_perigee_deg": 0.0, "mean_anomaly_deg": 0.0}})


def test_strict_types():
    with pytest.raises(ValidationError):
        craft(torque_max_Nm="0.1")
    with pytest.raises(ValidationError):
        craft(torque_max_Nm=True)


def test_json_schema_has_units_and_ranges():
    schema = cs.ScenarioFile.model_json_schema(by_alias=True)
    craft_schema = schema["$defs"]["Spacecraft"]["properties"]
    assert "kg m^2" in craft_schema["inertia_kg_m2"]["description"]
    gyro = schema["$defs"]["Gyro"]["properties"]["arw_deg_per_sqrt_h"]
    assert gyro["minimum"] == 0.0 and gyro["maximum"] == 100.0
    assert "/**" in schema["properties"]


def test_the_readers_take_defaults_and_ranges_from_the_models():
    from att_sim.models.actuator_specs import actuators_from_params
    from att_sim.models.sensor_specs import ARCSEC, sensors_from_params
    specs = sensors_from_params({"gyro": {}, "star_trackers": [{"name": "a"}]}, epoch_known=False)
    assert specs.gyro.rate == config_sensors.Gyro.model_fields["rate_Hz"].default
    about = config_sensors.StarTracker(name="a").about_boresight_arcsec
    assert specs.star_trackers[0].about_boresight == pytest.approx(about * ARCSEC)
    with pytest.raises(ValueError, match=r"sensors.gyro.rate_Hz: expected less than or equal to 1000; found 1000.5"):
        sensors_from_params({"gyro": {"rate_Hz": 1000.5}}, epoch_known=False)
    with pytest.raises(ValueError, match=r"actuators.wheels.friction_speed_rad_s: expected greater than 0; found 0.0"):
        actuators_from_params({"wheels": {"friction_speed_rad_s": 0.0}})
    assert actuators_from_params({"wheels": {}}).wheels.power_max == math.inf
