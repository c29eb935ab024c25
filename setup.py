"""att_suite: one ament_python package holding att_planner, att_sim and att_msgs_py.

The interfaces (att_msgs) are a separate rosidl package under att_msgs_py/interfaces, built by the
Makefile into the venv prefix before this package is installed.
"""
from glob import glob

from setuptools import find_packages, setup

PACKAGE = "att_suite"

setup(
    name=PACKAGE,
    version="0.1.0",
    packages=find_packages(include=["att_planner*", "att_sim*", "att_msgs_py*"]),
    package_data={"att_msgs_py": ["fastdds_profiles.xml"]},
    data_files=[
        ("share/ament_index/resource_index/packages", ["resource/" + PACKAGE]),
        ("share/" + PACKAGE, ["package.xml"]),
        ("share/" + PACKAGE + "/config", glob("config/*.yaml")),
        ("share/" + PACKAGE + "/config/spacecraft", glob("config/spacecraft/*.yaml")),
        ("share/" + PACKAGE + "/config/scenarios", glob("config/scenarios/*.yaml")),
        ("share/" + PACKAGE + "/config/targets", glob("config/targets/*.yaml")),
        ("share/" + PACKAGE + "/config/missions", glob("config/missions/*.yaml")),
        ("share/" + PACKAGE + "/config/schemas", glob("config/schemas/*.schema.json")),
        ("share/" + PACKAGE + "/campaigns", glob("campaigns/*.yaml")),
    ],
    install_requires=["numpy", "scipy", "pyyaml", "pydantic>=2", "mcap", "mcap-ros2-support", "casadi"],
    zip_safe=True,
    maintainer="att-suite maintainers",
    maintainer_email="maintainers@att-suite.org",
    description="Onboard-style spacecraft attitude planning suite for ROS 2",
    license="Apache-2.0",
    python_requires=">=3.11",
    entry_points={
        "console_scripts": [
            "att-sim = att_sim.truth.simulator_node:main",
            "att-planner = att_planner.nodes.planner_node:main",
            "att-controller = att_planner.nodes.controller_node:main",
            "att-estimator = att_planner.nodes.estimator_node:main",
            "att-recorder = att_msgs_py.log.recorder_node:main",
            "att-bridge = att_msgs_py.log.bridge_node:main",
            "att-replay = att_msgs_py.log.replay:main",
            "att-review = att_planner.tools.review:main",
            "att-demo = att_planner.tools.demo:main",
            "att-bench = att_planner.tools.bench:main",
            "att-tune = att_planner.tools.tune:main",
            "att-keygen = att_planner.tools.keygen:main",
            "att-log = att_msgs_py.log.cli:main",
            "att-mc = att_planner.tools.monte_carlo:main",
            "att-mission = att_planner.tools.mission:main",
            "att-config = att_planner.tools.config_cli:main",
        ],
    },
)
