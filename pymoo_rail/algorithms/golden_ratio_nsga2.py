"""Golden-ratio NSGA-II (Tang et al. (2020), section 3.1).

NSGA-II whose every generation also runs a golden-ratio local search on a sub-population
P_z of elite individuals, accepts the local-search points into the main population with the
Metropolis criterion, and adapts the crossover and mutation probabilities to the fitness of
the parents (Tang et al. (2020) eqs. 8 and 9). Depends on pymoo only.
"""

from __future__ import annotations

import math
from numbers import Integral, Real

import numpy as np
from pymoo.algorithms.moo.nsga2 import NSGA2, binary_tournament
from pymoo.core.crossover import Crossover
from pymoo.core.mating import Mating
from pymoo.core.population import Population
from pymoo.core.variable import get
from pymoo.operators.crossover.sbx import SBX
from pymoo.operators.mutation.pm import PM, PolynomialMutation, mut_pm
from pymoo.operators.repair.to_bound import set_to_bounds_if_outside
from pymoo.operators.sampling.rnd import FloatRandomSampling
from pymoo.operators.survival.rank_and_crowding.metrics import get_crowding_function
from pymoo.operators.selection.tournament import TournamentSelection
from pymoo.util.display.column import Column
from pymoo.util.display.multi import MultiObjectiveOutput
from pymoo.util.nds.non_dominated_sorting import NonDominatedSorting

# the golden-section fractions as Tang et al. (2020) writes them (fig. 3, eqs. 8-9)
GOLDEN_SHORT = 0.382
GOLDEN_LONG = 0.618


# ---------------------------------------------------------------------------------------------
# Adaptive probabilities (eqs. 8, 9)
# ---------------------------------------------------------------------------------------------


def adaptive_probability(f, f_avg: float, f_max: float, p_max: float, p_min: float, k: float):
    r"""Probability of eq. 8 (``k = 0.382``) or eq. 9 (``k = 0.618``) of Tang et al. (2020).

    .. math::

        p(f) = \begin{cases}
            p_{min} + (p_{max} - p_{min})\,\dfrac{e^{-k r} - e^{-k}}{1 - e^{-k}},
                & f > f_{avg},\quad r = \dfrac{f - f_{avg}}{f_{max} - f_{avg}} \\
            p_{max}, & f \le f_{avg}
        \end{cases}

    The seed prints :math:`p = e^{-k r}` above the average, which exceeds :math:`p_{max}`
    (up to 1.0 for crossover, and 0.54-1.0 for mutation against a :math:`p_{max}` of 0.1)
    and jumps at :math:`f_{avg}`; it evidently lost the factor :math:`p_{max}`. The form
    above equals :math:`p_{max} e^{-k r}` exactly when :math:`p_{min} = p_{max} e^{-k}`
    (the default of :class:`GoldenRatioNSGA2`), is continuous at :math:`f_{avg}`, and maps
    the above-average range onto :math:`[p_{min}, p_{max}]` for any other :math:`p_{min}`.
    Fitness is "larger is better": good individuals get the smaller probabilities.

    Parameters
    ----------
    f : array_like
        Fitness values (larger is better).
    f_avg, f_max : float
        Average and maximum fitness of the population.
    p_max, p_min : float
        Probability bounds.
    k : float
        0.382 for crossover (eq. 8), 0.618 for mutation (eq. 9).

    Returns
    -------
    numpy.ndarray
        Probabilities in ``[p_min, p_max]``, shaped like ``f``.
    """
    f = np.asarray(f, dtype=float)
    p = np.full(f.shape, float(p_max))
    if f_max > f_avg:
        above = f > f_avg
        r = np.clip((f[above] - f_avg) / (f_max - f_avg), 0.0, 1.0)
        shape = (np.exp(-k * r) - np.exp(-k)) / (1.0 - np.exp(-k))
        p[above] = p_min + (p_max - p_min) * shape
    return p


# ---------------------------------------------------------------------------------------------
# Mating with per-pair crossover and per-offspring mutation probabilities
# ---------------------------------------------------------------------------------------------


