"""Offset search of att-bench sky's leo_observatory case: the start offset after
2026-12-21T00:00Z at which the plan made against the frozen zones enters the moving Earth-limb zone
when verified against the motion.

Self-contained: skyfield directly for the sky, the Cone-based slepian_minimum_time for the
frozen plan (frozen zones are inertial cones), the verification's prediction for the attitude.
Usage (from the repository root): .venv/bin/python benchmarks/sky_offset_search.py [start stop step]
"""
import sys
from importlib.resources import files

import numpy as np
from skyfield.api import EarthSatellite, load, load_file

from att_msgs_py.types import Cone
from att_planner.methods.slepian import plan_slepian
from att_planner.reference.celani_bruni import benchmark_problem
from att_planner.verification import predict
from att_sim.models import rotations as rot

L1 = "1 28485U          26355.00000000  .00000000  00000-0  20000-4 0    07"
L2 = "2 28485  20.5600  60.0000 0005000  90.0000  10.0000 14.95764766    08"
RE = 6378.137e3
TS = load.timescale(builtin=True)
EPH = load_file(str(files("skyfield_data") / "data" / "de421.bsp"))
SAT = EarthSatellite(L1, L2, ts=TS)


def sky(t):
    """axes (K,3,3) [sun, moon, nadir] and half-angles (K,3) at seconds t past 2026-12-21T00:00Z."""
    tt = TS.utc(2026, 12, 21, 0, 0, np.atleast_1d(t))
    r = SAT.at(tt).position.m.T
    e = EPH["earth"].at(tt).position.m
    sun = (EPH["sun"].at(tt).position.m - e).T - r
    moon = (EPH["moon"].at(tt).position.m - e).T - r
    ax = np.stack([sun, moon, -r], axis=1)
    ax /= np.linalg.norm(ax, axis=2, keepdims=True)
    half = np.stack([np.full(len(r), np.radians(47)), np.full(len(r), np.radians(23)),
                     np.arcsin(RE / np.linalg.norm(r, axis=1)) + np.radians(10)], axis=1)
    return ax, half


SENSOR = np.array([0.0, 1.0, 0.0])


def margins(t, q, axis=SENSOR):
    ax, half = sky(t)
    b = np.einsum("kij,j->ki", rot.dcm_NB(q), axis)
    return np.arccos(np.clip(np.einsum("kzi,ki->kz", ax, b), -1, 1)) - half


def main(start=0.0, stop=5800.0, step=100.0):
    base = benchmark_problem("earth_obs")
    for off in np.arange(start, stop, step):
        ax, half = sky(off)
        cones = [Cone(ax[0, z], half[0, z], n) for z, n in enumerate(("sun", "moon", "earth_limb"))]
        prob = base.__class__(spacecraft=base.spacecraft, q_initial=base.q_initial, q_final=base.q_final,
                              sensor_axis=base.sensor_axis, cones=cones)
        ends = margins(off, np.stack([base.q_initial, base.q_final]))
        plan = plan_slepian(prob)
        if not plan.success:
            print(f"{off:7.0f}  ends {np.degrees(ends.min(axis=0)).round(2)}  {plan.status} {plan.message[:60]}")
            continue
        traj = predict(prob, plan)
        ax0, h0 = sky(off)
        b = np.einsum("kij,j->ki", rot.dcm_NB(traj.q_BN), base.sensor_axis)
        frozen = np.arccos(np.clip(b @ ax0[0].T, -1, 1)) - h0[0]
        true = margins(off + traj.t, traj.q_BN)
        end_true = margins(off + plan.duration, base.q_final[None])
        print(f"{off:7.0f}  tf {plan.duration:6.1f}  {plan.wall_time:4.1f}s  frozen min "
              f"{np.degrees(frozen.min(axis=0)).round(3)}  true min {np.degrees(true.min(axis=0)).round(3)}  "
              f"goal@tf {np.degrees(end_true[0]).round(2)} start {np.degrees(ends[0]).round(2)}", flush=True)


if __name__ == "__main__":
    main(*map(float, sys.argv[1:]))
