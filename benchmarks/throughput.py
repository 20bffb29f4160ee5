"""Throughput of the simulator and of MOABC, and how close the kernel is to the hardware.

Prints, measured in this one run:

1. the kernel on one core (``simulate_batch_serial``, CPU time per cell) for each built-in case,
   against the latency bound of docs/performance.md: the dependency chain of one cell (two square
   roots, two force-curve evaluations, two resistance evaluations and the two integration
   updates), timed on this CPU by a loop that runs exactly that chain;
2. evaluations and cells per second of ``Simulator.run_batch`` per case and population size;
3. thread scaling: wall time of the same batch on 1 and on 2 Numba threads (both through the
   parallel kernel), and the serial kernel against the parallel one for small batches, which
   is where ``PARALLEL_MIN_CELLS`` comes from;
4. MOABC, 40 bees x 100 cycles on ``yizhuang`` (energy, time error), warm (second run), with
   1 thread and with all threads: CPU and wall time;
5. the done-when lines: <= 20 ns per cell per core, >= 1.7x on 2 threads at population >= 200,
   MOABC <= 0.3 s.

``--jit`` measures instead the batch kernel (yizhuang, 200 speed-code programs) against the same
code without JIT (``NUMBA_DISABLE_JIT=1``), and the first call with an empty and a warm Numba cache,
each in a child process of this script.

Wall-clock ratios are only meaningful on a quiet machine: the script prints the load average
next to them. CPU time per cell is not distorted by other load (as long as the core is not
shared with a sibling thread). Every timing is the minimum over ``--repeats`` rounds.

Usage: ``python benchmarks/throughput.py [--repeats 5] [--quick]``, ``python benchmarks/throughput.py --jit``
"""

from __future__ import annotations

import argparse
import json
import math
import os
import subprocess
import sys
import tempfile
import time

import numba
import numpy as np
import pandas as pd
from numba import njit

from pymoo_rail.cases import load_case
from pymoo_rail.experiments.report import markdown
from pymoo_rail.problems import SpeedProfileProblem
from pymoo_rail.sim import kernel as k
from pymoo_rail.sim.simulator import PARALLEL_MIN_CELLS

CASES = ("yizhuang", "metro-a", "wuguang-crh3", "yizhuang-ttobench")
POPULATIONS = (10, 20, 50, 200, 1000)


@njit(cache=True)
def cell_chain(n, v0, c0, c1, c2, c3, a, b, c, gain):
    """``n`` cells' worth of the kernel's dependency chain, nothing else (the latency bound).

    Per cell: traction polynomial and Davis resistance at v, first-stage u, square root, the
    polynomial and resistance again at the mid speed, second-stage u, square root.
    """
    v = v0
    for _ in range(n):
        f = c0 + c1 * v + c2 * v * v + c3 * v * v * v
        u_half = v * v + (f - (a + (b + c * v) * v)) * gain
        v_half = math.sqrt(u_half)
        f = c0 + c1 * v_half + c2 * v_half * v_half + c3 * v_half * v_half * v_half
        u1 = v * v + 2.0 * (f - (a + (b + c * v_half) * v_half)) * gain
        v = math.sqrt(u1) * 1e-3 + v0  # keep v in range; the dependency is what counts
    return v


def chain_ns_per_cell(repeats: int) -> float:
    """Latency of one cell's dependency chain on this CPU (ns), minimum over ``repeats``."""
    args = (10.0, 2.0e5, -1.0e3, 10.0, -0.05, 2.0e3, 60.0, 6.0, 1.0 / 2.0e5)
    cell_chain(10, *args)
    n = 2_000_000
    best = math.inf
    for _ in range(repeats):
        t0 = time.process_time()
        cell_chain(n, *args)
        best = min(best, time.process_time() - t0)
    return 1e9 * best / n


