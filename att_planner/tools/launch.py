"""Start the suite's nodes as separate processes (there is no ros2 launch from PyPI).

Used by ``att-demo`` and the integration tests. :func:`isolated_env` gives a process environment
on a random ``ROS_DOMAIN_ID`` with localhost-only discovery, so runs never see each other or the
network (``inherit=True``, for ``att-demo``: a domain and discovery range the user set are kept).
:meth:`Suite.stop` stops the nodes with SIGINT (recorder last, so it sees everything), waits, and
kills what does not exit.
"""
from __future__ import annotations

import os
import random
import re
import signal
import subprocess
import sys
import time
from dataclasses import dataclass, field
from pathlib import Path

from att_msgs_py import memory

NODE_MODULES = {
    "simulator": "att_sim.truth.simulator_node",
    "controller": "att_planner.nodes.controller_node",
    "estimator": "att_planner.nodes.estimator_node",
    "planner": "att_planner.nodes.planner_node",
    "recorder": "att_msgs_py.log.recorder_node",
    "bridge": "att_msgs_py.log.bridge_node",
}


MAX_DOMAIN_ID = 232            # the largest ROS_DOMAIN_ID that maps to valid DDS ports on Linux
DISCOVERY_RANGES = ("OFF", "LOCALHOST", "SUBNET", "SYSTEM_DEFAULT")


_DOMAINS_HANDED_OUT: set[int] = set()


def fresh_domain_id() -> int:
    """A random ROS domain in 1..200 not yet handed out by this process (any when all were)."""
    free = sorted(set(range(1, 201)) - _DOMAINS_HANDED_OUT) or list(range(1, 201))
    domain = random.SystemRandom().choice(free)
    _DOMAINS_HANDED_OUT.add(domain)
    return domain


def isolated_env(domain_id: int | None = None, base: dict | None = None, *, inherit: bool = False) -> dict:
    """``base`` (default: this process's environment) on ``domain_id`` (default: random 1..200) with
    localhost-only discovery. ``inherit``: a ``ROS_DOMAIN_ID`` / ``ROS_AUTOMATIC_DISCOVERY_RANGE``
    set (non-empty) in ``base`` is kept instead (ValueError when it is not a valid value)."""
    env = dict(os.environ if base is None else base)
    user_domain = env.get("ROS_DOMAIN_ID", "").strip() if inherit and domain_id is None else ""
    if user_domain:
        if not re.fullmatch(r"[0-9]{1,3}", user_domain) or int(user_domain) > MAX_DOMAIN_ID:
            raise ValueError(f"ROS_DOMAIN_ID is '{user_domain[:40]}': expected an integer 0..{MAX_DOMAIN_ID} "
                             "(or unset it for a random free domain)")
        env["ROS_DOMAIN_ID"] = str(int(user_domain))
    else:
        env["ROS_DOMAIN_ID"] = str(domain_id if domain_id is not None else fresh_domain_id())
    user_range = env.get("ROS_AUTOMATIC_DISCOVERY_RANGE", "").strip() if inherit else ""
    if user_range and user_range not in DISCOVERY_RANGES:
        raise ValueError(f"ROS_AUTOMATIC_DISCOVERY_RANGE is '{user_range[:40]}': expected one of "
                         f"{', '.join(DISCOVERY_RANGES)}")
    env["ROS_AUTOMATIC_DISCOVERY_RANGE"] = user_range or "LOCALHOST"
    env.setdefault("RCUTILS_COLORIZED_OUTPUT", "0")
    for key, value in memory.C_ALLOCATOR.items():          # freed memory goes back (att_msgs_py.memory)
        env.setdefault(key, value)
    env["PYTHONUNBUFFERED"] = "1"
    return env


def join_env(env: dict) -> None:
    """Put this process on ``env``'s domain and discovery range, so that its own rclpy client
    (demo, tests) talks to the nodes started with ``env``."""
    os.environ.update({k: env[k] for k in ("ROS_DOMAIN_ID", "ROS_AUTOMATIC_DISCOVERY_RANGE")})


