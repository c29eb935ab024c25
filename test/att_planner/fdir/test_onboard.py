"""The fault_table parameter read (empty: off; a name of config/faults; a path) and hostile values
refused naming the parameter; the brake before a re-plan after a wheel loss (att_planner.fdir.replan);
the two nodes' monitors (att_planner.fdir.onboard.Onboard): the estimator's exclusions, the
controller acting on the estimator's reports, and a report the table does not declare refused."""
from __future__ import annotations

from datetime import UTC, datetime
from types import SimpleNamespace

import numpy as np
import pytest

from att_msgs_py.errors import ConfigError, ErrorCode
from att_msgs_py.types import ControlMode, FaultStatus
from att_planner.fdir import replan
from att_planner.fdir import table as tables
from att_planner.fdir.onboard import load_table


def test_an_empty_fault_table_is_off_and_a_name_or_a_path_is_read():
    assert load_table("") is None
    by_name, by_path = load_table("default"), load_table(str(tables.DEFAULT_TABLE))
    assert by_name == by_path == tables.read()
    assert "wheel_torque" in by_name.faults


@pytest.mark.parametrize("value, words", [("no_such_table", "found 'no_such_table', which is neither"),
                                          ("/nonexistent/faults.yaml", "a fault table file"),
                                          ("../../etc/passwd", "which is neither"),
                                          ("x" * 500, "which is neither")])
def test_a_fault_table_that_is_not_there_is_refused_naming_the_parameter(value, words):
    with pytest.raises(ConfigError) as err:
        load_table(value)
    assert err.value.code == ErrorCode.INVALID_CONFIG
    assert err.value.message.startswith("parameter 'fault_table': expected empty") and words in err.value.message
    assert len(err.value.message) < 400


def test_a_fault_table_file_with_a_bad_entry_is_refused_with_its_line(tmp_path):
    bad = tmp_path / "bad.yaml"
    bad.write_text("faults:\n  w:\n    detector: wheel_torque\n    threshold_Nm: -1\n    persistence_s: 0\n"
                   "    response: exclude_wheel\n")
    with pytest.raises(ConfigError) as err:
        load_table(str(bad))
    assert err.value.code == ErrorCode.INVALID_CONFIG
    assert err.value.message.startswith("parameter 'fault_table': ") and "threshold_Nm" in err.value.message


class Controller:
    """What the brake reads of a controller: its mode, estimated rate, start tolerance; and its hold."""

    def __init__(self, rate: float):
        self.mode = ControlMode.PLAN_TRACKING
        self.state = SimpleNamespace(omega=np.array([rate, 0.0, 0.0]))
        self.context = SimpleNamespace(max_start_rate_error=0.01)
        self.held = []

    def hold(self, message):
        self.held.append(message)
        return "ended"


def test_the_brake_holds_then_says_re_plan_once_the_rate_is_below_half_the_start_tolerance():
    ctl, brake = Controller(0.02), replan.Brake()
    assert brake.poll(ctl, 0.0) == replan.IDLE
    assert brake.begin(ctl, 10.0) == "ended" and ctl.held == [replan.HOLD_MESSAGE] and brake.since == 10.0
    assert brake.poll(ctl, 20.0) == replan.WAIT
    ctl.state.omega[0] = 0.0049
    assert brake.poll(ctl, 21.0) == replan.REPLAN and brake.since is None
    assert brake.poll(ctl, 22.0) == replan.IDLE


def test_the_brake_gives_up_after_its_limit_and_leaves_safe_mode_alone():
    ctl, brake = Controller(0.02), replan.Brake()
    brake.begin(ctl, 0.0)
    assert brake.poll(ctl, replan.BRAKE_LIMIT_S) == replan.WAIT
    assert brake.poll(ctl, replan.BRAKE_LIMIT_S + 0.1) == replan.SAFE and "0.02 rad/s" in brake.why
    ctl.mode = ControlMode.SAFE
    assert brake.begin(ctl, 200.0) is None and brake.since is None and len(ctl.held) == 1
    brake.since = 200.0
    assert brake.poll(ctl, 201.0) == replan.IDLE and brake.since is None


def test_the_utc_epoch_of_a_sim_time():
    assert replan.utc_epoch(None, 5.0) == (0, 0)
    epoch = datetime(2025, 3, 1, tzinfo=UTC)
    assert replan.utc_epoch(epoch, 1.25) == (int(epoch.timestamp()) + 1, 250_000_000)


def report(fault_id, component, index, response, active=True):
    return FaultStatus(12.0, fault_id, component, index, "d", "e", response, active, 12.0, "body")


