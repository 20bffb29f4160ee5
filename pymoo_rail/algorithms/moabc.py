"""Multi-objective Artificial Bee Colony (MOABC) of Liu (2019), section 4.5.2.

Pareto-dominance greedy choice, onlooker fitness ``dom(i) / N``, an external archive of
non-dominated solutions truncated by crowding distance, and a neighbour search guided by
a random archive member. Same ask/tell structure as :class:`pymoo_rail.algorithms.ABC`:
one pymoo iteration is one phase (employed or onlooker), a bee cycle is two iterations.
"""

from __future__ import annotations

import numpy as np
from pymoo.core.individual import default_config
from pymoo.core.population import Population
from pymoo.core.sampling import Sampling
from pymoo.operators.sampling.rnd import FloatRandomSampling
from pymoo.operators.survival.rank_and_crowding.metrics import calc_crowding_distance
from pymoo.util.display.multi import MultiObjectiveOutput
from pymoo.util.nds.non_dominated_sorting import NonDominatedSorting

from pymoo_rail.algorithms._bees import (
    BeeColony,
    ScoutColumn,
    constraint_dominates,
    one_variable_move,
)

MOVES = ("centred", "canonical", "literal")
_DEFAULT_CV_CONFIG = default_config()


class MOABCOutput(ScoutColumn, MultiObjectiveOutput):
    """Verbose output of :class:`MOABC`: pymoo's multi-objective columns plus scouts."""


def domination_counts(F: np.ndarray, CV: np.ndarray) -> np.ndarray:
    """``dom(i)``: how many members of the set solution ``i`` constraint-dominates."""
    n = len(F)
    less_eq = np.all(F[:, None, :] <= F[None, :, :], axis=2)
    less = np.any(F[:, None, :] < F[None, :, :], axis=2)
    pareto = less_eq & less & (CV[:, None] == CV[None, :])
    dominates = (CV[:, None] < CV[None, :]) | pareto
    dominates[np.arange(n), np.arange(n)] = False
    return dominates.sum(axis=1)


def dominance_probabilities(F: np.ndarray, CV: np.ndarray) -> np.ndarray:
    """Onlooker probabilities ``P_i = fit_i / sum(fit)`` with ``fit_i = dom(i) / N``.

    Seed 000, eq. 4-25 with eq. 3-5. When no food source dominates another (all mutually
    non-dominated, usual late in a run) every ``fit_i`` is 0 and ``P`` is uniform.
    """
    fit = domination_counts(F, CV) / len(F)
    total = fit.sum()
    if total == 0.0:
        return np.full(len(F), 1.0 / len(F))
    return fit / total


