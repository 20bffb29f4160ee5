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
