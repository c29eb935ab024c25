"""``att-tune``: find magnetorquer PD gains and write them into the controller's config YAML.

    att-tune --mode robust --budget 600 --out config/controller_gains.yaml
    att-tune --mode fixed --ic 0,0,0,0.02,0.02,-0.03,0.332
    att-tune --mode robust --scheduler tcp://scheduler-host:8786      # evaluate on a Dask cluster

Writes ``controller.ros__parameters.{kp, kd, m_max_Am2}`` (other keys of an existing file are kept),
the file the controller node loads. A progress bar with the elapsed time, ETA and the best
settling time so far is drawn on stderr.
"""
from __future__ import annotations

import argparse
import os
import sys
import time
from dataclasses import replace

import numpy as np
import yaml

from att_planner import tuning as gt
from att_planner.reference.bruni_celani import PUBLISHED_ICS, robust_seeds


class ProgressBar:
    """One-line text bar on a stream: fraction done, elapsed, ETA, a status text."""

    def __init__(self, stream=sys.stderr, width: int = 30):
        self.stream, self.width = stream, width
        self.start = time.monotonic()

    def line(self, fraction: float, text: str) -> str:
        fraction = min(max(fraction, 0.0), 1.0)
        elapsed = time.monotonic() - self.start
        eta = elapsed * (1.0 - fraction) / fraction if fraction > 0 else float("nan")
        filled = int(round(self.width * fraction))
        eta_s = "--" if not np.isfinite(eta) else f"{eta:5.0f}s"
        bar = f"[{'#' * filled}{'-' * (self.width - filled)}]"
        return f"{bar} {100 * fraction:3.0f}% {elapsed:5.0f}s ETA {eta_s} {text}"

    def update(self, fraction: float, text: str = ""):
        self.stream.write("\r" + self.line(fraction, text))
        self.stream.flush()

    def close(self):
        self.stream.write("\n")
        self.stream.flush()


def write_gains(path: str, kp: float, kd: float, m_max: float, node: str = "controller",
                comment: str = "") -> dict:
    """Set ``<node>.ros__parameters.{kp, kd, m_max_Am2}`` in the YAML at ``path`` (created if missing);
    ``comment`` lines head the file (YAML comments of an existing file are not kept); a key of the
    old name ``m_max`` is replaced."""
    doc = {}
    if os.path.exists(path):
        with open(path) as fh:
            doc = yaml.safe_load(fh) or {}
    params = doc.setdefault(node, {}).setdefault("ros__parameters", {})
    params.pop("m_max", None)                   # the old name of m_max_Am2, refused beside it
    params.update({"kp": float(kp), "kd": float(kd), "m_max_Am2": float(m_max)})
    os.makedirs(os.path.dirname(os.path.abspath(path)), exist_ok=True)
    with open(path, "w") as fh:
        fh.writelines(f"# {line}\n" for line in comment.splitlines())
        yaml.safe_dump(doc, fh, sort_keys=False)
    return doc


def parse_ic(text: str) -> np.ndarray:
    values = np.array([float(v) for v in text.split(",")])
    if values.size != len(gt.H_NAMES):
        raise argparse.ArgumentTypeError(f"--ic needs {len(gt.H_NAMES)} values {','.join(gt.H_NAMES)}")
    return values


def add_tuning_options(parser: argparse.ArgumentParser):
    """Options shared by ``att-tune`` and ``att-bench gains``."""
    parser.add_argument("--mode", choices=("fixed", "robust"), default="robust")
    parser.add_argument("--inner", choices=gt.INNER_METHODS, default="sdbox-multistart",
                        help="inner worst-case search of the robust mode")
    parser.add_argument("--budget", type=float, default=None,
                        help="wall-clock budget in seconds (default: 50 fixed, 560 robust: the last batch "
                             "started before the deadline still has to finish)")
    parser.add_argument("--ic", type=parse_ic, default=PUBLISHED_ICS["ic20"],
                        help="fixed mode: rho,phi,theta,w1,w2,w3,psi (default: the paper's IC (20))")
    parser.add_argument("--dt", type=float, default=gt.SimSettings.dt, help="integration step of the search (s)")
    parser.add_argument("--cap", type=float, default=None, help="settling-time cap of the search (orbits)")
    parser.add_argument("--margin", type=float, default=0.02,
                        help="the search settles to ν(1 − margin): its optimum then keeps a margin against "
                             "peaks that touch ν, which step-size changes would flip")
    parser.add_argument("--workers", type=int, default=2, help="local worker processes (1: in process)")
    parser.add_argument("--scheduler", default=None, help="Dask scheduler address: evaluate on that cluster")


def run_tuning(args, progress_bar: ProgressBar | None = None) -> gt.TuningResult:
    """Run the tuning the options ask for, drawing progress on ``progress_bar``."""
    budget = args.budget if args.budget is not None else (50.0 if args.mode == "fixed" else 560.0)
    cap = args.cap if args.cap is not None else (6.0 if args.mode == "fixed" else 10.0)
    settings = gt.SimSettings(dt=args.dt, cap_orbits=cap)
    executor = gt.make_executor(args.workers, args.scheduler)
    case = gt.MagnetorquerCase()
    evaluator = gt.BatchEvaluator(replace(case, nu=case.nu * (1.0 - args.margin)), settings, executor, min_chunk=48)
    start = time.monotonic()
    deadline = start + budget
    best = [np.inf]

    def on_batch(ev: gt.BatchEvaluator, result: gt.SettlingResult):
        if progress_bar is not None:
            best_text = f"{best[0]:.3f} orbits" if np.isfinite(best[0]) else "—"
            progress_bar.update((time.monotonic() - start) / budget,
                                f"evals {ev.evaluations:6d}  best t_s {best_text}")

    evaluator.on_batch = on_batch
    try:
        if args.mode == "fixed":
            def progress(_fraction, value):
                best[0] = value
            res = gt.tune_fixed(args.ic, evaluator, maxfun=100000, deadline=deadline, progress=progress)
        else:
            def progress(_cycle, value, _certified):
                best[0] = value
            res = gt.tune_robust(evaluator, seeds=robust_seeds(), inner=args.inner, deadline=deadline,
                                 inner_reserve=0.15 * budget, progress=progress)
    finally:
        executor.close()
    if progress_bar is not None:
        progress_bar.update(1.0, f"evals {res.nfev:6d}  t_s {res.ts:.3f} orbits  ({res.status})")
        progress_bar.close()
    return res


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(prog="att-tune", description=__doc__.splitlines()[0])
    add_tuning_options(parser)
    parser.add_argument("--out", default="config/controller_gains.yaml", help="controller config YAML to update")
    parser.add_argument("--no-progress", action="store_true")
    args = parser.parse_args(argv)
    res = run_tuning(args, None if args.no_progress else ProgressBar())
    write_gains(args.out, res.kp, res.kd, gt.MagnetorquerCase().m_max,
                comment=f"att-tune --mode {res.mode}: t_s = {res.ts:.4f} orbits ({res.status}), "
                        f"{res.nfev} simulations in {res.wall_time:.0f} s")
    print(f"{res.mode}: kp = {res.kp:.6g}, kd = {res.kd:.6g}, t_s = {res.ts:.4f} orbits "
          f"({res.nfev} simulations, {res.wall_time:.1f} s, {res.status}); wrote {args.out}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
