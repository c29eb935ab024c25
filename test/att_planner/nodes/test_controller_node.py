"""The controller node loads the gains att-tune writes."""
import pytest

from att_planner.tools.launch import Suite, isolated_env
from att_planner.tools.tune import write_gains

pytestmark = pytest.mark.ros


def test_tuned_gains_file_is_loaded_by_the_controller_node(tmp_path):
    """att-tune writes controller.ros__parameters.{kp, kd, m_max_Am2}; --params-file loads them."""
    gains = tmp_path / "controller_gains.yaml"
    write_gains(str(gains), 123456.5, 98765432.25, 7.5)
    suite = Suite(isolated_env(), tmp_path)
    suite.start("controller", {"scenario": "bruni_celani"}, params_files=(gains,))
    try:
        suite.wait_for_output("controller", "magnetorquer gains", 60)
    finally:
        suite.stop()
    assert "kp=123456 kd=9.87654e+07 m_max=7.5" in suite.log_text("controller")


@pytest.mark.parametrize("refuse", [True, False])
def test_a_status_the_middleware_refuses_is_logged_and_the_result_still_returned(refuse):
    """An action server's status write can fail ("cannot publish data"); the controller logs it
    instead of letting rclpy answer the goal with an empty result (error_code 0)."""
    from rclpy.impl.implementation_singleton import rclpy_implementation as _rclpy

    from att_planner.nodes.controller_node import ControllerNode

    warnings, sent = [], []

    class Logger:
        def warning(self, text):
            warnings.append(text)

    class Node:
        def get_logger(self):
            return Logger()

    def abort():
        sent.append("abort")
        if refuse:
            raise _rclpy.RCLError("Failed publish goal status array: cannot publish data")

    ControllerNode._to_client(Node(), "goal status", abort)
    assert sent == ["abort"]
    assert warnings == (["goal status not published: Failed publish goal status array: cannot publish data"]
                        if refuse else [])
