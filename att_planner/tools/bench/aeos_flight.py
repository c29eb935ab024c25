"""An imaging timeline flown in process, each image checked on the flown truth.

:func:`fly` flies a :class:`att_planner.imaging.timeline.Timeline` through
:class:`att_planner.tools.closed_loop.ClosedLoop` (the simulator with every sensor and imperfect
actuator, the MEKF, the controller on the estimate), starting on nadir tracking: the controller
points on nadir, then at each leg's start the slew is rebuilt from the controller's latest state
time onto the same arrival (:func:`att_planner.imaging.slews.build`: the timeline's slew started
a control step later), verified, and executed with the target's pointing mode after it, which the
controller takes over at the arrival and tracks through the settle and the dwell.

:func:`check` judges every planned image on the flown truth (the simulator's attitude and body
rate at the control instants), against the site's pointing law at the same instant:

* level (a), bsk-rl's tolerance at one instant (the image's time): the imager's angle to the line
  of sight ≤ :data:`LEVEL_A_POINTING_DEG` and the body rate's error to the law's ≤
  :data:`LEVEL_A_RATE_DEG_S`;
* level (b), held through the dwell: at every control instant of ``[t, t + dwell]`` the whole
  attitude's error to the law (line of sight and detector orientation) ≤ :data:`LEVEL_B_POINTING_DEG`
  and the rate error ≤ :data:`LEVEL_B_RATE_DEG_S`.

An image that fails is *lost* (planned, failed on the truth). The zones are measured on the flown
truth at every :data:`ZONE_DECIMATION`-th control instant at their true positions.
"""
from __future__ import annotations

import math
import time
from dataclasses import dataclass, field

import numpy as np

from att_msgs_py.types import ControlMode
from att_planner.imaging import slews
from att_planner.imaging.timeline import NADIR, Planner, Timeline
from att_planner.tools.closed_loop import ClosedLoop
from att_sim.models import rotations as rot

LEVEL_A_POINTING_DEG = 2.29     # deg: bsk-rl's imaging tolerance (one instant)
LEVEL_A_RATE_DEG_S = 0.57       # deg/s
LEVEL_B_POINTING_DEG = 0.05     # deg, held through the dwell
LEVEL_B_RATE_DEG_S = 0.01       # deg/s
IMAGING_GAINS = {"tracking_kp": 10.0, "tracking_kd": 60.0}    # N m/rad, N m s/rad: an imaging loop's
ZONE_DECIMATION = 4             # every this many control instants checked against the zones


@dataclass
class Flight:
    """What was flown: the loop's trace, the legs refused at their start (index: why), the rebuilt
    slews' verification refusals, and the wall and CPU time of the flight."""

    loop: ClosedLoop
    refused: dict[int, str] = field(default_factory=dict)
    cpu_s: float = 0.0
    sim_s: float = 0.0


def fly(scenario, planner: Planner, timeline: Timeline, *, seed: int | None = None,
        overrides: dict | None = None, end_s: float | None = None) -> Flight:
    """Fly ``timeline`` (module docstring) up to ``end_s`` (default the windows' horizon's end)."""
    start = time.process_time()
    laws = planner.laws
    q0, omega0 = laws(NADIR)(planner.windows.t0_s)
    loop = ClosedLoop(scenario, overrides=overrides if overrides is not None else {"controller": IMAGING_GAINS},
                      seed=seed, q0=q0, omega0=omega0)
    flight = Flight(loop)
    end_s = planner.windows.t1_s if end_s is None else end_s
    while True:                                          # on nadir as soon as the estimate allows
        loop.tick()
        if loop.controller.state is not None:
            code, _, _ = loop.controller.set_mode(ControlMode.POINTING, laws.mode(NADIR))
            if code == 0:
                break
    source = NADIR
    for k, leg in enumerate(timeline.legs):
        if leg.slew.t0_s >= end_s:
            break
        while loop.sim.t < leg.slew.t0_s - 1e-9 and not loop.sim.halted:
            loop.tick()
        t_state = float(loop.controller.state.t)
        slew = slews.build(laws(source)(t_state), t_state, laws(leg.target), leg.slew.arrival_s - t_state,
                           planner.limits)
        check = slews.verify(slew, planner.spacecraft, laws(leg.target), planner.limits, planner.zones)
        if check.refusal is not None:
            flight.refused[k] = f"rebuilt slew: {check.refusal}"
            continue
        refused = loop.execute(slew.plan, plan_id=f"leg{k}", after=laws.mode(leg.target))
        if refused is not None:
            flight.refused[k] = refused.message
            continue
        source = leg.target
    while loop.sim.t < end_s - 1e-9 and not loop.sim.halted:
        loop.tick()
    flight.cpu_s, flight.sim_s = time.process_time() - start, float(loop.sim.t)
    return flight


