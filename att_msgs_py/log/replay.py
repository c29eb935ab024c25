"""``att-replay LOG.mcap [--rate X] [--topics ...] [--clock] [--live]``: play a recorded log back under /replay.

Like ``ros2 bag play`` (not available from PyPI): every recorded message is republished as its
raw CDR bytes (rclpy ``Publisher.publish`` takes serialized bytes), with its original type
(``topics.message_class`` of the channel's schema name, resolved only for the suite's interface
packages: :func:`interface_type`) and the recorded QoS
(reliability and durability; the history depth is raised to the topic's message count, at least
1000: a keep-last writer overwrites what a slow reliable reader has not acknowledged, and at
``--rate 0`` on a loaded machine a depth of 1000 lost 19 of 1547 wheel-speed messages).
Messages keep their recorded order and spacing (log time) divided by ``--rate``; ``--rate 0``
publishes as fast as possible.

Topics are published under the ``/replay`` namespace by default (``/spacecraft/state`` ->
``/replay/spacecraft/state``, ``/clock`` -> ``/replay/clock``), so a replay onto a domain where
the suite runs never feeds its nodes; ``--namespace NS`` picks another, and only ``--live``
publishes on the recorded names (with a warning: the nodes then act on the replayed messages).

``/clock`` is replayed only with ``--clock`` (or when named in ``--topics``): the recorded sim-time
``/clock`` messages when the log has them, otherwise a clock built from each message's log time,
published just before it. Before playing, the tool waits up to ``--wait`` s until every topic has
a subscriber; after the last message it waits up to ``--linger`` s until reliable subscribers
have acknowledged everything, and exits 1 naming the topics when they have not (the replay was
published, but a slow subscriber misses what it had not received when the tool exits).
"""
from __future__ import annotations

import argparse
import os
import re
import sys
import time
from collections import Counter
from dataclasses import dataclass
from pathlib import Path

from att_msgs_py import topics as suite_topics
from att_msgs_py.log.reader import iter_records
from att_msgs_py.log.repair import printable

CLOCK = suite_topics.CLOCK
CLOCK_TYPE = suite_topics.RECORDED[CLOCK]
MIN_DEPTH = 1000
# s between seeing a subscriber and publishing to it: discovery is two-sided (0.5 s lost the first
# messages on a busy machine)
DISCOVERY_SETTLE = 2.0
NAMESPACE = "/replay"
NAMESPACE_PATTERN = re.compile(r"(/[A-Za-z][A-Za-z0-9_]*)+")
TOPIC_PATTERN = re.compile(r"(/[A-Za-z_][A-Za-z0-9_]*)+")
# the interface packages whose message types a log may name: the suite's own and the ROS ones it uses
INTERFACE_PACKAGES = frozenset({"att_msgs", "std_msgs", "geometry_msgs", "sensor_msgs", "visualization_msgs",
                                "tf2_msgs", "rosgraph_msgs", "builtin_interfaces"})
TYPE_PATTERN = re.compile(r"([a-z][a-z0-9_]*)/msg/([A-Z][A-Za-z0-9]*)")


def interface_type(topic: str, type_name: str) -> str:
    """``type_name`` when it names a message of :data:`INTERFACE_PACKAGES` (``pkg/msg/Name``);
    ValueError otherwise, before anything is imported: a log never chooses which module is loaded."""
    match = TYPE_PATTERN.fullmatch(type_name)
    if match is None or match[1] not in INTERFACE_PACKAGES:
        raise ValueError(f"topic {printable(topic)}: type '{printable(type_name)}' is not one of the suite's "
                         f"interface types ({', '.join(sorted(INTERFACE_PACKAGES))}/msg/...); refused")
    return type_name


def replayed_name(topic: str, namespace: str = NAMESPACE) -> str:
    """Where ``topic`` is republished: under ``namespace`` ("" for the recorded name itself)."""
    if namespace and not NAMESPACE_PATTERN.fullmatch(namespace):
        raise ValueError(f"--namespace must look like /replay (a '/' before each name of letters, digits "
                         f"and '_', starting with a letter), got '{namespace[:80]}'")
    return f"{namespace}/{topic.lstrip('/')}" if namespace else topic


@dataclass
class Record:
    log_time_ns: int
    topic: str
    data: bytes


class NotDelivered(RuntimeError):
    """Reliable subscribers had not acknowledged every replayed message when the linger ran out."""


