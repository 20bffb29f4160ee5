"""What the suite's seeded families cost: evaluations per CPU second, and the CPU time of a certified front.

Measured in this process (``time.process_time``) and returned as tables; ``benchmarks/suite_families.py``
prints them. The front is the line's, not the encoding's: every ``n_var`` of an instance shares it.
"""

from __future__ import annotations

import os
import tempfile
import time

import numpy as np
import pandas as pd

from pymoo_rail.optimal import reference
from pymoo_rail.suite import get_problem

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


def bounded_table(kinds, n_vars, seed: int) -> pd.DataFrame:
    """Per kind and n_var: the ``-3obj`` instance's bounded front (sizes, HV bracket, epsilon, comfort) and its CPU.

    ``inner_energy_gap_min_pct``: the inner point closest to the certified energy front at its own
    running time, in % of the reference point's energy.

    ``cpu_s`` is the first ``bounded_front()`` in a fresh cache directory (the inner recipe's 10,000
    evaluations; the line's certified front is computed too where it is not shipped).
    """
    rows = []
    with tempfile.TemporaryDirectory() as cache:
        os.environ[reference.CACHE_ENV] = cache
        for kind in kinds:
            for n_var in n_vars:
                problem = get_problem(f"generated-{kind}-3obj", n_var=n_var, seed=seed)
                start = time.process_time()
                bounded = problem.bounded_front()
                energy_gap = reference.certified_gap(problem.certified_front(), bounded.inner[:, 1], bounded.inner[:, 0])
                rows.append({"family": problem.family, "n_var": n_var, "seed": seed, "inner": len(bounded.inner),
                             "outer": len(bounded.outer), "hv_inner/hv_outer": round(bounded.hv_inner / bounded.hv_outer, 3),
                             "hv_gap": round(bounded.hv_gap, 3), "epsilon": round(bounded.epsilon, 3),
                             "comfort_floor_ms2": f"{bounded.outer[:, 2].min():.2f}-{bounded.outer[:, 2].max():.2f}",
                             "inner_comfort_min_ms2": round(float(bounded.inner[:, 2].min()), 2),
                             "inner_energy_gap_min_pct": round(100 * energy_gap["gap_min_kwh"]
                                                               / float(bounded.ref_point[0]), 2),
                             "cpu_s": round(time.process_time() - start, 1)})
                print(rows[-1], flush=True)
    return pd.DataFrame(rows)
