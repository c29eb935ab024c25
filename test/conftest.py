"""Shared test fixtures: an isolated ROS 2 domain per test process, and the one factory that
starts the suite's nodes as processes and tears them down (:func:`ros_suite`)."""
from __future__ import annotations

import os
import time
from contextlib import contextmanager
from dataclasses import dataclass, field
from pathlib import Path

import pytest

from att_planner.nodes.client import SuiteClient, client_session
from att_planner.tools.launch import Suite, default_nodes, fresh_domain_id, isolated_env, join_env, start_suite


def wait_for_controller_step(client: SuiteClient, timeout: float = 60.0) -> None:
    """Spin until the controller reports a step on a fresh state (a goal sent before its first state
    is answered NO_STATE: a race, not what the tests are about), as long as the services get: the
    nodes' imports on two busy cores took more than 30 s once."""
    import rclpy

    from att_msgs.msg import ControllerStatus
    from att_msgs_py import qos, topics

    stepped = []
    sub = client.create_subscription(ControllerStatus, topics.CONTROLLER_STATUS,
                                     lambda m: stepped.append(not m.state_stale), qos.STREAM_QOS)
    end = time.monotonic() + timeout
    while not any(stepped) and time.monotonic() < end:
        rclpy.spin_once(client, timeout_sec=0.05)
    client.destroy_subscription(sub)
    assert any(stepped), f"the controller did not step on a state within {timeout:g} s"


def wait_for_converged_estimate(client: SuiteClient, timeout: float = 60.0) -> None:
    """Spin until the estimator publishes a converged attitude (a goal sent before it is answered
    ESTIMATE_UNHEALTHY: a race, not what the tests are about)."""
    import rclpy

    from att_msgs.msg import AttitudeEstimate
    from att_msgs_py import qos, topics

    converged = []
    sub = client.create_subscription(AttitudeEstimate, topics.ESTIMATE,
                                     lambda m: converged.append(m.health == m.HEALTH_CONVERGED), qos.STREAM_QOS)
    end = time.monotonic() + timeout
    while not any(converged) and time.monotonic() < end:
        rclpy.spin_once(client, timeout_sec=0.05)
    client.destroy_subscription(sub)
    assert any(converged), f"the estimate did not converge within {timeout:g} s"


# pytest-timeout's deadline for a `ros` or `slow` test (pyproject.toml's `timeout` is the unit-test one):
# the slowest of a full run took 121 s of module setup (a mission flown) on the 2-core machine.
ROS_OR_SLOW_TIMEOUT = 600


def pytest_collection_modifyitems(config, items):
    """Give every `ros` or `slow` test without its own ``timeout`` mark the larger deadline."""
    for item in items:
        if item.get_closest_marker("timeout") is None and (
                item.get_closest_marker("ros") or item.get_closest_marker("slow")):
            item.add_marker(pytest.mark.timeout(ROS_OR_SLOW_TIMEOUT))


@pytest.fixture(scope="session", autouse=True)
def isolated_ros_domain():
    """Every test process talks on its own random domain, localhost only."""
    os.environ["ROS_DOMAIN_ID"] = str(fresh_domain_id())
    os.environ["ROS_AUTOMATIC_DISCOVERY_RANGE"] = "LOCALHOST"
    yield


@pytest.fixture(scope="session", autouse=True)
def isolated_state_dir(tmp_path_factory):
    """The nodes' kept state (the controller's last accepted mode sequences) in a folder of this run,
    never the user's: a test run neither reads nor leaves state behind."""
    os.environ["ATT_STATE_DIR"] = str(tmp_path_factory.mktemp("att_state"))
    yield


@dataclass
class RosSuite:
    """Nodes started by :func:`ros_suite`, a client joined to their domain, the run's log."""

    suite: Suite
    client: SuiteClient
    mcap: Path
    exit_codes: dict = field(default_factory=dict)     # filled when the nodes are stopped

    def stop(self) -> dict:
        """Stop every node now (the log is then finalised); their exit codes."""
        self.exit_codes = self.exit_codes or self.suite.stop()
        return self.exit_codes


@pytest.fixture(scope="session")
def ros_suite(tmp_path_factory):
    """Factory of running suites: ``with ros_suite("swift_demo", params=...) as s:`` starts the
    ``nodes`` of a scenario (default: its whole run, :func:`att_planner.tools.launch.default_nodes`)
    on a fresh isolated domain (simulator held at t = 0 until the recorder
    and controller listen), joins a :class:`SuiteClient` to it and waits for the services and for
    the controller's first step on a state (when both run); on exit
    every node is stopped and must have ended."""

    @contextmanager
    def start(scenario: str, *, nodes=None, params=None,
              schedule: bool = False, name: str = "test_client"):
        out = tmp_path_factory.mktemp(name)
        nodes = default_nodes(scenario) if nodes is None else nodes
        env = isolated_env()
        join_env(env)
        suite = start_suite(scenario, out / "run.mcap", out, env=env, nodes=nodes, params=params)
        running = None
        try:
            with client_session(name) as client:
                if "planner" in nodes and "controller" in nodes:
                    client.wait_for_servers(timeout=60, schedule=schedule)
                if "simulator" in nodes and "controller" in nodes:
                    wait_for_controller_step(client)
                if "simulator" in nodes and "estimator" in nodes:
                    wait_for_converged_estimate(client)
                running = RosSuite(suite, client, out / "run.mcap")
                yield running
        finally:
            codes = running.stop() if running is not None else suite.stop()
            assert all(p.poll() is not None for p in suite.procs.values()), codes

    return start
