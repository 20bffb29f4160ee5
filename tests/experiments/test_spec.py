"""Study declarations, study files, the registry and the seed's test functions."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from pymoo_rail.experiments import (
    AlgorithmSpec,
    Budget,
    ProblemSpec,
    Study,
    StudyError,
    algorithm,
    build_algorithm,
    build_problem,
    problem,
    read_study,
    study_to_toml,
    write_study,
)

EXAMPLE = Path(__file__).resolve().parents[2] / "examples" / "study_zdt.toml"


def test_example_study_file_is_3_problems_x_3_algorithms_x_5_seeds():
    study = read_study(EXAMPLE)
    assert [p.name for p in study.problems] == ["zdt1", "zdt2", "zdt3"]
    assert [a.display for a in study.algorithms] == ["nsga2", "grnsga2", "moead"]
    assert study.seeds == (1, 2, 3, 4, 5) and len(study.runs()) == 45
    assert study.baseline == "nsga2" and study.budget == Budget("n_eval", 4000)


def test_study_round_trips_through_toml(tmp_path):
    study = Study("rail", problems=[problem("speed_profile", label="yz", case="yizhuang",
                                            objectives=["energy", "time_error"], time_tolerance_s=1.5),
                                    problem("zdt1")],
                  algorithms=[algorithm("nsga2", pop_size=100), algorithm("moabc", label="MOABC w=0.5", w=0.5)],
                  seeds=[3, 1, 7], budget=Budget("n_eval", 5000), history=False, baseline="nsga2")
    path = write_study(study, tmp_path / "s.toml")
    assert read_study(path) == study
    assert "objectives = [\"energy\", \"time_error\"]" in study_to_toml(study)


def test_run_id_depends_on_what_determines_the_result_not_on_labels():
    base = Study("a", [problem("zdt1")], [algorithm("nsga2", pop_size=10)], seeds=[1], budget={"n_gen": 5})
    relabelled = Study("b", [problem("zdt1", label="Z1")], [algorithm("nsga2", label="N", pop_size=10)],
                       seeds=[1], budget={"n_gen": 5})
    other_param = Study("a", [problem("zdt1")], [algorithm("nsga2", pop_size=12)], seeds=[1], budget={"n_gen": 5})
    other_budget = Study("a", [problem("zdt1")], [algorithm("nsga2", pop_size=10)], seeds=[1], budget={"n_gen": 6})
    other_seed = Study("a", [problem("zdt1")], [algorithm("nsga2", pop_size=10)], seeds=[2], budget={"n_gen": 5})
    ids = [s.runs()[0].run_id for s in (base, relabelled, other_param, other_budget, other_seed)]
    assert ids[0] == ids[1]
    assert len(set(ids)) == 4
    assert len(ids[0]) == 16 and int(ids[0], 16) >= 0


def test_specs_are_hashable_and_compare_by_value():
    assert ProblemSpec("zdt1", {"n_var": 5}) == problem("zdt1", n_var=5)
    assert len({algorithm("nsga2", pop_size=5), AlgorithmSpec("nsga2", {"pop_size": 5})}) == 1
    assert problem("speed_profile", objectives=("energy", "jerk")).params == {"objectives": ["energy", "jerk"]}


@pytest.mark.parametrize("kwargs, field", [
    ({"seeds": []}, "seeds"),
    ({"seeds": [1, 1]}, "seeds"),
    ({"seeds": [1.5]}, "seeds"),
    ({"budget": {"n_gen": 0}}, "budget.n_gen"),
    ({"budget": {"time": 10}}, "budget"),
    ({"budget": {"n_gen": 5, "n_eval": 100}}, "budget"),
    ({"baseline": "nsga3"}, "baseline"),
    ({"problems": []}, "problems"),
    ({"algorithms": [algorithm("nsga2"), algorithm("nsga2", pop_size=5)]}, "algorithms"),
])
def test_bad_study_names_the_field(kwargs, field):
    args = {"name": "x", "problems": [problem("zdt1")], "algorithms": [algorithm("nsga2")], "seeds": 2,
            "budget": {"n_gen": 5}, **kwargs}
    with pytest.raises(StudyError) as err:
        Study(**args)
    assert err.value.field == field


def test_bad_spec_values_are_refused():
    with pytest.raises(StudyError, match="finite"):
        problem("zdt1", scale=float("nan"))
    with pytest.raises(StudyError, match="must be a string, number"):
        algorithm("nsga2", sampling=object())
    with pytest.raises(StudyError, match="reserved"):
        ProblemSpec("zdt1", {"label": "x"})


def test_bad_study_file_names_file_field_and_value(tmp_path):
    path = tmp_path / "bad.toml"
    path.write_text('name = "x"\nseeds = 3\nbudgets = {n_gen = 5}\n[[problems]]\nproblem = "zdt1"\n'
                    '[[algorithms]]\nalgorithm = "nsga2"\n')
    with pytest.raises(StudyError, match=r"bad\.toml: field 'budgets'.*unknown key"):
        read_study(path)
    path.write_text('name = "x"\n[budget]\nn_gen = 5\n[[problems]]\nn_var = 3\n[[algorithms]]\nalgorithm = "a"\n')
    with pytest.raises(StudyError, match=r"field 'problems\[0\]\.problem'.*required"):
        read_study(path)
    path.write_text("name = \n")
    with pytest.raises(StudyError, match="not valid TOML"):
        read_study(path)
    with pytest.raises(StudyError, match="no such study file"):
        read_study(tmp_path / "missing.toml")


def test_registry_builds_pymoo_problems_and_algorithms():
    from pymoo.algorithms.moo.moead import MOEAD
    from pymoo.algorithms.moo.nsga2 import NSGA2
    from pymoo.algorithms.moo.sms import SMSEMOA

    zdt1 = build_problem(problem("ZDT1", n_var=7))
    assert (zdt1.n_var, zdt1.n_obj) == (7, 2)
    assert build_problem(problem("dtlz2", n_obj=3)).n_obj == 3
    assert isinstance(build_algorithm(algorithm("nsga2", pop_size=10), zdt1), NSGA2)
    assert isinstance(build_algorithm(algorithm("sms_emoa"), zdt1), SMSEMOA)
    moead = build_algorithm(algorithm("moead", pop_size=15), zdt1)
    assert isinstance(moead, MOEAD) and len(moead.ref_dirs) == 15  # one weight vector per member


def test_registry_accepts_import_paths_only_when_trusted():
    from pymoo_rail.experiments.registry import UntrustedCodeError

    spec = problem("pymoo.problems.multi.zdt:ZDT2", n_var=4)
    with pytest.raises(UntrustedCodeError, match=r"'problem' = 'pymoo.problems.multi.zdt:ZDT2'.*trusted=True.*--trust"):
        build_problem(spec)
    assert type(build_problem(spec, trusted=True)).__name__ == "ZDT2"


def test_registry_errors_name_the_spec():
    zdt1 = build_problem(problem("zdt1"))
    with pytest.raises(StudyError, match="unknown problem"):
        build_problem(problem("zdt9"))
    with pytest.raises(StudyError, match="unknown algorithm"):
        build_algorithm(algorithm("nsga9"), zdt1)
    with pytest.raises(StudyError, match="single-objective; the problem has 2"):
        build_algorithm(algorithm("pso"), zdt1)
    with pytest.raises(StudyError, match="multi-objective; the problem has 1"):
        build_algorithm(algorithm("moead"), build_problem(problem("sphere")))
    with pytest.raises(StudyError, match=r"problem 'sphere'.colour' = 'red': unknown parameter.*accepted: n_var"):
        build_problem(problem("sphere", colour="red"))
    with pytest.raises(StudyError, match="cannot import module"):
        build_problem(problem("no_such_module:Thing"), trusted=True)


def test_operators_are_named_in_a_spec_and_survive_the_toml_file(tmp_path):
    """``crossover = {operator = "sbx", prob = 0.9, eta = 15}`` builds the same algorithm as the
    pymoo objects: the same seeded run gives the same front."""
    from pymoo.algorithms.moo.nsga2 import NSGA2
    from pymoo.operators.crossover.sbx import SBX
    from pymoo.operators.mutation.pm import PM
    from pymoo.optimize import minimize

    spec = algorithm("nsga2", pop_size=16, crossover={"operator": "sbx", "prob": 0.9, "eta": 15},
                     mutation={"operator": "PM", "prob": 1.0, "prob_var": 0.01, "eta": 20}, sampling="lhs")
    study = Study("ops", problems=[problem("zdt2", n_var=5)], algorithms=[spec], budget={"n_gen": 12})
    write_study(study, tmp_path / "ops.toml")
    again = read_study(tmp_path / "ops.toml").algorithms[0]
    assert again == spec
    zdt2 = build_problem(problem("zdt2", n_var=5))
    built = build_algorithm(again, zdt2)
    assert isinstance(built.mating.crossover, SBX) and built.mating.crossover.eta.value == 15
    assert built.mating.mutation.prob_var.value == 0.01 and type(built.initialization.sampling).__name__ == "LHS"

    from pymoo.operators.sampling.lhs import LHS

    direct = NSGA2(pop_size=16, crossover=SBX(prob=0.9, eta=15), mutation=PM(prob=1.0, prob_var=0.01, eta=20),
                   sampling=LHS())
    a = minimize(zdt2, built, ("n_gen", 12), seed=7).F
    b = minimize(zdt2, direct, ("n_gen", 12), seed=7).F
    np.testing.assert_array_equal(a, b)


@pytest.mark.parametrize("crossover, match", [
    ({"operator": "blend"}, r"crossover.operator' = 'blend': unknown crossover"),
    ({"prob": 0.9}, r"crossover.operator' = None"),
    ({"operator": "sbx", "etta": 3}, r"'nsga2'.crossover.etta' = 3: unknown parameter of crossover 'sbx' \(did you mean 'eta'"),
    (3, r"crossover' = 3: must be a crossover name"),
])
def test_bad_operator_names_spec_field_and_value(crossover, match):
    zdt1 = build_problem(problem("zdt1"))
    with pytest.raises(StudyError, match=match):
        build_algorithm(algorithm("nsga2", crossover=crossover), zdt1)


def test_rail_algorithms_are_registered_and_built_lazily():
    zdt1 = build_problem(problem("zdt1"))
    try:
        from pymoo_rail.algorithms.golden_ratio_nsga2 import GoldenRatioNSGA2
    except ImportError:
        pytest.skip("GoldenRatioNSGA2 not merged into this branch")
    assert isinstance(build_algorithm(algorithm("grnsga2", pop_size=20, local_size=4), zdt1), GoldenRatioNSGA2)


def test_speed_profile_problem_from_a_spec():
    pytest.importorskip("pymoo_rail.problems")
    p = build_problem(problem("speed_profile", case="yizhuang", objectives=["energy", "time_error"]))
    assert p.n_obj == 2 and p.case.name == "yizhuang" and p.objectives == ("energy", "time_error")
    with pytest.raises(Exception, match="nowhere"):
        build_problem(problem("speed_profile", case="nowhere"))


@pytest.mark.parametrize("name, low, high", [("sphere", -100.0, 100.0), ("griewank", -600.0, 600.0),
                                             ("rosenbrock", -2.048, 2.048)])
def test_seed_functions_use_the_seed_domains_and_optima(name, low, high):
    """Seed 000, eqs. 3-6 to 3-8: domains and minimum 0 (at the origin, at (1, ..., 1) for Rosenbrock)."""
    p = build_problem(problem(name, n_var=5))
    np.testing.assert_array_equal(p.xl, np.full(5, low))
    np.testing.assert_array_equal(p.xu, np.full(5, high))
    x_opt = np.ones((1, 5)) if name == "rosenbrock" else np.zeros((1, 5))
    assert p.evaluate(x_opt).item() == pytest.approx(0.0, abs=1e-12)
    if name == "sphere":
        assert p.evaluate(np.full((1, 5), 3.0)).item() == pytest.approx(45.0)  # 5 * 3^2


def test_every_forwarded_class_of_the_registry_exists():
    """A factory's parameters are checked against the class it forwards to: that class must import
    (a module moved without updating its registry entry would leave its parameters unchecked)."""
    import importlib

    from pymoo_rail.experiments.registry import ALGORITHMS, PROBLEMS

    factories = list(PROBLEMS.values()) + [entry.factory for entry in ALGORITHMS.values()]
    targets = [target for factory in factories for target in getattr(factory, "forwards_to", ())]
    assert targets, "no factory forwards its parameters: the check would be vacuous"
    missing = [f"{module}.{name}" for module, name in targets
               if not hasattr(importlib.import_module(module), name)]
    assert missing == []
