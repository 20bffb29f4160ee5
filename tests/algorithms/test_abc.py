"""Tests of the single-objective Artificial Bee Colony (pymoo_rail.algorithms.ABC)."""

import pickle
import subprocess
import sys

import numpy as np
import pytest
from pymoo.core.problem import Problem
from pymoo.optimize import minimize
from pymoo.termination.max_time import TimeBasedTermination

from pymoo_rail.algorithms import ABC


class Sphere(Problem):
    """Sphere of seed 000, eq. 3-6, on [-100, 100]^n; optimum 0 at the origin."""

    def __init__(self, n_var=10, shift=0.0):
        super().__init__(n_var=n_var, n_obj=1, xl=-100.0, xu=100.0)
        self.shift = shift

    def _evaluate(self, x, out, *args, **kwargs):
        out["F"] = np.sum(x**2, axis=1) + self.shift


class ConstrainedSphere(Problem):
    """min sum x_i^2 s.t. x_1 >= 1 and x_2 <= -2 on [-5, 5]^3.

    The unconstrained optimum (0, 0, 0) is infeasible; the constrained optimum is
    x = (1, -2, 0) with f = 5 (each term is minimised separately).
    """

    def __init__(self):
        super().__init__(n_var=3, n_obj=1, n_ieq_constr=2, xl=-5.0, xu=5.0)

    def _evaluate(self, x, out, *args, **kwargs):
        out["F"] = np.sum(x**2, axis=1)
        out["G"] = np.column_stack([1.0 - x[:, 0], x[:, 1] + 2.0])


def run_loop(problem, algorithm, termination, seed):
    algorithm.setup(problem, termination=termination, seed=seed)
    while algorithm.has_next():
        algorithm.next()
    return algorithm.result()


def run_ask_tell(problem, algorithm, termination, seed):
    algorithm.setup(problem, termination=termination, seed=seed)
    while algorithm.has_next():
        pop = algorithm.ask()
        algorithm.evaluator.eval(problem, pop)
        algorithm.tell(infills=pop)
    return algorithm.result()


@pytest.mark.parametrize("seed", [1, 2, 3])
def test_sphere_10d_reaches_1e_12_within_500_cycles(seed):
    # a cycle is two pymoo iterations (employed, onlooker) after the initial colony
    res = minimize(Sphere(10), ABC(pop_size=40), ("n_gen", 1 + 2 * 500), seed=seed)
    assert res.F[0] < 1e-12


@pytest.mark.parametrize("fitness", ["rank", "inverse"])
def test_negative_objective_values_work(fitness):
    # the onlooker fitness must not assume f >= 0 (seed eq. 3-3 needs a special case)
    algorithm = ABC(pop_size=20, onlooker_fitness=fitness)
    res = minimize(Sphere(5, shift=-100.0), algorithm, ("n_gen", 1 + 2 * 300), seed=1)
    assert res.F[0] == pytest.approx(-100.0, abs=1e-8)


def test_onlooker_probabilities():
    from pymoo_rail.algorithms.abc import inverse_probabilities, rank_probabilities

    F, CV = np.array([3.0, 0.0, 1.0]), np.zeros(3)
    # linear ranking: best gets 3, then 2, then 1, out of 6
    np.testing.assert_allclose(rank_probabilities(F, CV), [1 / 6, 3 / 6, 2 / 6])
    # eq. 3-3: 1/4, 1, 1/2 out of 7/4
    np.testing.assert_allclose(inverse_probabilities(F, CV), [1 / 7, 4 / 7, 2 / 7])
    # an infeasible source ranks last whatever its objective
    CV = np.array([0.0, 2.0, 0.0])
    assert np.argmin(rank_probabilities(F, CV)) == 1
    assert np.argmin(inverse_probabilities(F, CV)) == 1


