"""The plans a controller has received (no ROS): checked, bound to their ids, bounded.

:class:`PlanCache` keeps the published plans that pass :func:`~.plan_checks.check_plan` (fields,
spacecraft, signature), remembers each plan id with the SHA-256 of its signed bytes so that a
different plan can never take a known id (307, whatever its signature), remembers why refused
plans were refused (an execute goal for one is told), and is bounded by count and bytes: the
oldest plans go first, never the one being flown.
"""
from __future__ import annotations

import hashlib
from collections import OrderedDict
from dataclasses import dataclass

from att_msgs_py import validation
from att_msgs_py.errors import ErrorCode, RequestError
from att_msgs_py.types import Plan
from att_planner.control.plan_checks import PlanContext, check_plan

MAX_REMEMBERED_IDS = 100_000                   # plan ids whose content is remembered (32 bytes each)
MAX_REMEMBERED_REFUSALS = 1000                 # refused plan ids whose reason an execute goal is told


@dataclass
class CachedPlan:
    plan: Plan
    size: int                                  # bytes of its message


class PlanCache:
    def __init__(self, context: PlanContext, max_plans: int, max_bytes: int):
        self.context, self.max_plans, self.max_bytes = context, max_plans, max_bytes
        self.plans: OrderedDict[str, CachedPlan] = OrderedDict()
        self.seen: OrderedDict[str, bytes] = OrderedDict()   # plan id -> SHA-256 of its signed bytes
        self.refused: OrderedDict[str, RequestError] = OrderedDict()   # published plans refused, why

    @property
    def bytes(self) -> int:
        return sum(c.size for c in self.plans.values())

    def _remember(self, plan: Plan, payload: bytes) -> RequestError | None:
        """Record ``plan``'s id with its content; refuse a different plan under a known id."""
        digest = hashlib.sha256(payload).digest()
        known = self.seen.get(plan.plan_id)
        if known is not None and known != digest:
            return RequestError(ErrorCode.PLAN_ID_REUSED,
                                f"plan id '{plan.plan_id}' belongs to a different plan this controller received "
                                "before; refused")
        self.seen[plan.plan_id] = digest
        self.seen.move_to_end(plan.plan_id)
        while len(self.seen) > MAX_REMEMBERED_IDS:
            self.seen.popitem(last=False)
        return None

    def admit(self, plan: Plan, payload: bytes) -> RequestError | None:
        """Check a received plan (:func:`check_plan`) and its id; None when it is usable."""
        return check_plan(plan, payload, self.context) or self._remember(plan, payload)

    def receive(self, plan: Plan, payload: bytes, flying: str | None = None) -> RequestError | None:
        """Cache a published plan once it passes :meth:`admit`; the oldest plans go beyond
        ``max_plans`` or ``max_bytes``, never ``flying``."""
        refused = self.admit(plan, payload)
        if refused is not None:
            key = plan.plan_id[:validation.MAX_NAME_LENGTH]
            self.refused[key] = refused
            self.refused.move_to_end(key)
            while len(self.refused) > MAX_REMEMBERED_REFUSALS:
                self.refused.popitem(last=False)
            return refused
        if plan.plan_id in self.plans:
            return None
        self.plans[plan.plan_id] = CachedPlan(plan, len(payload))
        for plan_id in list(self.plans):
            if len(self.plans) <= self.max_plans and self.bytes <= self.max_bytes:
                break
            if plan_id != flying:
                del self.plans[plan_id]
        return None

    def resolve(self, plan_id: str, inline: Plan | None = None,
                payload: bytes = b"") -> tuple[Plan | None, RequestError | None]:
        """The plan to execute (``inline`` with its signed ``payload``, or the cached ``plan_id``),
        or why there is none."""
        if inline is not None:
            refused = self.admit(inline, payload)
            return (None, refused) if refused is not None else (inline, None)
        try:
            validation.text(plan_id, "plan_id")
        except RequestError as err:
            return None, err
        cached = self.plans.get(plan_id)
        if cached is None and plan_id in self.refused:
            why = self.refused[plan_id]
            return None, RequestError(why.code, f"plan '{plan_id}' was refused when it arrived: {why.message}")
        if cached is None:
            return None, RequestError(ErrorCode.UNKNOWN_PLAN,
                                      f"plan_id '{plan_id}' is not a plan this controller received")
        return cached.plan, None
