"""The recorder's and the live bridge's parameters, declared once."""
from __future__ import annotations

from att_msgs_py.parameters import Parameter, ParameterTable

RECORDER = ParameterTable("recorder", (
    Parameter("output", str, None, "MCAP file the run is recorded to (an unfinished one there is first repaired "
                                   "aside)", default_rule="runs/run_YYYYmmdd_HHMMSS.mcap (UTC start time)"),
    Parameter("flush_period_s", float, 0.5, "longest time between flushes to disk (a killed recorder loses at most "
                                          "this)", "s", 0.0, 3600.0, low_open=True),
), "writes every suite topic to one rosbag2-compatible MCAP file per run",
    renamed={"flush_period": "flush_period_s"})

BRIDGE = ParameterTable("bridge", (
    Parameter("host", str, "127.0.0.1", "address the Foxglove WebSocket server listens on"),
    Parameter("port", int, 8765, "port of that server (0: any free port)", "", 0, 65535),
), "serves the suite's topics to Foxglove over a WebSocket")
