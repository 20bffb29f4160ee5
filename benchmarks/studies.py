"""Study throughput: the same study in this process, on a local process pool and on Dask.

Prints, measured in this one run, the wall time of each backend, its speed-up over the
in-process run, the summed time of the runs themselves (what the backends share out), and
whether every backend stored bit-identical results.

Usage: ``nice -n 10 python benchmarks/studies.py [--workers 2] [--n-gen 60] [--seeds 4]``
"""

from __future__ import annotations

import argparse
import tempfile
import time
from pathlib import Path

import numpy as np


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--workers", type=int, default=2)
    parser.add_argument("--n-gen", type=int, default=60)
    parser.add_argument("--seeds", type=int, default=4)
    args = parser.parse_args()

    from pymoo_rail.experiments import Study, algorithm, load_results, problem, run_study

    study = Study("bench", problems=[problem("zdt1"), problem("zdt2"), problem("zdt3")],
                  algorithms=[algorithm("nsga2", pop_size=40), algorithm("sms-emoa", pop_size=40)],
                  seeds=args.seeds, budget={"n_gen": args.n_gen})
    backends = [("in-process", {"workers": 1}), (f"pool x{args.workers}", {"workers": args.workers}),
                (f"dask LocalCluster x{args.workers}", {"workers": args.workers, "scheduler": "local"})]
    times, frames = {}, {}
    with tempfile.TemporaryDirectory() as tmp:
        for name, kwargs in backends:
            directory = Path(tmp) / name.replace(" ", "_")
            start = time.perf_counter()
            run_study(study, directory, progress=False, **kwargs)
            times[name] = time.perf_counter() - start
            frames[name] = load_results(directory)
    reference = frames["in-process"]
    run_time = reference["wall_time_s"].sum()
    print(f"{len(study.runs())} runs (3 ZDT problems x NSGA-II, SMS-EMOA x {args.seeds} seeds, "
          f"pop 40, {args.n_gen} generations); the runs alone take {run_time:.1f} s in total")
    for name, seconds in times.items():
        same = all(np.array_equal(a, b) for a, b in zip(reference["F"], frames[name]["F"]))
        print(f"  {name:<24} {seconds:7.1f} s   speed-up {times['in-process'] / seconds:4.2f}   "
              f"identical results: {same}")


if __name__ == "__main__":
    main()
