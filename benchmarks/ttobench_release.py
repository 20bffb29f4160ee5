"""Every track of the TTOBench release x its suitable train: minimum time, optimum at 1.15 x, NSGA2.

Usage: python benchmarks/ttobench_release.py [TTOBENCH_ROOT] [--nsga2-gen N] [--only ID ...] [--report PATH]
Prints one row per track (first stop -> last stop): length, minimum running time, the exact
optimum's energy at 1.15 x that time, whether that run holds every limit and stops at the platform
(limit excess <= 1e-6 m/s, stop error <= 0.25 m, final speed 0), NSGA2's best feasible energy
(pop 40, N generations, seed 1, objectives energy and time error) among members within 2 s of the
planned time, the gap, the size of NSGA2's front, and the CPU seconds of each step. ``--report``
also writes the table, with the total CPU time, to a markdown file.
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
LIMIT_TOL_MS = 1e-6  # the problem's own limit tolerance
STOP_TOL_M = 0.25  # the problem's default stop tolerance
DEFAULT_ROOT = Path(__file__).resolve().parents[1] / "tests" / "data" / "ttobench"


def main() -> None:
    parser = argparse.ArgumentParser()
    parser.add_argument("root", nargs="?", default=DEFAULT_ROOT)
    parser.add_argument("--nsga2-gen", type=int, default=60)
    parser.add_argument("--only", nargs="*")
    parser.add_argument("--max-section-m", type=float, default=None,
                        help="speed-code sections no longer than this (default: the encoding's default)")
    parser.add_argument("--pop-size", type=int, default=40)
    parser.add_argument("--report", type=Path, default=None, help="also write the table to this markdown file")
    args = parser.parse_args()
    lines = ["| track | train | km | T_min s | optimum kWh @1.15 | limits, stop | CPU s | NSGA2 kWh | gap % "
             "| front size | n_var | CPU s |",
             "|---|---|---|---|---|---|---|---|---|---|---|---|"]
    print("\n".join(lines), flush=True)
    cpu0 = time.process_time()
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
        s = best.summary
        held = (s["limit_excess_ms"] <= LIMIT_TOL_MS and s["stop_error_m"] <= STOP_TOL_M
                and s["final_speed_ms"] == 0.0 and bool(s["reached"]))
        t1 = time.process_time()
        settings = {} if args.max_section_m is None else {"max_section_m": args.max_section_m}
        problem = SpeedProfileProblem(case, objectives=("energy", "time_error"), **settings)
        res = minimize(problem, NSGA2(pop_size=args.pop_size), ("n_gen", args.nsga2_gen), seed=1)
        t2 = time.process_time()
        F = np.atleast_2d(res.F) if res.F is not None else np.empty((0, 2))
        close = F[F[:, 1] <= TIME_TOL_S]
        nsga = float(close[:, 0].min()) if close.size else float("nan")
        gap = 100.0 * (nsga / best.energy.net_kwh - 1.0)
        row = (f"| {track.stem} | {train.stem} | {case.line.length_m / 1000:.1f} | {t_min:.1f} | "
               f"{best.energy.net_kwh:.2f} | {'held' if held else 'VIOLATED'} | {t1 - t0:.1f} | {nsga:.2f} | "
               f"{gap:.1f} | {F.shape[0]} | {problem.n_var} | {t2 - t1:.1f} |")
        print(row, flush=True)
        lines.append(row)
    total = f"Total CPU: {time.process_time() - cpu0:.0f} s (NSGA2 pop {args.pop_size}, {args.nsga2_gen} generations, seed 1)."
    print(total)
    if args.report is not None:
        args.report.write_text("# Every TTOBench track with its train\n\nWritten by `python benchmarks/ttobench_release.py"
                               f" --nsga2-gen {args.nsga2_gen} --report {args.report.as_posix()}`.\n\n"
                               + "\n".join(lines) + f"\n\n{total}\n")


if __name__ == "__main__":
    main()
