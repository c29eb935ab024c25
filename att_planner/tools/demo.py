"""``att-demo`` (``make demo``): the suite end to end.

Starts recorder, simulator, controller and planner as separate processes on the ``ROS_DOMAIN_ID``
you set (a random one when it is unset; localhost-only discovery unless
``ROS_AUTOMATIC_DISCOVERY_RANGE`` is set) and says which, asks the planner for the scenario's
keep-out maneuver, executes it on the simulator through the controller, stops everything cleanly
and prints a summary measured from the recorded MCAP, writes the ``att-review`` figures and HTML
page next to it (``review/``). The last line printed is ``MCAP: <path>``.

The maneuver is the scenario's ``demo:`` section (a scenario without one is refused in one line).
Its keep-out set is the section's cones and the scenario's ``zones``. With a scenario epoch the
request carries the maneuver's actual start epoch: the demo reads the simulator's time ``t`` from
its state, asks for a plan starting at ``epoch + t + start_lead`` (``start_lead``, s of sim time,
covers the planning) and executes it when the simulator reaches that time, so the moving zones the
plan avoids are where they are during the flight. With ``start_time`` (s of sim time) it first
waits for ``start_time − start_lead`` and resets the simulator to the initial attitude at rest
(the spacecraft drifts under the disturbances while nothing controls it), so the slew starts at
``start_time``: a chosen geometry of the sky. The summary's zone margins are taken at each
recorded state's time on the scenario's sky (Sun, Moon, Earth limb at their true positions).
"""
from __future__ import annotations

import argparse
import math
import os
import sys
import time
from datetime import UTC, datetime, timedelta
from pathlib import Path

import numpy as np
import rclpy

from att_msgs.msg import SpacecraftState
from att_msgs.srv import ResetSimulator
from att_msgs_py import convert, qos
from att_msgs_py.log import read_log
from att_msgs_py.topics import RESET_SIMULATOR, STATE
from att_planner.nodes.client import client_session, maneuver_request
from att_planner.service.warm import maneuver_from_scenario
from att_planner.tools.launch import isolated_env, join_env, start_suite
from att_planner.tools.review import review
from att_planner.zones import FittedZones, zones_from_cones
from att_sim.models import rotations as rot
from att_sim.models import scenario as scen
from att_sim.models.ephemeris import Ephemeris


def zone_margins(scenario: scen.Scenario, maneuver: dict, t: np.ndarray, q: np.ndarray) -> tuple[list, np.ndarray]:
    """Names and margins (K, Z) rad of the cones and zones at sim times ``t`` (their true positions
    on the scenario's sky; moving zones need the scenario's epoch)."""
    zones = zones_from_cones(maneuver["cones"], maneuver["sensor"]) + maneuver["zones"]
    if not zones:
        return [], np.zeros((len(t), 0))
    sky = Ephemeris(scenario.epoch, scenario.orbit_model) if scenario.epoch is not None else None
    zone_sky = FittedZones(zones, sky if any(z.body != "inertial" for z in zones) else None, window=1.0)
    return [z.name for z in zones], zone_sky.margins(t, q, true=True)


def summarize(mcap_path: Path, maneuver: dict, scenario: scen.Scenario) -> dict:
    """Figures measured from the recorded truth state."""
    state = read_log(mcap_path, topics=[STATE])[STATE]
    q, t = state["attitude"], np.asarray(state["header.stamp"], float)
    names, m = zone_margins(scenario, maneuver, t, q)
    return {"state_messages": len(state), "sim_time": float(t[-1]),
            "final_attitude_error_deg": float(np.degrees(rot.angle_between(q[-1], maneuver["qf"]))),
            "final_rate": float(np.linalg.norm(state["body_rate"][-1])),
            "min_cone_margin_deg": float(np.degrees(m.min())) if m.size else math.inf,
            "min_margin_per_cone_deg": {n: float(np.degrees(v)) for n, v in zip(names, m.min(axis=0))}}


