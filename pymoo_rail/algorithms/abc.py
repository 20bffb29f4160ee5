"""Artificial Bee Colony (ABC) for single-objective problems.

Karaboga's canonical ABC as described in Liu (2019), sections 3.2-3.3, written as a pymoo
``Algorithm`` in ask/tell form: one pymoo iteration (one ``ask``/``tell`` round, as pymoo counts
``n_gen``) is one phase, so a cycle (employed, onlooker, and the scouts flying with the next
employed phase) is two iterations and nothing is evaluated inside the algorithm.
"""

from __future__ import annotations

import numpy as np
from pymoo.core.population import Population
from pymoo.core.replacement import parameter_less
from pymoo.core.sampling import Sampling
from pymoo.operators.sampling.rnd import FloatRandomSampling
from pymoo.util.display.single import SingleObjectiveOutput
from pymoo.util.optimum import filter_optimum

from pymoo_rail.algorithms._bees import (
    BeeColony,
    ScoutColumn,
    feasibility_first_better,
    one_variable_move,
    random_partners,
)


class ABCOutput(ScoutColumn, SingleObjectiveOutput):
    """Verbose output of :class:`ABC`: best and mean objective plus scouts per cycle."""


def rank_probabilities(F: np.ndarray, CV: np.ndarray) -> np.ndarray:
    """Onlooker probabilities from linear ranking of the food sources.

    Sources are ordered feasibility first (by constraint violation, then by objective);
    the best of ``SN`` sources gets fitness ``SN``, the worst ``1``, and
    ``P_i = fit_i / sum(fit)``. Unlike ``1 / (1 + f)`` (Liu (2019), eq. 3-3) this does not
    depend on the scale or sign of ``f`` and does not flatten out near ``f = 0``.
    Ties keep their index order, so the result is deterministic.
    """
    n = len(F)
    order = np.lexsort((F, CV))
    fitness = np.empty(n)
    fitness[order] = np.arange(n, 0, -1, dtype=float)
    return fitness / fitness.sum()


def inverse_probabilities(F: np.ndarray, CV: np.ndarray) -> np.ndarray:
    """Onlooker probabilities of Liu (2019), eqs. 3-3 and 3-5 (Karaboga's fitness).

    ``fit = 1 / (1 + f)`` for ``f >= 0`` and ``1 + |f|`` otherwise, ``P_i = fit_i / sum(fit)``.
    Infeasible sources are first given pymoo's parameter-less value ``max(f) + CV``, so they
    rank below every feasible one. Near ``f = 0`` all fitness values approach 1 and the
    choice becomes uniform.
    """
    f = parameter_less(F, CV) if np.any(CV > 0) else F
    fitness = np.where(f >= 0, 1.0 / (1.0 + np.abs(f)), 1.0 + np.abs(f))
    return fitness / fitness.sum()


ONLOOKER_FITNESS = {"rank": rank_probabilities, "inverse": inverse_probabilities}


