"""The README's Python client snippet runs to the end against a running suite: it plans, executes,
prints the execution result and shuts rclpy down (exit status 0)."""
from __future__ import annotations

import re
import subprocess
import sys
from pathlib import Path

import pytest

pytestmark = [pytest.mark.ros, pytest.mark.slow]     # 33 s on the 2-core machine

README = Path(__file__).resolve().parents[2] / "README.md"


def snippet() -> str:
    blocks = re.findall(r"```python\n(.*?)```", README.read_text(), flags=re.S)
    client = [b for b in blocks if "SuiteClient()" in b]
    assert len(client) == 1, "expected one client snippet in the README"
    return client[0]


def test_the_readme_client_snippet_runs_to_the_end(ros_suite, tmp_path):
    code = snippet()
    assert "rclpy.shutdown()" in code and "client.execute(" in code
    script = tmp_path / "snippet.py"
    script.write_text(code)
    with ros_suite("swift_demo", params={"simulator": {"real_time_factor": 0.0}}, name="readme_test") as s:
        run = subprocess.run([sys.executable, str(script)], env=s.suite.env, capture_output=True, text=True,
                             timeout=300)
    assert run.returncode == 0, run.stderr[-2000:]
    assert "Traceback" not in run.stderr
    lines = run.stdout.splitlines()
    assert any(line.startswith("plan: True 0") for line in lines), run.stdout
    assert any(line.startswith("execution: True 0 maneuver complete") for line in lines), run.stdout
