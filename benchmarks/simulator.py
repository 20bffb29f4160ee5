"""Simulator throughput: the batched Numba kernel against the same code without JIT.

Prints, measured in this one run:
- evaluations per second for a population of 200 speed-code programs on ``yizhuang``;
- the same with ``NUMBA_DISABLE_JIT=1`` (a subprocess running this file in ``--worker`` mode);
- both ratios: wall clock, and CPU time per evaluation (summed over threads), which other load
  on the machine does not distort;
- the one-time JIT cost with an empty on-disk cache and with a warm one.

Usage: ``python benchmarks/simulator.py [--pop 200] [--repeats 20]``
"""

from __future__ import annotations

import argparse
import json
import os
import subprocess
import sys
import tempfile
import time

import numpy as np

from pymoo_rail.constants import KMH_PER_MS


def _programs(case, pop: int, seed: int = 0) -> np.ndarray:
    from pymoo_rail.sim import gradient_limit_partition, speed_code_programs

    bounds = gradient_limit_partition(case.line)
    rng = np.random.default_rng(seed)
    return speed_code_programs(bounds, rng.uniform(30 / KMH_PER_MS, 80 / KMH_PER_MS, size=(pop, bounds.shape[0] - 1)))


def worker(pop: int, repeats: int) -> dict:
    """Time the batch kernel in this process (JIT state decided by the environment)."""
    t0 = time.perf_counter()
    from pymoo_rail.cases import load_case
    from pymoo_rail.sim import Simulator

    case = load_case("yizhuang")
    sim = Simulator(case)
    programs = _programs(case, pop)
    sim.run_batch(programs[:2])  # compile or load from cache
    first_call_s = time.perf_counter() - t0
    t1, c1 = time.perf_counter(), time.process_time()
    for _ in range(repeats):
        sim.run_batch(programs)
    elapsed, cpu = time.perf_counter() - t1, time.process_time() - c1
    return {"evals_per_s": pop * repeats / elapsed, "cpu_us_per_eval": 1e6 * cpu / (pop * repeats),
            "first_call_s": first_call_s}


def _subprocess(args: list[str], env_extra: dict) -> dict:
    env = dict(os.environ, **env_extra)
    out = subprocess.run([sys.executable, __file__, "--worker", *args], env=env, check=True,
                         capture_output=True, text=True)
    return json.loads(out.stdout.strip().splitlines()[-1])


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--pop", type=int, default=200)
    parser.add_argument("--repeats", type=int, default=20)
    parser.add_argument("--worker", action="store_true", help=argparse.SUPPRESS)
    args = parser.parse_args()
    if args.worker:
        print(json.dumps(worker(args.pop, args.repeats)))
        return
    with tempfile.TemporaryDirectory() as cache:
        cold = _subprocess(["--pop", str(args.pop), "--repeats", str(args.repeats)], {"NUMBA_CACHE_DIR": cache})
        warm = _subprocess(["--pop", str(args.pop), "--repeats", str(args.repeats)], {"NUMBA_CACHE_DIR": cache})
    # pure Python is slow: one repeat of the same population is enough for a stable rate
    nojit = _subprocess(["--pop", str(args.pop), "--repeats", "1"], {"NUMBA_DISABLE_JIT": "1"})
    cores = os.cpu_count()
    print(f"yizhuang, population {args.pop}, {cores} cores")
    print(f"  Numba batch kernel      : {warm['evals_per_s']:12.1f} evaluations/s")
    print(f"  same code, no JIT       : {nojit['evals_per_s']:12.1f} evaluations/s")
    print(f"  speed-up, wall clock    : {warm['evals_per_s'] / nojit['evals_per_s']:12.1f} x")
    print(f"  CPU time per evaluation : {warm['cpu_us_per_eval']:12.1f} us JIT (all threads), "
          f"{nojit['cpu_us_per_eval']:.1f} us no JIT")
    print(f"  speed-up, CPU time      : {nojit['cpu_us_per_eval'] / warm['cpu_us_per_eval']:12.1f} x"
          "  (independent of other load on the machine)")
    load = os.getloadavg()[0]
    if load > 0.5 * (cores or 1):
        print(f"  note: load average {load:.1f} on {cores} cores while measuring; wall-clock rates are low")
    print(f"  first call, empty cache : {cold['first_call_s']:12.2f} s  (JIT compilation)")
    print(f"  first call, warm cache  : {warm['first_call_s']:12.2f} s  (cache=True)")


if __name__ == "__main__":
    main()
