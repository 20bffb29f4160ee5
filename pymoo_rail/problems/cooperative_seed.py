"""The paper's own encoding of two trains sharing braking energy (Chen et al. 2017), for reproduction.

``CooperativeSeedProblem`` is :class:`~pymoo_rail.problems.CooperativeTrainsProblem` with
``encoding="subsections"`` and the paper's remaining constraints. Each train's genes are its
braking distance and, per subsection (cut at every gradient and limit change, section 1.1), a
traction share, a turning speed and the share of the subsection run in its last phase
(:class:`pymoo_rail.sim.pacing.PacedSubsections`): the operating sequences of table 1 as rows of
the one simulation kernel, with one pace per train meeting the planned time. Every vector is on
time, so the paper's repair is not needed; its nested GA (:func:`nested_minimize`) and a
train-by-train search (:func:`alternating_minimize`) run on the problem unchanged.

Constraints (``G <= 0``), in ``constraint_names`` order:

- ``separation``: eq. 9, the following train A never closer to B than its braking distance at b;
- ``time``: the pace solve's guard, ``|T - T_plan| <= max_time_error_s`` for both trains;
- ``comfort``: eq. 8, the change of mean acceleration (over ``COMFORT_WINDOW_M`` each side) where
  the gradient changes between subsections, at most ``max_accel_change_ms2``;
- ``braking``: the constant deceleration of the braking phase, ``v_m^2 / (2 dS)``, at most b.

Speed limits (eq. 7) hold by construction: the kernel never runs above its braking envelope.
"""

from __future__ import annotations

import copy
from typing import Sequence

import numpy as np
from pymoo.core.problem import Problem

from pymoo_rail.model import Case
from pymoo_rail.problems.cooperative import (  # noqa: F401 (re-exported for reproduction scripts)
    SEED_001_OFFSETS_S,
    CooperativeTrainsProblem,
    finite_number,
    scale_gradients,
)
from pymoo_rail.sim.pacing import PacedSubsections

SEED_CONSTRAINTS = ("separation", "time", "comfort", "braking")
# eq. 8 compares the acceleration before and after a gradient change: each side's is the mean over
# this distance (about a second of running), so the measure does not depend on the grid step
COMFORT_WINDOW_M = 10.0


def comfort_and_braking(encoding: PacedSubsections, genes: np.ndarray, position_m: np.ndarray,
                        speed_ms: np.ndarray, dx_m: float) -> tuple[float, float]:
    """(largest change of mean acceleration at a gradient change, braking deceleration) of one traced run.

    ``genes`` are the train's genes (``genes[0]`` is ``dS``); ``position_m``, ``speed_ms`` its trace
    nodes on the grid of step ``dx_m``. Accelerations are ``(v1^2 - v0^2) / (2 d)`` over
    ``COMFORT_WINDOW_M`` on each side of the change, inside the subsections before the braking point.
    """
    n = speed_ms.shape[0]
    brake_point = encoding.length_m - float(genes[0])
    p_node = int(round(brake_point / dx_m))
    decel = speed_ms[p_node] ** 2 / (2.0 * float(genes[0])) if p_node < n else np.inf
    w = max(1, int(round(COMFORT_WINDOW_M / dx_m)))
    worst = 0.0
    for k in np.flatnonzero(encoding.grade_change):
        start = int(round(encoding.boundaries_m[k] / dx_m))
        end = min(int(round(encoding.boundaries_m[k + 1] / dx_m)), p_node)
        prev = int(round(encoding.boundaries_m[k - 1] / dx_m))
        w1, w2 = min(w, start - prev), min(w, end - start)
        if w1 < 1 or w2 < 1 or start + w2 >= n:
            continue
        u = speed_ms ** 2
        before = (u[start] - u[start - w1]) / (2.0 * w1 * dx_m)
        after = (u[start + w2] - u[start]) / (2.0 * w2 * dx_m)
        worst = max(worst, abs(after - before))
    return worst, decel


