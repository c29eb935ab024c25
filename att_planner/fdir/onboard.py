"""The fault monitor on board (no ROS): fed what the controller publishes and receives, its responses acted on.

:class:`Onboard` is what the controller node and the in-process closed loop
(:class:`att_planner.tools.closed_loop.ClosedLoop`) both hold: a :class:`~.monitor.FaultMonitor` of the
fault table on the scenario's spacecraft, fed through a :class:`~.tap.MonitorTap` (the commands, the
wheel speeds, the estimates, the controller's status; the estimator's innovations where the estimator
is in the same process), and :meth:`Onboard.respond`, which acts on the monitor's responses
(:func:`.recovery.act`) when it reported something new. :func:`load_table` reads the ``fault_table``
parameter: empty (no fault handling), a table's name under ``config/faults/`` or a file's path.
"""
from __future__ import annotations

from pathlib import Path

from att_msgs_py.errors import ConfigError, ErrorCode, clip
from att_msgs_py.types import FaultStatus, ManeuverResult
from att_planner.fdir import recovery
from att_planner.fdir import table as tables
from att_planner.fdir.monitor import FaultMonitor
from att_planner.fdir.tap import MonitorTap
from att_sim.models.config_files import ConfigFileError

TABLES = tables.DEFAULT_TABLE.parent          # config/faults/: the tables known by name


def load_table(value: str) -> tables.FaultTable | None:
    """The fault table of parameter ``fault_table``: None for an empty value, else the file
    ``config/faults/VALUE.yaml`` (a name: letters, digits, ``_``, ``-``) or the YAML file at path
    ``VALUE``; ConfigError (INVALID_CONFIG) naming the parameter, what was expected and found."""
    if not value:
        return None
    named = all(ch.isalnum() or ch in "_-" for ch in value) and len(value) <= 64
    path = TABLES / f"{value}.yaml" if named else Path(value)
    if path.suffix not in (".yaml", ".yml") or not path.is_file():
        known = ", ".join(sorted(p.stem for p in TABLES.glob("*.yaml")))
        raise ConfigError(ErrorCode.INVALID_CONFIG,
                          f"parameter 'fault_table': expected empty (no fault handling), a table of config/faults "
                          f"({known}) or a fault table file (.yaml); found '{clip(value, 200)}', which is neither")
    try:
        return tables.read(path)
    except ConfigFileError as err:
        raise ConfigError(ErrorCode.INVALID_CONFIG, f"parameter 'fault_table': {clip(err.message, 300)}") from None


class Onboard:
    """The monitor of ``table`` on ``scenario``'s spacecraft, acting on ``controller`` (and ``estimator``:
    its exclusions, and the innovations the monitor takes from it; None: in another process)."""

    def __init__(self, table: tables.FaultTable, scenario, controller, estimator=None):
        self.monitor = FaultMonitor(table, scenario.spacecraft, scenario.sensors, scenario.body_frame_id)
        self.tap = MonitorTap(self.monitor, estimator, controller.friction)
        self.controller, self.estimator = controller, estimator
        self._seen = 0

    def feed(self, topic: str, t: float, message) -> list[FaultStatus]:
        """What was published on ``topic`` (the mirror type of :mod:`att_msgs_py.types`): the reports it made."""
        n = len(self.tap.reports)
        self.tap(topic, t, message)
        return self.tap.reports[n:]

    def respond(self) -> tuple[ManeuverResult | None, bool]:
        """Act on the responses when the monitor reported something new: (the result of a maneuver safe
        mode aborted, whether the healthy wheels changed)."""
        if len(self.monitor.history) == self._seen:
            return None, False
        self._seen = len(self.monitor.history)
        before = self.controller.healthy
        ended = recovery.act(self.monitor.responses(), self.controller, self.estimator)
        return ended, self.controller.healthy != before
