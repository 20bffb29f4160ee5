"""GoldenRatioNSGA2 (seed 003, section 3.1) as a pymoo algorithm."""

import math
import pickle

import numpy as np
import pytest
from pymoo.core.callback import Callback
from pymoo.core.population import Population
from pymoo.core.problem import Problem
from pymoo.core.sampling import Sampling
from pymoo.indicators.igd import IGD
from pymoo.optimize import minimize
from pymoo.problems import get_problem
from pymoo.problems.multi import ZDT1

from pymoo_rail.algorithms.golden_ratio_nsga2 import GoldenRatioNSGA2, adaptive_probability


def small(**kwargs):
    return GoldenRatioNSGA2(**{"pop_size": 20, "local_size": 6, **kwargs})


# -- quality ----------------------------------------------------------------------------------


@pytest.mark.parametrize("name", ["zdt1", "zdt2", "zdt3"])
def test_converges_on_zdt(name):
    problem = get_problem(name)
    alg = GoldenRatioNSGA2(pop_size=100, local_size=20)
    res = minimize(problem, alg, ("n_eval", 12000), seed=1)
    assert res.algorithm.evaluator.n_eval <= 25000
    assert IGD(problem.pareto_front())(res.F) < 0.05


def test_constrained_bnh_front_is_feasible():
    problem = get_problem("bnh")
    res = minimize(problem, GoldenRatioNSGA2(pop_size=60, local_size=12), ("n_gen", 60), seed=1)
    assert np.all(res.CV <= 0.0)
    assert IGD(problem.pareto_front(), zero_to_one=True)(res.F) < 0.05


def test_constrained_problem_with_infeasible_start():
    # OSY: random points are mostly infeasible; the algorithm must still find a feasible front
    problem = get_problem("osy")
    res = minimize(problem, GoldenRatioNSGA2(pop_size=60, local_size=12), ("n_gen", 60), seed=2)
    assert len(res.F) > 1
    assert np.all(res.CV <= 0.0)


def test_three_objectives_dtlz2():
    problem = get_problem("dtlz2")
    res = minimize(problem, GoldenRatioNSGA2(pop_size=92, local_size=12), ("n_gen", 60), seed=1)
    assert res.F.shape[1] == 3
    assert IGD(problem.pareto_front())(res.F) < 0.2


# -- reproducibility --------------------------------------------------------------------------


def run_minimize(seed, n_gen=12):
    return minimize(ZDT1(n_var=10), small(), ("n_gen", n_gen), seed=seed)


def test_same_seed_bit_identical():
    a, b = run_minimize(3), run_minimize(3)
    np.testing.assert_array_equal(a.X, b.X)
    np.testing.assert_array_equal(a.F, b.F)


def test_different_seeds_differ():
    a, b = run_minimize(3), run_minimize(4)
    assert a.F.shape != b.F.shape or not np.array_equal(a.F, b.F)


def test_minimize_next_loop_and_ask_tell_agree():
    problem = ZDT1(n_var=10)
    ref = run_minimize(5)

    alg = small()
    alg.setup(problem, termination=("n_gen", 12), seed=5)
    while alg.has_next():
        alg.next()
    loop = alg.result()

    alg = small()
    alg.setup(problem, termination=("n_gen", 12), seed=5)
    while alg.has_next():
        pop = alg.ask()
        alg.evaluator.eval(problem, pop)
        alg.tell(infills=pop)
    asktell = alg.result()

    for res in (loop, asktell):
        np.testing.assert_array_equal(res.X, ref.X)
        np.testing.assert_array_equal(res.F, ref.F)


def test_pickle_mid_run_continues_identically():
    problem = ZDT1(n_var=10)

    def fresh():
        alg = small()
        alg.setup(problem, termination=("n_gen", 14), seed=9)
        return alg

    alg = fresh()
    while alg.has_next():
        alg.next()
    uninterrupted = alg.result()

    alg = fresh()
    for _ in range(6):
        alg.next()
    alg = pickle.loads(pickle.dumps(alg))
    while alg.has_next():
        alg.next()
    resumed = alg.result()

    np.testing.assert_array_equal(resumed.X, uninterrupted.X)
    np.testing.assert_array_equal(resumed.F, uninterrupted.F)


# -- evaluation accounting --------------------------------------------------------------------


def test_every_evaluation_is_counted():
    problem = ZDT1(n_var=10)
    alg = small()
    alg.setup(problem, termination=("n_gen", 10), seed=1)
    asked = 0
    while alg.has_next():
        pop = alg.ask()
        asked += len(pop)
        alg.evaluator.eval(problem, pop)
        alg.tell(infills=pop)
    assert alg.evaluator.n_eval == asked
    assert alg.n_local_evals > 0
    # initial population + offspring + local-search points
    assert asked == 20 + 9 * 20 + alg.n_local_evals