def test_minimize_loop_and_ask_tell_are_identical():
    problem, termination = Sphere(5), ("n_gen", 40)
    a = minimize(problem, ABC(pop_size=20, limit=10), termination, seed=7)
    b = run_loop(problem, ABC(pop_size=20, limit=10), termination, seed=7)
    asked = ABC(pop_size=20, limit=10)
    c = run_ask_tell(problem, asked, termination, seed=7)
    for other in (b, c):
        np.testing.assert_array_equal(a.X, other.X)
        np.testing.assert_array_equal(a.F, other.F)
        np.testing.assert_array_equal(a.pop.get("X"), other.pop.get("X"))
    assert a.algorithm.evaluator.n_eval == asked.evaluator.n_eval


def test_same_seed_same_result_different_seed_differs():
    a = minimize(Sphere(5), ABC(pop_size=20), ("n_gen", 30), seed=3)
    b = minimize(Sphere(5), ABC(pop_size=20), ("n_gen", 30), seed=3)
    c = minimize(Sphere(5), ABC(pop_size=20), ("n_gen", 30), seed=4)
    np.testing.assert_array_equal(a.X, b.X)
    assert not np.array_equal(a.X, c.X)


@pytest.mark.parametrize("n_tells", [9, 10])  # 9 stops between phases of a cycle
def test_pickle_mid_run_continues_identically(n_tells):
    problem, termination = Sphere(4), ("n_gen", 30)
    reference = run_ask_tell(problem, ABC(pop_size=10, limit=5), termination, seed=11)

    algorithm = ABC(pop_size=10, limit=5)
    algorithm.setup(problem, termination=termination, seed=11)
    for _ in range(n_tells):
        pop = algorithm.ask()
        algorithm.evaluator.eval(problem, pop)
        algorithm.tell(infills=pop)
    algorithm = pickle.loads(pickle.dumps(algorithm))
    while algorithm.has_next():
        pop = algorithm.ask()
        algorithm.evaluator.eval(problem, pop)
        algorithm.tell(infills=pop)
    res = algorithm.result()
    np.testing.assert_array_equal(res.X, reference.X)
    np.testing.assert_array_equal(res.pop.get("X"), reference.pop.get("X"))


def test_constraints_feasible_and_near_constrained_optimum():
    res = minimize(ConstrainedSphere(), ABC(pop_size=20), ("n_gen", 1 + 2 * 300), seed=1)
    assert res.CV[0] <= 0.0
    assert res.F[0] == pytest.approx(5.0, abs=1e-6)
    np.testing.assert_allclose(res.X, [1.0, -2.0, 0.0], atol=1e-3)


def test_save_history():
    res = minimize(Sphere(3), ABC(pop_size=10), ("n_gen", 12), seed=1, save_history=True)
    assert len(res.history) == 12
    best = [h.opt[0].F[0] for h in res.history]
    assert all(b1 <= b0 for b0, b1 in zip(best, best[1:]))  # best-so-far never gets worse


def test_n_gen_counts_ask_tell_rounds_like_pymoo():
    res = minimize(Sphere(3), ABC(pop_size=10, limit=1000), ("n_gen", 20), seed=1)
    # initial colony of 10, then 19 phases (employed, onlooker, ...) of 5 evaluations, no scouts
    assert res.algorithm.evaluator.n_eval == 10 + 19 * 5
    assert res.algorithm.n_cycles == 9  # 9 employed + onlooker pairs, then one employed phase
    # a hand-written loop of 20 ask/tell rounds gets the same budget and the same result
    looped = run_ask_tell(Sphere(3), ABC(pop_size=10, limit=1000), ("n_gen", 20), seed=1)
    asked = ABC(pop_size=10, limit=1000)
    asked.setup(Sphere(3), seed=1)
    for _ in range(20):
        pop = asked.ask()
        asked.evaluator.eval(asked.problem, pop)
        asked.tell(infills=pop)
    assert asked.evaluator.n_eval == res.algorithm.evaluator.n_eval
    np.testing.assert_array_equal(asked.result().X, res.X)
    np.testing.assert_array_equal(looped.X, res.X)


