"""Accuracy of the solver: closed-form optimum on level track, direct search, grid refinement."""

import numpy as np
import pytest

from pymoo_rail.optimal import OptimalSolver
from pymoo_rail.optimal.flat import flat_track_optimum, no_resistance_optimum
from pymoo_rail.optimal.strategies import hold_coast_search
from pymoo_rail.sim import REGIME_NAMES, Simulator, gradient_limit_partition, speed_code_programs
from tests.conftest import make_case
from tests.optimal.cases import level_case

ACCURACY = 5e-3  # the solver's stated accuracy (0.5 %)


def at_time(tr, t):
    """Net energy moved to exactly t along the front's slope lambda (first order)."""
    return tr.energy.net_kwh + tr.summary["lambda_w"] / 3.6e6 * (tr.running_time_s - t)


@pytest.fixture(scope="module")
def level_solver():
    return OptimalSolver(level_case())


# 260 s and 320 s are solved on the default speed grid (seconds); at 240 s the discrete optimum jumps
# over the requested time and the solver refines the grid twice (minutes): the same assertions,
# behind the slow marker
@pytest.mark.parametrize("running_time_s", [260.0, 320.0, pytest.param(240.0, marks=pytest.mark.slow)])
def test_level_track_closed_form(level_solver, running_time_s):
    # Pontryagin on level track: maximum traction to V, hold V, coast to W, maximum braking, with
    # lambda = V^2 R'(V) and lambda / W = R(V) + lambda / V (pymoo_rail.optimal.flat, by quadrature)
    exact = flat_track_optimum(level_solver.case, running_time_s)
    tr = level_solver.profile(running_time_s)
    assert at_time(tr, running_time_s) == pytest.approx(exact.energy_kwh, rel=ACCURACY)
    # the same structure: the speed held is V, braking starts at W where the closed form says
    names = np.array(REGIME_NAMES)[tr.regime]
    held = tr.speed_ms[:-1][names[:-1] == "hold"]
    assert np.median(held) == pytest.approx(exact.hold_speed_ms, rel=0.01)
    first_brake = np.argmax(names == "brake")
    assert tr.speed_ms[first_brake] == pytest.approx(exact.brake_speed_ms, rel=0.03)
    assert tr.position_m[first_brake] == pytest.approx(exact.brake_start_m, abs=30.0)
    assert tr.summary["lambda_w"] == pytest.approx(exact.lambda_w, rel=0.05)


def test_no_resistance_closed_form():
    # no resistance, 1 m/s^2 both ways on 2 km: accelerate to V, coast, brake; E = m V^2 / 2
    case = make_case()
    solver = OptimalSolver(case)
    for t in (100.0, 130.0):
        v, energy = no_resistance_optimum(case, t)
        tr = solver.profile(t)
        assert at_time(tr, t) == pytest.approx(energy, rel=1e-3)
        assert tr.speed_ms.max() == pytest.approx(v, rel=1e-3)


@pytest.mark.parametrize("name, running_time_s", [("yizhuang", 140.0), ("yizhuang", 175.0), ("hilly", 190.0)])
def test_never_worse_than_a_direct_search(yizhuang_solver, hilly_solver, name, running_time_s):
    # the best traction-hold-coast-brake strategy found by a direct search (hold speed, coast point)
    solver = yizhuang_solver if name == "yizhuang" else hilly_solver
    strategy = hold_coast_search(solver.case, running_time_s, n_grid=16)
    tr = solver.profile(running_time_s)
    assert at_time(tr, running_time_s) <= strategy.energy_kwh * (1 + ACCURACY)


def test_never_worse_than_random_strategies(yizhuang, yizhuang_solver):
    # speed codes on the gradient / limit partition (seed 000's encoding), 400 random ones: none
    # beats the optimum at its own running time
    sim = Simulator(yizhuang)
    bounds = gradient_limit_partition(yizhuang.line)
    rng = np.random.default_rng(7)
    codes = rng.uniform(35 / 3.6, 80 / 3.6, size=(400, bounds.shape[0] - 1))
    out = sim.run_batch(speed_code_programs(bounds, codes))
    times, energies = out[:, 4], out[:, 3]
    solver = yizhuang_solver
    # the best strategies relative to a straight line through the cloud, in three time bands
    for lo, hi in ((140.0, 150.0), (150.0, 165.0), (165.0, 185.0)):
        band = np.flatnonzero((times >= lo) & (times < hi))
        assert band.size > 0
        k = band[np.argmin(energies[band] + 0.2 * times[band])]
        tr = solver.profile(times[k])
        assert at_time(tr, times[k]) <= energies[k] * (1 + ACCURACY)


def test_refining_the_speed_grid(yizhuang, yizhuang_solver):
    # doubling the speed nodes changes the energy by far less than the stated accuracy
    coarse = yizhuang_solver.profile(150.0)
    fine = OptimalSolver(yizhuang, n_speeds=400).profile(150.0)
    assert at_time(coarse, 150.0) == pytest.approx(at_time(fine, 150.0), rel=ACCURACY / 5)


@pytest.mark.slow
def test_refining_the_position_grid(yizhuang, yizhuang_solver):
    # halving the position step (and the simulator's with it)
    coarse = yizhuang_solver.profile(150.0)
    fine = OptimalSolver(yizhuang, dx_m=0.5).profile(150.0)
    assert at_time(coarse, 150.0) == pytest.approx(at_time(fine, 150.0), rel=ACCURACY)
