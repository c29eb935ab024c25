"""One publisher per input, held until the ROS graph shows it gone (no ROS).

A receiver of a stream (states, estimates, measurements, actuator commands) acts on one publisher
of it at a time. The first publisher whose message the receiver accepts is *held*; a message from
any other publisher is refused while the held one is among the publishers of the topic in the ROS
graph, however long it is silent or late. A held publisher that leaves the graph (its process
stopped, or, after a crash, its DDS participant's lease expired: 20 s with Fast DDS's default) is
the evidence that the stream has a new source: the next accepted message of another publisher
takes the hold over (a restarted simulator, controller or estimator). Silence is never evidence:
a paused or starved source keeps its input, and a receiver without new input does what it does on
stale input; it never hands the input to whoever else publishes meanwhile.

Publishers are named by their GID (the bytes of ``rmw_gid_t``: what a subscription's message info
calls ``publisher_gid`` and the graph's endpoint info ``endpoint_gid``). The graph is asked through
``live``, a callable the node gives (the GIDs of the topic's publishers now), and only when a message
comes from a publisher that is not held, so the held stream costs nothing. Without ``live`` no held
publisher is ever taken to be gone. Messages whose publisher the middleware does not name
(``None``) are not compared.
"""
from __future__ import annotations

import enum
from collections.abc import Callable, Collection

Live = Callable[[], Collection[bytes]]        # the GIDs of a topic's publishers now in the graph


class Verdict(enum.Enum):
    """What the hold makes of a message's publisher."""

    HELD = "held"              # the held publisher (or one the middleware does not name): go on
    FIRST = "first"            # nothing held yet: the receiver may take it
    HANDOVER = "handover"      # the held publisher has left the graph: this one may take over (a new source)
    REFUSED = "refused"        # another publisher while the held one is in the graph: ignore the message

    @property
    def admitted(self) -> bool:
        return self is not Verdict.REFUSED


class SourceHold:
    """The held publisher of one input. :meth:`check` a message's publisher before the receiver's
    own checks, and :meth:`take` it once the receiver accepted the message: a message refused for
    another reason never moves the hold."""

    def __init__(self, live: Live | None = None):
        self.live = live
        self.held: bytes | None = None

    def check(self, source: bytes | None) -> Verdict:
        if source is None or source == self.held:
            return Verdict.HELD
        if self.held is None:
            return Verdict.FIRST
        if self.live is not None and self.held not in {bytes(gid) for gid in self.live()}:
            return Verdict.HANDOVER
        return Verdict.REFUSED

    def take(self, source: bytes | None) -> None:
        """Hold ``source`` (after the receiver accepted its message; ``None`` changes nothing)."""
        if source is not None:
            self.held = source

    def refusal(self, what: str) -> str:
        """The sentence that refuses ``what`` from a publisher that is not held."""
        return f"{what} from a second publisher while the held one is in the ROS graph; ignored"
