"""The gridded line: averaged gradients, limits over the train length, neutral sections."""

import numpy as np
import pytest

from pymoo_rail.model import GRAVITY_MS2, build_grid
from tests.conftest import make_case


def _mean_train_altitude(line, head_m, train_length_m):
    """Mean altitude under a train whose head is at head_m; stations beyond the ends are flat."""
    s = np.linspace(head_m - train_length_m, head_m, 20001)
    h = line.altitude_m(np.clip(s, 0.0, line.length_m))
    return np.trapezoid(h, s) / train_length_m


@pytest.mark.parametrize("model", ["train_length", "point_mass"])
def test_gradient_work_equals_potential_energy(model):
    case = make_case(line={"gradient_model": model,
                           "gradients": [[0, 300, 0], [300, 800, -8], [800, 1500, 12], [1500, 2000, 3]]})
    grid = build_grid(case, 2.0)
    work = np.sum(grid.grade_force_n * np.diff(grid.position_m))
    mass = case.train.mass_kg
    if model == "point_mass":
        rise = case.line.altitude_m(2000.0)
    else:
        length = case.train.length_m
        rise = _mean_train_altitude(case.line, 2000.0, length) - _mean_train_altitude(case.line, 0.0, length)
    assert work == pytest.approx(mass * GRAVITY_MS2 * rise, rel=1e-6)


def test_averaged_gradient_is_the_train_mean():
    # a 100 m train fully on a 10 permille slope feels 10 N/kN; half on it, 5 N/kN
    case = make_case(line={"gradients": [[0, 1000, 0], [1000, 2000, 10]]})
    grid = build_grid(case, 1.0)
    per_weight = grid.grade_force_n / (case.train.mass_kg * GRAVITY_MS2 / 1000.0)
    assert per_weight[1049] == pytest.approx(4.95, abs=1e-9)   # cell [1049, 1050]: on average 49.5 of 100 m on the slope
    assert per_weight[1200] == pytest.approx(10.0)
    assert per_weight[900] == pytest.approx(0.0)


def test_curve_and_tunnel_resistance():
    case = make_case(line={"curves": [[500, 900, 600.0]], "tunnels": [[1200, 1700]], "gradient_model": "point_mass"})
    grid = build_grid(case, 1.0)
    weight_kn = case.train.mass_kg * GRAVITY_MS2 / 1000.0
    assert grid.other_force_n[700] == pytest.approx(600.0 / 600.0 * weight_kn)        # eq. 2-11, A = 600
    assert grid.other_force_n[1500] == pytest.approx(0.00013 * 500.0 * weight_kn)     # eq. 2-12
    assert grid.other_force_n[100] == 0.0


def test_limits_hold_over_the_train_length(yizhuang):
    grid = build_grid(yizhuang, 1.0)
    kmh = grid.limit_ms * 3.6
    x = grid.position_m
    # 55 km/h until the tail (140 m behind the head) clears 130 m; 55 from 2155 m on
    assert np.all(kmh[x < 270] == 55.0)
    assert np.all(kmh[(x > 270) & (x < 2154)] == 80.0)
    assert np.all(kmh[x >= 2155] == 55.0)


def test_neutral_cells():
    case = make_case(line={"neutral_sections": [[1000.5, 1100.0]]})
    grid = build_grid(case, 1.0)
    assert grid.neutral[1000] == 1 and grid.neutral[1099] == 1
    assert grid.neutral[999] == 0 and grid.neutral[1100] == 0


def test_bad_step(yizhuang):
    with pytest.raises(ValueError, match="dx_m"):
        build_grid(yizhuang, 0.0)


def test_default_step_grows_with_the_line_without_a_jump():
    from pymoo_rail.model.grid import default_dx_m
    from tests.conftest import make_case

    def case(length_m):
        return make_case(line={"length_m": length_m, "gradients": [[0.0, length_m, 0.0]],
                               "speed_limits": [[0.0, length_m, 100.0]]})

    assert default_dx_m(case(2265.0)) == 1.0 and default_dx_m(case(10_000.0)) == 1.0
    assert default_dx_m(case(40_000.0)) == 5.0 and default_dx_m(case(48_531.0)) == 5.0
    lengths = np.linspace(9_000.0, 41_000.0, 161)
    cells = np.array([L / default_dx_m(case(L)) for L in lengths])
    assert np.all(np.abs(np.diff(cells)) <= 200 + 1e-6)  # continuous: no fivefold drop at one length
    assert cells[lengths >= 10_000].min() >= 8_000 - 1e-6 and cells[lengths <= 40_000].max() <= 10_000 + 1e-6