@dataclass(frozen=True)
class ImageCheck:
    """One image judged on the flown truth (module docstring): at its time the truth's attitude
    ``q_BN`` and body rate ``omega_BN_B``, the level-(a) pointing and rate errors, the level-(b)
    worst attitude and rate errors over the dwell, and whether each level passes."""

    site: int
    time_s: float
    q_BN: np.ndarray
    omega_BN_B: np.ndarray
    a_pointing_deg: float
    a_rate_deg_s: float
    b_pointing_deg: float
    b_rate_deg_s: float
    samples: int

    @property
    def level_a(self) -> bool:
        return self.a_pointing_deg <= LEVEL_A_POINTING_DEG and self.a_rate_deg_s <= LEVEL_A_RATE_DEG_S

    @property
    def level_b(self) -> bool:
        return (self.samples > 0 and self.b_pointing_deg <= LEVEL_B_POINTING_DEG
                and self.b_rate_deg_s <= LEVEL_B_RATE_DEG_S)


def _errors(law, boresight_B, t: float, q: np.ndarray, omega: np.ndarray) -> tuple[float, float, float]:
    """(imager angle to the line of sight, attitude error, rate error) of a truth sample to the law (rad, rad/s)."""
    q_RN, omega_RN_R = law(float(t))
    dcm_true, dcm_ref = rot.dcm_NB(q), rot.dcm_NB(q_RN)
    boresight = float(np.arccos(np.clip((dcm_true @ boresight_B) @ (dcm_ref @ boresight_B), -1.0, 1.0)))
    rate = float(np.linalg.norm(omega - dcm_true.T @ dcm_ref @ np.asarray(omega_RN_R, float)))
    return boresight, float(rot.angle_between(q, q_RN)), rate


def check(planner: Planner, timeline: Timeline, flight: Flight) -> list[ImageCheck]:
    """Every image of ``timeline`` judged on ``flight``'s truth (module docstring)."""
    trace = flight.loop.trace.arrays("t", "q_true", "omega_true")
    t, q, omega = trace["t"], trace["q_true"], trace["omega_true"]
    b = planner.laws.boresight
    out = []
    for image in timeline.images:
        law = planner.laws(image.site)
        k = int(np.searchsorted(t, image.time_s - 1e-9))
        if k >= len(t):
            out.append(ImageCheck(image.site, image.time_s, np.full(4, math.nan), np.full(3, math.nan),
                                  math.inf, math.inf, math.inf, math.inf, 0))
            continue
        a_point, _, a_rate = _errors(law, b, t[k], q[k], omega[k])
        held = np.flatnonzero((t >= image.time_s - 1e-9) & (t <= image.time_s + image.dwell_s + 1e-9))
        worst = [_errors(law, b, t[i], q[i], omega[i]) for i in held]
        b_point = max((w[1] for w in worst), default=math.inf)
        b_rate = max((w[2] for w in worst), default=math.inf)
        out.append(ImageCheck(image.site, float(t[k]), q[k].copy(), omega[k].copy(), math.degrees(a_point),
                              math.degrees(a_rate), math.degrees(b_point), math.degrees(b_rate), len(held)))
    return out


def zone_margins(planner: Planner, flight: Flight) -> tuple[float, int]:
    """The lowest zone margin (rad) on the flown truth and the number of entries (runs of samples
    inside a zone)."""
    if planner.zones is None or not planner.zones.zones:
        return math.inf, 0
    trace = flight.loop.trace.arrays("t", "q_true")
    t, q = trace["t"][::ZONE_DECIMATION], trace["q_true"][::ZONE_DECIMATION]
    if not len(t):
        return math.inf, 0
    m = planner.zones.margins(t, q, true=True).min(axis=1)
    inside = m < 0.0
    entries = int(np.count_nonzero(inside[1:] & ~inside[:-1]) + int(inside[0]))
    return float(m.min()), entries
