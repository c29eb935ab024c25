"""The one ``main()`` body of every suite node: init, spin until SIGINT/SIGTERM, clean up.

Stopping is done by rclpy alone. Its signal handler wakes the executors, then shuts the context
down, from its own thread. An executor woken before the shutdown can start a new wait that nothing
wakes again, so nodes spin with :func:`spin_until_shutdown`, whose waits are bounded, instead of
``executor.spin()`` (the planner hung this way in most runs).

Python's own SIGINT handler would also raise ``KeyboardInterrupt`` a moment later, at whatever
line runs then: a ``publish`` already failing on the dead context, or the recorder's ``close()``.
It is replaced by a handler that only notes the signal, which matters when the signal comes
before ``rclpy.init`` has installed rclpy's handler: the node then stops right after init.

An error raised after the context is shut down is the stop itself, not a fault. The node's
``close()`` (e.g. the recorder finalising its log) then runs before the node is destroyed, and the
process exits 0.

Once the node is built, what it holds from its start-up (imported modules, its scenario, a planner's
pool) is moved out of the cyclic garbage collector's reach (:func:`freeze_start_up`): rclpy converts
a received message into Python objects before any callback can look at it (100,000 zones of an
oversized request are some 300,000 objects), and each full collection those allocations trigger
would otherwise walk the whole start-up heap too (a planner's 100,000 objects: 1.08 s of CPU for that
request's take instead of 0.78 s). The frozen objects stay freed by their reference counts.
"""
from __future__ import annotations

import gc
import math
import signal
import sys
import time
from collections.abc import Callable
from pathlib import Path

import rclpy
import yaml
from rcl_interfaces.msg import FloatingPointRange, IntegerRange, ParameterDescriptor
from rclpy.clock import Clock, ClockType
from rclpy.exceptions import InvalidParameterTypeException, InvalidParameterValueException
from rclpy.executors import Executor, ExternalShutdownException, SingleThreadedExecutor
from rclpy.parameter import Parameter
from rclpy.signals import SignalHandlerOptions

from att_msgs_py import memory
from att_msgs_py.errors import ConfigError, ErrorCode, RequestError, clip
from att_msgs_py.parameters import SCENARIO_TABLE, ParameterTable, Reader
from att_msgs_py.parameters import Parameter as Declaration

_stop_signalled = False


def _stop_requested(_signum, _frame) -> None:
    """Python-level handler that rclpy's SIGINT/SIGTERM handler chains to. After ``rclpy.init``
    rclpy has already shut the context down; before it, only this flag knows."""
    global _stop_signalled
    _stop_signalled = True


def freeze_start_up() -> int:
    """Collect the garbage of the start-up, then move every object that survives it to the collector's
    permanent generation (``gc.freeze``), which its later collections do not walk (module docstring);
    the number of objects frozen."""
    gc.collect()
    gc.freeze()
    return gc.get_freeze_count()


def spin_until_shutdown(executor: Executor, poll: float = 0.2) -> None:
    """``executor.spin()`` that re-checks the context at least every ``poll`` s (see above)."""
    while executor.context.ok():
        executor.spin_once(timeout_sec=poll)


SHARED_PARAMETERS = ("scenario", "use_sim_time", "frame_id", "body_frame_id")
SHARED_PREFIXES = ("spacecraft.", "orbit.", "qos_overrides.", "sensors.", "actuators.", "environment.")
USE_SIM_TIME = "use_sim_time"
_ROS_TYPES = {float: Parameter.Type.DOUBLE, int: Parameter.Type.INTEGER, bool: Parameter.Type.BOOL,
              str: Parameter.Type.STRING, list: Parameter.Type.DOUBLE_ARRAY}
_INT64 = (-2**63, 2**63 - 1)
_FROM_THE_COMMAND_LINE = " (from the command line or a --params-file)"


