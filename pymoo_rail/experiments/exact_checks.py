"""Checks of the exact solver: timing of a front, grid refinement, the level-track closed form and a
direct search over traction-hold-coast-brake strategies, each as a table.

``benchmarks/optimal.py`` prints and reports them for yizhuang; every function takes the case, so
the same checks run on a user's line.
"""

from __future__ import annotations

import time
from typing import Sequence

import numpy as np
import pandas as pd

from pymoo_rail.constants import J_PER_KWH, KMH_PER_MS
from pymoo_rail.model import case_from_dict
from pymoo_rail.optimal import OptimalSolver, min_running_time, optimal_front
from pymoo_rail.optimal.flat import flat_track_optimum
from pymoo_rail.optimal.strategies import hold_coast_search, two_holds_search

REFINEMENT_GRIDS = ((1.0, 100), (1.0, 200), (1.0, 400), (2.0, 200))
FINE_GRIDS = ((1.0, 800), (0.5, 200), (0.5, 400))


def level_case():
    """5 km of level track with Davis resistance (as in tests/optimal/cases.py)."""
    return case_from_dict({
        "name": "level", "source": "synthetic", "run": {"planned_time_s": 300.0},
        "train": {"mass_t": 100.0, "length_m": 100.0, "max_speed_kmh": 100.0,
                  "resistance": {"a": 2.0, "b": 0.1, "c": 0.03, "unit": "kN", "speed_unit": "ms"},
                  "traction": {"max_force_kn": 100.0}, "braking": {"max_force_kn": 100.0}},
        "line": {"length_m": 5000.0, "gradients": [[0.0, 5000.0, 0.0]], "speed_limits": [[0.0, 5000.0, 100.0]]}})


def energy_at(run, time_s: float) -> float:
    """Net energy of an exact run moved to exactly ``time_s`` along the front's slope lambda (kWh)."""
    return run.energy.net_kwh + run.summary["lambda_w"] / J_PER_KWH * (run.running_time_s - time_s)


def timed_front(case, n_times: int = 10, slowest: float = 1.5) -> tuple:
    """``optimal_front`` from the minimum running time to ``slowest`` x it, after a coarse warm-up.

    Returns
    -------
    (pandas.DataFrame, float, float, float)
        The front, its wall-clock seconds, the warm-up's seconds (loads or compiles the kernels),
        and the minimum running time (s).
    """
    t0 = time.perf_counter()
    OptimalSolver(case, n_speeds=20, dx_m=50.0).profile(1.2 * min_running_time(case, dx_m=50.0))
    warm_up_s = time.perf_counter() - t0
    t0 = time.perf_counter()
    fastest = min_running_time(case)
    front = optimal_front(case, np.linspace(fastest, slowest * fastest, n_times))
    return front, time.perf_counter() - t0, warm_up_s, fastest


def grid_refinement(case, times: Sequence[float] = (135.0, 150.0, 180.0), grids=REFINEMENT_GRIDS) -> pd.DataFrame:
    """Energy at each running time per grid ``(dx_m, n_speeds)``, its cost and its change against the finest."""
    rows = []
    for dx, n_speeds in grids:
        solver = OptimalSolver(case, dx_m=dx, n_speeds=n_speeds)
        t0 = time.perf_counter()
        row = {"dx_m": dx, "n_speeds": n_speeds}
        for t in times:
            row[f"E({t:.0f} s) kWh"] = energy_at(solver.profile(t), t)
        row["seconds (3 profiles)"] = time.perf_counter() - t0
        row["memory MB"] = sum(a.nbytes for a in solver._tables) / 1e6 + solver._value.nbytes / 1e6
        rows.append(row)
    table = pd.DataFrame(rows)
    finest = table.iloc[int(np.argmax(table["n_speeds"] / table["dx_m"]))]
    for t in times:
        col = f"E({t:.0f} s) kWh"
        table[f"vs finest {t:.0f} s %"] = 100 * (table[col] / finest[col] - 1)
    return table


def level_track_table(times: Sequence[float] = (230.0, 260.0, 300.0, 350.0)) -> pd.DataFrame:
    """Pontryagin's closed form against the DP on :func:`level_case`."""
    case = level_case()
    solver = OptimalSolver(case)
    rows = []
    for t in times:
        exact = flat_track_optimum(case, t)
        e = energy_at(solver.profile(t), t)
        rows.append({"running time s": t, "closed form kWh": exact.energy_kwh, "DP kWh": e,
                     "difference %": 100 * (e / exact.energy_kwh - 1),
                     "hold speed km/h (closed form)": exact.hold_speed_ms * KMH_PER_MS,
                     "brake speed km/h (closed form)": exact.brake_speed_ms * KMH_PER_MS})
    return pd.DataFrame(rows)


def strategy_search_table(case, times: Sequence[float] = (135.0, 150.0, 170.0, 200.0),
                          two_holds: bool = True) -> pd.DataFrame:
    """The DP against a direct search over hold-coast (and, with ``two_holds``, two-hold) strategies."""
    solver = OptimalSolver(case)
    rows = []
    for t in times:
        e = energy_at(solver.profile(t), t)
        t0 = time.perf_counter()
        hc = hold_coast_search(case, t)
        row = {"running time s": t, "DP kWh": e, "hold-coast kWh": hc.energy_kwh,
               "hold speed km/h": hc.params[0] * KMH_PER_MS}
        if two_holds:
            row["two-holds kWh"] = two_holds_search(case, t, start=hc).energy_kwh
        row["search s"] = time.perf_counter() - t0
        best = min(v for k, v in row.items() if k.endswith("holds kWh") or k == "hold-coast kWh")
        row["DP vs best search %"] = 100 * (e / best - 1)
        rows.append(row)
    return pd.DataFrame(rows)
