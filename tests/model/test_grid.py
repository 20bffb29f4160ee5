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


def _naive_cell_means(groups, position_m, train_length_m):
    """The mean over each cell of w (or of its average over the train) by brute-force quadrature."""
    fine = np.linspace(position_m[0] - (train_length_m or 0.0), position_m[-1], 400_001)
    w = np.zeros_like(fine)
    for rows in groups:
        for start, end, value in rows:
            w[(fine >= start) & (fine < end)] += value
    integral = np.concatenate([[0.0], np.cumsum(0.5 * (w[1:] + w[:-1]) * np.diff(fine))])
    W = lambda x: np.interp(x, fine, integral)  # noqa: E731
    if train_length_m is None:
        return (W(position_m[1:]) - W(position_m[:-1])) / np.diff(position_m)
    xs = np.linspace(0.0, 1.0, 201)
    means = []
    for a, b in zip(position_m[:-1], position_m[1:]):
        heads = a + (b - a) * xs
        f = (W(heads) - W(heads - train_length_m)) / train_length_m
        means.append(np.mean(0.5 * (f[1:] + f[:-1])))  # trapezoids on a uniform grid
    return np.array(means)


@pytest.mark.parametrize("train_length_m", [None, 37.0])
def test_cell_means_of_many_rows_and_overlapping_groups_match_quadrature(train_length_m):
    from pymoo_rail.model.grid import cell_means

    rng = np.random.default_rng(3)
    cuts = np.sort(rng.uniform(0.0, 500.0, 300))
    edges = np.concatenate([[0.0], cuts, [500.0]])
    tiles = [(a, b, v) for a, b, v in zip(edges[:-1], edges[1:], rng.uniform(-30, 30, edges.size - 1))]
    loose = [(40.0, 90.0, 2.5), (90.0, 200.0, -1.0), (300.0, 310.0, 4.0)]
    overlapping = [(10.0, 400.0, 0.5), (100.0, 150.0, 1.5)]  # one group whose rows overlap: summed in order
    position = np.linspace(0.0, 500.0, 51)
    got = cell_means([tiles, loose, overlapping], position, train_length_m)
    want = _naive_cell_means([tiles, loose, overlapping], position, train_length_m)
    assert np.allclose(got, want, atol=2e-3 * 30)
    # exact, not approximate: the cells' means integrate to the rows' integral
    if train_length_m is None:
        total = sum((b - a) * v for rows in (tiles, loose, overlapping) for a, b, v in rows)
        assert np.sum(got * np.diff(position)) == pytest.approx(total, rel=1e-12, abs=1e-9)


def test_a_line_of_200k_gradient_rows_gives_the_rise_of_its_rows():
    from dataclasses import replace

    base = make_case()
    length = base.line.length_m
    edges = np.linspace(0.0, length, 200_001)
    permille = np.random.default_rng(1).uniform(-20.0, 20.0, edges.size - 1)
    line = replace(base.line, gradients=tuple(zip(edges[:-1].tolist(), edges[1:].tolist(), permille.tolist())),
                   gradient_model="point_mass")
    grid = build_grid(replace(base, line=line))
    work_j = np.sum(grid.grade_force_n * np.diff(grid.position_m))
    rise_m = float(np.sum(np.diff(edges) * permille) / 1000.0)
    assert work_j == pytest.approx(base.train.mass_kg * GRAVITY_MS2 * rise_m, rel=1e-9, abs=1e-6)
