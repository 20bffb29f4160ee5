"""The end speed a case asks for is an equality (or a window), in the DP, the problem's constraint,
the run checks and the plots alike (issue: the DP used to treat it as a ceiling)."""

from dataclasses import replace

import numpy as np
import pytest

from pymoo_rail.model import END_SPEED_TOL_MS, CaseError
from pymoo_rail.model import case_from_dict, case_to_dict
from pymoo_rail.optimal import OptimalSolver, min_running_time
from pymoo_rail.problems import SpeedProfileProblem
from pymoo_rail.sim import Simulator
from pymoo_rail.sim.checks import check_run
from tests.conftest import make_case_dict
from tests.optimal.cases import hilly_case

END_KMH = 54.0  # 15 m/s, below the last limit (70 km/h)


def moving_end_case(window_kmh=None):
    data = make_case_dict(**{k: v for k, v in case_to_dict(hilly_case()).items() if k != "name"})
    data["run"]["initial_speed_kmh"] = 36.0
    data["run"]["final_speed_kmh"] = END_KMH
    if window_kmh is not None:
        data["run"]["final_speed_window_kmh"] = list(window_kmh)
    return case_from_dict(data)


@pytest.fixture(scope="module")
def equality_case():
    return moving_end_case()


@pytest.mark.parametrize("factor", [1.1, 1.5])
def test_dp_arrives_at_exactly_the_end_speed(equality_case, factor):
    t = factor * min_running_time(equality_case)
    tr = OptimalSolver(equality_case).profile(t)
    assert tr.speed_ms[-1] == pytest.approx(END_KMH / 3.6, abs=1e-9)
    assert check_run(tr, equality_case).passes()


def test_window_allows_slower_arrivals_and_costs_less(equality_case):
    t = 1.5 * min_running_time(equality_case)
    exact = OptimalSolver(equality_case).profile(t)
    window = moving_end_case((18.0, END_KMH))
    free = OptimalSolver(window).profile(t)
    v_end = free.speed_ms[-1] * 3.6
    assert 18.0 - 1e-6 <= v_end <= END_KMH + 1e-6
    # arriving slower than asked for is cheaper at a long running time: the window is used
    assert v_end < END_KMH - 1.0
    moved = free.energy.net_kwh + free.summary["lambda_w"] * (free.running_time_s - exact.running_time_s) / 3.6e6
    assert moved < exact.energy.net_kwh


def test_problem_constrains_the_end_speed_of_every_encoding(equality_case):
    for encoding in ("speed_codes", "switching_points"):
        problem = SpeedProfileProblem(equality_case, objectives=("energy", "running_time"), encoding=encoding)
        assert problem.n_ieq_constr == 3  # limits, stop, end speed
        X = np.random.default_rng(0).uniform(problem.xl, problem.xu, size=(40, problem.n_var))
        out = problem.evaluate(X, return_as_dictionary=True)
        v_end = problem.summaries(X)[:, 15]
        lo, hi = equality_case.end_speed_window_ms()
        violated = (v_end < lo - END_SPEED_TOL_MS) | (v_end > hi + END_SPEED_TOL_MS)
        assert np.array_equal(out["G"][:, 2] > 0, violated)
        assert violated.any() and not violated.all(), encoding  # both kinds occur among random decisions
    # at rest the stop constraint holds the end speed: no extra constraint
    assert SpeedProfileProblem(hilly_case(), objectives=("energy", "running_time")).n_ieq_constr == 2


def test_check_run_flags_a_slow_arrival(equality_case):
    sim = Simulator(equality_case)
    # coast from 300 m to the end: arrives far below 54 km/h
    coast = sim.run(np.array([[300.0, 1.0, 0.0], [3000.0, 3.0, 0.0]]))
    assert coast.reached and coast.speed_ms[-1] * 3.6 < END_KMH - 5
    check = check_run(coast, equality_case)
    assert check.end_speed_excess_ms > 0 and not check.passes()


@pytest.mark.parametrize("window, match", [([60.0, 54.0], "lo <= hi"), ([10.0, 50.0], "upper end"),
                                           ([-1.0, 54.0], "final_speed_window_kmh"), ([54.0], "two speeds"),
                                           (["a", 54.0], "final_speed_window_kmh")])
def test_bad_windows_name_the_field(window, match):
    with pytest.raises(CaseError, match=match):
        moving_end_case(window)


def test_window_round_trips_and_defaults_the_final_speed():
    data = case_to_dict(moving_end_case((18.0, END_KMH)))
    assert case_from_dict(data).final_speed_window_kmh == pytest.approx((18.0, END_KMH))
    del data["run"]["final_speed_kmh"]
    case = case_from_dict(data)
    assert case.final_speed_ms * 3.6 == pytest.approx(END_KMH)
    assert replace(case, final_speed_window_ms=None).end_speed_window_ms() == (case.final_speed_ms,) * 2


def test_plot_marks_the_end_speed(equality_case):
    import matplotlib

    matplotlib.use("Agg")
    from pymoo_rail.plotting import plot_speed_profile

    tr = Simulator(equality_case).flat_out()
    fig = plot_speed_profile(tr, equality_case)
    labels = [h.get_label() for h in fig.axes[0].containers]
    assert "end speed asked for" in labels
    fig_w = plot_speed_profile(tr, moving_end_case((18.0, END_KMH)))
    assert "end speed window" in [h.get_label() for h in fig_w.axes[0].containers]
