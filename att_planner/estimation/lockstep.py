"""Estimators of lockstep Monte Carlo runs reprocessed together (no ROS).

The runs of a Monte Carlo task step in lockstep: at each step every run's estimator reprocesses
(catches up with its gyro sample, replays a late tracker sample). :func:`reprocess_together` runs
their :meth:`Estimator.reprocess_steps <att_planner.estimation.estimator.Estimator.reprocess_steps>`
side by side and, at each turn, propagates the filters of one tuning as one stack
(:func:`att_planner.estimation.mekf.propagate`) and makes the Kalman updates asked as stacks
(:func:`att_planner.estimation.mekf.update`), each to the bits it reaches alone; each
estimator's own operations keep their order.
"""
from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np

from att_planner.estimation import mekf

if TYPE_CHECKING:
    from att_planner.estimation.estimator import Estimator


def reprocess_together(jobs: list[tuple[Estimator, int | None]]) -> None:
    """:meth:`Estimator.reprocess` of each ``(estimator, start)`` (start None: nothing to do), all at once;
    then the largest attitude variance of each one's newest state, which its health needs, as one stack."""
    live = []
    for e, start in jobs:
        if start is not None:
            steps = e.reprocess_steps(start)
            request = next(steps, None)
            if request is not None:
                live.append((e, steps, request))
    while live:
        answers = _answer_together([(e, request) for e, _, request in live])
        live = [(e, steps, request) for (e, steps, _), answer in zip(live, answers)
                if (request := resume(steps, answer)) is not None]
    _largest_variances([e for e, start in jobs if start is not None])


def _largest_variances(estimators: list[Estimator]) -> None:
    """:meth:`Estimator.keep_largest_attitude_variance` of each estimator's newest state (stacked
    ``eigvalsh`` gives each matrix the bits it gets alone)."""
    states = [e.state for e in estimators]
    stack = [(e, x) for e, x in zip(estimators, states) if x is not None]
    if len(stack) > 1:
        largest = np.linalg.eigvalsh(np.array([x.P[:3, :3] for _, x in stack])).max(axis=-1)
        for (e, _), value in zip(stack, largest.tolist()):
            e.keep_largest_attitude_variance(value)


def _answer_together(requests: list[tuple[Estimator, tuple]]) -> list:
    """The answer to each estimator's request: its Kalman updates (:class:`~.mekf.Correction`)
    as stacks (:func:`~.mekf.update`), its propagations by :func:`_propagate_together`."""
    out = [None] * len(requests)
    corrections = [i for i, (_, request) in enumerate(requests) if isinstance(request, mekf.Correction)]
    for i, answer in zip(corrections, mekf.update([requests[i][1] for i in corrections])):
        out[i] = answer
    propagations = [i for i, (_, request) in enumerate(requests) if not isinstance(request, mekf.Correction)]
    for i, answer in zip(propagations, _propagate_together([requests[i] for i in propagations])):
        out[i] = answer
    return out


def _propagate_together(requests: list[tuple[Estimator, tuple]]) -> list:
    """:meth:`Estimator.propagate_to` of each ``(estimator, (x, ω_m, t, saturated))``: the real
    propagations of the first one's tuning as one stack, the others one by one."""
    out = [None] * len(requests)
    stack, first = [], None
    for i, (e, (x, omega, t, saturated)) in enumerate(requests):
        if x is not None and t > x.t and (first is None or e.tuning == first.tuning):
            first = first or e
            stack.append(i)
        else:
            out[i] = e.propagate_to(x, omega, t, saturated)
    if stack:
        states, omegas, intervals = [], [], []
        for i in stack:
            e, (x, omega, t, saturated) = requests[i]
            states.append(x)
            omegas.append(omega)
            intervals.append(e.interval(x, t, saturated))
        propagated = mekf.propagate(states, np.array(omegas), [dt for dt, _ in intervals], first.config.arw,
                                         first.config.rrw, first.consider, [extra for _, extra in intervals])
        for i, x, ok in zip(stack, propagated, mekf.healthy(np.array([x.P for x in propagated]))):
            e, (_, _, t, _) = requests[i]
            out[i] = e.checked(t, x, ok)
    return out


def resume(steps, value):
    """The generator ``steps`` sent ``value``: its next request, None when it has finished."""
    try:
        return steps.send(value)
    except StopIteration:
        return None

