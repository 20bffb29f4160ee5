"""Study throughput: the same study in this process, on a local process pool and on Dask.

Prints, measured in this one run, the wall time of each backend, its speed-up over the
in-process run, the summed time of the runs themselves (what the backends share out), and
whether every backend stored bit-identical results.

Usage: ``nice -n 10 python benchmarks/studies.py [--workers 2] [--n-gen 60] [--seeds 4]``
"""

from __future__ import annotations

import argparse

from pymoo_rail.experiments import Study, algorithm, problem
from pymoo_rail.experiments.scaling import backend_timings


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--workers", type=int, default=2)
    parser.add_argument("--n-gen", type=int, default=60)
    parser.add_argument("--seeds", type=int, default=4)
    args = parser.parse_args()
    study = Study("bench", problems=[problem("zdt1"), problem("zdt2"), problem("zdt3")],
                  algorithms=[algorithm("nsga2", pop_size=40), algorithm("sms-emoa", pop_size=40)],
                  seeds=args.seeds, budget={"n_gen": args.n_gen})
    table, run_time = backend_timings(study, {
        "in-process": {"workers": 1}, f"pool x{args.workers}": {"workers": args.workers},
        f"dask LocalCluster x{args.workers}": {"workers": args.workers, "scheduler": "local"}})
    print(f"{len(study.runs())} runs (3 ZDT problems x NSGA-II, SMS-EMOA x {args.seeds} seeds, "
          f"pop 40, {args.n_gen} generations); the runs alone take {run_time:.1f} s in total")
    for r in table.itertuples():
        print(f"  {r.backend:<24} {r.wall_s:7.1f} s   speed-up {r.speed_up:4.2f}   identical results: {r.identical}")


if __name__ == "__main__":
    main()
