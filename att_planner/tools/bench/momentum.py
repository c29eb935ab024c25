"""momentum: nadir pointing for days, with and without magnetorquer dumping.

``att-bench momentum [--scenario leo_momentum] [--orbits 15] --json PATH`` runs the scenario through
the ROS nodes (recorder, simulator, controller: the controller on the truth state) twice from the
nadir attitude and rate, the wheels at their null-space bias: holding ``nadir`` pointing for
``--orbits`` orbits with the momentum dumping on, then with it off until a wheel reaches its speed
limit (or the orbits are flown). Every figure comes from the recorded MCAP
(:mod:`att_planner.tools.review.pointing`: the controller's status, the truth's wheel speeds, the
commanded dipoles; the pointing error from the 600th second of pointing on, after the start's
transient), which also holds the reference attitude the controller tracked:

``{"mcap", "orbits", "period_s", "dumping": {"peak_wheel_speed_ratio", "pointing_error_rms_deg",
"pointing_error_max_deg", "dipole_duty", "mcap", "sim_seconds", "wall_seconds", "rtf"},
"no_dumping": {"peak_wheel_speed_ratio", "saturation_time_s", "mcap", ...}, "rtf"}``.
"""
from __future__ import annotations

import math
import multiprocessing
import time
from concurrent.futures import ProcessPoolExecutor
from datetime import UTC, datetime
from pathlib import Path

import numpy as np
import rclpy

from att_msgs.msg import SpacecraftState
from att_msgs.srv import ResetSimulator
from att_msgs_py import convert, qos, topics
from att_msgs_py.log import read_log
from att_msgs_py.types import ControlMode, PointingMode
from att_planner.control.momentum import null_space
from att_planner.guidance import reference
from att_planner.guidance.laws import PointingGeometry
from att_planner.guidance.modes import law_of
from att_planner.nodes.client import client_session
from att_planner.tools.closed_loop import ClosedLoop
from att_planner.tools.launch import isolated_env, join_env, start_suite
from att_planner.tools.loop_log import open_loop_log
from att_planner.tools.review.pointing import SATURATED, TOPICS, pointing_of, pointing_summary
from att_sim.models import scenario as scen
from att_sim.models import world

NODES = ("recorder", "simulator", "controller")
SETTLE = 600.0             # s after the pointing starts before its error counts (the start transient)


def configure(parser):
    parser.add_argument("--scenario", default="leo_momentum", help="a scenario with wheels and magnetorquers")
    parser.add_argument("--orbits", type=float, default=15.0, help="orbits flown with dumping (and at most without)")
    parser.add_argument("--out", default="bench_out/momentum", help="directory for the runs' logs")
    parser.add_argument("--in-process", action="store_true",
                        help="fly the simulator's and the controller's cores in this process (no DDS: several "
                             "times faster; the same figures from the same topics)")


