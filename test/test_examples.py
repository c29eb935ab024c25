"""Every script of examples/ runs to the end as a user would run it (a subprocess, a fresh working
directory, a deadline) and prints figures that only a real run produces."""
from __future__ import annotations

import os
import re
import subprocess
import sys
from pathlib import Path

import pytest

from att_planner.tools.launch import isolated_env

ROOT = Path(__file__).resolve().parents[1]
EXAMPLES = ROOT / "examples"
NUMBER = r"[0-9]+\.[0-9]+"

# script -> (marks, patterns each of which some line of its output must match)
CASES = {
    "plan_and_verify.py": ((), [rf"^plan: optimal in {NUMBER} s, computed in {NUMBER} s$",
                                rf"^verified: final error {NUMBER} deg, min margin {NUMBER} deg, "
                                rf"torque {NUMBER} x limit$",
                                r"^accepted$"]),
    "fly_closed_loop.py": ((), [rf"^plan: \w+ by \w+, {NUMBER} s$",
                                rf"^flown: True maneuver complete; final error {NUMBER} arcsec after {NUMBER} s$"]),
    "real_sky.py": ((), [rf"^plan: \w+ by \w+, {NUMBER} s from 2026-12-21 00:08:20 UTC$",
                         rf"^verified margins: sun {NUMBER} deg, moon {NUMBER} deg, earth {NUMBER} deg$"]),
    "monte_carlo.py": ((), [rf"^run 7 seed [0-9]+: success True, final error {NUMBER} arcsec, min margin {NUMBER} deg$",
                            rf"^8/8 successful; final error mean {NUMBER}, max {NUMBER} arcsec$"]),
    "review_log.py": ((), [rf"^log: [0-9]+ states over {NUMBER} s, peak rate {NUMBER} rad/s$",
                           rf"^reviewed: final attitude error {NUMBER} deg, estimation error rms {NUMBER} arcsec$",
                           r"^review: runs/review_example/review/index.html \(overview, sky, "]),
    "suite_client.py": ((pytest.mark.ros, pytest.mark.slow),
                        [rf"^plan: True 0 .* {NUMBER} s$",
                         rf"^execution: True 0 maneuver complete final error {NUMBER} deg$"]),
}


def test_every_example_is_tested():
    assert sorted(p.name for p in EXAMPLES.glob("*.py")) == sorted(CASES)


@pytest.mark.parametrize("script", [pytest.param(name, marks=marks) for name, (marks, _) in CASES.items()])
def test_the_example_runs_to_the_end(script, tmp_path):
    # a fresh ROS domain with localhost-only discovery even for the scripts that start no node
    path = os.pathsep.join([str(ROOT), os.environ.get("PYTHONPATH", "")])
    env = isolated_env(base={**os.environ, "PYTHONPATH": path})
    run = subprocess.run([sys.executable, str(EXAMPLES / script)], cwd=tmp_path, env=env, capture_output=True,
                         text=True, timeout=240)
    assert run.returncode == 0, run.stdout[-2000:] + run.stderr[-3000:]
    assert "Traceback" not in run.stderr
    lines = run.stdout.splitlines()
    for pattern in CASES[script][1]:
        assert any(re.search(pattern, line) for line in lines), (pattern, run.stdout[-2000:])
    if script == "review_log.py":
        assert (tmp_path / "runs" / "review_example" / "review" / "index.html").stat().st_size > 10_000
