"""Building blocks shared by the bee-colony algorithms (ABC and MOABC).

The functions here are pure: random numbers come from the generator that is passed in (the
algorithm's ``random_state``), never from global state. ``BeeColony`` is the cycle both
algorithms run.
"""

from __future__ import annotations

import numpy as np
from pymoo.core.algorithm import Algorithm
from pymoo.core.population import Population
from pymoo.util.display.column import Column


def check_colony_size(pop_size: object, minimum: int) -> int:
    """Validate the colony size and return the number of food sources ``SN``.

    Parameters
    ----------
    pop_size
        Colony size (employed plus onlooker bees). Must be an even integer
        (employed bees = onlooker bees = food sources).
    minimum
        Smallest allowed colony size.

    Returns
    -------
    int
        ``pop_size // 2``, the number of food sources.

    Raises
    ------
    ValueError
        If ``pop_size`` is not an integer, is odd or is smaller than ``minimum``.
    """
    if isinstance(pop_size, bool) or not isinstance(pop_size, (int, np.integer)):
        raise ValueError(f"pop_size must be an even integer >= {minimum}, got {pop_size!r}")
    if pop_size < minimum:
        raise ValueError(f"pop_size must be an even integer >= {minimum}, got {pop_size}")
    if pop_size % 2 != 0:
        raise ValueError(
            f"pop_size must be even (colony = employed + onlooker bees, one employed bee per "
            f"food source), got {pop_size}"
        )
    return int(pop_size) // 2


def check_limit(limit: object) -> int | None:
    """Validate the abandonment limit (``None`` means the default ``SN * D``)."""
    if limit is None:
        return None
    if isinstance(limit, bool) or not isinstance(limit, (int, np.integer)) or limit < 0:
        raise ValueError(f"limit must be None or an integer >= 0, got {limit!r}")
    return int(limit)


def check_bounds(problem) -> tuple[np.ndarray, np.ndarray]:
    """Return the bounds ``(xl, xu)`` of a problem; bee colonies need finite bounds."""
    if not problem.has_bounds():
        raise ValueError("bee colony algorithms need a problem with finite bounds xl and xu")
    xl, xu = problem.bounds()
    xl = np.asarray(xl, dtype=float)
    xu = np.asarray(xu, dtype=float)
    if not (np.all(np.isfinite(xl)) and np.all(np.isfinite(xu))):
        raise ValueError("bee colony algorithms need a problem with finite bounds xl and xu")
    return xl, xu


def one_variable_move(
    X: np.ndarray,
    partners: np.ndarray,
    xl: np.ndarray,
    xu: np.ndarray,
    random_state: np.random.Generator,
    centre_on_partner: bool = False,
    scale: float = 1.0,
) -> np.ndarray:
    """Karaboga's neighbour move on one random variable per row, clamped to the bounds.

    ``v_ij = x_ij + phi (x_ij - x_kj)`` (or ``x_kj + phi (x_ij - x_kj)`` when
    ``centre_on_partner``), ``phi ~ scale * U[-1, 1]``, ``j`` uniform; all other variables
    are copied from ``X``.

    Parameters
    ----------
    X
        Current positions, shape (n, n_var).
    partners
        Partner positions ``x_k``, shape (n, n_var).
    xl, xu
        Bounds used for clamping.
    random_state
        Generator for ``j`` and ``phi``.
    centre_on_partner
        Centre the move on the partner instead of on ``x_i``.
    scale
        Multiplies ``phi``.

    Returns
    -------
    numpy.ndarray
        New positions, shape (n, n_var).
    """
    n, n_var = X.shape
    rows = np.arange(n)
    j = random_state.integers(0, n_var, size=n)
    phi = scale * random_state.uniform(-1.0, 1.0, size=n)
    x_ij = X[rows, j]
    x_kj = partners[rows, j]
    centre = x_kj if centre_on_partner else x_ij
    V = X.copy()
    V[rows, j] = np.clip(centre + phi * (x_ij - x_kj), xl[j], xu[j])
    return V


