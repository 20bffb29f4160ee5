"""Tuning controller gains with pymoo on disturbed trains (``pymoo_rail.problems.controller_tuning``)."""

import numpy as np
import pytest

from pymoo_rail.cases import load_case
from pymoo_rail.problems.controller_tuning import ControllerTuningProblem, controller_from_gains
from pymoo_rail.sim import Simulator


def test_tuning_problem_scores_gains():
    case = load_case("metro-a")
    ref = Simulator(case).flat_out()
    p = ControllerTuningProblem(case, "pid", reference=ref, n_train=2)
    F = p.evaluate(np.array([[0.5, 0.05, 0.0], [0.05, 0.0, 0.0]]))
    assert F.shape == (2, 1) and np.all(F > 0) and F[0, 0] != F[1, 0]
    assert controller_from_gains("fuzzy_pid", np.zeros(6) + 0.1).dkd == pytest.approx(0.1)
    with pytest.raises(ValueError, match="family"):
        ControllerTuningProblem(case, "lqr", reference=ref)


def test_tuned_gains_track_no_worse_than_the_defaults_on_the_training_set():
    from pymoo_rail.control import PID
    from pymoo_rail.problems.controller_tuning import tune_controller

    case = load_case("metro-a")
    ref = Simulator(case).flat_out()
    tuned = tune_controller(case, "pid", ref, n_train=2, pop_size=6, n_gen=3, seed=1)
    assert isinstance(tuned, PID)
    assert tuned == tune_controller(case, "pid", ref, n_train=2, pop_size=6, n_gen=3, seed=1)  # seeded
    p = ControllerTuningProblem(case, "pid", reference=ref, n_train=2)
    default = PID()
    assert p.cost(np.array([tuned.kp, tuned.ki, tuned.kd])) <= p.cost(np.array([default.kp, default.ki, default.kd]))
