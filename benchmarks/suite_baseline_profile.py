"""Where a baseline run's CPU goes: kernel, problem, pymoo, history indicators, record, report indicators.

Runs runs of ``benchmarks/suite_baseline.toml`` (seed 1) in this process with one Numba thread
(``--threads``), as each worker of the study's pool runs them, through
``pymoo_rail.experiments.run_cost.cpu_breakdown``, and prints per run the CPU seconds of each part
and per algorithm the shares over all runs printed. A short first run of each algorithm (not
printed) loads the compiled kernels and the fronts and pays one-time compilations (pymoo's
AGE-MOEA compiles its Numba functions in every process).

Usage::

    nice python benchmarks/suite_baseline_profile.py                               # n_var 300 and 1000, every family
    nice python benchmarks/suite_baseline_profile.py --ladder 1000 --families generated-metro-bi --n-eval 2000
"""

from __future__ import annotations

import argparse
from collections import defaultdict
from dataclasses import replace
from pathlib import Path

import numba

from pymoo_rail.experiments import read_study
from pymoo_rail.experiments.baseline import cut_study
from pymoo_rail.experiments.run_cost import PARTS, cpu_breakdown
from pymoo_rail.experiments.spec import Budget

STUDY_FILE = Path(__file__).resolve().parent / "suite_baseline.toml"


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--families", nargs="+", default=None, help="families (default: all of the study)")
    parser.add_argument("--ladder", nargs="+", type=int, default=[300, 1000], help="n_var values (default 300 1000)")
    parser.add_argument("--algorithms", nargs="+", default=None, help="algorithm labels (default: all)")
    parser.add_argument("--n-eval", type=int, default=None, help="evaluations per run (default: the study's)")
    parser.add_argument("--threads", type=int, default=1,
                        help="Numba threads of the kernel (default 1, as each worker of the study's pool)")
    args = parser.parse_args(argv)
    previous = numba.get_num_threads()
    numba.set_num_threads(args.threads)
    try:
        return _profile(args)
    finally:
        numba.set_num_threads(previous)


def _profile(args) -> int:
    study = cut_study(read_study(STUDY_FILE), args.families, args.ladder, 1, args.n_eval)
    runs = [r for r in study.runs() if not args.algorithms or r.algorithm.display in args.algorithms]
    if not runs:
        raise SystemExit(f"--algorithms {args.algorithms}: none of the study's")
    warmed = set()
    for run in runs:  # loads the compiled kernels and the fronts, and compiles pymoo's AGE-MOEA (uncached)
        if run.algorithm.display not in warmed:
            cpu_breakdown(replace(run, budget=Budget("n_eval", 200)))
            warmed.add(run.algorithm.display)
    print(f"{'problem':28s} {'algorithm':11s} " + " ".join(f"{p:>8s}" for p in PARTS) + "    total  ms/eval")
    sums: dict[str, dict[str, float]] = defaultdict(lambda: defaultdict(float))
    for run in runs:
        parts, _ = cpu_breakdown(run)
        print(f"{run.problem.display:28s} {run.algorithm.display:11s} " + " ".join(f"{parts[p]:8.3f}" for p in PARTS)
              + f" {parts['total']:8.2f} {1000 * parts['total'] / parts['n_eval']:8.3f}", flush=True)
        for key, value in parts.items():
            sums[run.algorithm.display][key] += value
    print("\nshare of each part in the CPU of the runs above, per algorithm (%)")
    print(f"{'algorithm':11s} " + " ".join(f"{p:>8s}" for p in PARTS) + "  ms/eval")
    for name, total in sums.items():
        print(f"{name:11s} " + " ".join(f"{100 * total[p] / total['total']:8.1f}" for p in PARTS)
              + f" {1000 * total['total'] / total['n_eval']:8.3f}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
