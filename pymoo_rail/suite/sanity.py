"""The suite's sanity check: NSGA-II against random sampling of the same budget, on one problem.

A benchmark problem whose reference front is right lets a real optimiser get closer to it than
random sampling: for every suite problem, pymoo's IGD of NSGA-II (population 100, 200
generations) against ``pareto_front()`` must be finite and smaller than the IGD of as many random
decision vectors. IGD is pymoo's normalised IGD (``IGD(pf, zero_to_one=True)``: each objective
scaled to [0, 1] by the reference front's ideal and nadir points), since the objectives mix units
(kWh and s; for ``metro-a-4obj``, measured against its best-known front, kWh, s, m/s^2 and m) and raw
IGD would weigh them by their units (``docs/suite.md``). Raw IGD is reported too. A single-objective
problem's reference is one point, which cannot be normalised: its IGD is the distance in kWh.
"""

from __future__ import annotations

import time
from dataclasses import dataclass

import numpy as np

from pymoo_rail.optimal.reference import NoExactFrontError
from pymoo_rail.suite.fronts_io import best_known_front
from pymoo_rail.suite.problems import get_problem


@dataclass(frozen=True)
class SanityResult:
    """NSGA-II and random sampling on one suite problem, against its reference front.

    Attributes
    ----------
    problem : str
        Suite problem name.
    reference : str
        ``"certified front"``, ``"certified optimum"`` or ``"best-known front"``.
    n_eval : int
        Evaluations of each method.
    igd_nsga2, igd_random : float
        pymoo's IGD of the feasible, non-dominated final members (NSGA-II) and of the feasible,
        non-dominated random samples; ``inf`` when a method found no feasible point.
    normalised : bool
        IGD in the objective space normalised by the reference front's ideal and nadir points
        (pymoo's ``zero_to_one=True``; every problem with two or more objectives) rather than in raw
        units (one objective: kWh).
    igd_raw_nsga2, igd_raw_random : float
        The same in raw units (equal to the above when ``normalised`` is false).
    n_feasible_nsga2, n_feasible_random : int
        Feasible members of NSGA-II's final population, feasible random samples.
    n_front_nsga2, n_front_random : int
        Points each IGD is taken over: the non-dominated feasible members and samples. With three
        or more objectives the random set can hold many more points than NSGA-II's population of
        100, and IGD rewards a larger set.
    gap_nsga2_kwh, gap_random_kwh : float
        Single-objective problems: the best feasible energy minus the certified optimum, signed
        (negative: below the reference, which is an upper bound between the front's nodes); NaN
        otherwise or when nothing is feasible.
    n_below_certificate : int
        Feasible NSGA-II members below the certified front by more than its certificate (0 for a
        correct certificate; 0 where no certified front exists).
    cpu_s : float
        CPU seconds of both methods (``time.process_time``; the machine may be loaded).
    """

    problem: str
    reference: str
    n_eval: int
    igd_nsga2: float
    igd_random: float
    normalised: bool
    igd_raw_nsga2: float
    igd_raw_random: float
    n_feasible_nsga2: int
    n_feasible_random: int
    n_front_nsga2: int
    n_front_random: int
    gap_nsga2_kwh: float
    gap_random_kwh: float
    n_below_certificate: int
    cpu_s: float

    @property
    def passed(self) -> bool:
        """NSGA-II's IGD is finite and below random sampling's, and no member is below a certificate."""
        return bool(np.isfinite(self.igd_nsga2) and self.igd_nsga2 < self.igd_random
                    and self.n_below_certificate == 0)


def _igd(pf: np.ndarray, F: np.ndarray, CV: np.ndarray) -> tuple[float, float, int, int]:
    """(raw IGD, normalised IGD, feasible count, non-dominated count) of the feasible non-dominated points of ``F``."""
    from pymoo.indicators.igd import IGD
    from pymoo.util.nds.non_dominated_sorting import find_non_dominated

    F = F[CV <= 0.0]
    n_feasible = len(F)
    if n_feasible == 0:
        return float("inf"), float("inf"), 0, 0
    F = F[find_non_dominated(F)]
    spread = np.ptp(pf, axis=0).min() > 0  # a single optimum cannot be normalised
    normalised = float(IGD(pf, zero_to_one=True)(F)) if spread else float("nan")
    return float(IGD(pf)(F)), normalised, n_feasible, len(F)


