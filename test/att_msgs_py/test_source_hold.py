"""SourceHold: the held publisher keeps its input while it is in the ROS graph, however long it is
silent; another publisher takes over only once the held one has left the graph."""
from __future__ import annotations

from att_msgs_py.source_hold import SourceHold, Verdict

REAL, INTRUDER, RESTARTED = b"real-gid", b"intruder-gid", b"restarted-gid"


class Graph:
    """The publishers of one topic, as the graph lists them; counts the look-ups."""

    def __init__(self, *gids: bytes):
        self.gids, self.asked = set(gids), 0

    def __call__(self):
        self.asked += 1
        return [list(g) for g in self.gids]          # as rclpy gives endpoint_gid: a list of ints


def test_the_held_publisher_keeps_its_input_while_it_is_in_the_graph_however_long_it_is_silent():
    graph = Graph(REAL, INTRUDER)
    hold = SourceHold(graph)
    assert hold.check(REAL) is Verdict.FIRST
    hold.take(REAL)
    for _ in range(10_000):                          # a flood from another publisher while the real one is silent
        assert hold.check(INTRUDER) is Verdict.REFUSED
    assert hold.held == REAL and hold.check(REAL) is Verdict.HELD


def test_the_held_stream_never_asks_the_graph():
    graph = Graph(REAL)
    hold = SourceHold(graph)
    hold.take(REAL)
    for _ in range(100):
        assert hold.check(REAL) is Verdict.HELD
    assert graph.asked == 0


def test_a_held_publisher_that_leaves_the_graph_is_released_to_the_next_accepted_one():
    graph = Graph(REAL)
    hold = SourceHold(graph)
    hold.take(REAL)
    graph.gids = {RESTARTED}                         # the real source stopped; a restarted one appears
    assert hold.check(RESTARTED) is Verdict.HANDOVER
    assert hold.held == REAL                         # nothing moves until the receiver accepts the message
    hold.take(RESTARTED)
    assert hold.check(RESTARTED) is Verdict.HELD and hold.check(REAL) is Verdict.REFUSED


def test_the_real_source_is_followed_again_when_a_held_intruder_leaves():
    graph = Graph(INTRUDER, REAL)
    hold = SourceHold(graph)
    hold.take(INTRUDER)                              # the intruder came first
    assert hold.check(REAL) is Verdict.REFUSED
    graph.gids.discard(INTRUDER)                     # the intruder stops
    assert hold.check(REAL) is Verdict.HANDOVER
    hold.take(REAL)
    graph.gids.add(INTRUDER)                         # and comes back: the real one is held now
    assert hold.check(INTRUDER) is Verdict.REFUSED


def test_without_a_graph_a_held_publisher_is_never_taken_to_be_gone():
    hold = SourceHold()
    hold.take(REAL)
    assert hold.check(INTRUDER) is Verdict.REFUSED and not hold.check(INTRUDER).admitted


def test_unnamed_publishers_are_not_compared_and_move_nothing():
    hold = SourceHold(Graph())
    assert hold.check(None) is Verdict.HELD
    hold.take(None)
    assert hold.held is None
    hold.take(REAL)
    assert hold.check(None) is Verdict.HELD and hold.held == REAL
    assert "second publisher" in hold.refusal("state")