def descriptor(spec: Declaration, high: float | None = None) -> ParameterDescriptor:
    """The ROS descriptor of ``spec``: its type, its description with the unit, its range (ROS
    ranges are closed: an open bound is enforced by :meth:`Declaration.check`; an absent bound is
    the largest finite number, as a bounded number is finite), its other constraints in words and
    ``read_only``. ``high``: an upper bound found at start-up, tighter than the declared one."""
    d = ParameterDescriptor(name=spec.name, type=_ROS_TYPES[spec.kind].value, description=spec.summary(),
                            additional_constraints=spec.constraints(), read_only=spec.read_only)
    if spec.bounded and spec.kind is float:
        top = spec.high if high is None else high
        d.floating_point_range = [FloatingPointRange(
            from_value=-sys.float_info.max if spec.low is None else float(spec.low),
            to_value=(math.inf if spec.allow_inf else sys.float_info.max) if top is None else float(top), step=0.0)]
    elif spec.bounded and spec.kind is int:
        d.integer_range = [IntegerRange(from_value=_INT64[0] if spec.low is None else int(spec.low),
                                        to_value=_INT64[1] if spec.high is None else int(spec.high), step=1)]
    return d


class ParameterReader(Reader):
    """``read(name)`` or ``read(name, default)`` (a default found at start-up) for a node: declares ROS
    parameter ``name`` of ``table`` with its full :func:`descriptor` and the value of its
    scenario-file section (``scenario_values``) or else the default, so ``-p`` and ``--params-file``
    overrides win over both, and returns the value checked against its declaration
    (:meth:`att_msgs_py.parameters.Parameter.check`; an integer is accepted for a float, and handed to
    rclpy as a float). Anything else raises :class:`ConfigError` with one line naming the parameter,
    where it came from and what is expected. :meth:`refuse_unknown` then refuses every parameter
    given that the table does not declare (a typo) and declares the ones not read."""

    def __init__(self, node, table: ParameterTable, scenario_values: dict, source: str = ""):
        super().__init__(table)
        self.node, self.values, self.source = node, scenario_values, source

    def _given(self, spec: Declaration, default, high):
        """The value given for ``spec`` (an override, the scenario's ``NAME.params.yaml``, else ``default``) checked,
        with the override rclpy will take replaced by that value in the declared type."""
        overrides = self.node._parameter_overrides          # -p and --params-file values, by name
        if spec.name in overrides:
            value = spec.check(overrides[spec.name].value, _FROM_THE_COMMAND_LINE, high)
            overrides[spec.name] = Parameter(spec.name, _ROS_TYPES[spec.kind], value)
            return value
        if spec.name in self.values:
            return spec.check(self.values[spec.name], f" (from {self.source})" if self.source else "", high)
        return spec.check(default, "", high)

    def _source(self, spec: Declaration, default, high):
        value = self._given(spec, default, high)
        try:
            self.node.declare_parameter(spec.name, value, descriptor(spec, high))
        except (InvalidParameterTypeException, InvalidParameterValueException) as exc:
            raise ConfigError(ErrorCode.INVALID_PARAMETER, f"parameter '{spec.name}': {clip(exc, 200)}") from None
        return value

    def refuse_unknown(self) -> None:
        """A parameter of this node in the scenario's parameter file or on the command line that the table does
        not declare (a typo) is an error, not silently ignored; the shared ``/**`` ones are allowed.
        The declared parameters the node did not read (they do not apply in its configuration) are
        then read too, so a ROS user sees every one and a value given for one is still checked.
        ``use_sim_time`` (rclpy's) is described."""
        overrides = set(self.node._parameter_overrides)
        known = set(self.table.parameters) | set(SHARED_PARAMETERS)
        for where, names in ((self.source or "the scenario file", set(self.values)),
                             ("the command line or a --params-file", overrides)):
            old = sorted(n for n in names if n in self.table.renamed)
            if old:
                raise self.table.renamed_error(old[0], f" (from {where})")
            unknown = sorted(n for n in names - known if not n.startswith(SHARED_PREFIXES))
            if unknown:
                raise ConfigError(ErrorCode.INVALID_PARAMETER,
                                  f"unknown {self.node.get_name()} parameter(s) {clip(', '.join(unknown), 120)} "
                                  f"(from {where}); known: {clip(', '.join(self.table.parameters), 160)}")
        for spec in self.table:
            if spec.name not in self.used:
                if spec.default is None:        # a node reads these: only it knows the default
                    raise TypeError(f"{self.node.get_name()} did not read parameter '{spec.name}', whose default "
                                    "it finds at start-up")
                self(spec.name)
        if self.node.has_parameter(USE_SIM_TIME) and not self.node.describe_parameter(USE_SIM_TIME).description:
            self.node.set_descriptor(USE_SIM_TIME, ParameterDescriptor(
                type=Parameter.Type.BOOL.value, description="take the time from /clock (sim time) instead of the "
                                                            "system clock (rclpy's parameter)"))


