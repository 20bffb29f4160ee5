"""Done-when check: plain pymoo GA on CooperativeTrainsProblem against the exact uncoordinated baseline.

Runs ``minimize(CooperativeTrainsProblem(load_case("cooperative-pair"), offset_s=x), GA(pop_size=60),
("n_eval", 6000), seed=s)`` for seeds 1..N and prints each result, the median saving against the
exact uncoordinated baseline (each train's exact optimum alone, ``exact_baseline``), and one DE
and one NSGA2 run on the same problem, unchanged.

Usage: ``python benchmarks/cooperative_pair.py [--offset -45] [--seeds 10] [--n-eval 6000]``
"""

from __future__ import annotations

import argparse
import time

import numpy as np
from pymoo.algorithms.moo.nsga2 import NSGA2
from pymoo.algorithms.soo.nonconvex.de import DE
from pymoo.algorithms.soo.nonconvex.ga import GA
from pymoo.optimize import minimize

from pymoo_rail.cases import load_case
from pymoo_rail.problems import CooperativeTrainsProblem
from pymoo_rail.problems.cooperative_baseline import exact_baseline


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--offset", type=float, default=-45.0)
    parser.add_argument("--seeds", type=int, default=10)
    parser.add_argument("--n-eval", type=int, default=6000)
    parser.add_argument("--others", action="store_true", help="also one DE and one NSGA2 run")
    args = parser.parse_args()

    case = load_case("cooperative-pair")
    start = time.process_time()
    base = exact_baseline(case)
    print(f"exact uncoordinated baseline: {' + '.join(f'{e:.3f}' for e in base.energies_kwh)} = "
          f"{base.energy_kwh:.3f} kWh ({time.process_time() - start:.0f} s CPU); shared by chance at "
          f"x = {args.offset:g} s: {base.shared_by_chance_kwh(args.offset):.3f} kWh", flush=True)
    problem = CooperativeTrainsProblem(case, offset_s=args.offset)
    savings = []
    for seed in range(1, args.seeds + 1):
        start = time.process_time()
        res = minimize(problem, GA(pop_size=60), ("n_eval", args.n_eval), seed=seed)
        f = float(res.F[0])
        savings.append(1.0 - f / base.energy_kwh)
        print(f"GA seed {seed}: {f:.3f} kWh, saving {100 * savings[-1]:.2f} % (CV {float(res.CV[0]):.3g}, "
              f"{time.process_time() - start:.0f} s CPU)", flush=True)
    q1, med, q3 = np.percentile(savings, [25, 50, 75])
    print(f"median saving over {args.seeds} seeds: {100 * med:.2f} % (IQR {100 * q1:.2f}-{100 * q3:.2f} %)")
    if args.others:
        for name, algorithm in (("DE", DE(pop_size=60)), ("NSGA2", NSGA2(pop_size=60))):
            res = minimize(problem, algorithm, ("n_eval", args.n_eval), seed=1)
            f = float(np.min(res.F))
            print(f"{name} seed 1: {f:.3f} kWh, saving {100 * (1 - f / base.energy_kwh):.2f} %", flush=True)


if __name__ == "__main__":
    main()