@dataclass
class Suite:
    env: dict
    log_dir: Path
    procs: dict = field(default_factory=dict)
    profile_dir: Path | None = None      # run every node under cProfile, writing NAME.prof here
    cpu_dir: Path | None = None          # run every node with its CPU timed by layer, writing NAME.json here

    def __enter__(self) -> Suite:
        return self

    def __exit__(self, *exc) -> None:
        """Leaving a ``with`` block stops every node (:meth:`stop`), whatever happened in it."""
        self.stop()

    def start(self, name: str, params: dict | None = None, params_files: tuple = ()) -> subprocess.Popen:
        """Start node ``name`` with ``-p key:=value`` parameters and ``--params-file`` files
        (both override the scenario defaults; between them rcl's rule applies, see docs/running.md)."""
        module = NODE_MODULES[name]
        if self.cpu_dir is not None:            # att_planner.tools.cpu_layers runs the node module itself
            runner = ["-m", "att_planner.tools.cpu_layers", str(self.cpu_dir / f"{name}.json"), module]
        elif self.profile_dir is not None:
            runner = ["-m", "cProfile", "-o", str(self.profile_dir / f"{name}.prof"), "-m", module]
        else:
            runner = ["-m", module]
        args = [sys.executable, *runner, "--ros-args"]
        for path in params_files:
            args += ["--params-file", str(path)]
        for key, value in (params or {}).items():
            args += ["-p", f"{key}:={value}"]
        self.log_dir.mkdir(parents=True, exist_ok=True)
        out = open(self.log_dir / f"{name}.log", "w")
        self.procs[name] = subprocess.Popen(args, env=self.env, stdout=out, stderr=subprocess.STDOUT)
        return self.procs[name]

    def alive(self) -> dict[str, bool]:
        return {n: p.poll() is None for n, p in self.procs.items()}

    def stop(self, timeout: float = 10.0) -> dict[str, int]:
        """SIGINT every node (recorder last), wait up to ``timeout`` s each, kill stragglers."""
        order = [n for n in self.procs if n != "recorder"] + (["recorder"] if "recorder" in self.procs else [])
        codes = {}
        for name in order:
            proc = self.procs[name]
            if proc.poll() is None:
                proc.send_signal(signal.SIGINT)
                try:
                    proc.wait(timeout)
                except subprocess.TimeoutExpired:
                    proc.kill()
                    proc.wait()
            codes[name] = proc.returncode
        return codes

    def log_text(self, name: str) -> str:
        return (self.log_dir / f"{name}.log").read_text()

    def wait_for_output(self, name: str, text: str, timeout: float, poll: float = 0.2) -> bool:
        """Wait until node ``name`` has printed ``text``; False at the timeout or as soon as the
        process has exited without printing it."""
        end = time.monotonic() + timeout
        while time.monotonic() < end:
            if text in self.log_text(name):
                return True
            if self.procs[name].poll() is not None:
                return text in self.log_text(name)
            time.sleep(poll)
        return False


def default_nodes(scenario: str) -> tuple[str, ...]:
    """The nodes of a whole run of ``scenario``: recorder, simulator, the estimator when the
    scenario has a gyro (its controller then flies on the estimate), controller and planner."""
    from att_sim.models import scenario as scen

    estimator = ("estimator",) if scen.load(scenario).sensors.gyro is not None else ()
    return ("recorder", "simulator", *estimator, "controller", "planner")


def start_suite(scenario: str, mcap_path: str | Path, log_dir: str | Path, *, env: dict | None = None,
                nodes=None, params: dict | None = None, state_listeners: int = 0,
                profile_dir: str | Path | None = None, cpu_dir: str | Path | None = None) -> Suite:
    """Start ``nodes`` (default: :func:`default_nodes`) for ``scenario``; ``params`` maps node name ->
    extra ROS parameters; ``state_listeners``: the caller's own nodes that will subscribe to the
    state (a mission driver), which the simulator counts among its subscribers too; ``profile_dir``:
    every node runs under cProfile and writes ``NAME.prof`` there when it stops; ``cpu_dir``: every
    node runs with its CPU timed by layer (:mod:`att_planner.tools.cpu_layers`) and writes
    ``NAME.json`` there when it stops.

    The simulator holds sim time at zero until the recorder, the controller and the estimator
    (those started), and the caller's ``state_listeners``, subscribe to its state or sensors; the
    controller and the estimator subscribe only once their outputs are heard (commands by the
    simulator and the recorder, the estimate by the recorder), so every run is recorded and
    controlled from t = 0 (without ``state_listeners``, a caller's early subscription would stand in
    for a late recorder).
    """
    nodes = default_nodes(scenario) if nodes is None else nodes
    suite = Suite(env or isolated_env(), Path(log_dir), profile_dir=None if profile_dir is None else Path(profile_dir),
                  cpu_dir=None if cpu_dir is None else Path(cpu_dir))
    recorder = "recorder" in nodes
    listeners = {"simulator": sum(n in nodes for n in ("recorder", "controller", "estimator")) + state_listeners,
                 "controller": ("simulator" in nodes) + int(recorder),
                 "estimator": int(recorder)}
    for name in nodes:
        p = {"scenario": scenario}
        if name == "recorder":
            p = {"output": str(mcap_path)}
        if name in listeners:
            p["wait_for_subscribers"] = listeners[name]
        suite.start(name, {**p, **(params or {}).get(name, {})})
    return suite