def read_scenario(node) -> str:
    """The node's ``scenario`` parameter, declared and checked."""
    return ParameterReader(node, SCENARIO_TABLE, {})("scenario")


def publisher_of(info) -> bytes | None:
    """The publisher GID of a received message (None when the middleware does not say)."""
    gid = (info or {}).get("publisher_gid")
    return bytes(gid["data"]) if isinstance(gid, dict) and gid.get("data") is not None else None


def live_publishers(node, topic: str) -> Callable[[], list[bytes]]:
    """The GIDs of the publishers of ``topic`` (as ``node`` resolves it) now in the ROS graph, as
    a callable: the evidence a :class:`~att_msgs_py.source_hold.SourceHold` releases a publisher on."""
    name = node.resolve_topic_name(topic)
    return lambda: [bytes(i.endpoint_gid) for i in node.get_publishers_info_by_topic(name)]


def participant_of(gid: bytes | None) -> bytes | None:
    """The DDS participant of a publisher GID (its 12-byte GUID prefix): one per node process."""
    return None if gid is None else gid[:12]


class RefusalLog:
    """A node's refused inputs: counted per kind and logged at most once a second *per kind* (so a
    flood of one kind cannot hide another; rclpy's own throttling is per call site), clipped, with
    the running count: ``state refused (55 so far) [311 STATE_TIME_JUMP]: ...``. After a message
    refused for its size (SIZE_LIMIT) the memory its deserialised copy took is handed back
    (:func:`att_msgs_py.memory.trim`, a few ms: less than deserialising it cost)."""

    def __init__(self, logger, period: float = 1.0):
        self.logger, self.period = logger, period
        self.counts: dict[str, int] = {}
        self.logged: dict[str, float] = {}

    def __call__(self, what: str, err: RequestError) -> None:
        self.counts[what] = self.counts.get(what, 0) + 1
        if err.code == ErrorCode.SIZE_LIMIT:
            memory.trim()
        now = time.monotonic()
        if now - self.logged.get(what, -math.inf) >= self.period:
            self.logged[what] = now
            self.logger.warning(clip(f"{what} refused ({self.counts[what]} so far) [{int(err.code)} "
                                     f"{err.code.name}]: {err.message}"))


def subscribe_when_heard(node, publisher, count: int, timeout: float, subscribe: Callable[[], None]) -> None:
    """Call ``subscribe()`` once ``count`` subscriptions are matched to ``publisher`` (at once when
    they already are; after ``timeout`` s of wall time anyway, with a warning). A node whose answers
    are recorded takes its inputs only when the recorder hears it: the simulator waits for those
    inputs before sim time starts, so nothing the node says from t = 0 on is lost."""
    if publisher.get_subscription_count() >= count:
        subscribe()
        return
    give_up = time.monotonic() + timeout

    def check():
        heard = publisher.get_subscription_count()
        if heard < count and time.monotonic() < give_up:
            return
        node.destroy_timer(timer)
        if heard < count:
            node.get_logger().warning(f"taking inputs with {heard} of {count} expected subscribers to "
                                      f"{publisher.topic_name} after {timeout:g} s")
        subscribe()

    timer = node.create_timer(0.05, check, clock=Clock(clock_type=ClockType.STEADY_TIME))