def random_partners(n: int, random_state: np.random.Generator) -> np.ndarray:
    """For each food source ``i`` in ``0..n-1`` draw a partner ``k != i`` uniformly."""
    k = random_state.integers(0, n - 1, size=n)
    # shift indices >= i up by one so k is uniform over the other n - 1 sources
    return k + (k >= np.arange(n))


def feasibility_first_better(
    f_new: float, cv_new: float, f_old: float, cv_old: float
) -> bool:
    """Deb's feasibility-first comparison of two single-objective solutions.

    A solution with smaller constraint violation wins while the old one is infeasible;
    between feasible ones the strictly smaller objective wins. Ties (e.g. an offspring
    equal to its parent) are not an improvement.
    """
    if cv_old > 0.0:
        return cv_new < cv_old
    return cv_new <= 0.0 and f_new < f_old


def constraint_dominates(f_a, cv_a: float, f_b, cv_b: float) -> bool:
    """Whether ``a`` constraint-dominates ``b`` (Deb): less violation first, then Pareto.

    ``f_a`` and ``f_b`` are objective vectors (arrays or lists of floats).
    """
    if cv_a < cv_b:
        return True
    if cv_b < cv_a:
        return False
    pairs = list(zip(f_a, f_b))
    return all(a <= b for a, b in pairs) and any(a < b for a, b in pairs)


def roulette(probabilities: np.ndarray, n: int, random_state: np.random.Generator) -> np.ndarray:
    """Draw ``n`` indices with the given probabilities (with replacement)."""
    return random_state.choice(len(probabilities), size=n, replace=True, p=probabilities)


EMPLOYED, ONLOOKER = "employed", "onlooker"