def nsga2_against_random(name: str, pop_size: int = 100, n_gen: int = 200, seed: int = 1,
                         **problem_kwargs) -> SanityResult:
    """Run NSGA-II and random sampling with the same budget on suite problem ``name``.

    Parameters
    ----------
    name : str
        A suite problem (:func:`pymoo_rail.suite.list_problems`).
    pop_size, n_gen : int
        NSGA-II's population and generations; random sampling draws ``pop_size * n_gen`` vectors
        uniformly inside the bounds.
    seed : int
        Seed of both (NSGA-II's ``minimize`` seed; the sampling's ``numpy`` generator).
    **problem_kwargs
        Passed to :func:`~pymoo_rail.suite.get_problem` (e.g. ``encoding="speed_codes"``, the
        ``-single`` forms of suite version 1); the reference front is the problem's.

    Returns
    -------
    SanityResult
    """
    from pymoo.algorithms.moo.nsga2 import NSGA2
    from pymoo.operators.sampling.rnd import FloatRandomSampling
    from pymoo.optimize import minimize

    start = time.process_time()
    problem = get_problem(name, **problem_kwargs)
    try:
        pf = problem.pareto_front()
        front = problem.certified_front()
        reference = "certified optimum" if problem.n_obj == 1 else "certified front"
    except NoExactFrontError:
        pf, front, reference = best_known_front(name).to_numpy(), None, "best-known front"
    res = minimize(problem, NSGA2(pop_size=pop_size), ("n_gen", n_gen), seed=seed)
    pop = res.pop
    cv = pop.get("CV")[:, 0]
    raw_nsga2, norm_nsga2, n_nsga2, nd_nsga2 = _igd(pf, pop.get("F"), cv)
    below = 0
    if front is not None:
        feasible = cv <= 0.0
        _, mask = front.below_certificate(pop.get("running_time_s")[feasible], pop.get("energy_kwh")[feasible])
        below = int(mask.sum())

    n_eval = pop_size * n_gen
    X = FloatRandomSampling()(problem, n_eval, random_state=np.random.default_rng(seed)).get("X")
    out = problem.evaluate(X, return_as_dictionary=True)
    cv_random = np.maximum(out["G"], 0.0).sum(axis=1) if out.get("G") is not None else np.zeros(len(X))
    raw_random, norm_random, n_random, nd_random = _igd(pf, out["F"], cv_random)
    normalised = problem.n_obj >= 2
    igd_nsga2, igd_random = (norm_nsga2, norm_random) if normalised else (raw_nsga2, raw_random)
    gaps = [_signed_gap(pf, F, c) if problem.n_obj == 1 else float("nan")
            for F, c in ((pop.get("F"), cv), (out["F"], cv_random))]
    return SanityResult(name, reference, n_eval, igd_nsga2, igd_random, normalised, raw_nsga2, raw_random,
                        n_nsga2, n_random, nd_nsga2, nd_random, *gaps, below, time.process_time() - start)


def _signed_gap(pf: np.ndarray, F: np.ndarray, CV: np.ndarray) -> float:
    """Best feasible value minus the single reference value (NaN when nothing is feasible)."""
    feasible = CV <= 0.0
    return float(F[feasible, 0].min() - pf[0, 0]) if feasible.any() else float("nan")


def nsga2_trace(name: str, seed: int = 1, generations=(1, 2, 3, 4, 5, 10, 20, 40, 100, 200), pop_size: int = 100,
                **problem_kwargs) -> list[dict]:
    """How NSGA-II's population moves on suite problem ``name``: feasibility, running times, energies.

    Parameters
    ----------
    name : str
        A suite problem.
    seed : int
        NSGA-II's seed.
    generations : sequence of int
        Generations to record (the run lasts until the largest).
    pop_size : int
        NSGA-II's population.
    **problem_kwargs
        Passed to :func:`~pymoo_rail.suite.get_problem` (e.g. ``encoding="speed_codes"``, the
        ``-single`` forms' encoding of suite version 1).

    Returns
    -------
    list of dict
        Per recorded generation: ``n_gen``, ``n_feasible``, the feasible members' least, median
        and largest running time (s), their least energy above the reference optimum
        (``best_gap_kwh``; ``-single`` problems, else the least energy), ``n_distinct_x`` (distinct
        decision vectors among the feasible members) and ``n_distinct_runs`` (distinct running time
        and energy pairs, to 1e-6: many speed codes give the same run, e.g. any code below the
        train's speed means coasting).
    """
    from pymoo.algorithms.moo.nsga2 import NSGA2
    from pymoo.core.callback import Callback
    from pymoo.optimize import minimize

    problem = get_problem(name, **problem_kwargs)
    offset = float(problem.pareto_front()[0, 0]) if problem.n_obj == 1 else 0.0
    wanted = set(int(g) for g in generations)
    rows = []

    class Record(Callback):
        def notify(self, algorithm):
            if algorithm.n_gen not in wanted:
                return
            pop = algorithm.pop
            feasible = pop.get("CV")[:, 0] <= 0.0
            t, e = pop.get("running_time_s")[feasible], pop.get("energy_kwh")[feasible]
            row = {"n_gen": int(algorithm.n_gen), "n_feasible": int(feasible.sum())}
            if feasible.any():
                row.update(t_min_s=float(t.min()), t_median_s=float(np.median(t)), t_max_s=float(t.max()),
                           best_gap_kwh=float(e.min() - offset),
                           n_distinct_x=int(len(np.unique(pop.get("X")[feasible], axis=0))),
                           n_distinct_runs=int(len(np.unique(np.round(np.column_stack([t, e]), 6), axis=0))))
            rows.append(row)

    minimize(problem, NSGA2(pop_size=pop_size), ("n_gen", max(wanted)), seed=seed, callback=Record())
    return rows
