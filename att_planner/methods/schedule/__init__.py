"""Time-optimal attitude scheduling with reaction wheels through unordered targets.

Olivares & Staffetti (2018): visit every target attitude once, in the fastest order, starting and
ending at rest, with wheel torques ``|T_u,i| ≤ T̄`` and wheel speeds ``|Ω_i| ≤ Ω̄`` (inertial, and
relative to the body, the speed the model of :mod:`att_sim.models.dynamics` limits); at each target
the body rate about z is zero (the other rates are free and carry over).

Model (the model of :mod:`att_sim.models.dynamics`, J = I_s the total inertia, G the wheel axes)::

    q̇ = ½ q ⊗ [ω, 0],   J ω̇ = −ω × (J ω + G I_w Ω) − G T_u,   I_w Ω̇ = T_u.

No external torque acts, so the inertial angular momentum is conserved; starting at rest with the
wheels stopped it is zero for ever, hence in body axes ``J ω + G I_w Ω = 0`` and

    ω = −J⁻¹ G I_w Ω                                                              (1)

exactly. The transcription uses this reduced state (q, Ω): nothing is approximated, the gyroscopic
term vanishes identically, and ``I_w Ω̇ = T_u`` is integrated exactly for zero-order-hold torques.

Transcription (for a given order): direct multiple shooting, one phase per leg with a free
duration, N equal intervals per phase, wheel torque held constant over an interval (the plan is a
ZOH profile, exactly what the verification integrates), attitude propagated by RK4 with the rate
(1), which is linear in time within an interval. Because Ω (hence ω) is piecewise linear, the speed
and rate bounds imposed at the nodes hold everywhere. Phases share their boundary nodes (continuity
of the full state); the passage constraints are ``vec(q_target* ⊗ q) = 0`` (sign-free: q and −q are
the same attitude, the solver takes whichever is nearer) and ``ω_z = 0``.

Modules: :mod:`.transcription` (the NLP of one order), :mod:`.order_search`, :mod:`.planner`
(:func:`plan_schedule`; the experiments' data are in :mod:`att_planner.reference.olivares_staffetti`).

Order search (:func:`plan_schedule`): a lower bound for every leg (:func:`leg_bound_matrix`: the
minimum-time transfer between two attitudes with only what the schedule imposes at its ends, so
the sum along an order bounds that order from below), orders enumerated in increasing bound by a
best-first search whose heuristic is the exact Held–Karp completion cost
(:func:`orders_by_lower_bound`), multiphase solves of the first orders on a coarse grid, and a fine
solve of the winner. With ``prove=True`` every order whose bound is below the incumbent is solved:
when the enumeration stops on the bound, no unsolved order can beat the incumbent (on that grid,
and given that the NLPs reach their global minima). :func:`exhaustive_order_search` solves all n!
orders as an independent check (time reversal maps a schedule of an order onto one of the
reversed order with the same duration, so pairs must agree).

Zones (:mod:`.transcription`): the cones and zones of ``problem.zone_sky()``, moving
or not, keep-out or keep-in, each of its own sensor, are kept at every node and interval midpoint
of every leg at its physical time along the tour (a leg starts at the sum of the earlier legs'
durations), exactly in the phase durations; the leg bounds leave them out (still lower bounds).

Observations (``problem.target_dwell`` and ``target_windows``): a target held at rest for
its dwell, observed within its window and never while a zone covers it; the order search bounds each
order with its waits (:func:`.order_search.tour_bound`) and drops orders that miss a window.

Note on the paper's dynamics: ``|Ω| ≤ 710 rad/s`` with ``I_w = 1.69e-4`` gives h̄ = 0.12 N m s and
t_sat = h̄ / T̄ = 11.9 s; the body-rate bound 0.04 rad/s is implied by the wheel box (|ω_i| ≤ h̄ /
I_i ≤ 0.018 rad/s) and never binds.
"""
from att_planner.methods.schedule.order_search import exhaustive_order_search, leg_bound_matrix, orders_by_lower_bound
from att_planner.methods.schedule.planner import plan_schedule
from att_planner.methods.schedule.transcription import SUBSTEPS, eigenaxis_rest_to_rest_time

__all__ = ["SUBSTEPS", "eigenaxis_rest_to_rest_time", "exhaustive_order_search", "leg_bound_matrix",
           "orders_by_lower_bound", "plan_schedule"]
