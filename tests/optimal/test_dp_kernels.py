"""The DP's own kernels against the simulator's: the same figures, bit for bit."""

import math

import numpy as np
from numba import njit

from pymoo_rail.optimal import dp
from pymoo_rail.sim import Simulator
from pymoo_rail.sim.kernel import (
    REGIME_COAST,
    TOTAL_ELECTRIC_BRAKE_J,
    TOTAL_TIME,
    TOTAL_TRACTION_J,
    complete_cell,
    new_totals,
)
from tests.optimal.cases import hilly_case


@njit
def simulator_cell(m, cell, v0, u1, f, w0):
    """The simulator's own cell (its helpers are kernel-only: no Python entry of their own)."""
    return complete_cell(m, new_totals(), cell, v0, u1, f, w0, REGIME_COAST)


def test_cell_cost_is_the_simulators_accounting_bit_for_bit():
    """Traction, braking above and across the regen cut-off, coasting, stops inside a cell, the last cell."""
    m = Simulator(hilly_case()).model
    n = m.position_m.shape[0]
    rng = np.random.default_rng(3)
    cells = np.concatenate([rng.integers(0, n - 1, 400), [n - 2] * 20])
    checked = {"traction": 0, "braking": 0, "stopped": 0}
    for cell in cells:
        cell = int(cell)
        v0 = float(rng.choice([0.0, rng.uniform(0.0, 4.0), rng.uniform(0.0, 25.0)]))
        u1 = float(rng.choice([0.0, rng.uniform(-5.0, 20.0), rng.uniform(0.0, 600.0)]))
        f = float(rng.choice([0.0, rng.uniform(-2e5, 0.0), rng.uniform(0.0, 2e5)]))
        w0 = float(rng.uniform(0.0, 5e3))
        price = float(rng.uniform(0.0, 1e6))
        cost, dt = dp.cell_cost(m, v0, u1, f, w0, cell, price)
        v1, stopped, _, _, totals = simulator_cell(m, cell, v0, u1, f, w0)
        if stopped or v0 + v1 <= 0.0:
            assert cost == math.inf and dt == math.inf
            checked["stopped"] += 1
            continue
        e = totals[TOTAL_TRACTION_J] / m.traction_efficiency - m.regen_efficiency * totals[TOTAL_ELECTRIC_BRAKE_J]
        assert dt == totals[TOTAL_TIME]
        assert cost == e + price * totals[TOTAL_TIME]
        checked["traction" if f > 0 else "braking" if f < 0 else "stopped"] += f != 0.0
    assert min(checked.values()) > 10, checked


def test_cells_of_one_kind_share_tables_equal_to_their_own_bit_for_bit():
    """The tables tabulated once per kind of cell are every cell's own tables, bit for bit.

    On a line with everything the model has (grades, three limits and their braking curves, a
    neutral section, the last cell), so that a cell-dependent input missing from ``dp.cell_types``
    would show.
    """
    m = Simulator(hilly_case()).model
    n_cells = m.position_m.shape[0] - 1
    cell_type, first_cell = dp.cell_types(m)
    assert first_cell.shape[0] < n_cells / 3  # long stretches of one grade and one limit are one kind
    assert np.array_equal(cell_type[first_cell], np.arange(first_cell.shape[0]))
    assert cell_type[-1] != cell_type[-2]  # the last cell is its own kind
    shared = dp.transitions(m, 40, 8, 0.5)
    own = dp.transitions(m, 40, 8, 0.5, share=False)
    for a, b in zip(shared[:3], own[:3]):
        assert np.array_equal(a[shared[-1]].view(np.int32), b.view(np.int32))
    offsets_s, offsets_o = shared[3], own[3]
    for i in range(n_cells):
        t = cell_type[i]
        for a, b in zip(shared[4:7], own[4:7]):
            part_s = a[offsets_s[t * 40]:offsets_s[(t + 1) * 40]]
            part_o = b[offsets_o[i * 40]:offsets_o[(i + 1) * 40]]
            assert np.array_equal(part_s.view(np.int32), part_o.view(np.int32))
    assert np.array_equal(np.diff(offsets_s).reshape(-1, 40)[cell_type], np.diff(offsets_o).reshape(-1, 40))
