"""Every track of the TTOBench release with its train: minimum time, the exact optimum at 1.15 x
it (does the run hold every limit and stop at the platform?) and what NSGA2 finds.

``benchmarks/ttobench_release.py`` prints :func:`release_row` for every pair of
:func:`pymoo_rail.cases.ttobench_release.release_pairs`.
"""

from __future__ import annotations

import time
import warnings
from pathlib import Path
from typing import Mapping

import numpy as np

from pymoo_rail.cases.ttobench import TTOBenchWarning, from_ttobench
from pymoo_rail.optimal import min_running_time, optimal_profile
from pymoo_rail.problems import SpeedProfileProblem

TIME_TOL_S = 2.0  # NSGA2 members this close to the planned time count as punctual
LIMIT_TOL_MS = 1e-6  # the problem's own limit tolerance
STOP_TOL_M = 0.25  # the problem's default stop tolerance
SUPPLEMENT = 1.15


def release_case(track: str | Path, train: str | Path):
    """The whole track (first stop -> last stop) with ``train``, TTOBench's warnings silenced."""
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", TTOBenchWarning)
        return from_ttobench(track, train, 0, -1, 1.0)


def release_row(case, n_gen: int, pop_size: int = 40, settings: Mapping | None = None) -> dict:
    """The exact optimum at 1.15 x the minimum time and NSGA2's best punctual member on ``case``.

    Parameters
    ----------
    case : pymoo_rail.model.Case
        The line and train (its planned time is replaced).
    n_gen, pop_size : int
        NSGA2's budget (seed 1, objectives energy and time error).
    settings : mapping, optional
        Keyword arguments of :class:`~pymoo_rail.problems.SpeedProfileProblem` (e.g. ``max_section_m``).

    Returns
    -------
    dict
        ``km``, ``t_min_s``, ``optimum_kwh``, ``held`` (limit excess <= 1e-6 m/s, stop error <= 0.25 m,
        final speed 0, platform reached), ``optimum_cpu_s``, ``nsga2_kwh`` (least energy within 2 s
        of the planned time; nan if none), ``gap_pct``, ``front_size``, ``n_var``, ``nsga2_cpu_s``.
    """
    from pymoo.algorithms.moo.nsga2 import NSGA2
    from pymoo.optimize import minimize

    t0 = time.process_time()
    t_min = min_running_time(case)
    case = case.with_planned_time(SUPPLEMENT * t_min)
    best = optimal_profile(case, case.planned_time_s)
    s = best.summary
    held = (s["limit_excess_ms"] <= LIMIT_TOL_MS and s["stop_error_m"] <= STOP_TOL_M
            and s["final_speed_ms"] == 0.0 and bool(s["reached"]))
    t1 = time.process_time()
    problem = SpeedProfileProblem(case, objectives=("energy", "time_error"), **(settings or {}))
    res = minimize(problem, NSGA2(pop_size=pop_size), ("n_gen", n_gen), seed=1)
    t2 = time.process_time()
    F = np.atleast_2d(res.F) if res.F is not None else np.empty((0, 2))
    close = F[F[:, 1] <= TIME_TOL_S]
    nsga = float(close[:, 0].min()) if close.size else float("nan")
    return {"km": case.line.length_m / 1000, "t_min_s": t_min, "optimum_kwh": best.energy.net_kwh, "held": held,
            "optimum_cpu_s": t1 - t0, "nsga2_kwh": nsga, "gap_pct": 100.0 * (nsga / best.energy.net_kwh - 1.0),
            "front_size": F.shape[0], "n_var": problem.n_var, "nsga2_cpu_s": t2 - t1}
