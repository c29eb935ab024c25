"""The fault monitor on board (no ROS): fed what a node publishes and receives, its responses acted on.

:class:`Onboard` is what the controller node, the estimator node and the in-process closed loop
(:class:`att_planner.tools.closed_loop.ClosedLoop`) hold: a :class:`~.monitor.FaultMonitor` of the
fault table on the scenario's spacecraft, fed through a :class:`~.tap.MonitorTap` (the commands, the
wheel speeds, the estimates, the controller's status; the estimator's innovations where the estimator
is in the same process), and :meth:`Onboard.respond`, which acts on the monitor's responses
(:func:`.recovery.act`) when it reported something new. Through the nodes the estimator's runs its
sensor detectors (the gyro, magnetometer, tracker arrivals and innovations) and excludes a sensor
isolated; the controller's runs the others and hears the estimator's reports (:meth:`Onboard.hear`)
for their responses (safe mode on a gyro fault). :func:`load_table` reads the ``fault_table``
parameter: empty (no fault handling), a table's name under ``config/faults/`` or a file's path.
"""
from __future__ import annotations

from collections import deque
from pathlib import Path

from att_msgs_py import topics
from att_msgs_py.errors import ConfigError, ErrorCode, RequestError, clip
from att_msgs_py.types import FaultStatus, ManeuverResult
from att_planner.control.coil_check import CoilCheck
from att_planner.control.wheel_check import WheelCheck
from att_planner.fdir import recovery
from att_planner.fdir import table as tables
from att_planner.fdir.monitor import FaultMonitor
from att_planner.fdir.responses import responses
from att_planner.fdir.tap import MonitorTap
from att_sim.models.config_files import ConfigFileError

TABLES = tables.DEFAULT_TABLE.parent          # config/faults/: the tables known by name
MAX_PENDING = 64                              # commands waiting for the tachometer sample that ends them


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


def coil_check(table: tables.FaultTable, specs) -> CoilCheck | None:
    """The active coil check the table declares (its coil_torque entry's ``check``) for the sensors
    ``specs``: None without one or without a magnetometer to read it back."""
    entry = next((e for e in table.faults.values() if isinstance(e, tables.CoilTorque) and e.check is not None), None)
    if entry is None or specs.magnetometer is None or not specs.magnetometer.dipole_coupling > 0:
        return None
    c = entry.check
    return CoilCheck(c.period_s, c.dipole_fraction, c.dwell_s, 1.0 / specs.magnetometer.rate)


def wheel_check(table: tables.FaultTable, spacecraft) -> WheelCheck | None:
    """The null-space wheel excitation the table declares (its wheel_check entry) for ``spacecraft``:
    None without one or with fewer than four wheels (no null space)."""
    entry = next((e for e in table.faults.values() if isinstance(e, tables.WheelCheck)), None)
    if entry is None or spacecraft.n_wheels < 4:
        return None
    return WheelCheck(entry.amplitude_Nm, entry.period_s)


class Onboard:
    """The monitor of ``table`` on ``scenario``'s spacecraft, acting on ``controller`` (None: in another
    process, as in the estimator node) and ``estimator`` (its exclusions, and the innovations the monitor
    takes from it; None: in another process). :attr:`heard` holds the active faults another node's
    monitor reported (:meth:`hear`): the responses are those of both."""

    def __init__(self, table: tables.FaultTable, scenario, controller, estimator=None):
        self.monitor = FaultMonitor(table, scenario.spacecraft, scenario.sensors, scenario.body_frame_id)
        if controller is not None:
            controller.coil_check = coil_check(table, scenario.sensors)
            controller.wheel_check = wheel_check(table, scenario.spacecraft)
        self.tap = MonitorTap(self.monitor, estimator, None if controller is None else controller.friction)
        self.controller, self.estimator = controller, estimator
        self.heard: dict[tuple[str, int], FaultStatus] = {}
        self._seen, self._heard = (0, 0), 0
        self._commands: deque = deque(maxlen=MAX_PENDING)   # (t, command) not yet in force at a sample

    def hear(self, report: FaultStatus) -> RequestError | None:
        """A report of another node's monitor on the same table (the estimator's, for the controller):
        kept while active, dropped once cleared. Refused (INVALID_FAULT_REPORT, why) unless the table
        declares its fault id with that component and response and its index is a unit (≥ 0, or -1:
        the whole component)."""
        entry = self.monitor.table.faults.get(report.fault_id)
        if entry is None:
            why = f"fault_id: expected one of the fault table's; found '{clip(report.fault_id, 64)}'"
        elif report.component != type(entry).component or report.response != entry.response:
            why = (f"fault '{report.fault_id}': expected component {type(entry).component} and response "
                   f"{entry.response} (the table's); found {clip(report.component, 64)} and "
                   f"{clip(report.response, 64)}")
        elif report.index < -1:
            why = f"index: expected a unit (0 or more) or -1 (the whole component); found {report.index}"
        else:
            key = (report.fault_id, int(report.index))
            if report.active:
                self.heard[key] = report
            else:
                self.heard.pop(key, None)
            self._heard += 1
            return None
        return RequestError(ErrorCode.INVALID_FAULT_REPORT, why)

    def innovations(self) -> list[FaultStatus]:
        """The estimator's innovations since the last call, to the monitor: the reports it made."""
        return self.monitor.on_innovations(self.estimator.take_innovations())

    def feed(self, topic: str, t: float, message) -> list[FaultStatus]:
        """What was published on ``topic`` (the mirror type of :mod:`att_msgs_py.types`): the reports it made.

        A tachometer sample stamped ``t_s`` ends the interval over which the command stamped before
        ``t_s`` was in force, whichever of the two arrived first (a node may compute the command at
        ``t_s`` before the sample of ``t_s`` arrives): commands wait here and reach the monitor just
        before the first sample stamped after them (at most :data:`MAX_PENDING` wait)."""
        n = len(self.tap.reports)
        if topic == topics.COMMAND:
            self._commands.append((t, message))
            return []
        if topic == topics.WHEEL_SPEEDS:
            while self._commands and self._commands[0][0] < message.t:
                self.tap(topics.COMMAND, *self._commands.popleft())
        self.tap(topic, t, message)
        return self.tap.reports[n:]

    def respond(self) -> tuple[ManeuverResult | None, bool]:
        """Act on the responses when the monitor reported something new: (the result of a maneuver safe
        mode aborted, whether the healthy wheels changed)."""
        if (len(self.monitor.history), self._heard) == self._seen:
            return None, False
        self._seen = (len(self.monitor.history), self._heard)
        before = None if self.controller is None else self.controller.healthy
        m = self.monitor
        r = m.responses() if not self.heard else responses([*m.active.values(), *self.heard.values()],
                                                           m.spacecraft.wheel_axes, m.trackers)
        ended = recovery.act(r, self.controller, self.estimator)
        return ended, self.controller is not None and self.controller.healthy != before
