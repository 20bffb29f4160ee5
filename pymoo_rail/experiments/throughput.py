"""Throughput of the simulator on this machine: kernel CPU time per cell, evaluations per second,
thread scaling, a warm MOABC run and the JIT against pure Python.

Every function measures in this process (the JIT comparison in child processes) and returns plain
rows or tables; ``benchmarks/throughput.py`` prints them. Timings are minima over ``repeats``
rounds; CPU time per cell is not distorted by other load, wall-clock ratios need a quiet machine.

>>> from pymoo_rail.experiments.throughput import kernel_table
>>> kernel_table(repeats=3, cases=("yizhuang",))                     # doctest: +SKIP
"""

from __future__ import annotations

import json
import math
import os
import subprocess
import sys
import tempfile
import time
from typing import Callable, Sequence

import numba
import numpy as np
import pandas as pd
from numba import njit

from pymoo_rail.cases import load_case
from pymoo_rail.problems import SpeedProfileProblem
from pymoo_rail.sim import kernel as k

CASES = ("yizhuang", "metro-a", "wuguang-crh3", "yizhuang-ttobench")
POPULATIONS = (10, 20, 50, 200, 1000)
_CHAIN_ARGS = (10.0, 2.0e5, -1.0e3, 10.0, -0.05, 2.0e3, 60.0, 6.0, 1.0 / 2.0e5)


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


def best_time(fn: Callable[[], object], repeats: int, clock: Callable[[], float] = time.perf_counter) -> float:
    """The minimum over ``repeats`` calls of ``fn`` of the time ``clock`` measures (s)."""
    best = math.inf
    for _ in range(repeats):
        t0 = clock()
        fn()
        best = min(best, clock() - t0)
    return best


def chain_ns_per_cell(repeats: int, n: int = 2_000_000) -> float:
    """Latency of one cell's dependency chain on this CPU (ns of CPU time), minimum over ``repeats``."""
    cell_chain(10, *_CHAIN_ARGS)
    return 1e9 * best_time(lambda: cell_chain(n, *_CHAIN_ARGS), repeats, time.process_time) / n


def random_programs(problem: SpeedProfileProblem, pop: int, seed: int = 0) -> np.ndarray:
    """Kernel programs of ``pop`` decision vectors drawn uniformly within the bounds of ``problem``."""
    rng = np.random.default_rng(seed)
    X = problem.xl + rng.random((pop, problem.n_var)) * (problem.xu - problem.xl)
    return np.ascontiguousarray(problem.encoding.programs(X))


def cells_per_run(summaries: np.ndarray, dx_m: float) -> np.ndarray:
    """Cells each run simulated: a run that stops short ends in the cell where it stops."""
    return np.ceil(summaries[:, k.OUT_STOP_POSITION_M] / dx_m - 1e-9)


def static_balance(summaries: np.ndarray, dx_m: float, threads: int) -> float:
    """Best speed-up a batch allows on ``threads`` threads with Numba's static schedule.

    ``prange`` hands each thread one contiguous block of the pairs of runs; a pair costs the
    cells of its longer run. The ratio total / largest block is the speed-up of a machine with
    nothing else to do.

    Parameters
    ----------
    summaries : numpy.ndarray
        The batch's summaries (``simulate_batch``), one row per run.
    dx_m : float
        The model's cell length.
    threads : int
        Threads sharing the batch.

    Returns
    -------
    float
    """
    cells = cells_per_run(summaries, dx_m)
    if len(cells) % 2:
        cells = np.append(cells, 0.0)
    pair_cells = cells.reshape(-1, 2).max(axis=1)
    blocks = np.array_split(pair_cells, threads)
    return float(pair_cells.sum() / max(block.sum() for block in blocks))


def kernel_table(repeats: int, cases: Sequence[str] = CASES, pop: int = 200) -> pd.DataFrame:
    """CPU time per cell of the serial kernel on one core, per case, and its ratio to the latency bound.

    Returns
    -------
    pandas.DataFrame
        ``case``, ``cells_per_run``, ``ns_per_cell``, ``/ bound``; ``attrs["bound_ns"]`` holds the
        bound (:func:`chain_ns_per_cell`).
    """
    bound = chain_ns_per_cell(repeats)
    rows = []
    numba.set_num_threads(1)
    for name in cases:
        problem = SpeedProfileProblem(load_case(name))
        model = problem.simulator.model
        programs = random_programs(problem, pop)
        cells = float(cells_per_run(k.simulate_batch_serial(model, programs), model.dx_m).sum())
        cpu = best_time(lambda: k.simulate_batch_serial(model, programs), repeats, time.process_time)
        rows.append({"case": name, "cells_per_run": cells / len(programs), "ns_per_cell": 1e9 * cpu / cells})
    numba.set_num_threads(numba.config.NUMBA_NUM_THREADS)
    table = pd.DataFrame(rows)
    table["/ bound"] = table["ns_per_cell"] / bound
    table.attrs["bound_ns"] = bound
    return table