def start_state(s: scen.Scenario, t: float) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The nadir attitude and rate at sim time ``t`` and the wheel speeds at the controller's
    null-space bias."""
    geometry = PointingGeometry.of(world.Environment.from_scenario(s))
    law = law_of(PointingMode("nadir"), geometry, t, np.array([0, 0, 0, 1.0]))
    ref = reference(law.attitude, t)
    bias = float(s.node_params.get("controller", {}).get("null_space_speed_rad_s", 0.0))
    N = null_space(s.spacecraft)
    wheels = N @ np.full(N.shape[1], bias) if N.size else np.zeros(s.spacecraft.n_wheels)
    return ref.q_RN, ref.omega_RN_R, wheels + s.spacecraft.wheel_axes.T @ ref.omega_RN_R      # inertial spin rates


def fly(s: scen.Scenario, dumping: bool, seconds: float, out: Path) -> dict:
    """One run: nadir pointing for ``seconds`` of sim time (without dumping: until a wheel saturates)."""
    run_dir = out / f"{s.name}_{'dumping' if dumping else 'no_dumping'}_{datetime.now(UTC).strftime('%Y%m%d_%H%M%S')}"
    mcap = run_dir / "run.mcap"
    env = isolated_env()
    join_env(env)
    suite = start_suite(s.name, mcap, run_dir, env=env, nodes=NODES, params={"controller": {"state_source": "truth"}})
    limit = s.spacecraft.wheel_speed_max
    latest: dict = {}
    try:
        with client_session(f"bench_momentum_{int(dumping)}") as client:
            client.create_subscription(SpacecraftState, topics.STATE, lambda m: latest.update(msg=m), qos.STREAM_QOS)
            reset = client.create_client(ResetSimulator, topics.RESET_SIMULATOR)
            if not reset.wait_for_service(timeout_sec=60.0):
                raise TimeoutError(f"service {topics.RESET_SIMULATOR} not available")
            while "msg" not in latest:
                rclpy.spin_once(client, timeout_sec=0.1)
            q0, w0, wheels0 = start_state(s, convert.from_time(latest["msg"].header.stamp))
            start = ResetSimulator.Request(attitude=convert.quaternion(q0), body_rate=convert.vector3(w0),
                                           wheel_speeds=[float(v) for v in wheels0])
            future = reset.call_async(start)
            rclpy.spin_until_future_complete(client, future, timeout_sec=30.0)
            if future.result() is None or not future.result().success:
                raise RuntimeError(f"the simulator refused the start state: {future.result()}")
            answer = client.set_mode(ControlMode.POINTING, pointing=PointingMode("nadir"), dumping=dumping)
            if not answer.success:
                raise RuntimeError(f"the controller refused nadir pointing: {answer.message}")
            wall0 = time.monotonic()
            while True:
                rclpy.spin_once(client, timeout_sec=0.5)
                msg = latest.get("msg")
                if msg is None:
                    continue
                state = convert.state_from_msg(msg)
                ratio = np.max(np.abs(state.wheel_speeds - s.spacecraft.wheel_axes.T @ state.omega)) / limit
                if state.t >= seconds or (not dumping and ratio >= SATURATED):
                    break
            wall = time.monotonic() - wall0
    finally:
        suite.stop()
    return figures_of(s, mcap, wall)


def fly_in_process(s: scen.Scenario, dumping: bool, seconds: float, out: Path) -> dict:
    """:func:`fly` with the cores of the simulator and the controller in this process
    (:class:`~att_planner.tools.closed_loop.ClosedLoop`, no DDS): what the nodes would publish written
    to the MCAP (:mod:`att_planner.tools.loop_log`)."""
    run_dir = out / f"{s.name}_{'dumping' if dumping else 'no_dumping'}_in_process_{datetime.now(UTC):%Y%m%d_%H%M%S}"
    run_dir.mkdir(parents=True, exist_ok=True)
    mcap = run_dir / "run.mcap"
    q0, w0, wheels0 = start_state(s, 0.0)
    loop = ClosedLoop(s, q0=q0, omega0=w0, wheel_speed0=wheels0,
                      overrides={"controller": {"state_source": "truth", "momentum_dumping": dumping}})
    log, write = open_loop_log(mcap)
    limit, saturated = s.spacecraft.wheel_speed_max, []

    def record(topic, t, message):
        write(topic, t, message)
        if topic == topics.STATE and not dumping:
            relative = message.wheel_speeds - s.spacecraft.wheel_axes.T @ message.omega
            if np.max(np.abs(relative)) / limit >= SATURATED:
                saturated.append(t)

    wall0 = time.monotonic()
    loop.run(loop.step)
    code, why, _ = loop.controller.set_mode(ControlMode.POINTING, PointingMode("nadir"))
    if code:
        raise RuntimeError(f"the controller refused nadir pointing: {why}")
    loop.tap = record
    while loop.sim.t < seconds and not saturated and not loop.sim.halted:
        loop.run(60.0)
    wall = time.monotonic() - wall0
    log.close()
    return {**figures_of(s, mcap, wall), "in_process": True}


def figures_of(s: scen.Scenario, mcap: Path, wall: float) -> dict:
    """A flight's figures from its MCAP alone (:func:`pointing_summary`), with its real-time factor."""
    run = pointing_of(read_log(mcap, topics=TOPICS), s.spacecraft)
    sim_seconds = float(run.state_t[-1] - run.state_t[0])
    return {**pointing_summary(run, settle=SETTLE), "mcap": str(mcap), "sim_seconds": sim_seconds,
            "wall_seconds": wall, "rtf": sim_seconds / wall if wall > 0 else math.inf}


def run(args) -> dict:
    s = scen.load(args.scenario)
    period = getattr(s.orbit_model, "period", None) or 2 * math.pi / s.orbit.mean_motion
    seconds = args.orbits * period
    out = Path(args.out)
    if args.in_process:         # the two flights side by side, one process each
        with ProcessPoolExecutor(2, mp_context=multiprocessing.get_context("spawn")) as pool:
            on, off = pool.map(fly_in_process, [s, s], [True, False], [seconds, seconds], [out, out])
    else:
        on, off = fly(s, True, seconds, out), fly(s, False, seconds, out)
    print(f"\nmomentum: {s.name}, nadir pointing, {args.orbits:g} orbits of {period:.0f} s")
    print(f"{'':<28} {'dumping on':>14} {'dumping off':>14}")
    for key in ("peak_wheel_speed_ratio", "pointing_error_rms_deg", "pointing_error_max_deg", "dipole_duty",
                "saturation_time_s", "sim_seconds", "rtf"):
        row = [("-" if r.get(key) is None else f"{r[key]:.5g}") for r in (on, off)]
        print(f"{key:<28} {row[0]:>14} {row[1]:>14}")
    return {"mcap": on["mcap"], "orbits": args.orbits, "period_s": period,
            "dumping": on, "no_dumping": off, "rtf": (on["sim_seconds"] + off["sim_seconds"])
            / (on["wall_seconds"] + off["wall_seconds"])}
