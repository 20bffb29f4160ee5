"""Tests of the multi-objective Artificial Bee Colony (pymoo_rail.algorithms.MOABC)."""

import pickle

import numpy as np
import pytest
from pymoo.core.population import Population
from pymoo.indicators.igd import IGD
from pymoo.optimize import minimize
from pymoo.problems.many.dtlz import DTLZ2
from pymoo.problems.multi.bnh import BNH
from pymoo.problems.multi.tnk import TNK
from pymoo.problems.multi.zdt import ZDT1
from pymoo.termination.max_time import TimeBasedTermination
from pymoo.util.nds.non_dominated_sorting import NonDominatedSorting

from pymoo_rail.algorithms import MOABC
from pymoo_rail.algorithms.moabc import (
    domination_counts,
    dominance_probabilities,
    truncate_by_crowding,
)


def run_ask_tell(problem, algorithm, termination, seed, pickle_after=None):
    algorithm.setup(problem, termination=termination, seed=seed)
    n_tells = 0
    while algorithm.has_next():
        pop = algorithm.ask()
        algorithm.evaluator.eval(problem, pop)
        algorithm.tell(infills=pop)
        n_tells += 1
        if n_tells == pickle_after:
            algorithm = pickle.loads(pickle.dumps(algorithm))
    return algorithm.result()


def test_zdt1_igd_below_0_05():
    problem = ZDT1()
    res = minimize(problem, MOABC(pop_size=100), ("n_eval", 10000), seed=1)
    assert IGD(problem.pareto_front())(res.F) < 0.05


def test_result_is_the_archive():
    res = minimize(ZDT1(n_var=10), MOABC(pop_size=20, archive_size=30), ("n_gen", 30), seed=2)
    algorithm = res.algorithm
    np.testing.assert_array_equal(res.F, algorithm.pareto_archive.get("F"))
    np.testing.assert_array_equal(res.X, algorithm.pareto_archive.get("X"))
    assert algorithm.archive is None  # pymoo's own archive attribute is left alone


def test_archive_bounded_and_mutually_nondominated():
    sizes, fronts_ok = [], []

    def check(algorithm):
        F = algorithm.pareto_archive.get("F")
        sizes.append(len(F))
        front = NonDominatedSorting().do(F, only_non_dominated_front=True)
        fronts_ok.append(len(front) == len(F))

    minimize(
        ZDT1(n_var=10),
        MOABC(pop_size=20, archive_size=15),
        ("n_gen", 1 + 2 * 60),  # 60 cycles of two iterations
        seed=3,
        callback=check,
    )
    assert max(sizes) == 15  # the cap is reached and never exceeded
    assert all(fronts_ok)


def test_crowding_truncation_removes_most_crowded_point():
    # on a line front: (1, 3) sits between (0, 4) and (1.1, 2.9), a box of 1.1 x 1.1, while
    # (1.1, 2.9) spans 2 x 2 and (3, 1) spans 2.9 x 2.9; the extremes are infinite
    F = np.array([[0.0, 4.0], [1.0, 3.0], [1.1, 2.9], [3.0, 1.0], [4.0, 0.0]])
    pop = Population.new(X=np.arange(5.0)[:, None], F=F)
    kept = truncate_by_crowding(pop, 4)
    np.testing.assert_array_equal(kept.get("X")[:, 0], [0.0, 2.0, 3.0, 4.0])
    # one at a time: after removing (1, 3), (1.1, 2.9) spans 3 x 3 and (3, 1) spans
    # 2.9 x 2.9, so (3, 1) goes next; removing the two smallest initial distances at once
    # would wrongly drop (1.1, 2.9)
    kept = truncate_by_crowding(pop, 3)
    np.testing.assert_array_equal(kept.get("X")[:, 0], [0.0, 2.0, 4.0])


def test_crowding_truncation_tie_goes_to_lowest_index():
    F = np.array([[0.0, 4.0], [1.0, 3.0], [2.0, 2.0], [3.0, 1.0], [4.0, 0.0]])
    pop = Population.new(X=np.arange(5.0)[:, None], F=F)
    kept = truncate_by_crowding(pop, 4)
    np.testing.assert_array_equal(kept.get("X")[:, 0], [0.0, 2.0, 3.0, 4.0])


def test_domination_counts_and_probabilities():
    F = np.array([[0.0, 0.0], [1.0, 1.0], [2.0, 2.0], [0.0, 3.0]])
    CV = np.zeros(4)
    np.testing.assert_array_equal(domination_counts(F, CV), [3, 1, 0, 0])
    np.testing.assert_allclose(dominance_probabilities(F, CV), [0.75, 0.25, 0.0, 0.0])
    # constraint violation dominates first
    np.testing.assert_array_equal(domination_counts(F, np.array([1.0, 0, 0, 0])), [0, 2, 1, 1])
    # mutually non-dominated: uniform
    front = np.array([[0.0, 1.0], [1.0, 0.0]])
    np.testing.assert_allclose(dominance_probabilities(front, np.zeros(2)), [0.5, 0.5])


def test_three_objectives_dtlz2():
    problem = DTLZ2(n_var=7, n_obj=3)
    res = minimize(problem, MOABC(pop_size=40, archive_size=50), ("n_gen", 60), seed=1)
    assert res.F.shape[1] == 3 and 10 <= len(res.F) <= 50
    # DTLZ2's front is the unit sphere octant
    assert np.median(np.linalg.norm(res.F, axis=1)) < 1.2


