"""Time-optimal slews by direct collocation (Melton 2012): the Hermite–Simpson toolkit
(:mod:`.collocation`), the NLP (:mod:`.model`), warm starts (:mod:`.routes`) and the planner
(:mod:`.planner`, :func:`plan_time_optimal`)."""
from att_planner.methods.time_optimal.planner import plan_time_optimal

__all__ = ["plan_time_optimal"]
