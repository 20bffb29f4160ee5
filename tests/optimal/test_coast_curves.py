"""The cost-to-go's kinks as states: the coast curves into the braking envelope's corners and into the
end speed, and the run at full traction from a slow start (``dp.coast_curves``)."""

import math

import numpy as np
import pytest

from pymoo_rail.experiments.peers import comparable_case
from pymoo_rail.optimal import OptimalSolver, dp, min_running_time
from pymoo_rail.sim import Simulator
from pymoo_rail.sim.kernel import KIND_COAST, KIND_TRACTION, full_step
from tests.optimal.cases import level_case

J_PER_KWH = 3.6e6


@pytest.fixture(scope="module")
def moving_end_case():
    """Generated line 3 as the side-by-side comparison runs it: 6.7 km, 72 km/h at both ends."""
    return comparable_case(3)


def test_coasting_from_the_curve_lands_on_it(moving_end_case):
    m = Simulator(moving_end_case).model
    n = m.position_m.shape[0]
    curve = np.zeros(n)
    start = dp.coast_curve(m, n - 1, 20.0, curve)
    assert start < n - 200  # the curve reaches far back (a final coast of hundreds of metres)
    curve[n - 1] = 20.0
    for i in range(start, n - 1):
        u1 = min(full_step(m, curve[i], i, KIND_COAST)[0], m.envelope_ms[i + 1] ** 2)
        assert math.sqrt(u1) == pytest.approx(curve[i + 1], rel=1e-10)
        assert curve[i] <= m.envelope_ms[i]


def test_the_curves_are_states_between_the_nodes(moving_end_case):
    m = Simulator(moving_end_case).model
    curve_v, curve_p = dp.coast_curves(m, 20.0, 200, 0.5)
    assert curve_v.shape[0] == m.position_m.shape[0] and 1 <= curve_v.shape[1] <= 6
    on = curve_p >= 0.0
    assert on.any()
    # each is placed at its own fractional node index, never on a regular node
    assert np.all(np.abs(curve_p[on] - np.round(curve_p[on])) >= 1e-3)
    assert np.all(curve_v[on] ** 2 < (m.envelope_ms[:, None] ** 2 * np.ones_like(curve_v))[on])


def test_start_curve_is_the_full_traction_run():
    case = comparable_case(5)  # a start at 1 m/s
    m = Simulator(case).model
    curve = np.zeros(m.position_m.shape[0])
    end = dp.traction_curve(m, curve)
    assert end > 10 and curve[0] == case.initial_speed_ms
    for i in range(end - 1):
        assert curve[i + 1] == math.sqrt(full_step(m, curve[i], i, KIND_TRACTION)[0])


def test_no_curve_into_a_standstill_nor_from_rest():
    """A platform stop ends the envelope at 0, a start from rest is a node, and the level line has one
    limit: no curve at all."""
    m = Simulator(level_case()).model
    curve_v, curve_p = dp.coast_curves(m, 0.0, 200, 0.5)
    assert curve_v.shape[1] == 0 and curve_p.shape == (m.position_m.shape[0], 0)


def test_value_of_a_moving_end_matches_its_run(moving_end_case):
    """The DP's cost-to-go at the start against the energy + lambda x time of its own run: the kink along
    the final coast into 72 km/h, interpolated across, made it 0.53 kWh too high at 200 nodes (0.26 at 400);
    with the curve as a state 0.06 kWh."""
    t = 1.2 * min_running_time(moving_end_case)
    solver = OptimalSolver(moving_end_case, certify=False)
    lam = solver.profile(t).summary["lambda_w"]
    run = solver.solve_price(lam)
    gap_kwh = (run.value_j - (run.energy_j + lam * run.time_s)) / J_PER_KWH
    assert -0.01 < gap_kwh < 0.1


def test_extra_states_cost_to_go_is_the_least_cost_of_their_whole_control_table(moving_end_case):
    """The sweep keeps the coast curves' price-independent controls across prices (``dp.curve_controls``) and
    shares the singular speeds' tables per kind of cell without their ``toward``-curve entries: at every extra
    state its cost-to-go is still, bit for bit, the least cost of the state's whole control table
    (``dp.control_table`` with every extra state of the next node as a target)."""
    solver = OptimalSolver(moving_end_case, certify=False)
    m, tables = solver.simulator.model, solver.transition_tables()
    n, n_speeds, bias, max_targets = m.position_m.shape[0], solver.n_speeds, solver.top_bias, solver.max_targets
    curve_v, curve_p = dp.coast_curves(m, float(solver.end_speed_ms[0]), n_speeds, bias)
    value = np.empty((n, n_speeds))
    sing_v, sing_p, sing_val = (np.empty((n, dp.N_SINGULAR + curve_v.shape[1])) for _ in range(3))
    terminal_j = dp.terminal_cost(m, n_speeds, bias, solver.end_speed_ms[0])
    lam = 6.0e5
    dp.solve(m, tables, lam, max_targets, bias, solver.tie_j, value, terminal_j=terminal_j,
             sing=(sing_v, sing_p, sing_val), arrival=(curve_v, curve_p))
    size = dp.N_FIXED + sing_v.shape[1] + max_targets
    table = (np.empty(size, dtype=np.int64), *(np.empty(size) for _ in range(5)))
    steps = np.empty(9)
    checked = {"singular": 0, "curve": 0}
    for i in range(n - 1):
        for s in range(sing_v.shape[1]):
            if sing_p[i, s] < 0.0 or (s < dp.N_SINGULAR and i % 5):
                continue
            count = dp.control_table(m, i, sing_v[i, s], sing_v[i + 1], sing_p[i + 1], n_speeds - 1, max_targets, bias,
                                     table, steps)
            best = dp.table_minimum(table, count, lam + m.aux_power_w, value[i + 1], sing_p[i + 1], sing_val[i + 1])[0]
            assert sing_val[i, s] == min(best, dp.PENALTY_J), (i, s)
            checked["singular" if s < dp.N_SINGULAR else "curve"] += 1
    assert checked["singular"] > 100 and checked["curve"] > 100, checked
