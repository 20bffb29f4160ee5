"""Speed-profile encodings against the exact optimum: the rows of ``benchmarks/encodings.py``.

:func:`front_row` reads one stored run of the CLI's default job (the members of its front, the
feasible ones, the chosen member's gap to the optimum); :func:`de_budget_row` runs DE with a fixed
budget on one case and encoding; :func:`de_encodings` lists the encodings compared.
"""

from __future__ import annotations

import time
from typing import Mapping

import numpy as np

from pymoo_rail.experiments.fronts import choose_member
from pymoo_rail.indicators import energy_gap
from pymoo_rail.optimal import solved_energy_gap
from pymoo_rail.problems import SpeedProfileProblem
from pymoo_rail.problems.encodings import SwitchingPoints

DE_ENCODINGS = {
    "speed codes, gradient/limit partition": dict(encoding="speed_codes"),
    "speed codes, gradient/limit, sections <= 200 m": dict(encoding="speed_codes", max_section_m=200.0),
    "speed codes, 12 equal sections": dict(encoding="speed_codes", partition="equal", n_sections=12),
    "switching points": dict(encoding="switching_points"),
}


def front_row(record: Mapping, planned_time_s: float, reference) -> tuple:
    """One stored run: its front against the exact optimum.

    Parameters
    ----------
    record : mapping
        A run record (:func:`pymoo_rail.experiments.load_records`) with ``front`` extras
        ``running_time_s`` and ``energy_kwh``.
    planned_time_s : float
        The case's planned running time (the chosen member is the least energy within 1 s of it).
    reference : pandas.DataFrame
        The exact front (:func:`pymoo_rail.optimal.optimal_front`).

    Returns
    -------
    tuple
        ``(problem label, seed, distinct members, feasible members, feasible time range "lo-hi",
        chosen member's running time s, its gap %, mean gap % of the feasible members)``.
    """
    front = record["front"]
    F, CV = np.asarray(front["F"]), np.asarray(front["CV"])
    t, e = np.asarray(front["extras"]["running_time_s"]), np.asarray(front["extras"]["energy_kwh"])
    ok = CV <= 0
    chosen = choose_member(F, CV, t, e, planned_time_s)
    gap_chosen = energy_gap(np.array([[t[chosen], e[chosen]]]), reference)["points"]["gap_rel"].iloc[0]
    mean_gap = energy_gap(np.column_stack([t[ok], e[ok]]), reference)["mean_gap_rel"] if ok.any() else np.nan
    return (record["problem_label"], record["seed"], len(F), int(ok.sum()),
            f"{t[ok].min():.1f}-{t[ok].max():.1f}" if ok.any() else "-", t[chosen], 100 * gap_chosen, 100 * mean_gap)


def evaluations_per_s(problem, pop: int = 200, repeats: int = 5) -> float:
    """Evaluations per second through ``Problem.evaluate`` (random vectors, after a compile call)."""
    X = problem.xl + np.random.default_rng(0).random((pop, problem.n_var)) * (problem.xu - problem.xl)
    problem.evaluate(X[:2])
    start = time.perf_counter()
    for _ in range(repeats):
        problem.evaluate(X)
    return pop * repeats / (time.perf_counter() - start)


def de_encodings(case) -> dict:
    """:data:`DE_ENCODINGS` and switching points whose holds brake on descents (``hold_brake``)."""
    hold_brake = tuple("hold_brake" if r == "hold" else r for r in SwitchingPoints.build(case).regimes)
    return {**DE_ENCODINGS, "switching points, hold_brake": dict(encoding="switching_points", regimes=hold_brake)}


def de_budget_row(case, settings: Mapping, evals: int, reference: bool = False) -> dict:
    """DE (pop 40, seed 1) on ``min energy s.t. |T - T_plan| <= 1 s`` with ``evals`` evaluations.

    Returns
    -------
    dict
        ``n_var``, ``evals_per_s`` (:func:`evaluations_per_s`), ``energy_kwh``, ``running_time_s``
        of the best run; with ``reference`` also ``optimum_kwh`` and ``certificate_kwh`` (the exact
        optimum at the run's own running time and its bound) and ``gap_pct``.
    """
    from pymoo.algorithms.soo.nonconvex.de import DE
    from pymoo.optimize import minimize

    problem = SpeedProfileProblem(case, objectives=("energy",), time_tolerance_s=1.0, **settings)
    rate = evaluations_per_s(problem)
    tr = problem.trajectory(minimize(problem, DE(pop_size=40), ("n_evals", evals), seed=1).X)
    row = {"n_var": problem.n_var, "evals_per_s": rate, "energy_kwh": tr.energy.net_kwh,
           "running_time_s": tr.running_time_s}
    if reference:  # at the run's own time: a solve may end 0.5 s off, ~1 kWh along a 2.5 kWh/s slope
        point = solved_energy_gap(np.array([[tr.running_time_s, tr.energy.net_kwh]]), case)["points"]
        best = float(point["optimal_kwh"].iloc[0])
        row.update(optimum_kwh=best, certificate_kwh=float(point["energy_bound_kwh"].iloc[0]),
                   gap_pct=100 * (tr.energy.net_kwh / best - 1))
    return row