def read_records(path: str | Path) -> tuple[list[Record], dict[str, tuple[str, str]]]:
    """All cdr records in log-time order, and topic -> (type, QoS metadata); ValueError (one line,
    file strings escaped) for a topic that is not a plain ROS name or a type outside the suite's
    interface packages (:func:`interface_type`)."""
    records, channels = [], {}
    for schema, channel, message in iter_records(path):
        if schema is None or channel.message_encoding != "cdr":
            continue
        if channel.topic not in channels:
            if not TOPIC_PATTERN.fullmatch(channel.topic):
                raise ValueError(f"topic '{printable(channel.topic)}' is not a ROS topic name; refused")
            interface_type(channel.topic, schema.name)
        channels.setdefault(channel.topic, (schema.name, channel.metadata.get("offered_qos_profiles", "")))
        records.append(Record(message.log_time, channel.topic, bytes(message.data)))
    records.sort(key=lambda r: r.log_time_ns)      # stable: keeps the recorded order of equal times
    return records, channels


def qos_from_metadata(topic: str, metadata: str, messages: int = 0):
    """The recorded publisher QoS (rosbag2 ``offered_qos_profiles`` YAML), the suite's own for its
    topics when the metadata is empty; depth ``messages`` (the topic's whole replay), at least
    :data:`MIN_DEPTH`."""
    from rclpy.qos import DurabilityPolicy, HistoryPolicy, QoSProfile, ReliabilityPolicy

    from att_msgs_py import qos

    known = qos.recorded_topics().get(topic)
    if not metadata.strip():
        base = known[1] if known else qos.STREAM_QOS
        durability, reliability = base.durability, base.reliability
    else:
        durability = (DurabilityPolicy.TRANSIENT_LOCAL if re.search(r"durability:\s*transient_local", metadata)
                      else DurabilityPolicy.VOLATILE)
        reliability = (ReliabilityPolicy.BEST_EFFORT if re.search(r"reliability:\s*best_effort", metadata)
                       else ReliabilityPolicy.RELIABLE)
    return QoSProfile(history=HistoryPolicy.KEEP_LAST, depth=max(MIN_DEPTH, messages), reliability=reliability,
                      durability=durability)


def clock_bytes(log_time_ns: int) -> bytes:
    """CDR of a ``rosgraph_msgs/Clock`` at ``log_time_ns``."""
    from rclpy.serialization import serialize_message
    from rosgraph_msgs.msg import Clock

    sec, nanosec = divmod(int(log_time_ns), 1_000_000_000)
    msg = Clock()
    msg.clock.sec, msg.clock.nanosec = sec, nanosec
    return serialize_message(msg)


def schedule(records: list[Record], clock: bool, clock_recorded: bool) -> list[Record]:
    """Records to publish, with a log-time clock before each message when the log has no /clock."""
    if not clock or clock_recorded:
        return records
    out, last = [], None
    for r in records:
        if r.log_time_ns != last:
            out.append(Record(r.log_time_ns, CLOCK, clock_bytes(r.log_time_ns)))
            last = r.log_time_ns
        out.append(r)
    return out


