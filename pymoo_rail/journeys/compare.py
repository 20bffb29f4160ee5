"""Comparisons of section fronts and of running-time splits on a whole line.

:func:`front_gaps` measures how far estimated section fronts (the simulated strategy search, or a
combination) lie from reference fronts (the exact solver's); :func:`supplement_tables` sets, per
total supplement, the energy-optimal split beside the timetable rules of thumb (equal and
proportional supplements) and runs every split on a common set of fronts; :func:`split_sweep` is
the same against the trip time. ``benchmarks/journeys.py`` writes them as a report.
"""

from __future__ import annotations

import time
from typing import Sequence

import numpy as np
import pandas as pd

from pymoo_rail.journeys.allocation import allocate_running_time, section_fronts, supplement_split
from pymoo_rail.journeys.fronts import front_energy
from pymoo_rail.journeys.problem import BudgetRepair, RunningTimeAllocationProblem
from pymoo_rail.model import CaseError


def rule_energy(journey, total_s: float, fronts, rule: str) -> float:
    """Line energy (kWh) of a rule-of-thumb split (``"equal"`` or ``"proportional"``).

    NaN when the rule gives some section more time than its front covers.
    """
    try:
        return supplement_split(journey, total_s, fronts=fronts, rule=rule).energy_kwh
    except CaseError:
        return float("nan")


def on_fronts(fronts, times_s) -> float:
    """Line energy (kWh) of the given section running times on the given fronts.

    Raises
    ------
    pymoo_rail.model.CaseError
        A time outside its front's range.
    """
    return float(sum(front_energy(f, t) for f, t in zip(fronts, times_s)))


def front_gaps(reference, others: dict, journey, n_points: int = 200) -> pd.DataFrame:
    """Per section: the relative energy difference (%) of each front in ``others`` from ``reference``.

    Parameters
    ----------
    reference : list of pandas.DataFrame
        One front per section (``running_time_s``, ``energy_kwh``), e.g. the exact solver's.
    others : dict
        Label -> list of fronts. The running times compared span the range common to the reference
        and every front of ``others`` whose label does not start with ``"combined"`` (a combination
        of fronts spans the union of their ranges).
    journey : pymoo_rail.journeys.Journey
        For the section labels.
    n_points : int
        Running times spanning the common range.

    Returns
    -------
    pandas.DataFrame
        ``section``, ``label``, ``range s`` and ``<label> mean/min/max %`` per front of ``others``.
    """
    rows = []
    for k, ref in enumerate(reference):
        ranged = [ref] + [fronts[k] for label, fronts in others.items() if not label.startswith("combined")]
        t_lo = max(f.running_time_s.iloc[0] for f in ranged)
        t_hi = min(f.running_time_s.iloc[-1] for f in ranged)
        t = np.linspace(t_lo, t_hi, n_points)
        e = front_energy(ref, t)
        row = {"section": k, "label": journey.section_label(k), "range s": f"{t_lo:.1f}-{t_hi:.1f}"}
        for label, fronts in others.items():
            rel = 100 * (front_energy(fronts[k], t) - e) / np.abs(e)
            row.update({f"{label} mean %": np.mean(rel), f"{label} min %": np.min(rel), f"{label} max %": np.max(rel)})
        rows.append(row)
    return pd.DataFrame(rows)


def _split_on(journey, total_s: float, fronts, combined) -> float:
    """The optimal split on ``fronts``, run on ``combined`` (NaN when it leaves a front's range)."""
    try:
        return on_fronts(combined, allocate_running_time(journey, total_s, fronts=fronts).running_times_s)
    except CaseError:
        return float("nan")


