"""Every track of the TTOBench release x its suitable train: minimum time, optimum at 1.15 x, NSGA2.

Usage: python benchmarks/ttobench_release.py [TTOBENCH_ROOT] [--nsga2-gen N] [--only ID ...]
Prints one row per track (first stop -> last stop): length, minimum running time, the exact
optimum's energy at 1.15 x that time, NSGA2's best feasible energy
(pop 40, N generations, seed 1) among members within 2 s of the planned time, the gap, and the CPU seconds of each step.
"""

from __future__ import annotations

import argparse
import time
import warnings
from pathlib import Path

import numpy as np
from pymoo.algorithms.moo.nsga2 import NSGA2
from pymoo.optimize import minimize

from pymoo_rail.cases.ttobench import TTOBenchWarning, from_ttobench
from pymoo_rail.cases.ttobench_release import release_pairs
from pymoo_rail.optimal import min_running_time, optimal_profile
from pymoo_rail.problems import SpeedProfileProblem

TIME_TOL_S = 2.0  # NSGA2 members this close to the planned time count as punctual
DEFAULT_ROOT = Path(__file__).resolve().parents[1] / "tests" / "data" / "ttobench"


def main() -> None:
    parser = argparse.ArgumentParser()
    parser.add_argument("root", nargs="?", default=DEFAULT_ROOT)
    parser.add_argument("--nsga2-gen", type=int, default=60)
    parser.add_argument("--only", nargs="*")
    parser.add_argument("--max-section-m", type=float, default=None,
                        help="speed-code sections no longer than this (default: the encoding's default)")
    parser.add_argument("--pop-size", type=int, default=40)
    args = parser.parse_args()
    print("| track | train | km | T_min s | optimum kWh @1.15 | CPU s | NSGA2 kWh | gap % | n_var | CPU s |")
    print("|---|---|---|---|---|---|---|---|---|---|")
    for track, train in release_pairs(args.root):
        if args.only and track.stem not in args.only:
            continue
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", TTOBenchWarning)
            case = from_ttobench(track, train, 0, -1, 1.0)
        t0 = time.process_time()
        t_min = min_running_time(case)
        case = case.with_planned_time(1.15 * t_min)
        best = optimal_profile(case, case.planned_time_s)
        t1 = time.process_time()
        settings = {} if args.max_section_m is None else {"max_section_m": args.max_section_m}
        problem = SpeedProfileProblem(case, objectives=("energy", "time_error"), **settings)
        res = minimize(problem, NSGA2(pop_size=args.pop_size), ("n_gen", args.nsga2_gen), seed=1)
        t2 = time.process_time()
        F = res.F if res.F is not None else np.empty((0, 2))
        close = F[F[:, 1] <= TIME_TOL_S]
        nsga = float(close[:, 0].min()) if close.size else float("nan")
        gap = 100.0 * (nsga / best.energy.net_kwh - 1.0)
        print(f"| {track.stem} | {train.stem} | {case.line.length_m / 1000:.1f} | {t_min:.1f} | "
              f"{best.energy.net_kwh:.2f} | {t1 - t0:.1f} | {nsga:.2f} | {gap:.1f} | {problem.n_var} | {t2 - t1:.1f} |",
              flush=True)


if __name__ == "__main__":
    main()