def _programs(problem: SpeedProfileProblem, pop: int) -> np.ndarray:
    rng = np.random.default_rng(0)
    X = problem.xl + rng.random((pop, problem.n_var)) * (problem.xu - problem.xl)
    return np.ascontiguousarray(problem.encoding.programs(X))


def _cells(summaries: np.ndarray, dx_m: float) -> float:
    """Cells simulated: a run that stops short ends in the cell where it stops."""
    return float(np.ceil(summaries[:, k.OUT_STOP_POSITION_M] / dx_m - 1e-9).sum())


def _best(fn, repeats: int, clock=time.perf_counter) -> float:
    best = math.inf
    for _ in range(repeats):
        t0 = clock()
        fn()
        best = min(best, clock() - t0)
    return best


def kernel_rows(repeats: int, quick: bool) -> list[dict]:
    """CPU time per cell on one core, per case (population 200)."""
    rows = []
    numba.set_num_threads(1)
    for name in CASES[:1] if quick else CASES:
        problem = SpeedProfileProblem(load_case(name))
        model = problem.simulator.model
        programs = _programs(problem, 200)
        out = k.simulate_batch_serial(model, programs)
        cells = _cells(out, model.dx_m)
        cpu = _best(lambda: k.simulate_batch_serial(model, programs), repeats, time.process_time)
        rows.append({"case": name, "cells_per_run": cells / len(programs), "ns_per_cell": 1e9 * cpu / cells})
    numba.set_num_threads(numba.config.NUMBA_NUM_THREADS)
    return rows


def rate_rows(repeats: int, quick: bool) -> list[dict]:
    """Evaluations and cells per second of run_batch (all threads) per case and population."""
    rows = []
    for name in CASES[:1] if quick else CASES:
        problem = SpeedProfileProblem(load_case(name))
        sim = problem.simulator
        for pop in POPULATIONS:
            programs = _programs(problem, pop)
            cells = _cells(sim.run_batch(programs), sim.model.dx_m)
            wall = _best(lambda: sim.run_batch(programs), repeats)
            rows.append({"case": name, "pop": pop, "evals_per_s": pop / wall, "cells_per_s": cells / wall})
    return rows


def scaling_rows(repeats: int) -> list[dict]:
    """Wall time on 1 and 2 threads (parallel kernel), and serial vs parallel (yizhuang)."""
    problem = SpeedProfileProblem(load_case("yizhuang"))
    model = problem.simulator.model
    rows = []
    threads = min(2, numba.config.NUMBA_NUM_THREADS)
    for pop in POPULATIONS:
        programs = _programs(problem, pop)
        times = {}
        for _ in range(repeats):  # interleaved, so that a burst of load hits every variant
            for label, n_threads, fn in (("serial", 1, k.simulate_batch_serial), ("t1", 1, k.simulate_batch),
                                         ("t2", threads, k.simulate_batch)):
                numba.set_num_threads(n_threads)
                fn(model, programs)
                t0 = time.perf_counter()
                fn(model, programs)
                times[label] = min(times.get(label, math.inf), time.perf_counter() - t0)
        cpu = {}
        for label, n_threads in (("cpu1", 1), ("cpu2", threads)):
            numba.set_num_threads(n_threads)
            cpu[label] = _best(lambda: k.simulate_batch(model, programs), repeats, time.process_time)
        numba.set_num_threads(numba.config.NUMBA_NUM_THREADS)
        rows.append({"pop": pop, "cells": pop * (model.position_m.shape[0] - 1), **times, **cpu,
                     "balance": _static_balance(k.simulate_batch_serial(model, programs), model.dx_m, threads)})
    return rows


def _static_balance(summaries: np.ndarray, dx_m: float, threads: int) -> float:
    """Best speed-up the batch allows on ``threads`` threads with Numba's static schedule.

    ``prange`` hands each thread one contiguous block of the pairs of runs; a pair costs the
    cells of its longer run. The ratio total / largest block is the speed-up of a machine with
    nothing else to do.
    """
    cells = np.ceil(summaries[:, k.OUT_STOP_POSITION_M] / dx_m - 1e-9)
    if len(cells) % 2:
        cells = np.append(cells, 0.0)
    pair_cells = cells.reshape(-1, 2).max(axis=1)
    blocks = np.array_split(pair_cells, threads)
    return float(pair_cells.sum() / max(block.sum() for block in blocks))


