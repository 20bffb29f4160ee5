"""Exact gaps: each optimiser point against the optimum solved at its own running time."""

import numpy as np
import pytest
from pymoo.optimize import minimize

from pymoo_rail.algorithms import MOABC
from pymoo_rail.optimal import ReferenceAtTime, solved_energy_gap
from pymoo_rail.problems import SpeedProfileProblem


@pytest.fixture(scope="module")
def reference(yizhuang):
    return ReferenceAtTime(yizhuang, n_speeds=100)


def test_no_optimiser_point_lies_below_the_reference_by_more_than_its_certificate(yizhuang, reference):
    problem = SpeedProfileProblem(yizhuang, objectives=("energy", "running_time"))
    res = minimize(problem, MOABC(pop_size=20), ("n_gen", 1 + 2 * 14), seed=3)
    front = res.F[np.argsort(res.F[:, 1])][:, ::-1]  # (running time, energy)
    picks = front[np.linspace(0, front.shape[0] - 1, min(4, front.shape[0])).astype(int)]
    result = solved_energy_gap(picks, reference)
    points = result["points"]
    assert points["in_range"].all()
    assert (points["energy_bound_kwh"] >= 0).all()
    # a point below the optimum by more than the certificate would be a defect of the reference
    assert result["n_below_reference"] == 0, points
    assert (points["gap_kwh"] >= -points["energy_bound_kwh"]).all()


def test_a_point_below_the_certified_optimum_is_flagged(reference):
    at = reference.at(150.0)
    below = at["optimal_kwh"] - 2.0 * at["energy_bound_kwh"] - 1e-3
    within = at["optimal_kwh"] - 0.5 * at["energy_bound_kwh"]
    result = solved_energy_gap(np.array([[150.0, below], [150.0, within], [100.0, 30.0]]), reference)
    assert list(result["points"]["below_reference"]) == [True, False, False]
    assert list(result["points"]["in_range"]) == [True, True, False]  # 100 s is below the minimum time
    assert result["n_below_reference"] == 1 and result["n_out_of_range"] == 1


def test_the_solved_optimum_lies_on_or_below_the_interpolated_front(yizhuang, reference):
    # convexity: the chord between two solved points lies above the optimum between them
    a, b, mid = reference.at(140.0), reference.at(180.0), reference.at(160.0)
    chord = 0.5 * (a["optimal_kwh"] + b["optimal_kwh"])
    assert mid["optimal_kwh"] <= chord + mid["energy_bound_kwh"]


def test_the_optimum_at_a_time_lies_between_the_supporting_line_and_the_chord(yizhuang):
    # a run of the solver moved along the front's slope lies on the supporting line at the request:
    # the optimum there lies above it, below the chord of the solves on either side
    reference = ReferenceAtTime(yizhuang, n_speeds=100)
    at = reference.at(163.3)
    solves = reference.solver.solves()
    slow = min((h for h in solves if h.time_s >= 163.3), key=lambda h: h.time_s)
    fast = max((h for h in solves if h.time_s <= 163.3), key=lambda h: h.time_s)
    w = (163.3 - fast.time_s) / (slow.time_s - fast.time_s)
    chord_kwh = (fast.energy_j + w * (slow.energy_j - fast.energy_j)) / 3.6e6
    assert at["move_remainder_kwh"] >= 0.0
    # the chord (a run's energy there, the front being convex) lies within the bound above the line
    assert at["optimal_kwh"] <= chord_kwh + 1e-9 <= at["optimal_kwh"] + at["move_remainder_kwh"] + 2e-9
    assert at["energy_bound_kwh"] >= at["move_remainder_kwh"]