class BeeColony(Algorithm):
    """The employed - onlooker - scout cycle, one phase per pymoo iteration.

    pymoo counts one iteration (``n_gen``) per ``ask``/``tell`` round, and the onlookers of
    Liu (2019) (4.5.3 step 5, after step 4) choose their food sources from the colony the
    employed bees have just improved, so the two phases cannot share one evaluation. A bee
    cycle is therefore two pymoo iterations: the employed phase, then the onlooker phase.
    The scouts of a cycle (sources abandoned after the onlooker phase) fly with the next
    employed phase: their random points are the first rows of its infill, the employed bees
    of those sources move from the new points, and the greedy choice meets the scouts'
    values from the same evaluation. So ``n_gen = 1 + 2 * cycles`` (the initial colony is
    the first iteration), whatever the number of scouts, and a hand-written ask/tell loop
    with ``n`` rounds gets the same budget as ``minimize(..., ("n_gen", n))``.

    Subclasses provide ``_greedy(candidates)`` (keep better candidates, count trials),
    ``_onlooker_probabilities``, ``_candidates(X_sources, parents)`` and
    ``_initialize_advance`` (which calls :meth:`_start_colony`), and may override
    ``_observe(infills)`` to see every evaluated batch (MOABC's archive).

    Parameters
    ----------
    pop_size : int
        Colony size (employed plus onlooker bees), even and at least ``min_pop_size``.
    limit : int, optional
        Trial limit before a food source is abandoned. Default ``SN * n_var``.
    sampling : pymoo Sampling
        Initial colony and scouts.
    min_pop_size : int
        Smallest colony the subclass accepts.
    **kwargs
        Passed on to :class:`pymoo.core.algorithm.Algorithm`.
    """

    def __init__(self, pop_size: int, limit: int | None, sampling, min_pop_size: int, **kwargs) -> None:
        super().__init__(**kwargs)
        self.n_sources = check_colony_size(pop_size, minimum=min_pop_size)
        self.pop_size = int(pop_size)
        self.limit = check_limit(limit)
        self.sampling = sampling

        self.trials: np.ndarray | None = None
        self.n_scouts = 0
        self.n_scouts_total = 0
        self.n_cycles = 0
        self._phase = EMPLOYED
        self._parents: np.ndarray | None = None
        self._scouts = np.zeros(0, dtype=int)
        self._xl: np.ndarray | None = None
        self._xu: np.ndarray | None = None
        self._limit: int | None = None

    def _setup(self, problem, **kwargs) -> None:
        self._xl, self._xu = check_bounds(problem)
        self._limit = self.limit if self.limit is not None else self.n_sources * problem.n_var

    def _initialize_infill(self) -> Population:
        return self.sampling.do(self.problem, self.pop_size, random_state=self.random_state)

    def run_counters(self) -> dict[str, int]:
        """Totals of the run so far, stored with each study record: scouts sent."""
        return {"n_scouts_total": int(self.n_scouts_total)}

    def _observe(self, infills) -> None:
        """Called with every evaluated batch (scouts included) before it is used."""

    def _keep_better(self, infills: Population, off_F, off_CV, pop_F, pop_CV, better) -> None:
        """Greedy selection of both colonies: candidate ``c`` replaces source ``self._parents[c]`` when
        ``better(candidate F, CV, source F, CV)``; the source's trial counter restarts or grows.
        ``pop_F`` / ``pop_CV`` are updated in place, so a later candidate of the same source meets
        the new one."""
        for c, i in enumerate(self._parents):
            if better(off_F[c], off_CV[c], pop_F[i], pop_CV[i]):
                self.pop[i] = infills[c]
                pop_F[i], pop_CV[i] = off_F[c], off_CV[c]
                self.trials[i] = 0
            else:
                self.trials[i] += 1

    def _start_colony(self, infills, order: np.ndarray) -> None:
        """The first ``n_sources`` of ``order`` (indices of ``infills``) become the food sources."""
        self.pop = infills[np.sort(order[: self.n_sources])]
        self.trials = np.zeros(self.n_sources, dtype=int)
        self.n_scouts = 0
        self.n_scouts_total = 0
        self.n_cycles = 0
        self._phase = EMPLOYED
        self._scouts = np.zeros(0, dtype=int)

    def _infill(self):
        X_sources = np.array([ind.X for ind in self.pop])
        if self._phase == EMPLOYED:
            scouts = Population.empty()
            if len(self._scouts) > 0:
                # the abandoned sources' new random points, evaluated with this phase
                scouts = self.sampling.do(self.problem, len(self._scouts), random_state=self.random_state)
                X_sources[self._scouts] = scouts.get("X")
            self._parents = np.arange(self.n_sources)
            moved = Population.new(X=self._candidates(X_sources, self._parents))
            return Population.merge(scouts, moved)
        self._parents = roulette(self._onlooker_probabilities(), self.n_sources, self.random_state)
        return Population.new(X=self._candidates(X_sources, self._parents))

    def _onlooker_probabilities(self) -> np.ndarray:
        """Probability of each food source to be chosen by an onlooker."""
        raise NotImplementedError

    def _candidates(self, X_sources: np.ndarray, parents: np.ndarray) -> np.ndarray:
        """One neighbour of each source in ``parents``; ``X_sources`` holds every source's position."""
        raise NotImplementedError

    def _greedy(self, candidates: Population) -> None:
        """Keep the candidates better than their sources (``self._parents``); count trials."""
        raise NotImplementedError

    def _advance(self, infills=None, **kwargs) -> bool:
        if infills is None:
            raise ValueError(f"{type(self).__name__} uses ask/tell: tell() needs the evaluated infills")
        self._observe(infills)
        self.n_scouts = 0
        if self._phase == EMPLOYED:
            n_scouts = len(self._scouts)
            if n_scouts > 0:
                self.pop[self._scouts] = infills[:n_scouts]
                self.trials[self._scouts] = 0
                self.n_scouts = n_scouts
                self.n_scouts_total += n_scouts
            self._greedy(infills[n_scouts:])
            self._phase = ONLOOKER
            return True

        self._greedy(infills)
        self._scouts = np.flatnonzero(self.trials > self._limit)  # they fly with the next phase
        self.n_cycles += 1
        self._phase = EMPLOYED
        return True


class ScoutColumn:
    """Mixin for a pymoo output: adds the number of scouts that flew in the last iteration."""

    def __init__(self) -> None:
        super().__init__()
        self.n_scouts = Column(name="n_scouts", width=8)

    def initialize(self, algorithm) -> None:
        super().initialize(algorithm)
        self.columns += [self.n_scouts]

    def update(self, algorithm) -> None:
        super().update(algorithm)
        self.n_scouts.set(algorithm.n_scouts)
