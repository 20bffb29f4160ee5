"""The final front of a run, one member per objective vector.

An archive or a survival step can keep several members with the same objective vector (copies of
one solution, or decision vectors that drive the same run: a speed code above what the train can
reach on a section changes nothing). Counting them inflates the front size and gives spacing
zeros, so every front the package writes (``pymoo-rail optimize``, study records) goes through
:func:`distinct_front`. :func:`choose_member` picks the member to show.
"""

from __future__ import annotations

import numpy as np
from pymoo.core.population import Population


def distinct_index(F: np.ndarray, CV: np.ndarray | None = None) -> np.ndarray:
    """Indices of the members to keep: one per distinct row of ``F``, in their original order.

    Among members with equal objective vectors the one with the least constraint violation is
    kept (ties: the first). Objective vectors are compared exactly.

    Parameters
    ----------
    F : array (n, n_obj)
        Objective values.
    CV : array (n,), optional
        Constraint violation of each member (default: all zero).

    Returns
    -------
    numpy.ndarray
        Sorted integer indices into ``F``.
    """
    F = np.asarray(F, dtype=float)
    if F.ndim != 2:
        raise ValueError(f"F has shape {F.shape}: expected (n, n_obj)")
    n = F.shape[0]
    if n == 0:
        return np.zeros(0, dtype=int)
    cv = np.zeros(n) if CV is None else np.asarray(CV, dtype=float).reshape(-1)
    if cv.shape[0] != n:
        raise ValueError(f"CV has {cv.shape[0]} values for {n} members")
    order = np.lexsort((np.arange(n), cv))  # least violation first, then the original order
    _, first = np.unique(F[order], axis=0, return_index=True)
    return np.sort(order[first])


def distinct_front(opt: Population | None) -> Population:
    """The members of ``opt`` (e.g. ``res.algorithm.opt``) with distinct objective vectors.

    Parameters
    ----------
    opt : pymoo Population or None
        The final front of an algorithm; ``None`` gives an empty population.

    Returns
    -------
    Population
        A sub-population, in the original order; see :func:`distinct_index`.
    """
    if opt is None or len(opt) == 0:
        return Population.empty()
    F = np.asarray(opt.get("F"), dtype=float)
    CV = opt.get("CV")
    return opt[distinct_index(F, None if CV is None else np.asarray(CV, dtype=float).reshape(-1))]


def choose_member(F: np.ndarray, CV: np.ndarray, running_time_s: np.ndarray, energy_kwh: np.ndarray,
                  planned_time_s: float, window_s: float = 1.0) -> int:
    """Index of the front member to show (what ``pymoo-rail optimize`` writes to trajectory.csv).

    One objective: the best. Several: the least energy among the members within ``window_s`` of
    the planned time (what an operator would pick: punctual, then frugal); if none is that close,
    the one closest to the planned time (ties: least energy). Feasible members first.

    Parameters
    ----------
    F : array (n, n_obj)
        Objective values of the front members.
    CV : array (n,)
        Their constraint violations.
    running_time_s, energy_kwh : array (n,)
        Their running times (s) and net energies (kWh), e.g. ``opt.get("running_time_s")``.
    planned_time_s : float
        The case's planned running time (s).
    window_s : float
        How close to the planned time a punctual member is (s).

    Returns
    -------
    int
        Index of the chosen member.
    """
    F = np.asarray(F, dtype=float).reshape(len(F), -1)
    CV = np.asarray(CV, dtype=float).reshape(-1)
    running_time_s = np.asarray(running_time_s, dtype=float).reshape(-1)
    energy_kwh = np.asarray(energy_kwh, dtype=float).reshape(-1)
    candidates = np.flatnonzero(CV <= 0)
    if len(candidates) == 0:
        candidates = np.array([int(np.argmin(CV))])
    if F.shape[1] == 1:
        return int(candidates[np.argmin(F[candidates, 0])])
    punctual = punctual_member(running_time_s[candidates], energy_kwh[candidates], planned_time_s, window_s)
    if punctual is not None:
        return int(candidates[punctual])
    error = np.abs(running_time_s[candidates] - planned_time_s)
    order = np.lexsort((energy_kwh[candidates], error))
    return int(candidates[order[0]])


