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
from rcl_interfaces.msg import ParameterDescriptor
from rclpy.clock import Clock, ClockType
from rclpy.executors import Executor, ExternalShutdownException, SingleThreadedExecutor

from att_msgs_py import memory
from att_msgs_py.errors import ConfigError, ErrorCode, RequestError, clip
from att_msgs_py.parameters import checked, coerce

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


class ParameterReader:
    """``read(name, default, low=, high=, low_open=, length=, choices=)`` for a node: declares ROS
    parameter ``name`` with the value of its scenario-file section (``scenario_values``) or else
    ``default``, so ``-p`` and ``--params-file`` overrides win over both, and returns the value
    checked against the type of ``default`` (an integer is accepted for a float), the range
    [``low``, ``high``] (``(low, high]`` with ``low_open``; NaN and Inf never pass for a bounded
    number), the list ``length`` and the ``choices``. Anything else raises :class:`ConfigError`
    with one line naming the parameter, where it came from and what is expected.
    :meth:`refuse_unknown` then refuses every parameter given that no ``read`` asked for (a typo)."""

    def __init__(self, node, scenario_values: dict, source: str = ""):
        self.node, self.values, self.source = node, scenario_values, source
        self.used: set[str] = set()

    def __call__(self, name: str, default, low: float | None = None, high: float | None = None, *,
                 low_open: bool = False, length: int | None = None, choices=None):
        self.used.add(name)
        in_file = name in self.values
        where = f" (from {self.source})" if in_file and self.source else ""
        initial = coerce(name, self.values[name], default, where) if in_file else default
        value = self.node.declare_parameter(name, initial, ParameterDescriptor(dynamic_typing=True)).value
        if value != initial or type(value) is not type(initial):
            where = " (from the command line or a --params-file)"
        return checked(name, value, default, where, low, high, low_open=low_open, length=length, choices=choices)

    def refuse_unknown(self) -> None:
        """A parameter of this node in the scenario file or on the command line that nothing
        read (a typo) is an error, not silently ignored; the shared ``/**`` ones are allowed."""
        overrides = set(getattr(self.node, "_parameter_overrides", {}))     # -p and --params-file values
        for where, names in ((self.source or "the scenario file", set(self.values)),
                             ("the command line or a --params-file", overrides)):
            unknown = sorted(n for n in names - self.used - set(SHARED_PARAMETERS) if not n.startswith(SHARED_PREFIXES))
            if unknown:
                raise ConfigError(ErrorCode.INVALID_PARAMETER,
                                  f"unknown {self.node.get_name()} parameter(s) {clip(', '.join(unknown), 120)} "
                                  f"(from {where}); known: {', '.join(sorted(self.used))}")


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


def parameter_reader(node, scenario_values: dict, source: str = "") -> ParameterReader:
    return ParameterReader(node, scenario_values, source)


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
             loop: Callable | None = None) -> None:
    """Create node and executor after ``rclpy.init`` and run ``loop(node, executor)`` (default:
    :func:`spin_until_shutdown`); the C allocator and the middleware set to give large blocks back
    (:func:`memory.configure`, :func:`memory.middleware_env`)."""
    for signum in (signal.SIGINT, signal.SIGTERM):
        signal.signal(signum, _stop_requested)      # before rclpy.init, which chains to it
    memory.configure()                              # large blocks go back to the system when freed
    memory.middleware_env()                         # and the middleware's payloads too
    node, exit_code = None, 0
    try:
        _check_params_files(args)
        try:
            rclpy.init(args=args)
        except Exception as exc:         # rcl's own parse errors (a params file that is not YAML, ...)
            raise ConfigError(ErrorCode.INVALID_CONFIG, f"ROS arguments refused: {clip(exc, 300)}") from None
        if _stop_signalled:
            return
        node = make_node()
        executor = make_executor()
        executor.add_node(node)
        freeze_start_up()
        if loop is None:
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
