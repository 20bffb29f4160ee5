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
    nice python benchmarks/suite_families.py --bounded --n-vars 10 100 1000 --seed 1   # the -3obj gaps
"""

from __future__ import annotations

import argparse

from pymoo_rail.cases import KINDS
from pymoo_rail.experiments.family_cost import N_VARS, bounded_table, front_table, throughput_table
from pymoo_rail.suite import list_families


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--kinds", nargs="+", default=list(KINDS), choices=list(KINDS))
    parser.add_argument("--n-vars", nargs="+", type=int, default=list(N_VARS))
    parser.add_argument("--seed", type=int, default=7)
    parser.add_argument("--min-cpu-s", type=float, default=0.5, help="CPU seconds per throughput measurement")
    parser.add_argument("--no-fronts", action="store_true", help="throughput only")
    parser.add_argument("--bounded", action="store_true", help="only the -3obj families' bounded fronts and gaps")
    args = parser.parse_args()
    if args.bounded:
        print(bounded_table(args.kinds, args.n_vars, args.seed).to_string(index=False))
        return
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