def punctual_member(running_time_s: np.ndarray, energy_kwh: np.ndarray, planned_time_s: float, window_s: float,
                    CV: np.ndarray | None = None) -> int | None:
    """Index of the least-energy feasible member within ``window_s`` of the planned time, if any.

    The rule :func:`choose_member` applies first; studies that report "no punctual member" instead
    of a fallback (a run whose front misses the window) call it directly.

    Parameters
    ----------
    running_time_s, energy_kwh : array (n,)
        Running times (s) and net energies (kWh) of the members.
    planned_time_s : float
        The planned running time (s).
    window_s : float
        How far from the planned time a member may run (s), inclusive.
    CV : array (n,), optional
        Constraint violations; members with ``CV > 0`` are never chosen (default: all feasible).

    Returns
    -------
    int or None
        Index of the chosen member (ties: the first), or ``None`` when no feasible member is
        within the window.
    """
    running_time_s = np.asarray(running_time_s, dtype=float).reshape(-1)
    energy_kwh = np.asarray(energy_kwh, dtype=float).reshape(-1)
    within = np.abs(running_time_s - planned_time_s) <= window_s
    if CV is not None:
        within &= np.asarray(CV, dtype=float).reshape(-1) <= 0
    if not within.any():
        return None
    candidates = np.flatnonzero(within)
    return int(candidates[np.argmin(energy_kwh[candidates])])


def best_run(results, problem: str | None = None):
    """The stored single-objective run whose best feasible point has the lowest objective.

    What a study script takes as its one good reference run (e.g. the best of 3 DE runs as the
    profile a controller then tracks).

    Parameters
    ----------
    results : pandas.DataFrame
        Stored runs with fronts (``load_results(..., fronts=True)``), one objective.
    problem : str, optional
        Only the runs of this problem label (default: every row).

    Returns
    -------
    (pandas.Series, numpy.ndarray) or None
        The run's row and its best feasible decision ``x`` (ties: the lowest seed, then the
        first member), or ``None`` when no run stored a feasible point.
    """
    rows = results if problem is None else results[results["problem"] == problem]
    best, best_x, best_f = None, None, np.inf
    for _, row in rows.sort_values("seed", kind="stable").iterrows():
        F = np.asarray(row["F"], dtype=float)
        if F.ndim != 2 or F.shape[1] != 1:
            raise ValueError(f"best_run needs single-objective runs; run {row['run_id']} has F of shape {F.shape}")
        feasible = np.flatnonzero(np.asarray(row["CV"], dtype=float).reshape(-1) <= 0)
        if not len(feasible):
            continue
        member = int(feasible[np.argmin(F[feasible, 0])])
        if F[member, 0] < best_f:
            best, best_x, best_f = row, np.asarray(row["X"], dtype=float)[member], F[member, 0]
    return None if best is None else (best, best_x)


def best_of_seeds(problem, make_algorithm, termination, seeds):
    """The best feasible single-objective result of one algorithm over several seeds.

    For a problem a study spec cannot name (e.g. a case changed in memory); a problem that a
    spec names goes through the study runner and :func:`best_run` instead.

    Parameters
    ----------
    problem : pymoo Problem
        A single-objective problem.
    make_algorithm : callable
        ``make_algorithm()`` returns a fresh algorithm for each seed.
    termination : tuple or pymoo Termination
        As for ``pymoo.optimize.minimize``, e.g. ``("n_gen", 200)``.
    seeds : iterable of int
        The seeds, in order.

    Returns
    -------
    pymoo.core.result.Result or None
        The result with the lowest ``F[0]`` among those whose best point is feasible (ties: the
        first seed), or ``None`` when no seed found a feasible point.
    """
    from pymoo.optimize import minimize

    best = None
    for seed in seeds:
        res = minimize(problem, make_algorithm(), termination, seed=seed)
        if res.X is None or np.asarray(res.CV, dtype=float).reshape(-1)[0] > 0:
            continue
        if best is None or float(res.F[0]) < float(best.F[0]):
            best = res
    return best