def test_n_eval_termination_within_one_batch():
    budget = 1000
    res = minimize(ZDT1(n_var=10), small(), ("n_eval", budget), seed=2)
    n_eval = res.algorithm.evaluator.n_eval
    batch = 20 + 3 * (6 // 2)  # offspring + three golden points per pair
    assert budget <= n_eval < budget + batch


def test_local_size_zero_switches_local_search_off():
    res = minimize(ZDT1(n_var=10), small(local_size=0), ("n_gen", 5), seed=2)
    assert res.algorithm.n_local_evals == 0
    assert res.algorithm.evaluator.n_eval == 5 * 20


def test_local_search_points_get_accepted():
    res = minimize(ZDT1(n_var=10), small(), ("n_gen", 10), seed=2)
    assert 0 < res.algorithm.n_accepted_total <= res.algorithm.n_local_evals


# -- golden-ratio points ----------------------------------------------------------------------


def test_golden_points_and_opposite_point():
    problem = ZDT1(n_var=3)
    alg = GoldenRatioNSGA2(pop_size=2, local_size=2, eliminate_duplicates=False)
    alg.setup(problem, seed=1)
    xa, xc = np.array([0.2, 0.1, 0.3]), np.array([0.7, 0.5, 0.1])
    pop = Population.new("X", np.array([xa, xc]))
    alg.evaluator.eval(problem, pop)
    # both rank 0 with infinite crowding, so the order is by index: A = xa, C = xc
    alg.pop = alg.survival.do(problem, pop, n_survive=2, random_state=alg.random_state)
    first = int(np.flatnonzero((alg.pop.get("X") == xa).all(axis=1))[0])
    if first != 0:
        alg.pop = alg.pop[[1, 0]]
    pts = alg._golden_points(Population.new("X", np.empty((0, 3)))).get("X")
    d = xc - xa
    expected = np.array([xa + 0.382 * d, xa + 0.618 * d, np.clip(xa - 0.382 * d, 0.0, 1.0)])
    np.testing.assert_allclose(pts, expected)
    # the opposite point is B rotated by 180 degrees about A (before clipping at the bound)
    np.testing.assert_allclose((xa - 0.382 * d)[0], 2 * xa[0] - expected[0][0])


# -- fixed genes ------------------------------------------------------------------------------


class RecordingZDT1(Problem):
    """ZDT1 that keeps every decision vector it evaluates."""

    def __init__(self, n_var=8):
        super().__init__(n_var=n_var, n_obj=2, xl=0.0, xu=1.0)
        self.zdt = ZDT1(n_var=n_var)
        self.seen = []

    def _evaluate(self, x, out, *args, **kwargs):
        self.seen.append(np.array(x, copy=True))
        out["F"] = self.zdt.evaluate(x)


class FixedValueSampling(Sampling):
    def __init__(self, genes, value):
        super().__init__()
        self.genes, self.value = genes, value

    def _do(self, problem, n_samples, *args, random_state=None, **kwargs):
        X = random_state.random((n_samples, problem.n_var))
        X[:, self.genes] = self.value
        return X


@pytest.mark.parametrize("fixed", [[2, 5], np.array([0, 0, 1, 0, 0, 1, 0, 0], dtype=bool)])
def test_fixed_genes_never_change(fixed):
    problem = RecordingZDT1()
    genes = [2, 5]
    alg = GoldenRatioNSGA2(pop_size=20, local_size=6, fixed_genes=fixed,
                           sampling=FixedValueSampling(genes, 0.37))
    alg.setup(problem, termination=("n_gen", 15), seed=4)
    while alg.has_next():
        alg.next()
    X = np.vstack(problem.seen)
    assert len(X) > 15 * 20
    assert np.all(X[:, genes] == 0.37)
    # the other genes did move
    free = [0, 1, 3, 4, 6, 7]
    assert np.all(X[:, free].std(axis=0) > 0.01)


# -- adaptive probabilities -------------------------------------------------------------------


class RecordProbabilities(Callback):
    def __init__(self):
        super().__init__()
        self.pc, self.pm = [], []

    def notify(self, algorithm):
        self.pc.append(algorithm.last_pc.copy())
        self.pm.append(algorithm.last_pm.copy())


def test_adaptive_probabilities_stay_in_bounds():
    cb = RecordProbabilities()
    alg = small(pc_max=0.85, pc_min=0.5, pm_max=0.2, pm_min=0.05)
    minimize(ZDT1(n_var=10), alg, ("n_gen", 15), seed=1, callback=cb)
    pc, pm = np.concatenate(cb.pc), np.concatenate(cb.pm)
    assert len(pc) > 0 and len(pm) > 0
    assert pc.min() >= 0.5 and pc.max() <= 0.85
    assert pm.min() >= 0.05 and pm.max() <= 0.2
    # both ends are used: below-average pairs get the maximum
    assert pc.max() == 0.85 and pm.max() == 0.2
    assert pm.min() < 0.1


def test_eqs_8_9_with_default_minimum_are_the_seed_formula_times_p_max():
    f_avg, f_max = 0.5, 1.0
    f = np.array([0.2, 0.5, 0.6, 0.8, 1.0])
    r = np.clip((f - f_avg) / (f_max - f_avg), 0, None)
    for k, p_max in ((0.382, 0.9), (0.618, 0.1)):
        p = adaptive_probability(f, f_avg, f_max, p_max, p_max * math.exp(-k), k)
        expected = np.where(f > f_avg, p_max * np.exp(-k * r), p_max)
        np.testing.assert_allclose(p, expected, rtol=1e-12)
    alg = GoldenRatioNSGA2()
    assert alg.pc_min == pytest.approx(0.9 * math.exp(-0.382))
    assert alg.pm_min == pytest.approx(0.1 * math.exp(-0.618))


def test_adaptive_probability_degenerate_population():
    # all fitness equal: nobody is above average, everybody gets the maximum
    p = adaptive_probability(np.full(4, 0.3), 0.3, 0.3, 0.9, 0.5, 0.382)
    np.testing.assert_array_equal(p, 0.9)


def test_verbose_shows_pc_pm_and_accepted(capsys):
    minimize(ZDT1(n_var=10), small(), ("n_gen", 3), seed=1, verbose=True)
    out = capsys.readouterr().out
    assert "pc_mean" in out and "pm_mean" in out and "n_acc" in out


# -- bad parameters ---------------------------------------------------------------------------


@pytest.mark.parametrize(
    "kwargs, words",
    [
        ({"pop_size": 1}, ["pop_size", "1"]),
        ({"pop_size": 10.5}, ["pop_size", "10.5"]),
        ({"local_size": 7}, ["local_size", "7"]),
        ({"local_size": -2}, ["local_size", "-2"]),
        ({"pop_size": 10, "local_size": 12}, ["local_size", "12"]),
        ({"pc_max": 1.5}, ["pc_max", "1.5"]),
        ({"pc_min": -0.1}, ["pc_min", "-0.1"]),
        ({"pc_max": 0.6, "pc_min": 0.7}, ["pc_min", "0.7"]),
        ({"pm_max": 2}, ["pm_max", "2"]),
        ({"pm_max": 0.1, "pm_min": 0.2}, ["pm_min", "0.2"]),
        ({"pm_min": float("nan")}, ["pm_min", "nan"]),
        ({"t0": 0.0}, ["t0", "0.0"]),
        ({"cooling": 1.5}, ["cooling", "1.5"]),
        ({"n_offsprings": 0}, ["n_offsprings", "0"]),
        ({"fixed_genes": [[0, 1]]}, ["fixed_genes", "shape"]),
        ({"fixed_genes": [0.5]}, ["fixed_genes", "float"]),
    ],
)
def test_bad_parameters(kwargs, words):
    with pytest.raises(ValueError) as err:
        GoldenRatioNSGA2(**kwargs)
    for w in words:
        assert w in str(err.value)


def test_bad_operators():
    from pymoo.operators.crossover.sbx import SBX
    from pymoo.operators.mutation.gauss import GaussianMutation

    with pytest.raises(ValueError, match="crossover"):
        GoldenRatioNSGA2(crossover=SBX(n_offsprings=1))
    with pytest.raises(ValueError, match="crossover"):
        GoldenRatioNSGA2(crossover="sbx")
    with pytest.raises(ValueError, match="mutation"):
        GoldenRatioNSGA2(mutation=GaussianMutation())


@pytest.mark.parametrize(
    "fixed, words",
    [([0, 12], ["fixed_genes", "12"]), (np.ones(3, dtype=bool), ["fixed_genes", "length 3"])],
)
def test_fixed_genes_checked_against_problem(fixed, words):
    with pytest.raises(ValueError) as err:
        minimize(ZDT1(n_var=10), small(fixed_genes=fixed), ("n_gen", 2), seed=1)
    for w in words:
        assert w in str(err.value)