def _check_params_files(args) -> None:
    """``--params-file PATH`` arguments name readable files (paths relative to the current
    directory), checked before rcl reads them."""
    args = list(sys.argv if args is None else args)
    for flag, path in zip(args, args[1:]):
        if flag != "--params-file":
            continue
        if not Path(path).is_file():
            raise ConfigError(ErrorCode.INVALID_CONFIG,
                              f"--params-file '{clip(path, 200)}': no such file (relative paths are taken from the "
                              f"current directory, {Path.cwd()})")
        try:
            doc = yaml.safe_load(Path(path).read_text(encoding="utf-8"))
        except (OSError, UnicodeDecodeError, yaml.YAMLError) as exc:
            raise ConfigError(ErrorCode.INVALID_CONFIG, f"--params-file '{clip(path, 200)}' is not readable YAML: "
                                                        f"{clip(str(exc).splitlines()[0] if str(exc) else exc, 200)}"
                              ) from None
        if not isinstance(doc, dict) or not all(isinstance(v, dict) and "ros__parameters" in v for v in doc.values()):
            raise ConfigError(ErrorCode.INVALID_CONFIG,
                              f"--params-file '{clip(path, 200)}' is not a ROS 2 parameter file (expected "
                              "'<node or /**>: ros__parameters: {...}' sections)")


def run_node(make_node: Callable, args=None, make_executor: Callable[[], Executor] = SingleThreadedExecutor,
             loop: Callable | None = None, drain: Callable | None = None) -> None:
    """Create node and executor after ``rclpy.init`` and run ``loop(node, executor)`` (default:
    :func:`spin_until_shutdown`); the C allocator and the middleware set to give large blocks back
    (:func:`memory.configure`, :func:`memory.middleware_env`).

    ``drain(node, executor)``: the node stops itself instead of rclpy. rclpy's signal handler is not
    installed; the node spins until SIGINT/SIGTERM (this module's handler), then ``drain`` runs with the
    context still up (the recorder takes what its subscriptions hold, see
    :func:`att_msgs_py.log.recorder_node.drain`), then ``close()`` and the shutdown."""
    for signum in (signal.SIGINT, signal.SIGTERM):
        signal.signal(signum, _stop_requested)      # before rclpy.init, which chains to it
    memory.configure()                              # large blocks go back to the system when freed
    memory.middleware_env()                         # and the middleware's payloads too
    node, exit_code = None, 0
    try:
        _check_params_files(args)
        try:
            rclpy.init(args=args, signal_handler_options=None if drain is None else SignalHandlerOptions.NO)
        except Exception as exc:         # rcl's own parse errors (a params file that is not YAML, ...)
            raise ConfigError(ErrorCode.INVALID_CONFIG, f"ROS arguments refused: {clip(exc, 300)}") from None
        if _stop_signalled:
            return
        node = make_node()
        executor = make_executor()
        executor.add_node(node)
        freeze_start_up()
        if drain is not None:
            while executor.context.ok() and not _stop_signalled:
                executor.spin_once(timeout_sec=0.2)
            drain(node, executor)
        elif loop is None:
            spin_until_shutdown(executor)
        else:
            loop(node, executor)
    except ExternalShutdownException:
        pass
    except ConfigError as err:
        print(f"{Path(sys.argv[0]).name}: [{int(err.code)} {err.code.name}] {err.message}", file=sys.stderr, flush=True)
        exit_code = 2
    except Exception:
        if rclpy.ok():
            raise
    finally:
        if node is not None:
            if hasattr(node, "close"):
                node.close()
            node.destroy_node()
        rclpy.try_shutdown()
    if exit_code:
        sys.exit(exit_code)
