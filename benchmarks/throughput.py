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

Wall-clock ratios are only meaningful on a quiet machine: the script prints the load average
next to them. CPU time per cell is not distorted by other load (as long as the core is not
shared with a sibling thread). Every timing is the minimum over ``--repeats`` rounds.

Usage: ``python benchmarks/throughput.py [--repeats 5] [--quick]``
"""

from __future__ import annotations

import argparse
import math
import os
import time

import numba
import numpy as np
from numba import njit

from pymoo_rail.cases import load_case
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


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--repeats", type=int, default=5)
    parser.add_argument("--quick", action="store_true", help="yizhuang only")
    args = parser.parse_args()
    load = os.getloadavg()[0]
    print(f"{os.cpu_count()} CPUs, {numba.config.NUMBA_NUM_THREADS} Numba threads, load average {load:.2f} at start")

    bound = chain_ns_per_cell(args.repeats)
    kernel = kernel_rows(args.repeats, args.quick)
    print("\n1. Kernel on one core (CPU time, population 200)")
    print(f"   latency bound: one cell's dependency chain takes {bound:.1f} ns on this CPU")
    print(f"   {'case':18s} {'cells/run':>9s} {'ns/cell':>8s} {'/ bound':>8s}")
    for row in kernel:
        print(f"   {row['case']:18s} {row['cells_per_run']:9.0f} {row['ns_per_cell']:8.1f} "
              f"{row['ns_per_cell'] / bound:8.2f}")

    print("\n2. Simulator.run_batch, all threads (wall clock)")
    print(f"   {'case':18s} {'pop':>5s} {'evals/s':>10s} {'Mcells/s':>9s}")
    for row in rate_rows(args.repeats, args.quick):
        print(f"   {row['case']:18s} {row['pop']:5d} {row['evals_per_s']:10.0f} {row['cells_per_s'] / 1e6:9.1f}")

    scaling = scaling_rows(args.repeats)
    print(f"\n3. Thread scaling, yizhuang (wall clock, min of {args.repeats}; load average "
          f"{os.getloadavg()[0]:.2f}; Numba threading layer {numba.threading_layer()}); run_batch goes serial "
          f"below {PARALLEL_MIN_CELLS} cells")
    print("   wall: measured; cpu 2/1: CPU time of all threads with 2 threads over 1 thread (spinning and")
    print("   overhead show here even on a busy machine); balance: speed-up the static schedule allows;")
    print("   expected = balance / (cpu 2/1), the 2-thread speed-up of a quiet machine")
    print(f"   {'pop':>5s} {'cells':>9s} {'serial ms':>10s} {'1 thr ms':>9s} {'2 thr ms':>9s} "
          f"{'wall 1/2':>9s} {'cpu 2/1':>8s} {'balance':>8s} {'expected':>9s}")
    for row in scaling:
        row["expected"] = row["balance"] * row["cpu1"] / row["cpu2"]
        print(f"   {row['pop']:5d} {row['cells']:9d} {1e3 * row['serial']:10.3f} {1e3 * row['t1']:9.3f} "
              f"{1e3 * row['t2']:9.3f} {row['t1'] / row['t2']:8.2f}x {row['cpu2'] / row['cpu1']:8.2f} "
              f"{row['balance']:8.2f} {row['expected']:8.2f}x")

    moabc = [moabc_row(1), moabc_row(numba.config.NUMBA_NUM_THREADS)]
    print("\n4. MOABC 40 x 100 on yizhuang (warm)")
    for row in moabc:
        print(f"   {row['threads']} thread(s): {row['wall_s']:.3f} s wall, {row['cpu_s']:.3f} s CPU, "
              f"{row['n_eval']} evaluations")

    ns = kernel[0]["ns_per_cell"]
    big = [row["t1"] / row["t2"] for row in scaling if row["pop"] >= 200]
    best_moabc = min(row["wall_s"] for row in moabc)
    moabc_cpu = moabc[0]["cpu_s"]
    expected = min(row["expected"] for row in scaling if row["pop"] >= 200)
    print(f"\n5. Done-when (load average now {os.getloadavg()[0]:.2f}; wall-clock lines need a quiet machine)")
    print(f"   kernel {ns:.1f} ns/cell per core (yizhuang)             <= 20    : {'yes' if ns <= 20 else 'NO'}")
    print(f"   2-thread speed-up at pop >= 200: {min(big):.2f}x            >= 1.7x : "
          f"{'yes' if min(big) >= 1.7 else 'NO'}")
    print(f"   (expected on a quiet machine from CPU time and balance: {expected:.2f}x)")
    print(f"   MOABC 40 x 100 warm: {best_moabc:.3f} s wall                 <= 0.3 s: "
          f"{'yes' if best_moabc <= 0.3 else 'NO'}")
    print(f"   MOABC 40 x 100 warm, 1 thread: {moabc_cpu:.3f} s CPU          <= 0.3 s: "
          f"{'yes' if moabc_cpu <= 0.3 else 'NO'}")


if __name__ == "__main__":
    main()