class CooperativeSeedProblem(CooperativeTrainsProblem):
    """The paper's decision vector and constraints for two trains sharing braking energy.

    Parameters
    ----------
    case, offset_s
        As for :class:`~pymoo_rail.problems.CooperativeTrainsProblem`.
    max_accel_change_ms2 : float or None
        delta of eq. 8 (Chen et al. 2017 table 3: 0.8 m/s^2); ``None`` drops the comfort constraint.
    brake_range_factor : float
        r of section 3.2 (1.5).
    **kwargs
        Everything else of :class:`~pymoo_rail.problems.CooperativeTrainsProblem` (safety margin,
        b = ``separation_decel_ms2`` (table 3: 1.0 m/s^2), ``share_energy``, grid ...).

    Notes
    -----
    The genes of train A come first (``brake_a_m``, then ``gamma_a1, turn_a1, last_a1, ...``),
    then those of B; :attr:`brake_columns` are the two braking distances (the nested GA's outer
    chromosome).
    """

    constraint_names = SEED_CONSTRAINTS

    def __init__(self, case: Case, offset_s: float, *, max_accel_change_ms2: float | None = 0.8,
                 brake_range_factor: float = 1.5, **kwargs):
        self.max_accel_change_ms2 = (None if max_accel_change_ms2 is None
                                     else finite_number("max_accel_change_ms2", max_accel_change_ms2, positive=True))
        finite_number("brake_range_factor", brake_range_factor, positive=True)
        super().__init__(case, offset_s, encoding="subsections", brake_range_factor=brake_range_factor, **kwargs)

    @property
    def brake_columns(self) -> np.ndarray:
        """Indices of the braking distances ``dS_A``, ``dS_B`` in the decision vector."""
        return np.array([s.start for s in self.slices])

    def _constraints(self, sim: dict) -> np.ndarray:
        base = super()._constraints(sim)
        X = sim["X"]
        comfort = np.empty(X.shape[0])
        braking = np.empty(X.shape[0])
        for i, runs in enumerate(sim["clocked"]):
            worst_c, worst_b = -np.inf, -np.inf
            for tr, s, run in zip(self.trains, self.slices, runs):
                c, b = comfort_and_braking(tr.encoding, X[i, s], run.position_m, run.speed_ms,
                                           tr.simulator.model.dx_m)
                worst_c, worst_b = max(worst_c, c), max(worst_b, b)
            comfort[i] = -1.0 if self.max_accel_change_ms2 is None else worst_c - self.max_accel_change_ms2
            braking[i] = worst_b - self.separation_decel_ms2
        return np.column_stack([base, comfort, braking])


# ---------------------------------------------------------------------- the nested GA of section 3
class PartialProblem(Problem):
    """A problem with some genes held at reference values: only the ``free`` ones vary.

    Evaluating a partial vector evaluates the full one. Used by the nested GA and by
    :func:`alternating_minimize`.
    """

    def __init__(self, problem: Problem, free: np.ndarray, x_ref: np.ndarray):
        free = np.asarray(free, dtype=bool)
        x_ref = np.asarray(x_ref, dtype=float)
        if free.shape != (problem.n_var,) or x_ref.shape != (problem.n_var,) or not free.any():
            raise ValueError(f"free and x_ref must have n_var = {problem.n_var} entries, with at least one free gene")
        self.problem = problem
        self.free = free
        self.x_ref = x_ref
        super().__init__(n_var=int(free.sum()), n_obj=problem.n_obj, n_ieq_constr=problem.n_ieq_constr,
                         xl=problem.xl[free].copy(), xu=problem.xu[free].copy(), vtype=float)

    def full(self, x: np.ndarray) -> np.ndarray:
        """Full decision vectors: the reference vector with the free variables taken from ``x``."""
        x = np.atleast_2d(np.asarray(x, dtype=float))
        X = np.repeat(self.x_ref[None, :], x.shape[0], axis=0)
        X[:, self.free] = x
        return X

    def _evaluate(self, x, out, *args, **kwargs):
        res = self.problem.evaluate(self.full(x), return_as_dictionary=True)
        out["F"] = res["F"]
        out["G"] = res["G"]


class FixedBrakingProblem(PartialProblem):
    """The inner problem of the nested GA: the cooperative problem with both braking distances fixed."""

    def __init__(self, problem: CooperativeSeedProblem, brake_m: Sequence[float]):
        free = np.ones(problem.n_var, dtype=bool)
        free[problem.brake_columns] = False
        x_ref = problem.xl.copy()
        x_ref[problem.brake_columns] = np.asarray(brake_m, dtype=float)
        super().__init__(problem, free, x_ref)
        self.brake_m = np.asarray(brake_m, dtype=float)


