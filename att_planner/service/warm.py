"""Warm planner workers: the NLPs of the shapes a planner serves, built before it serves.

A collocation method builds its NLP once per problem shape (spacecraft inertia, interval count,
zones and their kind, goal; :func:`att_planner.methods.time_optimal.model.transcription`) and keeps
it; the build takes most of a second or more, a solve of a warm NLP a fraction of that. A planner
node therefore plans, in each worker process before it reports ready
(:func:`att_planner.service.worker.start_pool`), the maneuver of the ``demo:`` section of each of
its warm-up scenarios (:func:`maneuver_from_scenario`: the spacecraft, the attitudes and sensor,
the section's cones and the scenario's zones; :func:`warm_requests`) with its default method,
through the service's own pipeline (:func:`.planning.plan_maneuver`, the node's padding), so that
the NLPs a request of those shapes needs — the first mesh and its refinements — are built.
"""
from __future__ import annotations

import math
import time
from dataclasses import replace
from datetime import timedelta

import numpy as np

from att_msgs_py.types import Cone
from att_planner.service.planning import plan_maneuver
from att_planner.service.requests import ManeuverRequest, ValidRequest, validate_maneuver
from att_planner.verification import TOLERANCES, Tolerances
from att_sim.models import scenario as scen

DEMO_KEYS = ("initial_attitude", "final_attitude", "sensor_axis")
WARM_BUDGET = 60.0          # s each warm-up plan may take (it builds; the request it stands for will not)


def maneuver_from_scenario(s: scen.Scenario) -> dict:
    """The ``demo:`` section's maneuver with the scenario's zones; ValueError (one sentence) when
    the scenario has no such section (its keys are checked where the file is read)."""
    p = s.node_params.get("demo")
    if not isinstance(p, dict):
        raise ValueError(f"scenario '{s.name}' ({s.path}) has no 'demo:' section with the maneuver to fly "
                         f"({', '.join(DEMO_KEYS)}, optional cones, method, time_budget_s, start_lead_s, start_time_s)")
    # the section as config_schema.Demo validated it: every key present, defaults filled in there
    dirs = np.asarray(p["cone_directions"], float).reshape(-1, 3)
    cones = [Cone(d, math.radians(a), n) for d, a, n in zip(dirs, p["cone_half_angles_deg"], p["cone_names"])]
    return {"q0": np.asarray(p["initial_attitude"], float), "qf": np.asarray(p["final_attitude"], float),
            "sensor": np.asarray(p["sensor_axis"], float), "cones": cones, "zones": list(s.zones),
            "method": p["method"], "time_budget": float(p["time_budget_s"]),
            "start_lead": float(p["start_lead_s"]), "start_time": p["start_time_s"]}


def warm_requests(names: list[str], *, frame_id: str, default_method: str) -> list[ValidRequest]:
    """The demo maneuver of each scenario of ``names`` that has one, as a validated request for
    ``default_method`` of that scenario's spacecraft. With a sky, twice: its zones where they are
    at the scenario's epoch plus ``start_lead`` and at its ``start_time`` (as ``att-demo`` asks): a
    demo may be set where the default method finds no way (the leo_observatory one grazes the
    rising Earth limb), and the shape, not the geometry, is what the warm-up builds."""
    out = []
    for name in names:
        scenario = scen.load_checked(name)
        try:
            m = maneuver_from_scenario(scenario)
        except ValueError:
            continue
        epochs = [(0, 0)]
        if scenario.epoch is not None:
            offsets = dict.fromkeys([m["start_lead"]] + ([] if m["start_time"] is None else [float(m["start_time"])]))
            epochs = [_epoch_parts(scenario.epoch + timedelta(seconds=offset)) for offset in offsets]
        for epoch in epochs:
            request = ManeuverRequest(frame_id, m["q0"], m["qf"], m["sensor"],
                                      [(c.direction, c.half_angle, c.name) for c in m["cones"]],
                                      spacecraft=name, time_budget=WARM_BUDGET, epoch=epoch, zones=m["zones"])
            out.append(validate_maneuver(request, frame_id=frame_id, default_spacecraft=name,
                                         default_method=default_method, default_budget=WARM_BUDGET))
    return out


def _epoch_parts(epoch) -> tuple[int, int]:
    """``(sec, nanosec)`` of a UTC datetime, as a request carries it."""
    sec = math.floor(epoch.timestamp())
    return sec, round((epoch.timestamp() - sec) * 1e9)


def warm(requests: list[ValidRequest], tol: Tolerances = TOLERANCES, cone_padding: float = 0.0) -> list[str]:
    """Plan each request in this process (a worker's warm-up), its deadline counted from now;
    the stage each answer came from (the method's when the worker is warm for its shape)."""
    stages = []
    for valid in requests:
        problem = replace(valid.problem, deadline=time.monotonic() + WARM_BUDGET)
        stages.append(str(plan_maneuver(replace(valid, problem=problem), tol, cone_padding).stage))
    return stages
