"""Plans as a planner issues them (context filled, signed), for tests of the controller."""
from __future__ import annotations

from cryptography.hazmat.primitives.asymmetric.ed25519 import Ed25519PrivateKey

from att_msgs_py import convert, signing
from att_msgs_py.types import Plan
from att_planner.control.plan_checks import PlanContext
from att_sim.models import scenario

KEY = Ed25519PrivateKey.generate()       # this test process's planner key


def context(name: str = "swift_demo", key: Ed25519PrivateKey = KEY, **tolerances) -> PlanContext:
    s = scenario.load(name)
    return PlanContext(s.spacecraft, s.name, s.frame_id, key.public_key(), **tolerances)


def issue(plan: Plan, ctx: PlanContext, plan_id: str = "p1", key: Ed25519PrivateKey | None = KEY,
          fields: dict | None = None) -> tuple[Plan, bytes]:
    """``plan`` with the planner's context, through the wire and signed: (received plan, payload).
    ``fields`` change the message after the context is filled, before signing (``key=None``: unsigned)."""
    plan.plan_id, plan.spacecraft, plan.frame_id = plan_id, ctx.spacecraft_name, ctx.frame_id
    plan.spacecraft_digest = ctx.spacecraft.digest
    msg = convert.plan_msg(plan)
    for name, value in (fields or {}).items():
        setattr(msg, name, value)
    if key is not None:
        signing.sign(msg, key)
    return convert.plan_from_msg(msg), signing.payload(msg)
