"""The vocabularies of att_msgs_py.types are the .msg constants, and the mirror types round-trip."""
import numpy as np

from att_msgs.msg import ActuatorCommand, ControllerStatus, ManeuverPlan, PlanStage
from att_msgs_py import convert
from att_msgs_py.types import Command, ControlMode, Plan, Stage, StageReport, Status
from att_msgs_py.types import ControllerStatus as Status_


def constants(msg_class, prefix: str) -> dict:
    return {name[len(prefix):]: getattr(msg_class, name) for name in dir(msg_class) if name.startswith(prefix)}


def test_control_modes_are_the_actuator_command_constants():
    assert {m.name: int(m) for m in ControlMode} == constants(ActuatorCommand, "MODE_")


def test_plan_statuses_are_the_maneuver_plan_constants():
    assert {str(s) for s in Status} == set(constants(ManeuverPlan, "STATUS_").values())
    assert len(Status) == len(constants(ManeuverPlan, "STATUS_"))


def test_stage_names_are_the_plan_stage_constants():
    assert {s.name: str(s) for s in Stage} == constants(PlanStage, "STAGE_")


def test_stage_report_round_trips():
    report = StageReport(Stage.METHOD, "slepian_minimum_time", 0.61, Status.OPTIMAL, True, 3.7, "seeded")
    assert convert.stage_from_msg(convert.stage_msg(report)) == report
    empty = convert.stage_from_msg(convert.stage_msg(StageReport(Stage.FALLBACK, "eigenaxis_smooth", 0.0)))
    assert empty.status == "" and not empty.verified and np.isnan(empty.duration)


def test_command_and_status_round_trip():
    cmd = Command(mode=ControlMode.PLAN_TRACKING, wheel_torques=np.array([0.1, -0.2, 0.3]),
                  dipole=np.array([1.0, 2, 3]), body_torque=np.array([0.0, 0, 1e-3]), plan_id="p1", t=12.25,
                  frame_id="body")
    back = convert.command_from_msg(convert.command_msg(cmd))
    assert back.mode == ControlMode.PLAN_TRACKING and back.plan_id == "p1" and back.t == 12.25
    assert back.frame_id == "body"
    for key in ("wheel_torques", "dipole", "body_torque"):
        assert np.array_equal(getattr(back, key), getattr(cmd, key))
    msg = convert.controller_status_msg(Status_(mode=ControlMode.SAFE, t=3.5, plan_id="p1", plan_progress=0.5,
                                                state_stale=True, message="m", frame_id="body"))
    assert isinstance(msg, ControllerStatus) and msg.mode == 3 and msg.state_stale and msg.plan_progress == 0.5
    assert convert.from_time(msg.header.stamp) == 3.5


def test_a_plan_without_samples_is_not_a_success():
    assert not Plan(status=Status.OPTIMAL).success
    assert not Plan(t=np.arange(3.0), status=Status.FAILED).success
    assert Plan(t=np.arange(3.0), status=Status.BUDGET_EXPIRED).success