def supplement_tables(journey, exact, sim, combined, supplements: Sequence[float]):
    """Per total supplement: optimal against rule-of-thumb splits, and every split run on ``combined``.

    Parameters
    ----------
    journey : pymoo_rail.journeys.Journey
        The line.
    exact, sim, combined : list of pandas.DataFrame
        Section fronts: the exact solver's, the simulated strategy search's, their lower hull.
    supplements : sequence of float
        Total supplements over the sum of the sections' flat-out times (0.05 = 5 %); those beyond
        the exact fronts' range are left out.

    Returns
    -------
    (pandas.DataFrame, pandas.DataFrame)
        Per supplement on the exact fronts: trip time, optimal / equal / proportional energy, the
        saving, the marginal price and violation. Per supplement on the combined fronts: the optimal
        split, and the splits computed on the exact fronts, on the simulated ones and the equal split.
    """
    lo = np.array([f.running_time_s.iloc[0] for f in exact])
    hi = np.array([f.running_time_s.iloc[-1] for f in exact])
    rows, cross = [], []
    for s in supplements:
        total = lo.sum() * (1 + s)
        if total > hi.sum():
            continue
        best = allocate_running_time(journey, total, fronts=exact)
        equal = rule_energy(journey, total, exact, "equal")
        rows.append({"supplement %": 100 * s, "trip time s": journey.trip_time_s(total),
                     "optimal kWh": best.energy_kwh, "equal kWh": equal,
                     "proportional kWh": rule_energy(journey, total, exact, "proportional"),
                     "saving vs equal kWh": equal - best.energy_kwh,
                     "saving vs equal %": 100 * (equal - best.energy_kwh) / equal,
                     "price Wh/s": 1000 * best.price_kwh_per_s, "marginal violation": best.marginal_violation()})
        try:
            equal_split = on_fronts(combined, supplement_split(journey, total, fronts=combined).running_times_s)
        except CaseError:
            equal_split = float("nan")
        cross.append({"supplement %": 100 * s,
                      "optimal on combined kWh": allocate_running_time(journey, total, fronts=combined).energy_kwh,
                      "split from exact fronts kWh": _split_on(journey, total, exact, combined),
                      "split from simulated fronts kWh": _split_on(journey, total, sim, combined),
                      "equal split kWh": equal_split})
    return pd.DataFrame(rows), pd.DataFrame(cross)


def split_sweep(journey, fronts, n_points: int = 60) -> pd.DataFrame:
    """Line energy of the optimal, equal and proportional splits against the trip time.

    The running times span from flat out to where the fronts end or the equal supplement leaves
    the narrowest front, whichever comes first.

    Returns
    -------
    pandas.DataFrame
        ``running_time_s``, ``trip_time_s``, ``optimal_kwh``, ``equal_kwh``, ``proportional_kwh``.
    """
    lo = np.array([f.running_time_s.iloc[0] for f in fronts])
    hi = np.array([f.running_time_s.iloc[-1] for f in fronts])
    widest_equal = lo.sum() + len(fronts) * (hi - lo).min()
    sweep_t = np.linspace(lo.sum(), min(hi.sum(), widest_equal), n_points)
    return pd.DataFrame({
        "running_time_s": sweep_t, "trip_time_s": [journey.trip_time_s(t) for t in sweep_t],
        "optimal_kwh": [allocate_running_time(journey, t, fronts=fronts).energy_kwh for t in sweep_t],
        "equal_kwh": [rule_energy(journey, t, fronts, "equal") for t in sweep_t],
        "proportional_kwh": [rule_energy(journey, t, fronts, "proportional") for t in sweep_t]})


def timed_section_fronts(journey, source: str, cache_path, **kwargs) -> tuple:
    """:func:`~pymoo_rail.journeys.section_fronts` with its wall-clock seconds and how many sections came from the cache.

    Returns
    -------
    (list of pandas.DataFrame, float, int)
    """
    read = []
    t0 = time.perf_counter()
    fronts = section_fronts(journey, source, cache_path=cache_path,
                            on_front=lambda k, computed: read.append(not computed), **kwargs)
    return fronts, time.perf_counter() - t0, sum(read)


def de_allocation_runs(fronts, total_s: float, best_kwh: float, n_gen: int, seeds=(1, 2, 3)) -> pd.DataFrame:
    """pymoo's DE (pop 40) with the budget repair on the allocation problem, per seed, against ``best_kwh``.

    Returns
    -------
    pandas.DataFrame
        ``seed``, ``DE kWh``, ``gap to exact %``, ``evaluations``, ``time s`` (wall clock).
    """
    from pymoo.algorithms.soo.nonconvex.de import DE
    from pymoo.optimize import minimize

    rows = []
    for seed in seeds:
        t0 = time.perf_counter()
        res = minimize(RunningTimeAllocationProblem(fronts, total_s), DE(pop_size=40, repair=BudgetRepair()),
                       ("n_gen", n_gen), seed=seed)
        rows.append({"seed": seed, "DE kWh": float(res.F[0]), "gap to exact %": 100 * (res.F[0] / best_kwh - 1),
                     "evaluations": res.algorithm.evaluator.n_eval, "time s": time.perf_counter() - t0})
    return pd.DataFrame(rows)
