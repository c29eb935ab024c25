"""``att-log``: look at and repair MCAP logs (no ROS needed).

``att-log info FILE`` prints the profile, whether the file is complete (summary, footer) and
indexed, the topics with their types and message counts, and the log time range; exit 0 for a
complete, indexed file, 1 for one that needs ``att-log repair``, 2 for a file that is not MCAP.

``att-log repair IN.mcap [-o OUT.mcap | --in-place]`` rewrites a log whose writer was killed (no
summary, no footer, maybe a last chunk cut short) into a valid, indexed MCAP with the same profile,
schemas, channels (with their QoS metadata) and every message that was whole on disk, byte for
byte, with its log time, publish time and sequence (see :mod:`att_msgs_py.log.repair`). The default
output is ``IN.repaired.mcap``; the input is never overwritten except with ``--in-place``, and every
output is written to a temporary file and renamed once it reads back whole. A complete input is
copied without loss and reported as complete. Exit 0 when the output was written, 1 when it was
written but the input held a damaged record (named on stderr with its byte offset: what follows it
is lost), 2 when the input is not MCAP or holds nothing to recover. Strings from the file (topic,
type, profile, library) are printed with their control characters escaped.
"""
from __future__ import annotations

import argparse
import sys
from datetime import UTC, datetime

from att_msgs_py.log.repair import LogFileError, Scan, printable, repair, scan_records


def _stamp(ns: int) -> str:
    return datetime.fromtimestamp(ns * 1e-9, UTC).isoformat(timespec="milliseconds").replace("+00:00", "Z")


def time_range(scan: Scan) -> str:
    if scan.start_ns is None:
        return "no messages"
    return (f"log time {_stamp(scan.start_ns)} to {_stamp(scan.end_ns)} "
            f"({(scan.end_ns - scan.start_ns) * 1e-9:.3f} s)")


def status(scan: Scan) -> str:
    if scan.indexed:
        return f"complete and indexed ({scan.chunks} chunk{'' if scan.chunks == 1 else 's'}, summary and footer)"
    if scan.complete:
        return "complete but not indexed (footer without a chunk index for every chunk)"
    return (f"INCOMPLETE: {scan.problem}; readable up to byte {scan.good_bytes}, {scan.dropped_bytes} bytes after it "
            f"(`att-log repair {scan.path}` rewrites it)")


def info_lines(scan: Scan) -> list[str]:
    lines = [f"{scan.path}: {scan.size} bytes, profile '{printable(scan.profile)}', "
             f"library '{printable(scan.library)}'",
             f"status    {status(scan)}",
             f"messages  {scan.messages} on {len(scan.channels)} channels, {time_range(scan)}"]
    topics = {cid: printable(c.topic) for cid, c in scan.channels.items()}
    width = max((len(t) for t in topics.values()), default=0)
    for cid, channel in scan.channels.items():
        schema = scan.schemas.get(channel.schema_id)
        type_name = printable(schema.name) if schema is not None else "(no schema)"
        lines.append(f"  {topics[cid]:<{width}}  {type_name:<40} {scan.counts[cid]:>8}")
    return lines


def info(path: str) -> int:
    scan = Scan(path, 0)
    for _ in scan_records(path, scan):
        pass
    if not scan.header:
        raise LogFileError(f"{path}: {scan.problem}; nothing to recover")
    print("\n".join(info_lines(scan)))
    if scan.damaged:
        print(f"att-log: {path}: {scan.problem}", file=sys.stderr)
    return 0 if scan.indexed else 1


def repair_command(path: str, output: str | None, in_place: bool) -> int:
    done = repair(path, output, in_place=in_place)
    src, out = done.source, done.result
    topics = f"{out.messages} messages on {len(out.channels)} topics, {time_range(out)}"
    if src.indexed:
        print(f"{path} was complete and indexed: copied {topics} to {done.output}")
    else:
        print(f"{path} was {'complete but not indexed' if src.complete else 'incomplete: ' + printable(src.problem)}")
        print(f"recovered {topics}; {src.dropped_bytes} bytes after the last whole record dropped")
        print(f"wrote {done.output}: {status(out)}")
    if src.damaged:
        print(f"att-log: {path}: {src.problem}; the {out.messages} messages before it were recovered",
              file=sys.stderr)
        return 1
    return 0


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(prog="att-log", description=__doc__.splitlines()[0])
    sub = parser.add_subparsers(dest="command", required=True)
    p_info = sub.add_parser("info", help="topics, counts, time range; complete and indexed or not")
    p_info.add_argument("file")
    p_repair = sub.add_parser("repair", help="rewrite a killed writer's file into a valid, indexed MCAP")
    p_repair.add_argument("file")
    where = p_repair.add_mutually_exclusive_group()
    where.add_argument("-o", "--output", default=None, help="output file (default: IN.repaired.mcap)")
    where.add_argument("--in-place", action="store_true", help="replace the input (atomically)")
    args = parser.parse_args(argv)
    try:
        if args.command == "info":
            return info(args.file)
        return repair_command(args.file, args.output, args.in_place)
    except (LogFileError, OSError) as err:
        print(f"att-log: {err}", file=sys.stderr)
        return 2


if __name__ == "__main__":
    sys.exit(main())
