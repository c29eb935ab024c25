"""The controller node loads the gains att-tune writes."""
import pytest

from att_planner.tools.launch import Suite, isolated_env
from att_planner.tools.tune import write_gains

pytestmark = pytest.mark.ros


def test_tuned_gains_file_is_loaded_by_the_controller_node(tmp_path):
    """att-tune writes controller.ros__parameters.{kp, kd, m_max}; --params-file loads them."""
    gains = tmp_path / "controller_gains.yaml"
    write_gains(str(gains), 123456.5, 98765432.25, 7.5)
    suite = Suite(isolated_env(), tmp_path)
    suite.start("controller", {"scenario": "bruni_celani"}, params_files=(gains,))
    try:
        suite.wait_for_output("controller", "magnetorquer gains", 60)
    finally:
        suite.stop()
    assert "kp=123456 kd=9.87654e+07 m_max=7.5" in suite.log_text("controller")