def moabc_row(threads: int) -> dict:
    """A warm MOABC run, 40 bees x 100 cycles on yizhuang."""
    from pymoo.optimize import minimize

    from pymoo_rail.algorithms import MOABC

    numba.set_num_threads(threads)
    problem = SpeedProfileProblem(load_case("yizhuang"), objectives=("energy", "time_error"))
    minimize(problem, MOABC(pop_size=40), ("n_gen", 1 + 2 * 100), seed=1)  # warm: compiled, caches filled
    t0, c0 = time.perf_counter(), time.process_time()
    res = minimize(problem, MOABC(pop_size=40), ("n_gen", 1 + 2 * 100), seed=1)
    row = {"threads": threads, "wall_s": time.perf_counter() - t0, "cpu_s": time.process_time() - c0,
           "n_eval": res.algorithm.evaluator.n_eval}
    numba.set_num_threads(numba.config.NUMBA_NUM_THREADS)
    return row


def jit_worker(repeats: int) -> dict:
    """Time ``run_batch`` in this process (JIT state from the environment): rate, CPU per run, first call."""
    t0 = time.perf_counter()
    problem = SpeedProfileProblem(load_case("yizhuang"))
    sim, programs = problem.simulator, _programs(problem, 200)
    sim.run_batch(programs[:2])  # compile or load from cache
    first_call_s = time.perf_counter() - t0
    t1, c1 = time.perf_counter(), time.process_time()
    for _ in range(repeats):
        sim.run_batch(programs)
    return {"evals_per_s": 200 * repeats / (time.perf_counter() - t1),
            "cpu_us_per_eval": 1e6 * (time.process_time() - c1) / (200 * repeats), "first_call_s": first_call_s}


def jit_rows(repeats: int) -> list[str]:
    """The kernel with an empty and a warm cache, and without JIT (one repeat: pure Python is slow)."""
    def child(n: int, **env) -> dict:
        out = subprocess.run([sys.executable, __file__, "--jit-worker", "--repeats", str(n)], env=dict(os.environ, **env),
                             check=True, capture_output=True, text=True)
        return json.loads(out.stdout.strip().splitlines()[-1])

    with tempfile.TemporaryDirectory() as cache:
        cold, warm = child(repeats, NUMBA_CACHE_DIR=cache), child(repeats, NUMBA_CACHE_DIR=cache)
    nojit = child(1, NUMBA_DISABLE_JIT="1")
    return [f"yizhuang, population 200: {warm['evals_per_s']:.1f} evaluations/s JIT, {nojit['evals_per_s']:.1f} without",
            f"speed-up: wall clock {warm['evals_per_s'] / nojit['evals_per_s']:.1f}x, CPU time per evaluation "
            f"{nojit['cpu_us_per_eval'] / warm['cpu_us_per_eval']:.1f}x ({warm['cpu_us_per_eval']:.1f} us JIT, all "
            f"threads; {nojit['cpu_us_per_eval']:.1f} us without)",
            f"first call: {cold['first_call_s']:.2f} s with an empty cache (compilation), {warm['first_call_s']:.2f} s "
            "warm (cache=True)"]


def print_kernel_and_rates(repeats: int, quick: bool) -> float:
    """Sections 1 and 2; returns the yizhuang ns per cell."""
    bound = chain_ns_per_cell(repeats)
    kernel = pd.DataFrame(kernel_rows(repeats, quick))
    kernel["/ bound"] = kernel["ns_per_cell"] / bound
    print(f"\n1. Kernel on one core (CPU time, population 200); latency bound: one cell's dependency chain takes "
          f"{bound:.1f} ns on this CPU\n" + markdown(kernel, 2))
    rates = pd.DataFrame(rate_rows(repeats, quick))
    rates["Mcells_per_s"] = rates.pop("cells_per_s") / 1e6
    print("\n2. Simulator.run_batch, all threads (wall clock)\n" + markdown(rates, 1))
    return float(kernel["ns_per_cell"].iloc[0])