def play(path: str | Path, *, rate: float = 1.0, topics: list[str] | None = None, clock: bool = False,
         wait: float = 5.0, linger: float = 5.0, namespace: str = NAMESPACE, node_name: str = "att_replay",
         log=print) -> dict[str, int]:
    """Republish the log under ``namespace`` ("": the recorded names); returns messages published
    per published topic name. Needs ``rclpy`` initialised."""
    from rclpy.duration import Duration
    from rclpy.node import Node

    if not rate >= 0:
        raise ValueError(f"--rate must be >= 0 (0: as fast as possible), got {rate}")
    replayed_name(CLOCK, namespace)        # the namespace is checked before anything is read
    all_records, channels = read_records(path)
    selected = set(topics) if topics else {t for t in channels if t != CLOCK}
    if clock:
        selected.add(CLOCK)
    unknown = sorted(t for t in selected if t not in channels and t != CLOCK)
    if unknown:
        raise ValueError(f"--topics names topics the log does not have: {', '.join(unknown)} "
                         f"(it has {', '.join(sorted(channels))})")
    records = schedule([r for r in all_records if r.topic in selected], clock,
                       CLOCK in channels)
    types = {t: channels[t] for t in selected if t in channels}
    if CLOCK in selected and CLOCK not in types:
        types[CLOCK] = (CLOCK_TYPE, "")
    per_topic = Counter(r.topic for r in records)
    node = Node(node_name)
    try:
        pubs = {t: node.create_publisher(suite_topics.message_class(type_name), replayed_name(t, namespace),
                                         qos_from_metadata(t, meta, per_topic[t]))
                for t, (type_name, meta) in types.items()}
        deadline = time.monotonic() + wait
        while time.monotonic() < deadline and any(p.get_subscription_count() == 0 for p in pubs.values()):
            time.sleep(0.05)
        if any(p.get_subscription_count() for p in pubs.values()):
            time.sleep(DISCOVERY_SETTLE)   # they must have discovered us too, or the first messages are lost
        counts = dict.fromkeys(pubs, 0)
        listened = sum(p.get_subscription_count() > 0 for p in pubs.values())
        log(f"replaying {len(records)} messages on {len(pubs)} topics "
            f"{f'under {namespace}' if namespace else 'on their recorded (live) names'} ({listened} with "
            f"subscribers), {'as fast as possible' if rate == 0 else f'rate {rate:g}'}")
        t_start, wall_start = (records[0].log_time_ns if records else 0), time.monotonic()
        for r in records:
            if rate > 0:
                delay = wall_start + (r.log_time_ns - t_start) * 1e-9 / rate - time.monotonic()
                if delay > 0:
                    time.sleep(delay)
            pubs[r.topic].publish(r.data)
            counts[r.topic] += 1
        acked_by = time.monotonic() + linger
        unacknowledged = [pub.topic_name for pub in pubs.values()   # reliable subscribers: until they have everything
                          if not pub.wait_for_all_acked(
                              Duration(nanoseconds=int(max(0.0, acked_by - time.monotonic()) * 1e9)))]
        if unacknowledged:
            raise NotDelivered(f"not acknowledged by every reliable subscriber within --linger {linger:g} s: "
                               f"{', '.join(unacknowledged)} (a slow subscriber misses what it had not "
                               f"received; a longer --linger waits for it)")
        return {p.topic_name: n for p, n in zip(pubs.values(), counts.values())}
    finally:
        node.destroy_node()


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(prog="att-replay", description=__doc__.splitlines()[0])
    parser.add_argument("log", help="MCAP file written by the suite's recorder (or any rosbag2 MCAP)")
    parser.add_argument("--rate", type=float, default=1.0, help="playback speed factor; 0 = as fast as possible")
    parser.add_argument("--topics", nargs="+", default=None, help="topics to replay (default: all but /clock)")
    parser.add_argument("--clock", action="store_true", help="also publish /clock from the log")
    parser.add_argument("--wait", type=float, default=5.0, help="s to wait for subscribers before playing")
    parser.add_argument("--linger", type=float, default=5.0,
                        help="at most this many s waited after the last message for reliable subscribers "
                             "to acknowledge")
    where = parser.add_mutually_exclusive_group()
    where.add_argument("--namespace", default=NAMESPACE,
                       help=f"publish under this namespace (default {NAMESPACE}: live nodes never see the replay)")
    where.add_argument("--live", action="store_true",
                       help="publish on the recorded topic names: nodes on this domain act on the replay")
    args, ros_args = parser.parse_known_args(argv)
    if not Path(args.log).is_file():
        parser.error(f"log file '{args.log}' does not exist")
    namespace = "" if args.live else args.namespace
    try:
        replayed_name(CLOCK, namespace)
    except ValueError as err:
        parser.error(str(err))
    if args.live:
        print(f"att-replay: WARNING: --live publishes on the recorded topic names: every node on ROS_DOMAIN_ID "
              f"{os.environ.get('ROS_DOMAIN_ID', '0 (unset)')} acts on the replayed messages as if they were live",
              file=sys.stderr, flush=True)
    try:
        read_records(args.log)         # a damaged or hostile file is refused before ROS starts
    except ValueError as err:
        print(f"att-replay: {err}", file=sys.stderr)
        return 2
    import rclpy
    from rclpy.executors import ExternalShutdownException

    rclpy.init(args=ros_args)
    try:
        counts = play(args.log, rate=args.rate, topics=args.topics, clock=args.clock, wait=args.wait,
                      linger=args.linger, namespace=namespace)
    except ValueError as err:
        print(f"att-replay: {err}", file=sys.stderr)
        return 2
    except NotDelivered as err:
        print(f"att-replay: {err}", file=sys.stderr)
        return 1
    except (KeyboardInterrupt, Exception) as err:
        # Ctrl-C: KeyboardInterrupt, or any error once rclpy's handler has shut the context down
        if not isinstance(err, (KeyboardInterrupt, ExternalShutdownException)) and rclpy.ok():
            raise
        print("att-replay: interrupted", file=sys.stderr)
        return 130
    finally:
        rclpy.try_shutdown()
    print("published " + ", ".join(f"{t}: {n}" for t, n in sorted(counts.items())))
    return 0


if __name__ == "__main__":
    sys.exit(main())
