"""pymoo_rail.experiments.verify: every member of a front replayed and checked against the case and its objectives."""

from __future__ import annotations

import numpy as np
import pytest

from pymoo_rail.cases import load_case
from pymoo_rail.experiments.verify import check_members, worst_checks
from pymoo_rail.problems import SpeedProfileProblem


@pytest.fixture(scope="module")
def members():
    problem = SpeedProfileProblem(load_case("yizhuang"), objectives=("energy", "running_time"))
    X = problem.xl + np.random.default_rng(1).random((4, problem.n_var)) * (problem.xu - problem.xl)
    runs = [problem.trajectory(x) for x in X]
    energy = np.array([r.energy.net_kwh for r in runs])
    time_s = np.array([r.running_time_s for r in runs])
    return problem, X, energy, time_s


def test_replayed_members_match_their_objectives_and_pass(members):
    problem, X, energy, time_s = members
    row = check_members(problem, X, energy, time_s)
    assert row["verified"] and row["fixed_genes_ok"]
    assert row["energy_mismatch_kwh"] == 0.0 and row["time_mismatch_s"] == 0.0
    assert row["neutral_traction_j_max"] == 0.0 and row["limit_excess_ms_max"] <= 1e-6
    worst = worst_checks([{**row, "n_points": len(X)}, {"n_points": 0}])  # a run without members is not counted
    assert (worst["n_runs"], worst["n_members"]) == (1, 4) and worst["all_ok"] and worst["energy_ok"] == "pass"


def test_a_stored_energy_that_the_replay_does_not_give_fails(members):
    problem, X, energy, time_s = members
    row = check_members(problem, X, energy + np.array([0.0, 0.5, 0.0, 0.0]), time_s)
    assert row["energy_mismatch_kwh"] == pytest.approx(0.5)
    worst = worst_checks([{**row, "n_points": len(X)}])
    assert worst["energy_ok"] == "FAIL" and not worst["all_ok"] and worst["time_ok"] == "pass"
    with pytest.raises(ValueError, match="no member"):
        check_members(problem, X[:0], energy[:0], time_s[:0])


def test_the_check_table_has_one_row_per_check_and_says_pass_or_fail(members):
    from pymoo_rail.experiments.verify import CHECKS, check_rows

    problem, X, energy, time_s = members
    worst = worst_checks([{**check_members(problem, X, energy, time_s + 1.0), "n_points": len(X)}])
    rows = check_rows(worst, lambda v: f"{v:.1f}")
    assert len(rows) == len(CHECKS) + 1 and rows[-1][-1] == "pass"
    assert rows[6] == ["stored vs re-simulated running time (s)", "1.0", "0", "FAIL"]
