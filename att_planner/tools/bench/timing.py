"""timing: the cost of one sky evaluation, one orbit propagation and the closed-sky check of a request.

``att-bench timing [--repeats 30] [--scalar-calls 300] --json PATH`` times, after one untimed call
that builds the tables and does the imports:

* ``sky``: each function of :class:`att_sim.models.ephemeris.Ephemeris` (DE421 Sun and Moon seen
  from a 580 km TLE orbit) called on one scalar time (``--scalar-calls`` calls per repeat, the time
  per call) and once on 2000 times spanning 9000 s;
* ``orbit``: ``state(t)`` of :class:`~att_sim.models.orbit.TLEOrbit` (SGP4 through its
  quintic-Hermite table), :class:`~att_sim.models.orbit.KeplerOrbit` (J2 secular rates) and
  :class:`~att_sim.models.orbit.CircularOrbit`, the same two ways;
* ``closed_sky``: the validation of a ``PlanManeuver`` request whose 16 overlapping cones (two
  rings of 8 about +x and -x) close the sky around the boresight
  (:func:`att_planner.service.requests.validate_maneuver`, refused as INFEASIBLE before any solving);
  ``goal_in_cone``: the same cones with the goal inside one of them (refused by the end-point check
  that runs before the closed-sky one), see :func:`closed_sky_request`.

Each figure is timed ``--repeats`` times (``timeit``: the garbage collector off while timing); the
JSON holds every repeat, their median and best, the target and whether the median meets it, and the
machine's load (``os.getloadavg``) before and after. Targets: :data:`SCALAR_TARGET` a scalar call,
:data:`VECTOR_TARGET` for 2000 times, :data:`CLOSED_SKY_TARGET` for the check. The exit status is 1
when a median misses its target (a wall-clock figure: on a loaded machine, compare the best).
"""
from __future__ import annotations

import math
import os
import platform
import statistics
import time
import timeit

import numpy as np

EPOCH = "2026-12-21T00:00:00Z"
LINE1 = "1 28485U          26355.00000000  .00000000  00000-0  20000-4 0    07"   # a 580 km, 20.56 deg LEO
LINE2 = "2 28485  20.5600  60.0000 0005000  90.0000  10.0000 14.95764766    08"
SKY_FUNCTIONS = ("sun_direction", "moon_direction", "shadow", "earth_angular_radius", "nadir")
VECTOR_TIMES = 2000
SCALAR_TARGET = 50e-6        # s per scalar call
VECTOR_TARGET = 20e-3        # s for 2000 times in one call
CLOSED_SKY_TARGET = 0.1      # s for the 16-cone check of a request


def configure(parser) -> None:
    parser.add_argument("--repeats", type=int, default=30, help="timed repeats of each figure (median and best)")
    parser.add_argument("--scalar-calls", type=int, default=300, help="scalar calls per repeat")


def figure(call, repeats: int, target: float, per: int = 1) -> dict:
    """``call`` (``per`` evaluations) timed ``repeats`` times after one untimed call; s per evaluation."""
    call()
    per_call = [total / per for total in timeit.Timer(call).repeat(repeat=repeats, number=1)]
    median = statistics.median(per_call)
    return {"median_s": median, "best_s": min(per_call), "repeats_s": per_call, "calls_per_repeat": per,
            "target_s": target, "meets_target": median <= target}


def sky_and_orbits():
    """The sky and the three orbit models the figures are taken on."""
    from att_sim.models import environment as env
    from att_sim.models import ephemeris as eph
    from att_sim.models import orbit as ob

    tle = ob.TLEOrbit(EPOCH, LINE1, LINE2)
    orbits = {"TLEOrbit": tle, "KeplerOrbit": ob.KeplerOrbit(EPOCH, 7000e3, 0.01, 1.7, 0.3, 0.5, 0.1),
              "CircularOrbit": ob.CircularOrbit(env.OrbitParams())}
    return eph.Ephemeris(EPOCH, tle), orbits


def scalar_and_vector(f, t: np.ndarray, scalar_calls: int, repeats: int) -> dict:
    """A scalar call of ``f`` (cycling through the first ``scalar_calls`` times) and one call on ``t``."""
    times = t[:scalar_calls].tolist()

    def scalars():
        for x in times:
            f(x)

    return {"scalar": figure(scalars, repeats, SCALAR_TARGET, per=len(times)),
            "vector": figure(lambda: f(t), repeats, VECTOR_TARGET)}