@pytest.fixture(scope="module")
def sides():
    """The two nodes' monitors on leo_pyramid: the estimator's (no controller) and the controller's."""
    from att_planner.fdir.onboard import Onboard
    from att_planner.tools.closed_loop import ClosedLoop
    from att_sim.models import scenario as scen

    s = scen.load("leo_pyramid")
    loop = ClosedLoop(s)
    estimator = SimpleNamespace(excluded=set(), take_innovations=list)
    return s, Onboard(tables.read(), s, None, estimator), Onboard(tables.read(), s, loop.controller)


def test_the_estimator_side_excludes_what_its_monitor_isolated_and_touches_no_controller(sides):
    s, estimator_side, _ = sides
    tracker = s.sensors.star_trackers[0].name
    assert estimator_side.hear(report("tracker_outage", "star_tracker", 0, "exclude_sensor")) is None
    ended, changed = estimator_side.respond()
    assert ended is None and not changed and estimator_side.estimator.excluded == {tracker}
    assert estimator_side.respond() == (None, False)            # nothing new: nothing acted on
    estimator_side.hear(report("tracker_outage", "star_tracker", 0, "exclude_sensor", active=False))
    estimator_side.respond()
    assert estimator_side.estimator.excluded == set() and estimator_side.heard == {}


def test_the_controller_side_flies_safe_mode_on_a_gyro_fault_the_estimator_reported(sides):
    _, _, controller_side = sides
    ctl = controller_side.controller
    assert controller_side.hear(report("gyro_axis_frozen", "gyro", 1, "safe_mode")) is None
    controller_side.respond()
    assert ctl.mode == ControlMode.SAFE and ctl.safe_actuation is not None and not ctl.safe_actuation.gyro_trusted


@pytest.mark.parametrize("fault, words", [
    (("no_such_fault", "gyro", 0, "safe_mode"), "fault_id: expected one of the fault table's; found 'no_such_fault'"),
    (("gyro_axis_frozen", "wheel", 0, "safe_mode"), "expected component gyro and response safe_mode"),
    (("wheel_torque", "wheel", 0, "safe_mode"), "expected component wheel and response exclude_wheel"),
    (("wheel_torque", "wheel", -2, "exclude_wheel"), "index: expected a unit (0 or more) or -1"),
])
def test_a_report_the_table_does_not_declare_as_reported_is_refused(sides, fault, words):
    _, _, controller_side = sides
    before = dict(controller_side.heard)
    refused = controller_side.hear(report(*fault))
    assert refused.code == ErrorCode.INVALID_FAULT_REPORT and words in refused.message
    assert controller_side.heard == before                   # nothing kept


def test_a_tachometer_sample_meets_the_command_in_force_over_its_interval_whatever_arrived_first(sides):
    """A node may compute the command at t before the sample stamped t arrives: that command is in
    force after t, so the sample of t meets the one before it (as the in-process loop orders them)."""
    _, _, controller_side = sides
    tap = controller_side.tap
    at_rest = np.zeros(4)

    def command(t, torque):
        return SimpleNamespace(t=t, wheel_torques=[torque] * 4, dipole=[])

    def sample(t):
        return SimpleNamespace(t=t, speeds=at_rest)

    controller_side.feed("/actuator/command", 1.00, command(1.00, 0.1))
    assert controller_side.feed("/sensors/wheel_speeds", 0.95, sample(0.95)) == []
    controller_side.feed("/sensors/wheel_speeds", 1.00, sample(1.00))
    assert np.all(tap.torques != 0.1)                        # the command of 1.00 is not in force yet
    controller_side.feed("/actuator/command", 1.05, command(1.05, 0.2))
    controller_side.feed("/sensors/wheel_speeds", 1.05, sample(1.05))
    assert np.all(tap.torques == 0.1)                        # over [1.00, 1.05]: the command of 1.00
    controller_side.feed("/sensors/wheel_speeds", 1.10, sample(1.10))
    assert np.all(tap.torques == 0.2)


def test_the_in_process_loop_reads_either_node_s_fault_table_parameter():
    from att_planner.tools.closed_loop import ClosedLoop
    from att_sim.models import scenario as scen

    s = scen.load("leo_pyramid")
    loop = ClosedLoop(s, overrides={"estimator": {"fault_table": "default"}})
    assert loop.onboard is not None and loop.monitor.table == tables.read()
    assert loop.onboard.estimator is loop.estimator and loop.onboard.controller is loop.controller
    with pytest.raises(ConfigError) as err:
        ClosedLoop(s, overrides={"controller": {"fault_table": "no_such_table"}})
    assert "parameter 'fault_table'" in err.value.message