@pytest.mark.parametrize("problem", [BNH(), TNK()], ids=["BNH", "TNK"])
def test_constrained_problem_gives_feasible_archive(problem):
    res = minimize(problem, MOABC(pop_size=40, archive_size=50), ("n_gen", 80), seed=1)
    assert len(res.F) >= 10
    assert np.all(res.CV <= 0.0)
    assert np.all(problem.evaluate(res.X, return_as_dictionary=True)["G"] <= 0.0)


def test_determinism_across_driving_modes_and_pickling():
    problem, termination = ZDT1(n_var=6), ("n_gen", 25)
    a = minimize(problem, MOABC(pop_size=10, archive_size=12, limit=3), termination, seed=5)
    loop = MOABC(pop_size=10, archive_size=12, limit=3)
    loop.setup(problem, termination=termination, seed=5)
    while loop.has_next():
        loop.next()
    b = loop.result()
    c = run_ask_tell(problem, MOABC(pop_size=10, archive_size=12, limit=3), termination, 5)
    d = run_ask_tell(
        problem, MOABC(pop_size=10, archive_size=12, limit=3), termination, 5, pickle_after=13
    )
    for other in (b, c, d):
        np.testing.assert_array_equal(a.X, other.X)
        np.testing.assert_array_equal(a.F, other.F)
        np.testing.assert_array_equal(a.pop.get("X"), other.pop.get("X"))


def test_different_seeds_differ():
    a = minimize(ZDT1(n_var=6), MOABC(pop_size=10), ("n_gen", 10), seed=1)
    b = minimize(ZDT1(n_var=6), MOABC(pop_size=10), ("n_gen", 10), seed=2)
    assert not np.array_equal(a.F, b.F)


@pytest.mark.parametrize("move", ["centred", "canonical", "literal"])
def test_each_move_runs_within_bounds(move):
    res = minimize(ZDT1(n_var=5), MOABC(pop_size=10, move=move), ("n_gen", 20), seed=1)
    assert np.all(res.X >= 0.0) and np.all(res.X <= 1.0)


def test_terminations_and_history():
    problem = ZDT1(n_var=5)
    res = minimize(problem, MOABC(pop_size=10), ("n_eval", 205), seed=1)
    # checked after every phase: 5 candidates plus at most 5 scouts
    assert 205 <= res.algorithm.evaluator.n_eval < 205 + 5 + 5
    res = minimize(problem, MOABC(pop_size=10), TimeBasedTermination(0.3), seed=1)
    assert len(res.F) > 0
    res = minimize(problem, MOABC(pop_size=10), ("n_gen", 8), seed=1, save_history=True)
    assert len(res.history) == 8
    assert all(len(h.opt) > 0 for h in res.history)


def test_one_iteration_per_ask_tell_round():
    """n_gen counts ask/tell rounds as pymoo does: scouts fly with the next employed phase."""
    res = minimize(ZDT1(n_var=5), MOABC(pop_size=10, limit=1), ("n_gen", 31), seed=1)
    algorithm = res.algorithm
    assert algorithm.n_cycles == 15 and algorithm.n_scouts_total > 0
    assert algorithm.evaluator.n_eval == 10 + 30 * 5 + algorithm.n_scouts_total
    asked = MOABC(pop_size=10, limit=1)
    asked.setup(ZDT1(n_var=5), seed=1)
    for _ in range(31):
        pop = asked.ask()
        asked.evaluator.eval(asked.problem, pop)
        asked.tell(infills=pop)
    np.testing.assert_array_equal(asked.result().F, res.F)


def test_scouts_happen_when_limit_is_small(capsys):
    scouts = []
    minimize(
        ZDT1(n_var=5),
        MOABC(pop_size=10, limit=1),
        ("n_gen", 20),
        seed=1,
        verbose=True,
        callback=lambda algorithm: scouts.append(algorithm.n_scouts),
    )
    assert sum(scouts) > 0
    assert "n_scouts" in capsys.readouterr().out


@pytest.mark.parametrize(
    "kwargs, name",
    [
        ({"pop_size": 0}, "pop_size"),
        ({"pop_size": 7}, "pop_size"),
        ({"archive_size": 0}, "archive_size"),
        ({"archive_size": 2.5}, "archive_size"),
        ({"move": "spiral"}, "move"),
        ({"w": 0.0}, "w"),
        ({"limit": -2}, "limit"),
    ],
)
def test_bad_input_raises(kwargs, name):
    with pytest.raises(ValueError, match=name) as info:
        MOABC(**kwargs)
    assert repr(next(iter(kwargs.values()))) in str(info.value) or str(
        next(iter(kwargs.values()))
    ) in str(info.value)


def test_archive_arrays_match_the_archive_population():
    """The archive's arrays (used for sorting and truncation) stay aligned with its members."""
    res = minimize(BNH(), MOABC(pop_size=20, archive_size=15), ("n_gen", 15), seed=4)
    algorithm = res.algorithm
    archive = algorithm.pareto_archive
    np.testing.assert_array_equal(algorithm.archive_X, archive.get("X"))
    np.testing.assert_array_equal(algorithm.archive_F, archive.get("F"))
    np.testing.assert_array_equal(algorithm.archive_CV, archive.get("CV")[:, 0])
    assert len(archive) == 15