def rate_table(repeats: int, cases: Sequence[str] = CASES, populations: Sequence[int] = POPULATIONS) -> pd.DataFrame:
    """Evaluations and million cells per second of ``Simulator.run_batch`` (all threads, wall clock)."""
    rows = []
    for name in cases:
        problem = SpeedProfileProblem(load_case(name))
        sim = problem.simulator
        for pop in populations:
            programs = random_programs(problem, pop)
            cells = float(cells_per_run(sim.run_batch(programs), sim.model.dx_m).sum())
            wall = best_time(lambda: sim.run_batch(programs), repeats)
            rows.append({"case": name, "pop": pop, "evals_per_s": pop / wall, "Mcells_per_s": cells / wall / 1e6})
    return pd.DataFrame(rows)


def _scaling_row(model, programs: np.ndarray, repeats: int, threads: int) -> dict:
    times: dict[str, float] = {}
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
        cpu[label] = best_time(lambda: k.simulate_batch(model, programs), repeats, time.process_time)
    numba.set_num_threads(numba.config.NUMBA_NUM_THREADS)
    balance = static_balance(k.simulate_batch_serial(model, programs), model.dx_m, threads)
    return {"pop": len(programs), "cells": len(programs) * (model.position_m.shape[0] - 1), **times, **cpu,
            "balance": balance}


def scaling_table(repeats: int, case: str = "yizhuang", populations: Sequence[int] = POPULATIONS) -> pd.DataFrame:
    """Wall time on 1 and 2 threads (parallel kernel) and of the serial kernel, per population.

    Returns
    -------
    pandas.DataFrame
        ``pop``, ``cells``, ``balance`` (:func:`static_balance`), ``wall 1/2`` (speed-up on 2
        threads), ``cpu 2/1`` (CPU time of all threads, 2 over 1), ``expected`` (balance / cpu 2/1:
        the 2-thread speed-up of a quiet machine), ``serial ms``, ``t1 ms``, ``t2 ms``.
    """
    problem = SpeedProfileProblem(load_case(case))
    threads = min(2, numba.config.NUMBA_NUM_THREADS)
    table = pd.DataFrame([_scaling_row(problem.simulator.model, random_programs(problem, pop), repeats, threads)
                          for pop in populations])
    table["wall 1/2"] = table["t1"] / table["t2"]
    table["cpu 2/1"] = table["cpu2"] / table["cpu1"]
    table["expected"] = table["balance"] * table["cpu1"] / table["cpu2"]
    for col in ("serial", "t1", "t2"):
        table[col + " ms"] = 1e3 * table.pop(col)
    return table.drop(columns=["cpu1", "cpu2"])


def moabc_timing(threads: int, bees: int = 40, cycles: int = 100, case: str = "yizhuang") -> dict:
    """Wall and CPU time of a warm MOABC run (energy, time error) on ``threads`` Numba threads."""
    from pymoo.optimize import minimize

    from pymoo_rail.algorithms import MOABC

    numba.set_num_threads(threads)
    problem = SpeedProfileProblem(load_case(case), objectives=("energy", "time_error"))
    minimize(problem, MOABC(pop_size=bees), ("n_gen", 1 + 2 * cycles), seed=1)  # warm: compiled, caches filled
    t0, c0 = time.perf_counter(), time.process_time()
    res = minimize(problem, MOABC(pop_size=bees), ("n_gen", 1 + 2 * cycles), seed=1)
    row = {"threads": threads, "wall_s": time.perf_counter() - t0, "cpu_s": time.process_time() - c0,
           "n_eval": res.algorithm.evaluator.n_eval}
    numba.set_num_threads(numba.config.NUMBA_NUM_THREADS)
    return row


def jit_worker(repeats: int, case: str = "yizhuang", pop: int = 200) -> dict:
    """``run_batch`` in this process (JIT state from the environment): rate, CPU per run, first call."""
    t0 = time.perf_counter()
    problem = SpeedProfileProblem(load_case(case))
    sim, programs = problem.simulator, random_programs(problem, pop)
    sim.run_batch(programs[:2])  # compile or load from cache
    first_call_s = time.perf_counter() - t0
    t1, c1 = time.perf_counter(), time.process_time()
    for _ in range(repeats):
        sim.run_batch(programs)
    return {"evals_per_s": pop * repeats / (time.perf_counter() - t1),
            "cpu_us_per_eval": 1e6 * (time.process_time() - c1) / (pop * repeats), "first_call_s": first_call_s}


def _worker_in_child(repeats: int, **env: str) -> dict:
    code = ("import json, sys; from pymoo_rail.experiments.throughput import jit_worker; "
            "print(json.dumps(jit_worker(int(sys.argv[1]))))")
    out = subprocess.run([sys.executable, "-c", code, str(repeats)], env=dict(os.environ, **env),
                         check=True, capture_output=True, text=True)
    return json.loads(out.stdout.strip().splitlines()[-1])


def jit_comparison(repeats: int) -> dict:
    """:func:`jit_worker` in child processes: with an empty and a warm Numba cache, and without JIT.

    Returns
    -------
    dict
        ``{"cold": ..., "warm": ..., "nojit": ...}``, each a :func:`jit_worker` dict; without JIT
        one repeat only (pure Python is slow).
    """
    with tempfile.TemporaryDirectory() as cache:
        cold, warm = _worker_in_child(repeats, NUMBA_CACHE_DIR=cache), _worker_in_child(repeats, NUMBA_CACHE_DIR=cache)
    return {"cold": cold, "warm": warm, "nojit": _worker_in_child(1, NUMBA_DISABLE_JIT="1")}
