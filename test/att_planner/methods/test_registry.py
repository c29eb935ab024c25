"""The method registry, the one source of option ranges: every corner of every range either plans
or is refused by validation (INVALID_OPTION, 131), never answered as a solver failure."""
from __future__ import annotations

import itertools
import math
import pickle

import numpy as np
import pytest

from att_msgs_py.errors import ErrorCode, RequestError
from att_planner import methods
from att_planner.service.planning import plan_maneuver, run_method
from att_planner.service.requests import ManeuverRequest, validate_maneuver
from att_sim.models import rotations as rot

BUDGET = 2.0        # s per request: the corners are about running at all, not about the best plan


def corners(method: methods.Method) -> list[dict]:
    """Each option at both ends of its range (the others at their defaults), and every vertex of the
    box of the options the method's hook combines."""
    out = [{name: value} for name, spec in method.options.items() for value in (spec.low, spec.high)]
    ends = [(method.options[n].low, method.options[n].high) for n in method.combined]
    return out + [dict(zip(method.combined, values)) for values in itertools.product(*ends)]


CASES = [(m.name, options) for m in methods.REGISTRY for options in corners(m)]


def request(method: str, options: dict, time_budget: float = BUDGET) -> ManeuverRequest:
    """A 60° slew about body z of the swift_demo spacecraft, sensor x, one cone well off the path."""
    return ManeuverRequest(frame_id="eci", q_initial=rot.IDENTITY,
                           q_final=rot.from_axis_angle([0, 0, 1], math.radians(60)),
                           sensor_axis=np.array([1.0, 0, 0]), cones=[([0.0, 0.0, 1.0], math.radians(30), "zenith")],
                           method=method, time_budget=time_budget, option_names=list(options),
                           option_values=[float(v) for v in options.values()])


def test_every_method_has_its_ranges_in_the_registry_and_travels_to_child_processes():
    assert [m.name for m in methods.REGISTRY][:3] == ["smooth_collocation", "slepian_minimum_time", "time_optimal"]
    for m in methods.REGISTRY:
        assert callable(m.load())
        assert pickle.loads(pickle.dumps(m)) == m       # the planner sends it to a child solver
        for name, spec in m.options.items():
            assert spec.low <= spec.high and (not spec.integer or float(spec.low).is_integer()), (m.name, name)


@pytest.mark.slow
@pytest.mark.parametrize("method, options", CASES, ids=[f"{m}-{o}" for m, o in CASES])
def test_every_corner_plans_or_is_refused_by_validation(method, options):
    try:
        valid = validate_maneuver(request(method, options), frame_id="eci", default_spacecraft="swift_demo",
                                  default_method=method, default_budget=BUDGET)
    except RequestError as err:
        assert err.code == ErrorCode.INVALID_OPTION, err.message
        return
    ran = []

    def runner(m, problem, opts, wait):
        ran.append(run_method(m, problem, opts, wait))
        return ran[-1]

    outcome = plan_maneuver(valid, runner=runner)
    assert "exception" not in ran[0].stats, f"{method} {options} raised: {ran[0].message}"
    assert outcome.code == ErrorCode.OK, outcome.message


@pytest.mark.parametrize("method, options, words", [
    ("mssa", {"N": 50, "W": 1e-4}, "below 1"),                   # N·W = 0.005: no concentrated sequence
    ("slepian_minimum_time", {"M": 12, "N": 50, "W": 0.1}, "M (basis size) = 12 exceeds"),
    ("dfsp", {"N": 100, "W": 0.005}, "below 1"),
    ("time_optimal", {"intervals": 100, "max_intervals": 50}, "max_intervals = 50 is below intervals = 100"),
])
def test_combinations_a_method_cannot_run_are_refused_with_131(method, options, words):
    with pytest.raises(RequestError) as err:
        validate_maneuver(request(method, options), frame_id="eci", default_spacecraft="swift_demo",
                          default_method=method, default_budget=BUDGET)
    assert err.value.code == ErrorCode.INVALID_OPTION and words in err.value.message


def test_large_basis_at_the_largest_n_plans():
    """N = 2000 with the paper's W (N·W = 30) used to fail on the coarse grid ('NW must be less than M/2')."""
    # a budget of its own: the point is the large basis, not its speed on a loaded machine
    valid = validate_maneuver(request("slepian_minimum_time", {"N": 2000}, time_budget=20.0), frame_id="eci",
                              default_spacecraft="swift_demo", default_method="slepian_minimum_time",
                              default_budget=20.0)
    ran = []

    def runner(m, problem, opts, wait):
        ran.append(run_method(m, problem, opts, wait))
        return ran[-1]

    outcome = plan_maneuver(valid, runner=runner)
    assert outcome.code == ErrorCode.OK and outcome.stages[1].verified, outcome.message
    assert ran[0].method == "slepian_minimum_time" and len(ran[0].t) == 2001