def test_scouts_fly_with_the_next_employed_phase():
    """Scouts do not add rounds: every cycle is two iterations, scouts add evaluations."""
    sizes = []
    res = minimize(Sphere(3), ABC(pop_size=10, limit=1), ("n_gen", 41), seed=1,
                   callback=lambda algorithm: sizes.append((algorithm.n_iter, algorithm.n_scouts)))
    algorithm = res.algorithm
    assert algorithm.n_scouts_total > 0 and algorithm.n_cycles == 20
    assert algorithm.evaluator.n_eval == 10 + 40 * 5 + algorithm.n_scouts_total
    # scouts only ever fly with an employed phase (even iterations: 2, 4, ...)
    assert all(n_iter % 2 == 0 for n_iter, n in sizes if n > 0)


def test_n_eval_termination():
    res = minimize(Sphere(3), ABC(pop_size=10), ("n_eval", 503), seed=1)
    n_eval = res.algorithm.evaluator.n_eval
    # termination is checked after each phase (5 evaluations plus at most 5 scouts)
    assert 503 <= n_eval < 503 + 5 + 5


def test_time_termination():
    res = minimize(Sphere(3), ABC(pop_size=10), TimeBasedTermination(0.3), seed=1)
    assert res.F[0] < 1e3
    assert res.exec_time < 5.0


def test_scouts_happen_when_limit_is_small():
    scouts = []
    minimize(
        Sphere(3),
        ABC(pop_size=10, limit=2),
        ("n_gen", 30),
        seed=1,
        callback=lambda algorithm: scouts.append(algorithm.n_scouts),
    )
    assert sum(scouts) > 0


def test_no_scouts_with_huge_limit():
    scouts = []
    minimize(
        Sphere(3),
        ABC(pop_size=10, limit=10**6),
        ("n_gen", 30),
        seed=1,
        callback=lambda algorithm: scouts.append(algorithm.n_scouts),
    )
    assert sum(scouts) == 0


def test_verbose_output_has_scouts_column(capsys):
    minimize(Sphere(3), ABC(pop_size=10), ("n_gen", 3), seed=1, verbose=True)
    out = capsys.readouterr().out
    assert "n_scouts" in out and "f_min" in out and "f_avg" in out


def test_stays_within_bounds():
    res = minimize(Sphere(3), ABC(pop_size=10, limit=1), ("n_gen", 50), seed=1)
    X = res.pop.get("X")
    assert np.all(X >= -100.0) and np.all(X <= 100.0)


@pytest.mark.parametrize("pop_size", [0, 1, 2, 3, 7, 2.0, "40"])
def test_bad_pop_size_raises(pop_size):
    with pytest.raises(ValueError, match="pop_size"):
        ABC(pop_size=pop_size)


@pytest.mark.parametrize("limit", [-1, 1.5])
def test_bad_limit_raises(limit):
    with pytest.raises(ValueError, match="limit"):
        ABC(pop_size=10, limit=limit)


def test_bad_onlooker_fitness_raises():
    with pytest.raises(ValueError, match="onlooker_fitness.*'roulette'"):
        ABC(pop_size=10, onlooker_fitness="roulette")


def test_multi_objective_problem_rejected():
    from pymoo.problems.multi.zdt import ZDT1

    with pytest.raises(ValueError, match="n_obj"):
        minimize(ZDT1(), ABC(pop_size=10), ("n_gen", 2))


def test_algorithms_import_no_other_pymoo_rail_module():
    code = (
        "import sys, pymoo_rail.algorithms; "
        "print(sorted(m for m in sys.modules if m.startswith('pymoo_rail.') "
        "and not m.startswith('pymoo_rail.algorithms')))"
    )
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True)
    assert out.stdout.strip() == "[]"
