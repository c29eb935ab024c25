"""The flown imaging day's image check: a truth on the site's law passes both levels, a truth 0.1 deg
off passes (a) and fails (b), a truth 3 deg off fails both; a dwell without samples fails (b); the zone
entries are counted as runs; and a bad --policies is refused."""
from __future__ import annotations

import math
from types import SimpleNamespace

import numpy as np
import pytest

from att_planner.imaging import timeline
from att_planner.tools.bench import aeos_flight, main
from att_sim.models import rotations as rot

from ..imaging.conftest import planner  # noqa: F401  (the shared planner fixture)


def _flight(t, q, omega):
    arrays = {"t": np.asarray(t), "q_true": np.asarray(q), "omega_true": np.asarray(omega)}
    return SimpleNamespace(loop=SimpleNamespace(trace=SimpleNamespace(arrays=lambda *names: arrays)))


@pytest.mark.parametrize("offset_deg, level_a, level_b", [(0.0, True, True), (0.1, True, False), (3.0, False, False)])
def test_an_image_is_judged_at_both_levels_on_the_truth(planner, offset_deg, level_a, level_b):  # noqa: F811
    law = planner.laws(0)
    image = timeline.Image(0, 0, 200.0, 2.0, 197.0)
    t = np.arange(199.0, 203.0, 0.05)
    tilt = rot.from_axis_angle(np.array([1.0, 0.0, 0.0]), math.radians(offset_deg))   # about a body axis ⟂ boresight
    q = np.array([rot.multiply(law(s)[0], tilt) for s in t])
    omega = np.array([rot.dcm_NB(tilt).T @ law(s)[1] for s in t])     # the same motion, body axes
    plan = timeline.Timeline("greedy", images=[image])
    (check,) = aeos_flight.check(planner, plan, _flight(t, q, omega))
    assert (check.level_a, check.level_b) == (level_a, level_b)
    assert check.samples == 41 and check.a_pointing_deg == pytest.approx(offset_deg, abs=1e-6)
    assert check.b_rate_deg_s < 1e-3


def test_an_image_after_the_flight_fails_both_levels(planner):  # noqa: F811
    plan = timeline.Timeline("ours", images=[timeline.Image(0, 0, 900.0, 2.0, 897.0)])
    (check,) = aeos_flight.check(planner, plan, _flight([0.0, 0.05], [rot.IDENTITY] * 2, [[0.0] * 3] * 2))
    assert not check.level_a and not check.level_b and check.samples == 0


def test_bad_policies_are_refused(capsys):
    with pytest.raises(SystemExit) as exit_:
        main(["aeos", "--targets", "uniform:5", "--orbits", "0.05", "--fly", "--policies", "random",
              "--json", "/dev/null"])
    assert exit_.value.code == 2 and "--policies" in capsys.readouterr().err
