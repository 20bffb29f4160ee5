"""The tracking scripts' DE references go through the study runner and are the runs pymoo gives."""

from __future__ import annotations

import numpy as np
from pymoo.algorithms.soo.nonconvex.de import DE
from pymoo.optimize import minimize

from benchmarks import tracking
from pymoo_rail.cases import load_case
from pymoo_rail.control import Hysteresis
from pymoo_rail.experiments import best_run, load_results, run_study
from pymoo_rail.problems import SpeedProfileProblem


def test_the_tracked_de_reference_is_the_run_minimize_gives(tmp_path):
    study = tracking.reference_study("yizhuang", [2], 2)
    study = type(study)(study.name, study.problems[1:], study.algorithms, seeds=study.seeds, budget=study.budget)
    run_study(study, tmp_path, workers=1, progress=False)
    _, x = best_run(load_results(tmp_path, study=study), "DE tracked")
    by_hand = SpeedProfileProblem(load_case("yizhuang"), objectives=("energy",), time_tolerance_s=0.5,
                                  tracking=Hysteresis(2.0, 3.0))
    res = minimize(by_hand, DE(pop_size=50, CR=0.9), ("n_gen", 2), seed=2)
    np.testing.assert_array_equal(x, res.X)


def test_the_metro_reference_study_is_the_scripts_de():
    study = tracking.reference_study("metro-a", (1, 2), 150)
    assert study.budget.to_dict() == {"n_gen": 150} and study.seeds == (1, 2)
    (spec,) = study.algorithms
    assert spec.name == "de" and spec.params == {"pop_size": 40, "CR": 0.9}
    assert study.problems[0].params == {"case": "metro-a", "objectives": ["energy"], "time_tolerance_s": 0.5}