def closed_sky_request(goal_deg: float = 90.0):
    """The validation of a PlanManeuver request (boresight +x, identity to ``goal_deg`` about z) with
    two closed rings of 8 overlapping 20 deg cones, 45 deg about +x and -x. At 90 deg the goal (+y)
    is free and the ring about +x walls the start in: refused as INFEASIBLE by the closed-sky check.
    At 135 deg (the request the unit test timed) the goal lies inside a cone of the ring about -x:
    refused as SENSOR_IN_CONE by the end-point check, before the closed-sky check runs."""
    from att_planner.service.requests import ManeuverRequest, validate_maneuver
    from att_sim.models import rotations as rot

    def ring(center) -> list:
        w = np.asarray(center, float)
        u, v = rot.orthonormal_basis(w)
        b = math.radians(45.0)
        return [(math.cos(b) * w + math.sin(b) * (math.cos(a) * u + math.sin(a) * v), math.radians(20.0), f"r{k}")
                for k, a in enumerate(np.linspace(0, 2 * math.pi, 8, endpoint=False))]

    x = np.array([1.0, 0.0, 0.0])
    req = ManeuverRequest(frame_id="eci", q_initial=rot.IDENTITY, q_final=rot.from_axis_angle([0, 0, 1],
                          math.radians(goal_deg)), sensor_axis=x, cones=ring(x) + ring(-x), method="eigenaxis_smooth")
    return lambda: validate_maneuver(req, frame_id="eci", default_spacecraft="swift_demo",
                                     default_method="eigenaxis_smooth", default_budget=5.0)


def refusal_figure(goal_deg: float, repeats: int) -> dict:
    """:func:`closed_sky_request` timed; ``codes``: the codes it was refused with (None: accepted)."""
    from att_msgs_py.errors import ErrorCode, RequestError

    check, codes = closed_sky_request(goal_deg), []

    def call():
        try:
            check()
            codes.append(None)
        except RequestError as err:
            codes.append(ErrorCode(err.code).name)

    out = figure(call, repeats, CLOSED_SKY_TARGET)
    out.update(cones=16, goal_deg=goal_deg, codes=sorted(set(codes), key=str))
    return out


def _row(name: str, f: dict) -> str:
    unit, scale = ("us", 1e6) if f["target_s"] < 1e-3 else ("ms", 1e3)
    return (f"{name:<36}{f['median_s'] * scale:10.2f}{f['best_s'] * scale:10.2f}{f['target_s'] * scale:10.2f} {unit}"
            f"  {'ok' if f['meets_target'] else 'MISSED'}")


def run(args) -> dict:
    started, load_before = time.perf_counter(), os.getloadavg()
    sky, orbits = sky_and_orbits()
    t = np.linspace(0.0, 9000.0, VECTOR_TIMES)
    sky_figures = {name: scalar_and_vector(getattr(sky, name), t, args.scalar_calls, args.repeats)
                   for name in SKY_FUNCTIONS}
    orbit_figures = {name: scalar_and_vector(o.state, t, args.scalar_calls, args.repeats) for name, o in orbits.items()}
    closed = refusal_figure(90.0, args.repeats)
    end_point = refusal_figure(135.0, args.repeats)
    closed["refused"] = closed["codes"] == ["INFEASIBLE"]
    load_after = os.getloadavg()
    print(f"timing: load {load_before[0]:.2f} -> {load_after[0]:.2f} on {os.cpu_count()} cores; "
          f"{args.repeats} repeats, median / best / target")
    print(f"{'':<36}{'median':>10}{'best':>10}{'target':>10}")
    rows = [(f"sky.{n} scalar", f["scalar"]) for n, f in sky_figures.items()]
    rows += [(f"sky.{n} x{VECTOR_TIMES}", f["vector"]) for n, f in sky_figures.items()]
    rows += [(f"{n}.state scalar", f["scalar"]) for n, f in orbit_figures.items()]
    rows += [(f"{n}.state x{VECTOR_TIMES}", f["vector"]) for n, f in orbit_figures.items()]
    rows.append(("closed sky check (16 cones)", closed))
    rows.append(("goal-in-cone check (16 cones)", end_point))
    for name, f in rows:
        print(_row(name, f))
    print(f"  refused as: closed sky {closed['codes']}, the unit test's request (goal 135 deg) {end_point['codes']}")
    failed = [name for name, f in rows if not f["meets_target"]] + ([] if closed["refused"] else ["closed sky refused"])
    print(f"criteria: {'all met' if not failed else 'missed: ' + ', '.join(failed)}")
    return {"sky": sky_figures, "orbit": orbit_figures, "closed_sky": closed, "goal_in_cone": end_point,
            "vector_times": VECTOR_TIMES,
            "targets": {"scalar_s": SCALAR_TARGET, "vector_s": VECTOR_TARGET, "closed_sky_s": CLOSED_SKY_TARGET},
            "failed": failed, "passed": not failed,
            "machine": {"cores": os.cpu_count(), "load_before": list(load_before), "load_after": list(load_after),
                        "python": platform.python_version(), "omp_num_threads": os.environ.get("OMP_NUM_THREADS"),
                        "nice": os.nice(0), "wall_seconds": time.perf_counter() - started}}