class AdaptiveMating(Mating):
    """Selection, crossover and polynomial mutation with the probabilities of eqs. 8-9.

    Reads the fitness stored as ``"gr_fitness"`` on the population, asks the algorithm for
    the probabilities, restores fixed genes to the parent's values and logs the
    probabilities it used on the algorithm (``_pc_log``, ``_pm_log``).
    """

    def _do(self, problem, pop, n_offsprings, parents=None, random_state=None,
            algorithm=None, **kwargs):
        n_matings = math.ceil(n_offsprings / self.crossover.n_offsprings)

        if parents is None:
            parents = self.selection.do(
                problem, pop, n_matings, n_parents=self.crossover.n_parents, to_pop=False,
                random_state=random_state, algorithm=algorithm, **kwargs,
            )
        parents = np.asarray(parents, dtype=int).reshape(n_matings, 2)

        fit = np.asarray(pop.get("gr_fitness"), dtype=float)
        f_avg, f_max = float(fit.mean()), float(fit.max())

        # eq. 8: f' is the larger fitness of the two parents
        pc = algorithm.crossover_probability(fit[parents].max(axis=1), f_avg, f_max)

        Xpop = pop.get("X").astype(float)
        X = np.swapaxes(Xpop[parents], 0, 1)  # (2, n_matings, n_var)
        Q = self.crossover._do(problem, X, random_state=random_state)
        cross = random_state.random(n_matings) < pc
        Xoff = np.where(cross[None, :, None], Q, X).reshape(-1, problem.n_var)

        # offspring j of a mating takes the slot of parent j: its fitness drives eq. 9 and
        # its genes are the ones a fixed gene keeps
        parent_of = parents.T.reshape(-1)
        pm = algorithm.mutation_probability(fit[parent_of], f_avg, f_max)
        eta = get(self.mutation.eta, size=len(Xoff))
        Xoff = mut_pm(Xoff, problem.xl, problem.xu, eta, pm, at_least_once=False,
                      random_state=random_state)

        fixed = algorithm.fixed_mask
        if fixed is not None and fixed.any():
            Xoff[:, fixed] = Xpop[parent_of][:, fixed]

        algorithm._pc_log.append(pc)
        algorithm._pm_log.append(pm)
        return Population.new("X", Xoff)


# ---------------------------------------------------------------------------------------------
# Display
# ---------------------------------------------------------------------------------------------


class GoldenRatioOutput(MultiObjectiveOutput):
    """NSGA-II output plus mean pc, mean pm and accepted local-search members."""

    def __init__(self) -> None:
        super().__init__()
        self.pc = Column("pc_mean", width=8)
        self.pm = Column("pm_mean", width=8)
        self.n_acc = Column("n_acc", width=6)

    def initialize(self, algorithm) -> None:
        """Add the crossover and mutation probabilities and the accepted local points to the columns."""
        super().initialize(algorithm)
        self.columns += [self.pc, self.pm, self.n_acc]

    def update(self, algorithm) -> None:
        """Fill the columns from the generation just finished (means over the mating pairs)."""
        super().update(algorithm)
        pc, pm = algorithm.last_pc, algorithm.last_pm
        self.pc.set(float(pc.mean()) if len(pc) > 0 else None)
        self.pm.set(float(pm.mean()) if len(pm) > 0 else None)
        self.n_acc.set(algorithm.n_accepted)


# ---------------------------------------------------------------------------------------------
# Algorithm
# ---------------------------------------------------------------------------------------------


def _check_probability(name: str, value) -> float:
    if isinstance(value, bool) or not isinstance(value, Real) or not 0.0 <= value <= 1.0:
        raise ValueError(f"{name} must be a probability in [0, 1], got {value!r}")
    return float(value)


def _check_int(name: str, value, low: int) -> int:
    if isinstance(value, bool) or not isinstance(value, Integral) or value < low:
        raise ValueError(f"{name} must be an integer >= {low}, got {value!r}")
    return int(value)