class ABC(BeeColony):
    """Artificial Bee Colony (Karaboga 2005; Liu (2019), sections 3.2-3.3).

    Parameters
    ----------
    pop_size : int
        Colony size: employed plus onlooker bees, as in Liu (2019) (a colony of 30 has 15
        employed bees, 15 onlookers and ``SN = 15`` food sources). Must be even and at
        least 4 (the neighbour move needs a second food source). The initial sample has
        ``pop_size`` points and the best ``SN = pop_size // 2`` become the food sources
        (Liu (2019), section 3.3, steps 1-3).
    limit : int, optional
        A food source whose trial counter exceeds ``limit`` is abandoned and replaced by a
        random one (scout bee). Default ``SN * n_var``.
    onlooker_fitness : {"rank", "inverse"}
        Fitness behind the onlookers' roulette. ``"rank"`` (default): linear ranking, see
        :func:`rank_probabilities`. ``"inverse"``: the seed's ``1 / (1 + f)`` (eq. 3-3), see
        :func:`inverse_probabilities`; kept to reproduce the seed.
    sampling : pymoo Sampling
        Draws the initial colony and the scouts' new food sources.
    output : pymoo Output
        Verbose output; shows best and mean objective and the number of scouts per cycle.
    **kwargs
        Passed on to :class:`pymoo.core.algorithm.Algorithm`.

    Notes
    -----
    One pymoo iteration is one ``ask``/``tell`` round, as pymoo counts ``n_gen``: the employed
    phase (``SN`` evaluations plus one per scout) or the onlooker phase (``SN`` evaluations).
    A cycle is two iterations, so ``maxCycle`` cycles are ``("n_gen", 1 + 2 * maxCycle)``
    (the onlookers choose from the colony the employed bees have just improved, so the two
    phases cannot share one evaluation). The cycle is:

    * Employed bees: for every food source ``i`` one random variable ``j`` moves,
      ``v_ij = x_ij + phi (x_ij - x_kj)``, ``phi ~ U[-1, 1]``, ``k != i`` uniform; the result
      is clamped to ``[xl, xu]``.
    * Greedy choice: the candidate replaces its source only if it is strictly better by
      pymoo's feasibility-first rule (less constraint violation, or both feasible and
      smaller ``F``). Objective values are compared directly, not through ``1 / (1 + f)``,
      which saturates near 0. A candidate equal to its source is a failed trial.
    * Onlooker bees: ``SN`` onlookers pick food sources by roulette on linear-ranking
      fitness (see :func:`rank_probabilities`; works for negative ``F`` and with
      constraints; ``onlooker_fitness="inverse"`` selects the seed's eq. 3-3) and move
      like employed bees. Several onlookers on the same source are
      applied one after another in draw order.
    * Scout bees: every source whose trial counter exceeds ``limit`` after the onlooker phase
      is replaced by a random point (Liu (2019) step 7-8 abandons each such source, not only
      the worst); the random points are evaluated with the next employed phase, whose bees
      start from them.

    The phases work on the colony as it was when the phase was asked for (a batch, not a
    bee-by-bee sequence), so one phase is one ``ask``/``tell``. The best solution ever seen
    is kept in ``opt``, so an abandoned best source is not lost. ``pop`` holds the current
    food sources.
    """

    def __init__(
        self,
        pop_size: int = 40,
        limit: int | None = None,
        onlooker_fitness: str = "rank",
        sampling: Sampling = FloatRandomSampling(),
        output=ABCOutput(),
        **kwargs,
    ) -> None:
        super().__init__(pop_size, limit, sampling, min_pop_size=4, output=output, **kwargs)
        if onlooker_fitness not in ONLOOKER_FITNESS:
            raise ValueError(
                f"onlooker_fitness must be one of {tuple(ONLOOKER_FITNESS)}, "
                f"got {onlooker_fitness!r}"
            )
        self.onlooker_fitness = onlooker_fitness

    def _setup(self, problem, **kwargs) -> None:
        if problem.n_obj != 1:
            raise ValueError(f"ABC is single-objective, the problem has n_obj={problem.n_obj}")
        super()._setup(problem, **kwargs)

    # ------------------------------------------------------------------ initialisation
    def _initialize_advance(self, infills=None, **kwargs) -> None:
        F, CV = infills.get("F")[:, 0], infills.get("CV")[:, 0]
        self._start_colony(infills, np.lexsort((F, CV)))

    # ------------------------------------------------------------------ one cycle
    def _onlooker_probabilities(self) -> np.ndarray:
        F, CV = self.pop.get("F")[:, 0], self.pop.get("CV")[:, 0]
        return ONLOOKER_FITNESS[self.onlooker_fitness](F, CV)

    def _candidates(self, X_sources: np.ndarray, parents: np.ndarray) -> np.ndarray:
        partners = random_partners(self.n_sources, self.random_state)[parents]
        return one_variable_move(
            X_sources[parents], X_sources[partners], self._xl, self._xu, self.random_state
        )

    def _greedy(self, candidates: Population) -> None:
        """Replace sources by strictly better candidates, in draw order; count trials."""
        off_F, off_CV = candidates.get("F")[:, 0], candidates.get("CV")[:, 0]
        pop_F, pop_CV = self.pop.get("F")[:, 0], self.pop.get("CV")[:, 0]
        self._keep_better(candidates, off_F, off_CV, pop_F, pop_CV, feasibility_first_better)

    def _set_optimum(self) -> None:
        # keep the best ever seen: scouts may abandon the current best source
        candidates = self.pop if self.opt is None else Population.merge(self.opt, self.pop)
        self.opt = filter_optimum(candidates, least_infeasible=True)
