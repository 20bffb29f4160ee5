"""Suite family instances in studies: the ``suite_family`` registry entry, its checksum in the
fingerprint, random search, and MOEA/D on a constrained instance through the penalty wrapper."""

import numpy as np
import pytest

from pymoo_rail.experiments.inputs import resolve_run
from pymoo_rail.experiments.registry import build_problem, check_parameters
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