def _check_probabilities(pc_max, pc_min, pm_max, pm_min) -> tuple[float, float, float, float]:
    """The crossover and mutation probability bounds, checked; a missing minimum from eqs. 8-9's golden ratios."""
    pc_max = _check_probability("pc_max", pc_max)
    pm_max = _check_probability("pm_max", pm_max)
    pc_min = pc_max * math.exp(-GOLDEN_SHORT) if pc_min is None else pc_min
    pm_min = pm_max * math.exp(-GOLDEN_LONG) if pm_min is None else pm_min
    pc_min = _check_probability("pc_min", pc_min)
    pm_min = _check_probability("pm_min", pm_min)
    if pc_min > pc_max:
        raise ValueError(f"pc_min must not exceed pc_max ({pc_max}), got {pc_min!r}")
    if pm_min > pm_max:
        raise ValueError(f"pm_min must not exceed pm_max ({pm_max}), got {pm_min!r}")
    return pc_max, pc_min, pm_max, pm_min


def _check_operators(crossover, mutation) -> tuple[Crossover, PolynomialMutation]:
    """The crossover (2 parents, 2 offspring; default SBX eta 15) and the polynomial mutation (default eta 20)."""
    crossover = SBX(eta=15) if crossover is None else crossover
    shape = (getattr(crossover, "n_parents", None), getattr(crossover, "n_offsprings", None))
    if not isinstance(crossover, Crossover) or shape != (2, 2):
        raise ValueError(
            "crossover must be a pymoo Crossover with 2 parents and 2 offspring, "
            f"got {crossover!r}"
        )
    mutation = PM(eta=20) if mutation is None else mutation
    if not isinstance(mutation, PolynomialMutation):
        raise ValueError(
            "mutation must be a pymoo PolynomialMutation (eq. 9 sets its probability), "
            f"got {mutation!r}"
        )
    return crossover, mutation