def population_arrays(pop: Population) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Decisions (n, n_var), objectives (n, n_obj) and violations (n,) of a non-empty population.

    The same values as ``pop.get("X")``, ``pop.get("F")``, ``pop.get("CV")[:, 0]`` in one pass.
    """
    X = np.array([ind.X for ind in pop])
    F = np.array([ind.F for ind in pop])
    if all((ind.H is None or len(ind.H) == 0) and ind.config == _DEFAULT_CV_CONFIG for ind in pop):
        # pymoo's default violation (sum of positive G, no H) for all rows at once
        G = np.array([ind.G if ind.G is not None else np.zeros(0) for ind in pop])
        return X, F, np.maximum(0.0, G - 0.0).sum(axis=1) if G.shape[1] > 0 else np.zeros(len(pop))
    return X, F, np.array([ind.CV[0] for ind in pop])


def nondominated_indices(X: np.ndarray, F: np.ndarray, CV: np.ndarray) -> np.ndarray:
    """Indices (ascending) of the constraint-non-dominated rows, first copy of each ``X`` only.

    With at least one feasible row these are the feasible Pareto-optimal ones; otherwise the
    least-violating ones (ties broken by Pareto dominance).
    """
    if len(X) == 0:
        return np.zeros(0, dtype=int)
    _, first = np.unique(X, axis=0, return_index=True)
    idx = np.sort(first)
    cv = CV[idx]
    idx = idx[cv == cv.min()]
    front = NonDominatedSorting().do(F[idx], only_non_dominated_front=True)
    return idx[np.sort(front)]


def nondominated(pop: Population) -> Population:
    """Constraint-non-dominated members of ``pop``, without duplicate ``X``, in order."""
    if len(pop) == 0:
        return pop
    return pop[nondominated_indices(pop.get("X"), pop.get("F"), pop.get("CV")[:, 0])]


def crowding_truncation_indices(F: np.ndarray, max_size: int) -> np.ndarray:
    """Indices (ascending) of the rows of ``F`` kept by :func:`truncate_by_crowding`."""
    keep = np.arange(len(F))
    while len(keep) > max_size:
        cd = calc_crowding_distance(F[keep])
        keep = np.delete(keep, int(np.argmin(cd)))
    return keep


def truncate_by_crowding(pop: Population, max_size: int) -> Population:
    """Remove the most crowded member, one at a time, until ``len(pop) <= max_size``.

    Crowding distance as in NSGA-II (Liu (2019), eq. 4-26), recomputed after every removal;
    boundary points have infinite distance. Ties go to the lowest index, so the result is
    deterministic.
    """
    if len(pop) <= max_size:
        return pop
    return pop[crowding_truncation_indices(pop.get("F"), max_size)]


class MOABC(BeeColony):
    """Multi-objective Artificial Bee Colony (Liu (2019), section 4.5.2).

    Parameters
    ----------
    pop_size : int
        Colony size (employed plus onlooker bees), even and at least 2; there are
        ``SN = pop_size // 2`` food sources. The initial sample has ``pop_size`` points;
        the ``SN`` with the largest ``dom(i)`` become food sources (Liu (2019), 4.5.3 step 3)
        and its non-dominated points start the archive.
    archive_size : int
        Maximum size of the external archive.
    w : float
        Scale factor ``w_1`` of eq. 4-27 (``"literal"``); scales ``phi`` for the other
        moves.
    move : {"centred", "canonical", "literal"}
        Neighbour search, always guided by a random archive member ``x_k``:

        * ``"centred"`` (default): one random variable ``j``,
          ``v_j = x_kj + w phi (x_ij - x_kj)``, ``phi ~ U[-1, 1]``.
        * ``"canonical"``: Karaboga's move with the archive member as partner,
          ``v_j = x_ij + w phi (x_ij - x_kj)``.
        * ``"literal"``: eq. 4-27 read literally, all variables,
          ``v = x_i + w r (x_i - x_k)``, ``r ~ U[0, 1]``.

        The literal move pushes ``x_i`` away from the archive and does not converge
        (IGD around 2 on ZDT1); the canonical move converges; centring on the archive
        member pulls the changed variable into the neighbourhood of the current front
        and converges fastest (see ``benchmarks/reports/moabc_zdt.md``).
    limit : int, optional
        Trial limit before a food source is abandoned (scout). Default ``SN * n_var``.
    sampling : pymoo Sampling
        Initial colony and scouts.
    output : pymoo Output
        Verbose output.
    **kwargs
        Passed on to :class:`pymoo.core.algorithm.Algorithm`.

    Notes
    -----
    * Budget: one pymoo iteration is one ``ask``/``tell`` round, as pymoo counts ``n_gen``:
      the employed phase (``SN`` candidates plus the scouts' new points) or the onlooker
      phase (``SN`` candidates). Liu (2019), 4.5.3 step 5, has the onlookers choose from the
      colony the employed bees have just improved, so the two phases cannot share one
      evaluation: ``maxCycle`` cycles are ``("n_gen", 1 + 2 * maxCycle)``, and the counter
      ``n_cycles`` holds the cycles completed.
    * Greedy choice: a candidate replaces its food source only if it constraint-dominates
      it (less violation, or equal violation and Pareto-dominance). Otherwise the source
      stays and its trial counter grows by one (also when the two are mutually
      non-dominated; the candidate still reaches the archive).
    * Onlookers choose food sources by roulette on ``fit_i = dom(i) / N`` where ``dom(i)``
      counts the food sources that ``i`` constraint-dominates and ``N = SN``; see
      :func:`dominance_probabilities`.
    * The archive (attribute ``pareto_archive``) receives every evaluated candidate, keeps
      the constraint-non-dominated ones and, above ``archive_size``, drops the most crowded
      point one at a time (:func:`truncate_by_crowding`). ``opt``, and therefore
      ``res.X``/``res.F``, is this archive; ``pop`` holds the current food sources.
      ``archive_X``, ``archive_F`` and ``archive_CV`` hold its decisions, objectives and
      violations as arrays, row by row; sorting and truncation work on them.
    """

    def __init__(
        self,
        pop_size: int = 100,
        archive_size: int = 100,
        w: float = 1.0,
        move: str = "centred",
        limit: int | None = None,
        sampling: Sampling = FloatRandomSampling(),
        output=MOABCOutput(),
        **kwargs,
    ) -> None:
        super().__init__(pop_size, limit, sampling, min_pop_size=2, output=output, **kwargs)
        if (
            isinstance(archive_size, bool)
            or not isinstance(archive_size, (int, np.integer))
            or archive_size < 1
        ):
            raise ValueError(f"archive_size must be an integer >= 1, got {archive_size!r}")
        self.archive_size = int(archive_size)
        if move not in MOVES:
            raise ValueError(f"move must be one of {MOVES}, got {move!r}")
        self.move = move
        if not np.isfinite(w) or w <= 0:
            raise ValueError(f"w must be a positive finite number, got {w!r}")
        self.w = float(w)
        self.pareto_archive: Population | None = None
        # the archive's decisions, objectives and violations, aligned with ``pareto_archive``:
        # reading them back from the individuals each cycle cost more than the simulations
        self.archive_X: np.ndarray | None = None
        self.archive_F: np.ndarray | None = None
        self.archive_CV: np.ndarray | None = None
        self._infill_arrays: tuple | None = None

    # ------------------------------------------------------------------ initialisation
    def _initialize_advance(self, infills=None, **kwargs) -> None:
        dom = domination_counts(infills.get("F"), infills.get("CV")[:, 0])
        self.pareto_archive = Population.empty()
        self.archive_X = np.zeros((0, self.problem.n_var))
        self.archive_F = np.zeros((0, self.problem.n_obj))
        self.archive_CV = np.zeros(0)
        self._update_archive(infills, population_arrays(infills))
        self._start_colony(infills, np.argsort(-dom, kind="stable"))

    # ------------------------------------------------------------------ one cycle
    def _onlooker_probabilities(self) -> np.ndarray:
        _, F, CV = population_arrays(self.pop)
        return dominance_probabilities(F, CV)

    def _candidates(self, X_sources: np.ndarray, parents: np.ndarray) -> np.ndarray:
        X = X_sources[parents]
        guides = self.random_state.integers(0, len(self.pareto_archive), size=len(X))
        return self._move(X, self.archive_X[guides])

    def _move(self, X: np.ndarray, X_k: np.ndarray) -> np.ndarray:
        if self.move == "literal":
            r = self.random_state.random((len(X), 1))
            return np.clip(X + self.w * r * (X - X_k), self._xl, self._xu)
        return one_variable_move(
            X,
            X_k,
            self._xl,
            self._xu,
            self.random_state,
            centre_on_partner=self.move == "centred",
            scale=self.w,
        )

    def _observe(self, infills: Population) -> None:
        self._infill_arrays = population_arrays(infills)  # read once, used by _greedy too
        self._update_archive(infills, self._infill_arrays)  # every evaluated candidate may enter the archive

    def _greedy(self, candidates: Population) -> None:
        """Replace a source by a candidate that constraint-dominates it; count trials."""
        # the candidates are the last rows of the evaluated batch (scouts come first);
        # Python floats: a scalar comparison per pair is cheaper on lists than on array rows
        first = len(self._infill_arrays[0]) - len(candidates)
        _, off_F, off_CV = (a[first:].tolist() for a in self._infill_arrays)
        _, pop_F, pop_CV = (a.tolist() for a in population_arrays(self.pop))
        self._keep_better(candidates, off_F, off_CV, pop_F, pop_CV, constraint_dominates)

    def _update_archive(self, infills: Population, arrays: tuple) -> None:
        X_new, F_new, CV_new = arrays
        X = np.concatenate([self.archive_X, X_new])
        F = np.concatenate([self.archive_F, F_new])
        CV = np.concatenate([self.archive_CV, CV_new])
        keep = nondominated_indices(X, F, CV)
        keep = keep[crowding_truncation_indices(F[keep], self.archive_size)]
        self.pareto_archive = Population.merge(self.pareto_archive, infills)[keep]
        self.archive_X, self.archive_F, self.archive_CV = X[keep], F[keep], CV[keep]

    def _set_optimum(self) -> None:
        self.opt = self.pareto_archive