class SimClock:
    """The simulator's time as its latest state says, heard on the client's node."""

    def __init__(self, node):
        self.node, self.t = node, None
        node.create_subscription(SpacecraftState, STATE, self._on_state, qos.STREAM_QOS)

    def _on_state(self, msg):
        self.t = convert.from_time(msg.header.stamp)

    def wait(self, until: float = -math.inf, timeout: float = 120.0) -> float:
        """Spin until a state at or after sim time ``until`` has arrived; its time."""
        deadline = time.monotonic() + timeout
        while self.t is None or self.t < until:
            if time.monotonic() > deadline:
                raise TimeoutError(f"the simulator's state did not reach t = {until:.1f} s within {timeout:.0f} s")
            rclpy.spin_once(self.node, timeout_sec=0.05)
        return self.t


def domain_line(env: dict, base: dict | None = None) -> str:
    """Which domain and discovery range the run uses, and whether they were inherited or chosen."""
    base = os.environ if base is None else base
    inherited = bool(base.get("ROS_DOMAIN_ID", "").strip())
    range_set = bool(base.get("ROS_AUTOMATIC_DISCOVERY_RANGE", "").strip())
    how = ("inherited from your environment" if inherited
           else "chosen at random: ROS_DOMAIN_ID is unset (export ROS_DOMAIN_ID=<0..232> to pick one)")
    return (f"ROS_DOMAIN_ID {env['ROS_DOMAIN_ID']} ({how}), discovery {env['ROS_AUTOMATIC_DISCOVERY_RANGE']} "
            f"({'inherited' if range_set else 'default: this host only'})")


def reset_to_start(client, clock: SimClock, maneuver: dict) -> float:
    """Wait for ``start_time − start_lead`` and reset the simulator to the initial attitude at
    rest; the sim time of the reset."""
    t_reset = float(maneuver["start_time"]) - maneuver["start_lead"]
    print(f"[demo] waiting for sim time {t_reset:.1f} s, then resetting to the initial attitude at rest")
    t = clock.wait(t_reset, timeout=600.0)
    reset = client.create_client(ResetSimulator, RESET_SIMULATOR)
    if not reset.wait_for_service(timeout_sec=30.0):
        raise TimeoutError(f"service {RESET_SIMULATOR} not available")
    future = reset.call_async(ResetSimulator.Request(attitude=convert.quaternion(maneuver["q0"]),
                                                     body_rate=convert.vector3(np.zeros(3))))
    rclpy.spin_until_future_complete(client, future, timeout_sec=30.0)
    answer = future.result()
    if answer is None or not answer.success:
        raise RuntimeError(f"the simulator refused the reset: {answer.message if answer else 'no answer'}")
    return t


