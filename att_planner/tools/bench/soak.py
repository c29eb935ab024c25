"""Soak: simulator + controller + recorder for N orbits as fast as possible."""
from __future__ import annotations

import tempfile

from att_planner.tools.review.run import SETTLING_THRESHOLD
from att_planner.tools.soak import run_soak


def configure(parser):
    parser.add_argument("--scenario", default="bruni_celani")
    parser.add_argument("--orbits", type=float, default=10.0)
    parser.add_argument("--out", default=None, help="directory for the log (default: a temporary one)")


def run(args) -> dict:
    out = args.out or tempfile.mkdtemp(prefix="att_soak_")
    r = run_soak(args.scenario, args.orbits, out)
    print(f"soak {r['scenario']}: {r['orbits']:g} orbits = {r['sim_time']:.0f} s of sim time in "
          f"{r['wall_seconds']:.1f} s wall -> real-time factor {r['real_time_factor']:.0f}")
    print(f"  state messages recorded {r['state_messages']} / expected {r['state_expected']} "
          f"(dropped {r['dropped_state']}); commands {r['command_messages']}; "
          f"lockstep suspended {r['lockstep_suspensions']} times")
    for name, m in r["memory"].items():
        print(f"  {name:10s} RSS {m['start_mib']:7.1f} -> {m['end_mib']:7.1f} MiB")
    settling = "not within the run" if r["settling_orbits"] is None else f"{r['settling_orbits']:.3f} orbits"
    print(f"  magnetorquer settling (|q_i| <= {SETTLING_THRESHOLD}): {settling}; exit codes {r['exit_codes']}")
    print(f"  log: {out}/soak.mcap")
    return r
