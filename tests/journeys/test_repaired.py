"""Repaired one-objective algorithms on a -trip instance: every evaluated candidate is on the budget,
the runs end feasible and never below the exact split, the same seed gives the same run."""

from __future__ import annotations

import numpy as np
import pytest
from pymoo.algorithms.soo.nonconvex.ga import GA
from pymoo.optimize import minimize

from pymoo_rail.experiments.runner import execute_run
from pymoo_rail.experiments.spec import Budget, RunSpec, algorithm, problem
from pymoo_rail.journeys.repaired import REPAIRED_METHODS, repaired_algorithm
from pymoo_rail.suite import get_problem

TRIP = "generated-suburban-trip"
# the populations of benchmarks/suite_baseline_trip.toml
METHODS = {"ga": {"pop_size": 50}, "de": {"pop_size": 50}, "pso": {"pop_size": 25}, "abc": {"pop_size": 40},
           "random": {"n_points_per_iteration": 50}}
N_EVAL = 400


@pytest.fixture(scope="module")
def instance():
    return get_problem(TRIP, n_var=10, seed=1)


def _evaluated(instance, algo, seed: int):
    """pymoo's result of ``algo`` on ``instance`` and every decision vector it evaluated, in order."""
    seen: list[np.ndarray] = []
    evaluate = instance._evaluate

    def recording(x, out, *args, **kwargs):
        seen.append(np.array(x, copy=True))
        return evaluate(x, out, *args, **kwargs)

    instance._evaluate = recording  # the instance's own attribute, removed below
    try:
        res = minimize(instance, algo, ("n_eval", N_EVAL), seed=seed)
    finally:
        del instance._evaluate
    return np.vstack(seen), res


def _run(instance, method: str, seed: int = 1):
    return _evaluated(instance, repaired_algorithm(method, **METHODS[method]), seed)


def test_the_five_methods_are_the_single_tables():
    assert set(REPAIRED_METHODS) == set(METHODS)


@pytest.mark.parametrize("method", sorted(METHODS))
def test_every_evaluated_candidate_is_on_the_budget_and_the_run_ends_feasible_above_the_exact_split(instance, method):
    X, res = _run(instance, method)
    # the initial sample, the offspring / moves / scouts: each evaluated vector, not only the survivors
    assert len(X) >= N_EVAL
    np.testing.assert_allclose(X.sum(axis=1), instance.total_time_s, rtol=0, atol=1e-6)
    assert (X >= instance.xl - 1e-12).all() and (X <= instance.xu + 1e-12).all()
    assert res.CV[0] == 0.0 and res.F.shape == (1,)
    optimum = instance.optimum[1]
    assert res.F[0] >= optimum - 1e-9 * abs(optimum)
    # and it searched: the best found beats the mean of the first sample (not the repair's fixed point)
    assert res.F[0] < instance.section_energies(X[:20]).sum(axis=1).mean()


@pytest.mark.parametrize("method", sorted(METHODS))
def test_the_same_seed_gives_the_same_run(instance, method):
    X1, first = _run(instance, method, seed=3)
    X2, again = _run(instance, method, seed=3)
    np.testing.assert_array_equal(X1, X2)
    np.testing.assert_array_equal(first.X, again.X)


def test_without_the_repair_a_sampled_split_misses_the_budget(instance):
    # why the repair: the same GA unrepaired evaluates candidates off the budget and ends infeasible
    X, res = _evaluated(instance, GA(pop_size=50), seed=1)
    assert np.abs(X.sum(axis=1) - instance.total_time_s).min() > 1e-4
    assert res.F is None or res.CV[0] > 0


def test_a_study_runs_it_by_import_path_when_trusted():
    spec = problem("suite_family", family=TRIP, n_var=10, seed=1)
    algo = algorithm("pymoo_rail.journeys.repaired:repaired_algorithm", method="abc", pop_size=40)
    record = execute_run(RunSpec(spec, algo, 1, Budget("n_eval", 200)), trusted=True)
    assert record["feasible"]
    assert "algorithm module pymoo_rail.journeys.repaired" in record["inputs"]


def test_bad_method_or_keyword_is_named():
    with pytest.raises(ValueError, match=r"method: 'cmaes' is not one of \['abc', 'de', 'ga', 'pso', 'random'\]"):
        repaired_algorithm("cmaes")
    with pytest.raises(TypeError, match=r"random.pop_size: 50 is not a parameter of RandomSearch"):
        repaired_algorithm("random", pop_size=50)
    with pytest.raises(TypeError, match=r"ga.pop_sise: 50"):
        repaired_algorithm("ga", pop_sise=50)
    assert repaired_algorithm("de", pop_size=20, CR=0.5).pop_size == 20  # DE's variant keywords pass


def test_a_keyword_the_algorithm_sets_itself_is_named():
    with pytest.raises(TypeError, match="abc.min_pop_size"):
        repaired_algorithm("abc", min_pop_size=2)
