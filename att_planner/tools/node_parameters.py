"""Every suite node's parameter declarations, by node name (as :data:`att_planner.tools.launch.NODE_MODULES`
names the nodes), and their Markdown reference for the documentation.

``python -m att_planner.tools.node_parameters`` prints that reference.
"""
from __future__ import annotations

from att_msgs_py.log.log_parameters import BRIDGE, RECORDER
from att_msgs_py.parameter_docs import markdown_all
from att_msgs_py.parameters import SCENARIO, ParameterTable
from att_planner.control.controller_parameters import CONTROLLER
from att_planner.estimation.estimator_parameters import ESTIMATOR
from att_planner.service.planner_parameters import PLANNER
from att_sim.truth.simulator_parameters import SIMULATOR

SCENARIO_NODES = ("simulator", "controller", "estimator", "planner")    # the nodes that take ``scenario``
NODE_PARAMETERS: dict[str, ParameterTable] = {
    "simulator": SIMULATOR, "controller": CONTROLLER, "estimator": ESTIMATOR, "planner": PLANNER,
    "recorder": RECORDER, "bridge": BRIDGE,
}


def declared(node: str) -> ParameterTable:
    """Every parameter ``node`` declares: its own and, for a node of a scenario, ``scenario``."""
    table = NODE_PARAMETERS[node]
    return ParameterTable(node, (SCENARIO,), table.summary) + table if node in SCENARIO_NODES else table


def reference(level: int = 2) -> str:
    """The Markdown reference of every node's parameters."""
    return markdown_all({node: declared(node) for node in NODE_PARAMETERS}, level)


if __name__ == "__main__":
    print(reference(), end="")
