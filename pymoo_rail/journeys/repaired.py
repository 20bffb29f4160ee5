"""One-objective algorithms that repair every candidate onto a running-time budget before it is evaluated.

The running-time allocation (:class:`~pymoo_rail.journeys.RunningTimeAllocationProblem`, the suite's
``-trip`` families) has an equality budget, ``sum_k t_k = T``, that no sampled or recombined vector
meets by chance. :func:`repaired_algorithm` builds pymoo's GA, DE and PSO, the package's ABC or a
random search with :class:`~pymoo_rail.journeys.BudgetRepair` on every candidate:

- GA and DE: pymoo's own ``repair=`` hook, which its initialisation and its mating both apply;
- PSO: ``repair=`` repairs the moved swarm (and the perturbed best), but pymoo's PSO samples its
  first swarm without it, so its sampling is a :class:`RepairedSampling`;
- ABC (:class:`RepairedABC`): its colony and scouts come from a :class:`RepairedSampling` and
  every batch it asks to evaluate (the bees' moves) is repaired;
- random search: pymoo's ``RandomSearch`` takes no repair, so it draws from a
  :class:`RepairedSampling` (uniform samples projected onto the budget).

A study names it by import path, which needs a trusted study (``--trust``)::

    [[algorithms]]
    algorithm = "pymoo_rail.journeys.repaired:repaired_algorithm"
    method = "ga"
    label = "GA"
    pop_size = 50

The repair draws no random numbers, so a run is as repeatable from its seed as the algorithm is.
"""

from __future__ import annotations

import inspect
from typing import Any, Callable

from pymoo.algorithms.soo.nonconvex.de import DE, Variant
from pymoo.algorithms.soo.nonconvex.ga import GA
from pymoo.algorithms.soo.nonconvex.pso import PSO
from pymoo.algorithms.soo.nonconvex.random_search import RandomSearch
from pymoo.core.population import Population
from pymoo.core.repair import Repair
from pymoo.core.sampling import Sampling
from pymoo.operators.sampling.lhs import LHS
from pymoo.operators.sampling.rnd import FloatRandomSampling

from pymoo_rail.algorithms import ABC
from pymoo_rail.journeys.problem import BudgetRepair


class RepairedSampling(Sampling):
    """Draw with ``sampling``, then repair every point with ``repair``.

    Parameters
    ----------
    sampling : pymoo Sampling
        Draws the points (e.g. uniform in the bounds).
    repair : pymoo Repair
        Applied to every drawn point.
    """

    def __init__(self, sampling: Sampling, repair: Repair) -> None:
        super().__init__()
        self.sampling, self.repair = sampling, repair

    def _do(self, problem, n_samples, *args, random_state=None, **kwargs):
        drawn = self.sampling.do(problem, n_samples, *args, random_state=random_state, **kwargs)
        return self.repair.do(problem, drawn, random_state=random_state).get("X")


class RepairedABC(ABC):
    """:class:`~pymoo_rail.algorithms.ABC` whose every candidate is repaired before it is evaluated.

    The initial colony and the scouts' new food sources are drawn by a :class:`RepairedSampling`;
    each batch of the employed and onlooker bees' moves is repaired as a whole (pymoo's ``_infill``),
    so a food source is always a repaired point.

    Parameters
    ----------
    repair : pymoo Repair
    sampling : pymoo Sampling
        Draws the colony and the scouts before the repair (default uniform in the bounds).
    **kwargs
        Passed on to :class:`~pymoo_rail.algorithms.ABC` (``pop_size``, ``limit``, ...).
    """

    def __init__(self, repair: Repair, sampling: Sampling = FloatRandomSampling(), **kwargs) -> None:
        super().__init__(sampling=RepairedSampling(sampling, repair), **kwargs)
        self.repair = repair

    def _infill(self) -> Population:
        return self.repair.do(self.problem, super()._infill(), random_state=self.random_state)


def _repaired_ga(repair: Repair, **params) -> GA:
    return GA(repair=repair, **params)


def _repaired_de(repair: Repair, **params) -> DE:
    return DE(repair=repair, **params)


def _repaired_pso(repair: Repair, sampling: Sampling = LHS(), **params) -> PSO:
    return PSO(repair=repair, sampling=RepairedSampling(sampling, repair), **params)


def _repaired_random(repair: Repair, sampling: Sampling = FloatRandomSampling(), **params) -> RandomSearch:
    return RandomSearch(sampling=RepairedSampling(sampling, repair), **params)


# method -> (how it is built with a repair, the classes whose keywords it takes: DE hands its own to its variant)
REPAIRED_METHODS: dict[str, tuple[Callable[..., Any], tuple[type, ...]]] = {
    "ga": (_repaired_ga, (GA,)),
    "de": (_repaired_de, (DE, Variant)),
    "pso": (_repaired_pso, (PSO,)),
    "abc": (RepairedABC, (ABC,)),
    "random": (_repaired_random, (RandomSearch,)),
}
"""The methods :func:`repaired_algorithm` builds: pymoo's GA, DE, PSO, the package's ABC, random search."""


def _keywords(classes: tuple[type, ...]) -> set[str]:
    """Keywords of the classes' constructors up their bases (pymoo's ``Algorithm`` drops unknown keywords
    silently, so a keyword no constructor names is a mistake)."""
    names: set[str] = set()
    for base in {base for klass in classes for base in klass.__mro__}:
        if "__init__" in vars(base) and base is not object:
            names |= {p.name for p in inspect.signature(base.__init__).parameters.values()
                      if p.kind in (p.POSITIONAL_OR_KEYWORD, p.KEYWORD_ONLY)} - {"self"}
    return names


def repaired_algorithm(method: str, **params: Any):
    """A one-objective algorithm with :class:`~pymoo_rail.journeys.BudgetRepair` on every evaluated candidate.

    Parameters
    ----------
    method : {"ga", "de", "pso", "abc", "random"}
        pymoo's GA, DE or PSO, the package's ABC, or random search (pymoo's ``RandomSearch`` drawing
        uniform samples projected onto the budget).
    **params
        Keyword arguments of that algorithm (``pop_size``; ``n_points_per_iteration`` for random
        search; ``sampling`` draws before the repair).

    Returns
    -------
    pymoo Algorithm
        For a :class:`~pymoo_rail.journeys.RunningTimeAllocationProblem` (the suite's ``-trip`` instances).

    Raises
    ------
    ValueError
        An unknown ``method``.
    TypeError
        A keyword the algorithm does not take (named with its value and the accepted ones).
    """
    if method not in REPAIRED_METHODS:
        raise ValueError(f"method: {method!r} is not one of {sorted(REPAIRED_METHODS)}")
    build, classes = REPAIRED_METHODS[method]
    # the repair is this function's; ABC sets its bee colony's min_pop_size itself
    accepted = _keywords(classes) - {"repair", "min_pop_size"}
    unknown = sorted(set(params) - accepted)
    if unknown:
        raise TypeError(f"{method}.{unknown[0]}: {params[unknown[0]]!r} is not a parameter of {classes[0].__name__} "
                         f"(accepted: {', '.join(sorted(accepted))})")
    return build(BudgetRepair(), **params)
