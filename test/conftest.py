"""Shared test fixtures: an isolated ROS 2 suite started as processes, torn down after use."""
from __future__ import annotations

import os
import random

import pytest


@pytest.fixture(scope="session", autouse=True)
def isolated_ros_domain():
    """Every test process talks on its own random domain, localhost only."""
    os.environ["ROS_DOMAIN_ID"] = str(random.randint(1, 200))
    os.environ["ROS_AUTOMATIC_DISCOVERY_RANGE"] = "LOCALHOST"
    yield
