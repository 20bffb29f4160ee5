"""The certificate's run without the tie rule reuses the chosen run's backward sweep: same numbers as a new sweep."""

from __future__ import annotations

import pytest

from pymoo_rail.cases import load_case
from pymoo_rail.optimal import OptimalSolver


def test_untied_run_on_a_reused_sweep_equals_a_fresh_sweep():
    solver = OptimalSolver(load_case("yizhuang"), n_speeds=60)
    found = solver.solve_price(2.0e6)
    reused = solver.run_dp(found.lambda_w, 0.0)  # the sweep of the solve just made still holds
    solver.solve_price(1.0e6)  # another price: the next call must sweep again
    fresh = solver.run_dp(found.lambda_w, 0.0)
    assert reused[3] == fresh[3] and reused[4] == fresh[4] and reused[5] == fresh[5]
    assert (reused[2] == fresh[2]).all()
    # with the tie rule, at the same price: the same sweep, a different forward run (tied regimes kept)
    tied = solver.run_dp(found.lambda_w, solver.tie_j)
    assert tied[4] == pytest.approx(found.energy_j, rel=0, abs=0) and tied[5] == found.time_s


def test_a_new_speed_floor_forgets_the_sweep():
    solver = OptimalSolver(load_case("yizhuang"), n_speeds=60)
    solver.solve_price(2.0e6)
    floor = [0.0] * solver.simulator.grid.n_nodes
    floor[solver.simulator.grid.n_nodes // 2] = 15.0
    import numpy as np

    solver.set_speed_floor(np.array(floor))
    run = solver.run_dp(2.0e6, solver.tie_j)
    assert run[2][solver.simulator.grid.n_nodes // 2] >= 15.0 - 1e-9  # swept again, under the floor
