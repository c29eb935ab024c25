"""Regenerate ``test/data/swift_short.mcap``, the regression log of ``test/test_review_replay.py``.

Runs the suite (recorder, simulator, estimator, controller, planner as processes on an isolated
domain, as fast as possible, states, clock and commands at 10 Hz, the sensors at their rates, 5 s
hold; the controller on the estimate) through one short keep-out maneuver of the ``swift_demo``
spacecraft: 45° about body y with the sensor along body x, Sun/Earth/Moon
cones (the path ends 14° from the Moon cone). Run it from the repository root when the log format
changes on purpose:

    .venv/bin/python test/data/make_fixture.py

and commit the new file (it must stay under 1 MB: noisy sensor streams compress poorly).
"""
from __future__ import annotations

import math
import shutil
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE.parents[1]))

from att_msgs_py.types import Cone  # noqa: E402
from att_planner.tools.launch import isolated_env, join_env, start_suite  # noqa: E402
from att_sim.models import rotations as rot  # noqa: E402

FIXTURE = HERE / "swift_short.mcap"
SENSOR = np.array([1.0, 0.0, 0.0])
CONES = [Cone([0.5, 0.866, 0.0], math.radians(47), "sun"), Cone([0.0, 0.0, -1.0], math.radians(33), "earth"),
         Cone([0.1795, 0.3109, 0.9333], math.radians(23), "moon")]
GOAL = rot.from_axis_angle([0, 1, 0], math.radians(-45))
METHOD = "eigenaxis_smooth"
PARAMS = {"simulator": {"real_time_factor": 0.0, "publish_rate_Hz": 10.0, "clock_rate_Hz": 10.0},
          "controller": {"control_rate_Hz": 10.0, "settle_time_s": 5.0}}


def main() -> int:
    work = Path(tempfile.mkdtemp(prefix="att_fixture_"))
    env = isolated_env()
    join_env(env)
    # the simulator starts once the plan is ready, so the log holds little idle time before the maneuver
    suite = start_suite("swift_demo", work / "run.mcap", work, env=env, params=PARAMS,
                        nodes=("recorder", "estimator", "controller", "planner"))
    from att_msgs_py.errors import ErrorCode
    from att_planner.nodes.client import client_session, maneuver_request

    try:
        with client_session("make_fixture") as client:
            client.wait_for_servers(timeout=60)
            response = client.plan(maneuver_request(rot.IDENTITY, GOAL, SENSOR, CONES, method=METHOD, time_budget=20))
            if not response.success:
                print(f"planner refused: {response.message}")
                return 1
            # sim time stays at zero until the recorder, the estimator and the controller listen
            suite.start("simulator", {"scenario": "swift_demo", "wait_for_subscribers": 3, **PARAMS["simulator"]})
            for _ in range(40):
                result = client.execute(response.plan.plan_id)
                if result.error_code not in (ErrorCode.NO_STATE, ErrorCode.ESTIMATE_UNHEALTHY):   # not yet
                    break
                time.sleep(0.25)    # wait-ok: retry period of a goal refused while the state is missing (40 tries)
            plan = response.plan
            print(f"plan {plan.plan_id} ({plan.method}, {plan.duration:.1f} s): {result.message}")
            if not result.success:
                return 1
    finally:
        codes = suite.stop()
    if any(codes.values()):
        print(f"a node exited with an error: {codes} (logs in {work})")
        return 1
    from att_msgs_py.log import read_log
    first_state = read_log(work / "run.mcap")["/spacecraft/state"]["header.stamp"][0]
    if first_state > 0.0:
        print(f"the recorder missed the states before t = {first_state:.2f} s (logs in {work})")
        return 1
    shutil.copyfile(work / "run.mcap", FIXTURE)
    shutil.rmtree(work)
    print(f"wrote {FIXTURE} ({FIXTURE.stat().st_size / 1024:.0f} KB)")
    return 0


if __name__ == "__main__":
    sys.exit(main())
