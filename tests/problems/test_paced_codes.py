"""Paced speed codes: every decision vector runs its chosen time, stops at the platform, keeps the limits."""

import numpy as np
import pytest

from pymoo_rail.cases import load_case
from pymoo_rail.problems import SpeedProfileProblem
from pymoo_rail.optimal.reference import constrained_optimum
from pymoo_rail.sim import kernel as k
from pymoo_rail.sim.pacing import DEFAULT_TIME_TOL_S


@pytest.fixture(scope="module")
def problem():
    return SpeedProfileProblem(load_case("metro-a"), objectives=("energy",), time_tolerance_s=1.0,
                               encoding="paced_speed_codes", max_section_m=1000.0 / 12)


def test_every_vector_in_the_box_runs_its_chosen_time(problem):
    """The last variable is the running time: each shape is paced to it, so every vector is on time."""
    case = problem.case
    assert problem.xu[-1] == pytest.approx(case.planned_time_s + 1.0 - DEFAULT_TIME_TOL_S)
    assert problem.xl[-1] == pytest.approx(max(case.planned_time_s - 1.0, problem.min_running_time_s)
                                           + DEFAULT_TIME_TOL_S)
    X = problem.xl + np.random.default_rng(3).random((200, problem.n_var)) * (problem.xu - problem.xl)
    X[:5, :-1] = 0.0  # shapes of all zeros: the pace alone moves the train
    s = problem.summaries(X)
    assert np.all(s[:, k.OUT_REACHED] > 0)
    assert np.all(np.abs(s[:, k.OUT_RUNNING_TIME_S] - X[:, -1]) <= DEFAULT_TIME_TOL_S + 1e-9)
    out = problem.evaluate(X, return_as_dictionary=True)
    assert np.all(out["G"] <= 0.0)  # on time, at the platform, under every limit
    assert np.all(out["stop_error_m"] < 1e-6)


def test_no_vector_beats_the_certified_optimum(problem):
    optimum = problem.pareto_front()[0, 0]
    _, bound, _ = constrained_optimum(problem.certified_front(), problem.time_tolerance_s)
    X = problem.xl + np.random.default_rng(4).random((300, problem.n_var)) * (problem.xu - problem.xl)
    energy = problem.evaluate(X, return_as_dictionary=True)["F"][:, 0]
    assert energy.min() >= optimum - bound
    # the trajectory of a vector is the run evaluate scored
    tr = problem.trajectory(X[0])
    assert tr.energy.net_kwh == pytest.approx(energy[0], rel=1e-9)
    assert abs(tr.running_time_s - X[0, -1]) <= DEFAULT_TIME_TOL_S + 1e-9


def test_paced_codes_need_a_window_and_refuse_tracking():
    case = load_case("metro-a")
    with pytest.raises(ValueError, match="time_tolerance_s or time_window_s"):
        SpeedProfileProblem(case, objectives=("energy", "running_time"), encoding="paced_speed_codes")
    with pytest.raises(ValueError, match="integer_codes"):
        SpeedProfileProblem(case, objectives=("energy",), time_tolerance_s=1.0, encoding="paced_speed_codes",
                            integer_codes=True)
    # a window that ends before the flat-out run: no time to pace to
    with pytest.raises(ValueError, match="time window"):
        SpeedProfileProblem(case, objectives=("energy", "running_time"), encoding="paced_speed_codes",
                            time_window_s=(60.0, 69.7))
