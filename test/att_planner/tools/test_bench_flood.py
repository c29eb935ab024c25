"""Flood (reduced): every node keeps serving a flood of large messages, valid and invalid, refuses
each oversized one for its size, and holds no more than 50 MB beyond its start-up size after it.
``att-bench flood`` runs the full 1000 messages and reports the answer times."""
import pytest

from att_msgs_py.errors import ErrorCode
from att_planner.tools.bench.flood import GROWTH_LIMIT, KINDS, flood

pytestmark = [pytest.mark.ros, pytest.mark.slow]


def test_a_reduced_flood_leaves_every_node_within_its_memory_bound(tmp_path):
    r = flood("swift_demo", 3 * len(KINDS), tmp_path)
    assert all(r["alive"].values()), r["alive"]
    for kind in ("plan request of 100k zones", "schedule of 100k targets", "inline plan 10 MB", "reset 10 MB",
                 "mode request 10 MB", "plan request of 100k cones"):
        assert {a["code"] for a in r["answers"][kind]} == {ErrorCode.SIZE_LIMIT}, kind
    assert {a["code"] for a in r["answers"]["invalid inline plan"]} == {ErrorCode.INVALID_PLAN}
    for name, growth in r["growth_mib"].items():
        assert growth <= GROWTH_LIMIT, f"{name} grew by {growth:.1f} MB: {r['start_mib']} -> {r['end_mib']}"
    assert r["passed"]