class GoldenRatioNSGA2(NSGA2):
    r"""Golden-ratio NSGA-II of Tang et al. (2020) (Tang, Wang, Yu 2020, section 3.1).

    Each generation ``k`` asks for one batch: ``n_offsprings`` NSGA-II offspring ``Q_k``
    plus up to ``3 * local_size / 2`` golden-ratio points ``Z_k``; both are evaluated by
    pymoo's evaluator, so every evaluation counts in ``evaluator.n_eval`` and ``("n_eval",
    N)`` termination stops after the generation that reaches ``N`` (it may overshoot by
    less than one batch). Then

    1. ``P_{k+1}`` = NSGA-II survival (fast non-dominated sorting, crowding distance,
       :class:`~pymoo.operators.survival.rank_and_crowding.RankAndCrowding`) of
       ``P_k + Q_k`` (``Z_k`` takes no part in it);
    2. the Metropolis criterion offers each point of ``Z_k`` in turn the place of the
       current worst member of ``P_{k+1}``;
    3. P_z for the next generation is the best ``local_size`` (= 2m) members of the
       population, ordered by feasibility, constraint violation, rank, then descending
       crowding distance (so rank 0 whenever there are at least 2m of them).

    Choices where Tang et al. (2020) is silent (all deterministic given ``seed``):

    * **Pairs.** The best m members of P_z are the points A; each is paired with one of the
      other m members C, in a random permutation drawn from ``random_state``.
    * **Candidates** per pair (fig. 3, ``|AB| / |AC| = 0.382``): B = A + 0.382 (C - A),
      the symmetric golden point A + 0.618 (C - A), and the opposite point
      B' = A - 0.382 (C - A), i.e. B rotated by 180 degrees about A: it lies outside the
      segment, beyond the better point A, and widens the local search as the seed says.
      Coordinates outside the bounds are set to the bound; fixed genes keep A's values;
      candidates equal to existing individuals are dropped (duplicate elimination), so a
      pair of identical points costs nothing. Cost: at most 1.5 ``local_size`` evaluations
      per generation.
    * **Initial P_z** is taken from the evaluated initial population instead of a second
      random population (a random P_z would just be a larger initial sample).
    * **Metropolis acceptance.** Each candidate z in turn: rank and crowd ``P_{k+1} + {z}``
      together (constrained non-dominated sorting and crowding distance, as NSGA-II's
      survival does) and let w be the worst member of ``P_{k+1}`` in that order. If z
      comes before w (NSGA-II's crowded comparison: smaller CV, else lower rank, else
      larger crowding distance), z replaces w. Otherwise z replaces w with probability
      ``exp(-delta / T_k)``, where the deficit ``delta`` in [0, 1] is
      ``(CV_z - CV_w) / CV_z`` if z violates more, 1 if z lies in a worse front, and
      ``1 - cd_z / cd_w`` if both share a front (ties give 0). Rejected candidates are
      discarded (their evaluations still count). At most half the population is replaced
      per generation. (A first version accepted z whenever w did not dominate it; late in
      a run almost every candidate passed, the criterion decided nothing and the final
      fronts were less even, see ``benchmarks/reports/grnsga2_zdt.md``.)
    * **Temperature.** Geometric cooling ``T_k = t0 * cooling ** k``, k = 0, 1, ... the
      number of local-search rounds so far. Defaults 0.5 and 0.95: in the first
      generation a candidate in a worse front gets in with probability exp(-2) = 0.14 and
      one with half w's crowding distance with 0.37; after 60 generations (T = 0.023)
      essentially only candidates that beat w get in.
    * **Fitness for eqs. 8-9.** The seed's fitness is scalar; here it is the position in
      the NSGA-II order above, scaled to [0, 1] (best 1, worst 0), so ``f_avg = 0.5`` and
      ``f_max = 1``. This keeps the adaptation alive when the whole population is rank 0.
      ``f'`` of eq. 8 is the larger fitness of the two parents; the ``f`` of eq. 9 is the
      fitness of the parent whose slot the offspring takes (offspring are not evaluated
      before mutation).
    * **Eqs. 8-9 as implemented**: see :func:`adaptive_probability` (the printed formula
      lacks the factor ``p_max``). ``pc`` is the probability that a mating applies the
      crossover operator (else the parents are copied); ``pm`` is the per-variable
      probability of polynomial mutation of that offspring (every offspring is offered
      mutation; the individual-level ``prob`` and ``prob_var`` of ``mutation`` are not used).

    Parameters
    ----------
    pop_size : int
        Size N of the main population P_k.
    local_size : int
        Size 2m of P_z (even, at most ``pop_size``); 0 switches the local search off.
    pc_max, pc_min : float
        Bounds of the crossover probability; ``pc_min`` defaults to ``pc_max * exp(-0.382)``
        (the seed's eq. 8 with the factor ``pc_max``).
    pm_max, pm_min : float
        Bounds of the per-variable mutation probability; ``pm_min`` defaults to
        ``pm_max * exp(-0.618)``.
    fixed_genes : array_like of bool or int, optional
        Boolean mask of length ``n_var``, or indices, of genes that variation and local
        search must not change (genes inside neutral sections of a rail problem). They keep
        the values of the parent (of A for local-search points); initial values come from
        ``sampling``.
    t0 : float
        Initial Metropolis temperature (> 0), in units of the normalised deficit.
    cooling : float
        Geometric cooling factor in (0, 1].
    n_offsprings : int, optional
        NSGA-II offspring per generation (default ``pop_size``).
    sampling : pymoo Sampling, optional
        Initial population (default :class:`FloatRandomSampling`).
    crossover : pymoo Crossover, optional
        A two-parent, two-offspring crossover (default ``SBX(eta=15)``); its own ``prob`` is
        replaced by eq. 8.
    mutation : PolynomialMutation, optional
        Supplies ``eta`` (default ``PM(eta=20)``); eq. 9 sets the probability.
    **kwargs
        Passed to :class:`~pymoo.algorithms.moo.nsga2.NSGA2` (e.g. ``eliminate_duplicates``).

    Attributes
    ----------
    last_pc, last_pm : numpy.ndarray
        Crossover probability of each mating and mutation probability of each offspring in
        the last generation.
    n_accepted : int or None
        Local-search points accepted in the last generation.
    n_local_evals, n_accepted_total : int
        Local-search points evaluated and accepted since the start.
    temperature : float
        Temperature used by the last Metropolis step.

    Examples
    --------
    >>> from pymoo.optimize import minimize
    >>> from pymoo.problems.multi import ZDT1
    >>> res = minimize(ZDT1(), GoldenRatioNSGA2(pop_size=40, local_size=8), ("n_gen", 5), seed=1)
    >>> res.F.shape[1]
    2
    """

    def __init__(
        self,
        pop_size: int = 100,
        local_size: int = 20,
        pc_max: float = 0.9,
        pc_min: float | None = None,
        pm_max: float = 0.1,
        pm_min: float | None = None,
        fixed_genes=None,
        t0: float = 0.5,
        cooling: float = 0.95,
        n_offsprings: int | None = None,
        sampling=None,
        crossover: Crossover | None = None,
        mutation: PolynomialMutation | None = None,
        output=None,
        **kwargs,
    ) -> None:
        pop_size = _check_int("pop_size", pop_size, 2)
        local_size = _check_int("local_size", local_size, 0)
        if local_size % 2 != 0:
            raise ValueError(
                f"local_size must be even (P_z holds 2m individuals), got {local_size}"
            )
        if local_size > pop_size:
            raise ValueError(
                f"local_size must not exceed pop_size ({pop_size}), got {local_size}"
            )
        if n_offsprings is not None:
            n_offsprings = _check_int("n_offsprings", n_offsprings, 1)

        pc_max, pc_min, pm_max, pm_min = _check_probabilities(pc_max, pc_min, pm_max, pm_min)
        if isinstance(t0, bool) or not isinstance(t0, Real) or not (0.0 < t0 < math.inf):
            raise ValueError(f"t0 must be a positive finite temperature, got {t0!r}")
        if isinstance(cooling, bool) or not isinstance(cooling, Real) or not 0.0 < cooling <= 1.0:
            raise ValueError(f"cooling must lie in (0, 1], got {cooling!r}")
        crossover, mutation = _check_operators(crossover, mutation)

        self.fixed_genes = self._check_fixed_genes(fixed_genes)

        super().__init__(
            pop_size=pop_size,
            n_offsprings=n_offsprings,
            sampling=FloatRandomSampling() if sampling is None else sampling,
            selection=TournamentSelection(func_comp=binary_tournament),
            crossover=crossover,
            mutation=mutation,
            output=GoldenRatioOutput() if output is None else output,
            **kwargs,
        )
        self.mating = AdaptiveMating(
            self.mating.selection, crossover, mutation, repair=self.repair,
            eliminate_duplicates=self.eliminate_duplicates, n_max_iterations=100,
        )

        self.local_size = local_size
        self.pc_max, self.pc_min = pc_max, pc_min
        self.pm_max, self.pm_min = pm_max, pm_min
        self.t0, self.cooling = float(t0), float(cooling)

        self.fixed_mask: np.ndarray | None = None
        # ranking used by the Metropolis step: the survival's own, else NSGA-II's defaults
        self._nds = getattr(self.survival, "nds", None) or NonDominatedSorting()
        self._crowding = (
            getattr(self.survival, "crowding_func", None) or get_crowding_function("cd")
        )
        self._reset_state()

    # -- parameters ---------------------------------------------------------------------------

    @staticmethod
    def _check_fixed_genes(fixed_genes):
        if fixed_genes is None:
            return None
        arr = np.asarray(fixed_genes)
        if arr.ndim != 1:
            raise ValueError(f"fixed_genes must be a 1-D mask or index list, got shape {arr.shape}")
        if arr.size > 0 and arr.dtype != bool and not np.issubdtype(arr.dtype, np.integer):
            raise ValueError(
                f"fixed_genes must be booleans or integer indices, got dtype {arr.dtype}"
            )
        return arr.copy()

    def _fixed_mask_for(self, n_var: int) -> np.ndarray | None:
        if self.fixed_genes is None:
            return None
        arr = self.fixed_genes
        if arr.dtype == bool:
            if len(arr) != n_var:
                raise ValueError(
                    f"fixed_genes mask has length {len(arr)} but the problem has n_var = {n_var}"
                )
            return arr.copy()
        idx = arr.astype(int)
        if idx.size and (idx.min() < -n_var or idx.max() >= n_var):
            raise ValueError(
                f"fixed_genes indices must lie in [0, {n_var}), got {idx.tolist()}"
            )
        mask = np.zeros(n_var, dtype=bool)
        mask[idx] = True
        return mask

    def crossover_probability(self, f, f_avg: float, f_max: float) -> np.ndarray:
        """Eq. 8: crossover probability for pairs whose larger parent fitness is ``f``."""
        return adaptive_probability(f, f_avg, f_max, self.pc_max, self.pc_min, GOLDEN_SHORT)

    def mutation_probability(self, f, f_avg: float, f_max: float) -> np.ndarray:
        """Eq. 9: per-variable mutation probability for individuals of fitness ``f``."""
        return adaptive_probability(f, f_avg, f_max, self.pm_max, self.pm_min, GOLDEN_LONG)

    def run_counters(self) -> dict[str, int]:
        """Totals of the run so far, stored with each study record: local-search points
        evaluated and accepted."""
        return {"n_local_evals": int(self.n_local_evals), "n_accepted_total": int(self.n_accepted_total)}

    # -- life cycle ---------------------------------------------------------------------------

    def _reset_state(self) -> None:
        self.last_pc = np.empty(0)
        self.last_pm = np.empty(0)
        self.n_accepted = None
        self.n_local_evals = 0
        self.n_accepted_total = 0
        self.temperature = self.t0
        self._n_rounds = 0
        self._pc_log: list = []
        self._pm_log: list = []

    def _setup(self, problem, **kwargs) -> None:
        super()._setup(problem, **kwargs)
        self.fixed_mask = self._fixed_mask_for(problem.n_var)
        self._reset_state()

    def _order(self, pop) -> np.ndarray:
        """Indices of ``pop`` from best to worst: feasibility, CV, rank, -crowding, index."""
        n = len(pop)
        cv = np.asarray(pop.get("CV"), dtype=float).reshape(n, -1)[:, 0]
        feas = cv <= 0.0
        rank = np.array([r if r is not None else 0 for r in pop.get("rank")], dtype=float)
        crowd = np.array([c if c is not None else 0.0 for c in pop.get("crowding")], dtype=float)
        # infeasible members are ordered by CV alone (their rank may be stale)
        rank[~feas] = 0.0
        crowd[~feas] = 0.0
        cv[feas] = 0.0
        return np.lexsort((np.arange(n), -crowd, rank, cv, ~feas))

    def _assign_fitness(self, pop) -> None:
        order = self._order(pop)
        fit = np.empty(len(pop))
        fit[order] = 1.0 - np.arange(len(pop)) / max(len(pop) - 1, 1)
        pop.set("gr_fitness", fit)

    def _infill(self):
        self._assign_fitness(self.pop)
        self._pc_log, self._pm_log = [], []

        off = self.mating.do(
            self.problem, self.pop, self.n_offsprings, algorithm=self,
            random_state=self.random_state,
        )
        self.last_pc = np.concatenate(self._pc_log) if self._pc_log else np.empty(0)
        self.last_pm = np.concatenate(self._pm_log) if self._pm_log else np.empty(0)
        self._pc_log, self._pm_log = [], []

        if len(off) == 0:
            self.termination.force_termination = True
            return None
        off.set("golden", False)

        loc = self._golden_points(off)
        loc.set("golden", True)
        return Population.merge(off, loc)

    def _golden_points(self, off) -> Population:
        """Golden-ratio candidates from pairs of P_z (see the class docstring)."""
        m = min(self.local_size, len(self.pop)) // 2
        if m == 0:
            return Population.new("X", np.empty((0, self.problem.n_var)))

        pz = self._order(self.pop)[: 2 * m]
        a = pz[:m]
        c = pz[m:][self.random_state.permutation(m)]
        X = self.pop.get("X").astype(float)
        XA, D = X[a], X[c] - X[a]

        cand = np.stack(
            [XA + GOLDEN_SHORT * D, XA + GOLDEN_LONG * D, XA - GOLDEN_SHORT * D], axis=1
        )
        if self.fixed_mask is not None:
            cand[:, :, self.fixed_mask] = XA[:, None, self.fixed_mask]
        cand = cand.reshape(-1, X.shape[1])
        cand = set_to_bounds_if_outside(cand, self.problem.xl, self.problem.xu)

        loc = Population.new("X", cand)
        return self.eliminate_duplicates.do(loc, self.pop, off)

    def _advance(self, infills=None, **kwargs):
        if infills is None:
            return super()._advance(infills=infills, **kwargs)

        is_local = np.array([bool(g) for g in infills.get("golden")], dtype=bool)
        off, loc = infills[~is_local], infills[is_local]

        # NSGA-II survival on P_k + Q_k
        super()._advance(infills=off, **kwargs)

        self.temperature = self.t0 * self.cooling ** self._n_rounds
        self._n_rounds += 1
        self.n_local_evals += len(loc)
        self.n_accepted = self._metropolis(loc, self.temperature)
        self.n_accepted_total += self.n_accepted

        if self.n_accepted > 0:
            # refresh rank and crowding (no truncation, so no random draw happens)
            self.pop = self.survival.do(
                self.problem, self.pop, n_survive=len(self.pop), algorithm=self,
                random_state=self.random_state,
            )

    def _ranking(self, F: np.ndarray, cv: np.ndarray):
        """Order (best first), rank and crowding of a set, as NSGA-II's survival sees it."""
        n = len(F)
        feas = cv <= 0.0
        rank = np.zeros(n)
        crowd = np.zeros(n)
        idx = np.flatnonzero(feas)
        if len(idx) > 0:
            fronts = self._nds.do(F[idx])
            for k, front in enumerate(fronts):
                rank[idx[front]] = k
                crowd[idx[front]] = self._crowding.do(F[idx[front]], n_remove=0)
        key_cv = np.where(feas, 0.0, cv)
        order = np.lexsort((np.arange(n), -crowd, rank, key_cv, ~feas))
        return order, rank, crowd

    def _metropolis(self, loc, temperature: float) -> int:
        """Offer each local point the place of the worst member; return the number accepted."""
        if len(loc) == 0:
            return 0

        n = len(self.pop)
        F = np.asarray(self.pop.get("F"), dtype=float)
        cv = np.asarray(self.pop.get("CV"), dtype=float).reshape(n, -1)[:, 0]

        n_acc = 0
        for z in loc:
            if n_acc >= n // 2:
                break
            # rank and crowd P_{k+1} + {z} together so that z and w compare on equal terms
            F_all = np.vstack([F, np.asarray(z.F, dtype=float)[None, :]])
            cv_all = np.append(cv, float(z.CV[0]))
            order, rank, crowd = self._ranking(F_all, cv_all)
            pos = np.empty(n + 1, dtype=int)
            pos[order] = np.arange(n + 1)
            w = int(order[order < n][-1])

            if pos[n] < pos[w]:
                accept = True  # z beats w by constrained crowded comparison
            else:
                if cv_all[n] > cv_all[w]:
                    delta = (cv_all[n] - cv_all[w]) / cv_all[n]
                elif cv_all[n] > 0.0 or rank[n] == rank[w] and crowd[n] == crowd[w]:
                    delta = 0.0  # a tie
                elif rank[n] > rank[w]:
                    delta = 1.0
                elif np.isfinite(crowd[w]) and crowd[w] > 0.0:
                    delta = 1.0 - crowd[n] / crowd[w]
                else:
                    delta = 1.0
                accept = delta == 0.0 or self.random_state.random() < math.exp(-delta / temperature)

            if accept:
                self.pop[w] = z
                F[w], cv[w] = F_all[n], cv_all[n]
                n_acc += 1
        return n_acc
