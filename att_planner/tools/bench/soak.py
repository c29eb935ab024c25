"""Soak: the flight loop's nodes (recorder, simulator, estimator, controller) for a long sim time as fast
as possible: the real-time factor, messages dropped, memory, and where each node's time went: with
``--profile`` its functions under cProfile (wall clock), with ``--cpu`` its CPU by layer."""
from __future__ import annotations

import math
import tempfile

from att_planner.tools.review.run import SETTLING_THRESHOLD
from att_planner.tools.soak import run_soak
from att_sim.models import scenario as scen

RTF_TARGET = 50.0        # a day of the real sky through the nodes at least this many times real time


def configure(parser):
    parser.add_argument("--scenario", default="bruni_celani")
    length = parser.add_mutually_exclusive_group()
    length.add_argument("--orbits", type=float, default=None, help="sim time in orbits (default 10)")
    length.add_argument("--hours", type=float, default=None, help="sim time in hours")
    parser.add_argument("--rate-Hz", type=float, default=None,
                        help="step, state, clock, control and estimate rate (default: the scenario's)")
    how = parser.add_mutually_exclusive_group()
    how.add_argument("--profile", default=None, help="run every node under cProfile, its file in this directory")
    how.add_argument("--cpu", default=None, metavar="DIR",
                     help="time every node's CPU by layer (conversion, publish, executor, models), its file in DIR")
    parser.add_argument("--out", default=None, help="directory for the log (default: a temporary one)")


def _refuse(args) -> str | None:
    """Why the arguments cannot be flown (None when they can): a scenario not shipped or a file that
    is not a valid one, a length or rate that is not a finite number > 0."""
    unreadable = scen.refusal(args.scenario)
    if unreadable:
        return unreadable
    for flag, value in (("--orbits", args.orbits), ("--hours", args.hours), ("--rate-Hz", args.rate_Hz)):
        if value is not None and not (math.isfinite(value) and value > 0.0):
            return f"{flag} must be a finite number > 0, found {value:g}"
    return None


def run(args) -> dict:
    refused = _refuse(args)
    if refused:
        raise SystemExit(f"att-bench soak: {refused}")
    out = args.out or tempfile.mkdtemp(prefix="att_soak_")
    orbits = 10.0 if args.orbits is None and args.hours is None else args.orbits
    r = run_soak(args.scenario, orbits, out, hours=args.hours, rate_Hz=args.rate_Hz, profile_dir=args.profile,
                 cpu_dir=args.cpu)
    r["rtf_target"] = RTF_TARGET
    print(f"soak {r['scenario']} ({', '.join(r['nodes'])}; {r['rate_Hz']:g} Hz): {r['hours']:.3g} h = "
          f"{r['orbits']:.3g} orbits = {r['sim_time']:.0f} s of sim time in {r['loop_wall_seconds']:.1f} s wall "
          f"-> real-time factor {r['real_time_factor']:.1f}")
    print(f"  state messages recorded {r['state_messages']} / expected {r['state_expected']} "
          f"(dropped {r['dropped_state']}); commands {r['command_messages']}; "
          f"lockstep suspended {r['lockstep_suspensions']} times")
    for name, m in r["memory"].items():
        cpu = r["cpu_seconds"][name]
        print(f"  {name:10s} RSS {m['start_mib']:7.1f} -> {m['end_mib']:7.1f} MiB, "
              f"CPU {cpu:6.1f} s ({cpu / r['sim_time'] * 1e3:.2f} ms per s of sim)")
    settling = "not within the run" if r["settling_orbits"] is None else f"{r['settling_orbits']:.3f} orbits"
    print(f"  magnetorquer settling (|q_i| <= {SETTLING_THRESHOLD}): {settling}; exit codes {r['exit_codes']}")
    for name, prof in r.get("profile", {}).items():
        if prof:
            print(f"  profile {name} ({prof['total_s']:.1f} s own time in all):")
            for row in prof["functions"][:8]:
                print(f"    {row['own_s']:7.2f} s own {row['cumulative_s']:7.2f} s cum {row['calls']:8d} calls  "
                      f"{row['function']}")
    for name, cpu in r.get("cpu_layers", {}).items():
        if cpu:
            print(f"  CPU {name}: {cpu['process_ms_per_sim_s']:.2f} ms per s of sim (main thread "
                  f"{cpu['main_thread_ms_per_sim_s']:.2f}, other threads {cpu['other_threads_ms_per_sim_s']:.2f})")
            for layer, row in cpu["layers"].items():
                print(f"    {layer:20s} {row['ms_per_sim_s']:6.2f} ms  {row['calls_per_sim_s']:6.1f} calls "
                      f"per s of sim")
            print(f"    {'other (main thread)':20s} {cpu['other_main_thread_ms_per_sim_s']:6.2f} ms")
    print(f"  log: {out}/soak.mcap")
    return r