def request_and_execute(client, scenario: scen.Scenario, maneuver: dict):
    """Plan the maneuver over the service (starting at the epoch of the sim time it will be
    executed at) and execute it then; (success, plan message or None)."""
    client.wait_for_servers(timeout=60)
    clock = SimClock(client)
    t_now = clock.wait()
    if maneuver["start_time"] is not None and scenario.epoch is not None:
        t_now = reset_to_start(client, clock, maneuver)
    t_start, epoch = t_now, None
    if scenario.epoch is not None:
        t_start = t_now + maneuver["start_lead"]
        epoch = scenario.epoch + timedelta(seconds=t_start)
    print(f"[demo] sim time {t_now:.1f} s: requesting the maneuver"
          + (f" to start at {t_start:.1f} s ({epoch.isoformat()})" if epoch else ""))
    response = client.plan(maneuver_request(maneuver["q0"], maneuver["qf"], maneuver["sensor"], maneuver["cones"],
                                            method=maneuver["method"], time_budget=maneuver["time_budget"],
                                            frame_id=scenario.frame_id, epoch=epoch, zones=maneuver["zones"]))
    plan = response.plan
    if not response.success:
        print(f"[demo] planner refused: code {response.error_code}: {response.message}")
        return False, None
    v = plan.verification
    print(f"[demo] plan {plan.plan_id}: method {plan.method}, status {plan.status}, duration {plan.duration:.1f} s, "
          f"solved in {plan.solve_seconds:.2f} s; verified: final error "
          f"{math.degrees(v.final_attitude_error):.4f} deg, "
          f"min cone margin {math.degrees(v.min_cone_margin):.2f} deg, torque/limit {v.torque_ratio:.3f}")
    last = [0.0]

    def on_feedback(msg):
        fb = msg.feedback
        if time.monotonic() - last[0] > 2.0:
            last[0] = time.monotonic()
            print(f"[demo]   t = {fb.elapsed:6.1f} s  progress {100 * fb.progress:5.1f} %  "
                  f"tracking error {math.degrees(fb.attitude_error):6.3f} deg  cone margin "
                  f"{math.degrees(fb.min_cone_margin):6.2f} deg")

    if epoch is not None:
        late = clock.wait() - t_start
        if late > 0:
            print(f"[demo] planning took longer than start_lead: the flight starts {late:.1f} s of sim time after "
                  "the plan's epoch (its moving zones are that much further on)")
        clock.wait(t_start)
    result = client.execute(plan.plan_id, on_feedback=on_feedback)
    print(f"[demo] execution: {result.message} (code {result.error_code}) after {result.duration:.1f} s of sim time")
    return result.success, plan


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(prog="att-demo", description=__doc__.splitlines()[0])
    parser.add_argument("--scenario", default="swift_demo")
    parser.add_argument("--out", default="runs", help="directory for the MCAP and the node logs")
    args = parser.parse_args(argv)

    try:
        scenario = scen.load(args.scenario)
        maneuver = maneuver_from_scenario(scenario)
    except (KeyError, ValueError) as err:       # KeyError: an unknown scenario (its message is the one argument)
        print(f"att-demo: {err.args[0] if isinstance(err, KeyError) and err.args else err}", file=sys.stderr)
        return 2
    run_dir = Path(args.out) / f"{scenario.name}_{datetime.now(UTC).strftime('%Y%m%d_%H%M%S')}"
    mcap_path = run_dir / "run.mcap"
    try:
        env = isolated_env(inherit=True)
    except ValueError as err:
        print(f"att-demo: {err}", file=sys.stderr)
        return 2
    print(f"[demo] {domain_line(env)}")
    join_env(env)
    print(f"[demo] scenario {scenario.name}, logs in {run_dir}")
    suite = start_suite(scenario.name, mcap_path, run_dir, env=env)

    ok, plan = False, None
    try:
        with client_session("demo") as client:
            ok, plan = request_and_execute(client, scenario, maneuver)
    finally:
        codes = suite.stop()
        print(f"[demo] nodes stopped: {codes}")
    summary = summarize(mcap_path, maneuver, scenario)
    print(f"[demo] summary from the recorded state ({summary['state_messages']} messages, "
          f"{summary['sim_time']:.1f} s):")
    if plan is not None:
        print(f"[demo]   method {plan.method}, maneuver time {plan.duration:.1f} s")
    print(f"[demo]   final attitude error {summary['final_attitude_error_deg']:.4f} deg, final rate "
          f"{summary['final_rate']:.2e} rad/s")
    print(f"[demo]   minimum zone margin {summary['min_cone_margin_deg']:.2f} deg "
          f"({', '.join(f'{k} {v:.2f}' for k, v in summary['min_margin_per_cone_deg'].items())})")
    try:
        print(f"[demo] review (figures, summary, HTML): {review(mcap_path, run_dir / 'review').html}")
    except (ValueError, OSError) as err:
        print(f"[demo] review failed: {err}")
    print(f"MCAP: {mcap_path}")
    return 0 if ok else 1


if __name__ == "__main__":
    sys.exit(main())
