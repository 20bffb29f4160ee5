"""CPU time of one backward sweep and one forward run of the exact solver, with and without the singular
speeds, on a comparable generated line of ``peers.py --generated`` at the price of its optimum
(``pymoo_rail.experiments.peers.sweep_cpu``).

    python benchmarks/dp_sweep.py [--seed 21] [--factor 1.5] [--repeats 5]
"""

import argparse

from pymoo_rail.experiments.peers import sweep_cpu

if __name__ == "__main__":
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--seed", type=int, default=21)
    parser.add_argument("--factor", type=float, default=1.5, help="running time, x the minimum")
    parser.add_argument("--repeats", type=int, default=5)
    args = parser.parse_args()
    print("\n".join(sweep_cpu(args.seed, args.factor, args.repeats)))