def print_scaling(repeats: int) -> pd.DataFrame:
    """Section 3: 1 against 2 threads, serial against parallel, and the speed-up a quiet machine would show."""
    scaling = pd.DataFrame(scaling_rows(repeats))
    scaling["wall 1/2"] = scaling["t1"] / scaling["t2"]
    scaling["cpu 2/1"] = scaling["cpu2"] / scaling["cpu1"]
    scaling["expected"] = scaling["balance"] * scaling["cpu1"] / scaling["cpu2"]
    for col in ("serial", "t1", "t2"):
        scaling[col + " ms"] = 1e3 * scaling.pop(col)
    print(f"\n3. Thread scaling, yizhuang (wall clock, min of {repeats}; load average {os.getloadavg()[0]:.2f}; Numba "
          f"threading layer {numba.threading_layer()}); run_batch goes serial below {PARALLEL_MIN_CELLS} cells.\n"
          "   cpu 2/1: CPU time of all threads with 2 threads over 1 thread (spinning and overhead show here even on "
          "a busy machine); balance: speed-up the static schedule allows; expected = balance / (cpu 2/1), the "
          "2-thread speed-up of a quiet machine\n" + markdown(scaling.drop(columns=["cpu1", "cpu2"]), 3))
    return scaling


def main(argv=None) -> None:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--repeats", type=int, default=5)
    parser.add_argument("--quick", action="store_true", help="yizhuang only")
    parser.add_argument("--jit", action="store_true", help="the kernel against the same code without JIT")
    parser.add_argument("--jit-worker", action="store_true", help=argparse.SUPPRESS)
    args = parser.parse_args(argv)
    if args.jit_worker:
        print(json.dumps(jit_worker(args.repeats)))
        return
    print(f"{os.cpu_count()} CPUs, {numba.config.NUMBA_NUM_THREADS} Numba threads, load average "
          f"{os.getloadavg()[0]:.2f} at start")
    if args.jit:
        print("\n".join(jit_rows(4 * args.repeats)))
        return
    ns = print_kernel_and_rates(args.repeats, args.quick)
    scaling = print_scaling(args.repeats)
    moabc = [moabc_row(1), moabc_row(numba.config.NUMBA_NUM_THREADS)]
    print("\n4. MOABC 40 x 100 on yizhuang (warm)\n" + markdown(pd.DataFrame(moabc), 3))
    big = scaling[scaling["pop"] >= 200]
    best_moabc, moabc_cpu = min(row["wall_s"] for row in moabc), moabc[0]["cpu_s"]
    verdict = {True: "yes", False: "NO"}
    print(f"\n5. Done-when (load average now {os.getloadavg()[0]:.2f}; wall-clock lines need a quiet machine)\n"
          f"   kernel {ns:.1f} ns/cell per core (yizhuang) <= 20: {verdict[ns <= 20]}\n"
          f"   2-thread speed-up at pop >= 200: {big['wall 1/2'].min():.2f}x >= 1.7x: "
          f"{verdict[big['wall 1/2'].min() >= 1.7]} (expected on a quiet machine from CPU time and balance: "
          f"{big['expected'].min():.2f}x)\n"
          f"   MOABC 40 x 100 warm: {best_moabc:.3f} s wall <= 0.3 s: {verdict[best_moabc <= 0.3]}; 1 thread "
          f"{moabc_cpu:.3f} s CPU <= 0.3 s: {verdict[moabc_cpu <= 0.3]}")


if __name__ == "__main__":
    main()
