"""Throughput and front cost of the suite's seeded families (``pymoo_rail.suite.list_families()``).

Prints, for each family and ``n_var``, the evaluations per CPU second of ``problem.evaluate`` on
batches of uniform random vectors (one pymoo population: 100), and for each kind of line the CPU
time of the certified front computed from nothing (a fresh cache directory) for the instance at
``n_var = 300`` and at ``n_var = 1000`` (another seed: another line), and of reading it back from the
disk cache. The front is the line's, not the encoding's: every ``n_var`` of an instance shares it.

Usage::

    nice python benchmarks/suite_families.py                      # every family, n_var 10-1000, fronts
    nice python benchmarks/suite_families.py --no-fronts          # throughput only (about a minute)
    nice python benchmarks/suite_families.py --kinds metro --n-vars 10 1000
"""

from __future__ import annotations

import argparse
import os
import tempfile
import time

import numpy as np
import pandas as pd

from pymoo_rail.cases import KINDS
from pymoo_rail.optimal import reference
from pymoo_rail.suite import get_problem, list_families

N_VARS = (10, 30, 100, 300, 1000)
BATCH = 100


def evaluations_per_s(problem, min_cpu_s: float) -> float:
    """Evaluations per CPU second of batches of :data:`BATCH` random vectors (first batch untimed: compilation)."""
    rng = np.random.default_rng(0)
    X = rng.uniform(problem.xl, problem.xu, (BATCH, problem.n_var))
    problem.evaluate(X)
    done, start = 0, time.process_time()
    while time.process_time() - start < min_cpu_s:
        problem.evaluate(X)
        done += BATCH
    return done / (time.process_time() - start)


def throughput_table(families, n_vars, seed: int, min_cpu_s: float) -> pd.DataFrame:
    """One row per family and n_var: evaluations per CPU second."""
    rows = []
    for name in families:
        for n_var in n_vars:
            problem = get_problem(name, n_var=n_var, seed=seed)
            rows.append({"family": name, "n_var": n_var, "evals_per_cpu_s": round(evaluations_per_s(problem, min_cpu_s))})
            print(rows[-1], flush=True)
    return pd.DataFrame(rows)


def front_cpu_s(name: str, n_var: int, seed: int) -> tuple[float, int]:
    """CPU seconds of ``pareto_front()`` of an instance and the number of front nodes."""
    reference.forget_fronts()  # memory off: the disk cache or the solver answers
    problem = get_problem(name, n_var=n_var, seed=seed)
    start = time.process_time()
    problem.pareto_front()
    return time.process_time() - start, len(problem.certified_front().table)


def front_table(kinds, seed: int) -> pd.DataFrame:
    """Per kind: the front of n_var 300 (seed), of n_var 1000 (seed + 1), both cold, then n_var 1000 of seed cached."""
    rows = []
    with tempfile.TemporaryDirectory() as cache:
        os.environ[reference.CACHE_ENV] = cache  # nothing computed before is served
        for kind in kinds:
            name = f"generated-{kind}-bi"
            for n_var, s, what in ((300, seed, "computed"), (1000, seed + 1, "computed"), (1000, seed, "disk cache")):
                line_km = get_problem(name, n_var=10, seed=s).case.line.length_m / 1000
                row = {"family": name, "n_var": n_var, "seed": s, "line_km": round(line_km, 1)}
                try:
                    cpu_s, nodes = front_cpu_s(name, n_var, s)
                    rows.append({**row, "nodes": nodes, "front": what, "cpu_s": round(cpu_s, 2)})
                except RuntimeError as err:  # the exact solver gives up on this line: say so, go on
                    rows.append({**row, "nodes": 0, "front": f"failed: {str(err)[:60]}", "cpu_s": float("nan")})
                print(rows[-1], flush=True)
    return pd.DataFrame(rows)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--kinds", nargs="+", default=list(KINDS), choices=list(KINDS))
    parser.add_argument("--n-vars", nargs="+", type=int, default=list(N_VARS))
    parser.add_argument("--seed", type=int, default=7)
    parser.add_argument("--min-cpu-s", type=float, default=0.5, help="CPU seconds per throughput measurement")
    parser.add_argument("--no-fronts", action="store_true", help="throughput only")
    args = parser.parse_args()
    families = [f for f in list_families() if any(f.startswith(f"generated-{k}-") for k in args.kinds)]
    table = throughput_table(families, args.n_vars, args.seed, args.min_cpu_s)
    print("\nEvaluations per CPU second (batches of 100):")
    print(table.pivot(index="n_var", columns="family", values="evals_per_cpu_s").to_string())
    if not args.no_fronts:
        fronts = front_table(args.kinds, args.seed)
        print("\nCertified front, CPU seconds of the first pareto_front() call:")
        print(fronts.to_string(index=False))


if __name__ == "__main__":
    main()