class BrakingDistanceProblem(Problem):
    """The outer problem of the nested GA: braking distances, each evaluated by an inner pymoo run.

    The value of a pair of braking distances is the best the inner algorithm finds for the rest of
    the vector (Chen et al. 2017 section 3.1); its constraint is that solution's violation. Inner runs are
    seeded from the outer algorithm's ``random_state``.
    """

    def __init__(self, problem: CooperativeSeedProblem, inner_algorithm, inner_termination):
        self.problem = problem
        self.inner_algorithm = inner_algorithm
        self.inner_termination = inner_termination
        cols = problem.brake_columns
        super().__init__(n_var=2, n_obj=1, n_ieq_constr=1, xl=problem.xl[cols].copy(), xu=problem.xu[cols].copy(),
                         vtype=float)

    def _evaluate(self, x, out, *args, algorithm=None, **kwargs):
        from pymoo.optimize import minimize

        rng = algorithm.random_state if algorithm is not None else np.random.default_rng(0)
        f = np.empty(x.shape[0])
        g = np.empty(x.shape[0])
        inner = np.empty((x.shape[0], self.problem.n_var))
        for i, brake in enumerate(x):
            partial = FixedBrakingProblem(self.problem, brake)
            res = minimize(partial, copy.deepcopy(self.inner_algorithm), self.inner_termination,
                           seed=int(rng.integers(2**31 - 1)))
            best = res.algorithm.opt[0]  # the best found, or the least infeasible
            f[i] = best.F[0]
            g[i] = best.CV[0]
            inner[i] = partial.full(best.X)[0]
        out["F"] = f[:, None]
        out["G"] = g[:, None]
        out["full_X"] = inner


def nested_minimize(problem: CooperativeSeedProblem, *, outer_pop_size: int = 24, outer_n_gen: int = 20,
                    inner_pop_size: int = 100, inner_n_gen: int = 80, inner_algorithm=None, seed: int = 1,
                    verbose: bool = False):
    """The nested GA of Chen et al. (2017) section 3: an outer pymoo GA on the braking distances whose every
    evaluation runs an inner pymoo GA on the rest of the vector.

    Defaults are the paper's sizes (section 4.1: outer 24 x 20, inner 100 x 80, 3.84 million
    evaluations); pymoo's GA operators (SBX, polynomial mutation, elitist survival) stand in for
    the paper's roulette wheel and one/two-point operators. No repair: every vector is on time.
    Returns ``(x, F, outer_result)`` with ``x`` the full best vector.
    """
    from pymoo.algorithms.soo.nonconvex.ga import GA
    from pymoo.optimize import minimize

    if inner_algorithm is None:
        inner_algorithm = GA(pop_size=inner_pop_size, eliminate_duplicates=True)
    outer = BrakingDistanceProblem(problem, inner_algorithm, ("n_gen", inner_n_gen))
    res = minimize(outer, GA(pop_size=outer_pop_size, eliminate_duplicates=True), ("n_gen", outer_n_gen), seed=seed,
                   verbose=verbose)
    best = res.algorithm.opt[0]  # the best found, or the least infeasible
    return best.get("full_X"), float(best.F[0]), res


def train_genes(problem: CooperativeTrainsProblem, k: int) -> np.ndarray:
    """Mask of train k's genes."""
    mask = np.zeros(problem.n_var, dtype=bool)
    mask[problem.slices[k]] = True
    return mask


def alternating_minimize(problem: CooperativeTrainsProblem, x0: np.ndarray, *, rounds: int = 2,
                         n_evals: Sequence[int] = (4000, 3000), pop_size: int = 40, seed: int = 1,
                         algorithm=None):
    """Train-by-train optimisation: A and B take turns, each optimised with the other held fixed.

    Each turn is a pymoo run (by default DE/best/1/bin, CR 0.3) on a :class:`PartialProblem`
    holding one train's genes free, started from the current vector plus random vectors. A turn
    keeps its result only when it is at least as good, so the objective never rises. Returns
    ``(x, F)``.
    """
    from pymoo.algorithms.soo.nonconvex.de import DE
    from pymoo.core.evaluator import Evaluator
    from pymoo.core.population import Population
    from pymoo.optimize import minimize

    x = np.asarray(x0, dtype=float).copy()

    def score(vec):
        pop = Population.new(X=np.atleast_2d(vec))
        Evaluator().eval(problem, pop)
        return float(pop.get("F")[0, 0]), float(pop.get("CV")[0, 0])

    best = score(x)
    rng = np.random.default_rng(seed)
    for r in range(rounds):
        for k in (0, 1):
            sub_problem = PartialProblem(problem, train_genes(problem, k), x)
            X = sub_problem.xl + rng.random((pop_size, sub_problem.n_var)) * (sub_problem.xu - sub_problem.xl)
            X[0] = x[sub_problem.free]
            algo = copy.deepcopy(algorithm) if algorithm is not None else DE(
                pop_size=pop_size, variant="DE/best/1/bin", CR=0.3, F=0.5)
            algo.initialization.sampling = X
            res = minimize(sub_problem, algo, ("n_evals", n_evals[k % len(n_evals)]),
                           seed=int(rng.integers(2**31 - 1)))
            cand = sub_problem.full(res.algorithm.opt[0].X)[0]
            cand_score = score(cand)
            if (cand_score[1], cand_score[0]) <= (best[1], best[0]):
                x, best = cand, cand_score
    return x, best[0]
