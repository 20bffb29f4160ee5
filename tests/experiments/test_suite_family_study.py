"""Suite family instances in studies: the ``suite_family`` registry entry, its checksum in the
fingerprint, random search, and MOEA/D on a constrained instance through the penalty wrapper."""

import numpy as np
import pytest

from pymoo_rail.experiments.inputs import resolve_run
from pymoo_rail.experiments.registry import build_algorithm, build_problem, check_parameters
from pymoo_rail.experiments.runner import execute_run
from pymoo_rail.experiments.spec import Budget, RunSpec, StudyError, algorithm, problem
from pymoo_rail.suite import get_problem
from pymoo_rail.suite.families import DEFAULT_N_VAR, DEFAULT_SEED, instance_name

FAMILY = "generated-metro-bi"


def test_spec_builds_the_instance_get_problem_gives():
    spec = problem("suite_family", family=FAMILY, n_var=12, seed=7)
    check_parameters(spec, "problems[0]")
    built = build_problem(spec)
    assert built.checksum == get_problem(FAMILY, n_var=12, seed=7).checksum
    assert built.n_var == 12


def test_defaults_are_the_suite_defaults():
    assert build_problem(problem("suite_family", family=FAMILY)).suite_name == \
        instance_name(FAMILY, DEFAULT_N_VAR, DEFAULT_SEED)


@pytest.mark.parametrize("params, field", [({"family": FAMILY, "n_vars": 10}, "n_vars"),
                                           ({"family": FAMILY, "n_var": "10"}, "n_var")])
def test_bad_parameters_name_the_field(params, field):
    with pytest.raises(StudyError, match=field):
        check_parameters(problem("suite_family", **params), "problems[0]")


@pytest.mark.parametrize("params, words", [({"seed": 1.5}, "seed"), ({"n_var": 0}, "n_var")])
def test_bad_instance_values_name_the_field(params, words):
    with pytest.raises(StudyError, match=words):
        build_problem(problem("suite_family", family=FAMILY, **params))


def test_unknown_family_names_it():
    with pytest.raises(StudyError, match="atlantis-bi"):
        build_problem(problem("suite_family", family="atlantis-bi"))


def test_fingerprint_carries_the_instance_checksum_and_changes_with_the_seed():
    def fingerprint(seed):
        run = RunSpec(problem("suite_family", family=FAMILY, n_var=10, seed=seed), algorithm("nsga2"), 1,
                      Budget("n_eval", 100))
        return resolve_run(run).fingerprint["problem instance checksum"]

    assert fingerprint(7) == get_problem(FAMILY, n_var=10, seed=7).checksum
    assert fingerprint(7) != fingerprint(8)


def test_moead_runs_penalised_and_records_true_objectives():
    spec = problem("suite_family", family=FAMILY, n_var=10, seed=7)
    record = execute_run(RunSpec(spec, algorithm("moead", pop_size=10), 1, Budget("n_eval", 100)))
    instance = get_problem(FAMILY, n_var=10, seed=7)
    X = np.asarray(record["front"]["X"])
    out = instance.evaluate(X, return_as_dictionary=True)
    np.testing.assert_allclose(np.asarray(record["front"]["F"]), out["F"], rtol=1e-12)
    np.testing.assert_allclose(np.asarray(record["front"]["CV"]), np.maximum(out["G"], 0).sum(axis=1), atol=1e-12)


def test_random_search_spends_its_budget_and_keeps_a_nondominated_front():
    spec = problem("suite_family", family=FAMILY, n_var=10, seed=7)
    record = execute_run(RunSpec(spec, algorithm("random", n_points_per_iteration=25), 3, Budget("n_eval", 100)))
    assert record["n_eval"] == 100
    F = np.asarray(record["front"]["F"])[np.asarray(record["front"]["CV"]) <= 0]
    dominated = [(np.all(F <= f, axis=1) & np.any(F < f, axis=1)).any() for f in F]
    assert not any(dominated)


def test_rail_suite_refuses_a_family_and_names_the_entry_that_takes_it():
    with pytest.raises(StudyError, match='problem = "suite_family"'):
        build_problem(problem("rail_suite", suite_problem=FAMILY))
    with pytest.raises(StudyError):
        build_problem(problem("rail_suite", suite_problem=FAMILY, n_var=10, seed=7))


@pytest.mark.parametrize("name, cls", [("nsga3", "NSGA3"), ("ctaea", "CTAEA"), ("c-taea", "CTAEA")])
def test_reference_direction_algorithms_get_one_direction_per_member(name, cls):
    instance = build_problem(problem("suite_family", family="generated-metro-3obj", n_var=10, seed=7))
    spec = algorithm(name, pop_size=28)
    check_parameters(spec, "algorithms[0]")
    built = build_algorithm(spec, instance)
    assert type(built).__name__ == cls and built.ref_dirs.shape == (28, 3) and built.pop_size == 28


@pytest.mark.parametrize("params, field", [({"pop_sise": 20}, "pop_sise"), ({"pop_size": "20"}, "pop_size"),
                                           ({"eliminate_duplicate": False}, "eliminate_duplicate")])
def test_bad_ctaea_parameters_name_the_field(params, field):
    with pytest.raises(StudyError, match=field):
        check_parameters(algorithm("ctaea", **params), "algorithms[0]")


@pytest.fixture(scope="module")
def front_cache(tmp_path_factory):
    """One fresh cache for the module: the 3-objective instance's inner front is computed there once."""
    mp = pytest.MonkeyPatch()
    mp.setenv("PYMOO_RAIL_CACHE_DIR", str(tmp_path_factory.mktemp("fronts")))
    yield
    mp.undo()


@pytest.mark.parametrize("name", ["nsga3", "ctaea"])
def test_a_tiny_study_runs_nsga3_and_ctaea_on_a_constrained_3obj_instance(front_cache, name):
    spec = problem("suite_family", family="generated-metro-3obj", n_var=10, seed=1)
    record = execute_run(RunSpec(spec, algorithm(name, pop_size=15), 2, Budget("n_eval", 150)))
    # the budget is counted in evaluations, one generation of pop_size offspring at a time
    assert 150 <= record["n_eval"] <= 150 + 15 and record["n_obj"] == 3
    instance = get_problem("generated-metro-3obj", n_var=10, seed=1)
    X, F = np.asarray(record["front"]["X"]), np.asarray(record["front"]["F"])
    np.testing.assert_allclose(instance.evaluate(X, return_values_of=["F"]), F, rtol=1e-12)  # searched unpenalised
    again = execute_run(RunSpec(spec, algorithm(name, pop_size=15), 2, Budget("n_eval", 150)))
    np.testing.assert_array_equal(np.asarray(again["front"]["F"]), F)  # same seed, same front
