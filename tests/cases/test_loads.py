"""Load states of the built-in cases (Liu 2019 table 5-2) and whole-km/h speed codes."""


import numpy as np
import pytest

from pymoo_rail.cases import load_case
from pymoo_rail.model import CaseError
from pymoo_rail.problems import SpeedProfileProblem


@pytest.mark.parametrize("load, mass_t", [("AW0", 194.295), ("AW2", 282.375), ("AW3", 307.095)])
def test_yizhuang_loads_from_the_thesis(load, mass_t):
    case = load_case("yizhuang", load=load)
    assert case.train.mass_t == mass_t
    assert case.name == f"yizhuang-{load}"
    base = load_case("yizhuang")
    assert case.line == base.line and case.train.traction == base.train.traction


def test_unknown_loads_name_the_field():
    with pytest.raises(CaseError, match="load.*AW9"):
        load_case("yizhuang", load="AW9")
    with pytest.raises(CaseError, match="no load states"):
        load_case("metro-a", load="AW3")


def test_heavier_train_needs_more_energy_for_the_same_codes():
    X = np.array([[55.0, 70.0, 70.0, 70.0, 70.0, 70.0, 70.0, 55.0]])
    e = [SpeedProfileProblem(load_case("yizhuang", load=ld)).evaluate(X, return_as_dictionary=True)["energy_kwh"][0]
         for ld in ("AW0", "AW2", "AW3")]
    assert e[0] < e[1] < e[2]


def test_integer_codes_with_pymoo_integer_operators():
    from pymoo.algorithms.moo.nsga2 import NSGA2
    from pymoo.operators.crossover.sbx import SBX
    from pymoo.operators.mutation.pm import PM
    from pymoo.operators.repair.rounding import RoundingRepair
    from pymoo.operators.sampling.rnd import IntegerRandomSampling
    from pymoo.optimize import minimize

    p = SpeedProfileProblem(load_case("yizhuang"), integer_codes=True)
    assert p.vtype is int
    assert np.all(p.xl == np.round(p.xl)) and np.all(p.xu == np.round(p.xu))
    assert np.all(p.xu <= p.encoding.xu + 1e-9)
    algorithm = NSGA2(pop_size=12, sampling=IntegerRandomSampling(),
                      crossover=SBX(prob=0.9, eta=15, vtype=float, repair=RoundingRepair()),
                      mutation=PM(eta=20, vtype=float, repair=RoundingRepair()))
    res = minimize(p, algorithm, ("n_gen", 3), seed=1)
    X = np.asarray(res.pop.get("X"), dtype=float)
    assert np.all(X == np.round(X))
    with pytest.raises(ValueError, match="whole km/h"):
        p.evaluate(np.full((1, p.n_var), 50.5))


def test_a_multi_leg_case_is_refused_by_a_single_run_problem_with_the_leg_api_named():
    case = load_case("cooperative-pair")
    with pytest.raises(CaseError) as raised:
        SpeedProfileProblem(case)
    message = str(raised.value)
    assert raised.value.field == "run.legs" and raised.value.value == 2
    assert "case.leg(k)" in message and "Journey" in message and "SpeedProfileProblem" in message
    assert SpeedProfileProblem(case.leg(0)).n_var > 0  # one leg is a single run
