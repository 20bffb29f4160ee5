"""Paced shapes (running time by a 1-D solve) and runs on a common clock, all on the main simulator."""

import numpy as np
import pytest

from pymoo_rail.cases import load_case
from pymoo_rail.sim import Simulator
from pymoo_rail.sim import cooperation as coop
from pymoo_rail.sim.pacing import PacedSpeedCodes, solve_pace, split_long_sections



@pytest.fixture(scope="module")
def leg():
    return load_case("cooperative-pair").leg(1)  # 1350 m in 100 s


@pytest.fixture(scope="module")
def simulator(leg):
    return Simulator(leg, dx_m=2.0)


def test_sections_split_at_gradients_and_length(leg):
    enc = PacedSpeedCodes.build(leg, max_section_m=200.0)
    assert np.all(np.diff(enc.boundaries_m) <= 200.0 + 1e-9)
    for p in leg.line.breakpoints_m():
        assert np.min(np.abs(enc.boundaries_m - p)) < 1e-9  # every gradient change is a boundary
    assert np.all(enc.limits_ms == pytest.approx(80.0 / 3.6))
    np.testing.assert_allclose(split_long_sections(np.array([0.0, 500.0]), 200.0), [0, 500 / 3, 1000 / 3, 500])
    with pytest.raises(ValueError, match="max_section_m = -1"):
        split_long_sections(np.array([0.0, 500.0]), -1.0)


def test_every_shape_runs_its_planned_time(leg, simulator):
    enc = PacedSpeedCodes.build(leg)
    shapes = np.random.default_rng(4).random((12, enc.n_var))
    shapes[0] = 0.0  # a flat shape: the pace alone sets the speed
    shapes[1] = 1.0
    runs = solve_pace(simulator, enc, shapes, time_tol_s=0.02)
    np.testing.assert_array_less(np.abs(runs.running_time_s - 100.0), 0.02 + 1e-12)
    assert np.all(runs.summaries[:, 16] == 1.0)  # every run stops at the platform
    # replaying the returned programs gives the same runs
    np.testing.assert_array_equal(simulator.run_batch(runs.programs), runs.summaries)


def test_running_time_falls_as_the_pace_rises(leg, simulator):
    enc = PacedSpeedCodes.build(leg)
    shape = np.random.default_rng(1).random((1, enc.n_var))
    paces = np.linspace(-0.3, 1.0, 14)
    out = simulator.run_batch(np.concatenate([enc.programs(shape, np.array([p])) for p in paces]))
    times = np.where(out[:, 16] > 0, out[:, 4], np.inf)
    assert np.all(np.diff(times) <= 1e-9)
    assert times[-1] == pytest.approx(simulator.min_running_time_s(), abs=1e-9)  # pace 1: flat out


def test_cell_energies_of_a_trace_add_up_to_the_kernel_summary(leg, simulator):
    enc = PacedSpeedCodes.build(leg)
    runs = solve_pace(simulator, enc, np.full((1, enc.n_var), 0.4))
    tr = simulator.run(runs.programs[0])
    clocked = coop.clocked_run(simulator.model, tr, departure_s=12.0, start_m=2600.0)
    assert clocked.traction_kwh == pytest.approx(tr.energy.traction_kwh, rel=1e-12)
    assert clocked.regen_kwh == pytest.approx(tr.energy.regen_kwh, rel=1e-12)
    assert clocked.regen_kwh > 0.5  # it brakes into the platform from speed
    assert clocked.arrival_s == pytest.approx(12.0 + tr.running_time_s)


def test_pool_is_eq5_for_a_pair_and_bounded_by_supply_and_demand():
    rng = np.random.default_rng(0)
    trac = rng.random((2, 50)) * (rng.random((2, 50)) < 0.5)
    regen = rng.random((2, 50)) * (trac == 0)
    # one train draws while the other brakes, bin by bin: the pool is min(P_A, eta P_B) both ways
    trac[1, :25] = 0.0
    regen[0, :25] = 0.0
    trac[0, 25:] = 0.0
    regen[1, 25:] = 0.0
    shared = coop.shared_energy_bins(trac, regen, 1.0)
    eq5 = np.minimum(trac[0], regen[1]) + np.minimum(trac[1], regen[0])
    np.testing.assert_allclose(shared, eq5)
    # a train alone shares nothing with itself, even where it draws and brakes in one bin
    assert coop.shared_energy_bins(np.ones((1, 3)), np.ones((1, 3)), 1.0).sum() == 0.0
    # three trains: as much as a flow from the braking to the other, drawing trains allows
    t3 = np.array([[5.0], [0.0], [1.0]])
    r3 = np.array([[0.0], [4.0], [3.0]])
    assert coop.shared_energy_bins(t3, r3, 1.0)[0] == pytest.approx(6.0)  # 5 from B and C, C's 1 from B
    lossy = coop.shared_energy_bins(trac, regen, 0.9)
    assert np.all(lossy <= trac.sum(axis=0) + 1e-15)
    assert np.all(lossy <= 0.9 * regen.sum(axis=0) + 1e-15)


def test_shared_energy_of_a_departure_over_a_stop(leg, simulator):
    enc = PacedSpeedCodes.build(leg)
    tr = simulator.run(solve_pace(simulator, enc, np.full((1, enc.n_var), 0.5)).programs[0])
    braking = coop.clocked_run(simulator.model, tr, 0.0)
    # the same run departing as this one stops: its traction meets the other's braking
    departing = coop.clocked_run(simulator.model, tr, tr.running_time_s - 20.0)
    shared = coop.shared_energy_kwh([braking, departing])
    assert 0.0 < shared <= min(braking.regen_kwh, departing.traction_kwh) + 1e-12
    # far apart: nothing
    assert coop.shared_energy_kwh([braking, coop.clocked_run(simulator.model, tr, 1000.0)]) == 0.0
    frame = coop.power_profiles([braking, departing], ("a", "b"), 1.0, 0.1)
    assert frame["shared_kw"].sum() * 0.1 / 3600 == pytest.approx(shared, rel=1e-12)


def test_a_journey_stands_still_between_its_runs(leg, simulator):
    enc = PacedSpeedCodes.build(leg)
    tr = simulator.run(solve_pace(simulator, enc, np.full((1, enc.n_var), 0.5)).programs[0])
    first = coop.clocked_run(simulator.model, tr, 0.0, 0.0)
    second = coop.clocked_run(simulator.model, tr, first.arrival_s + 30.0, 1350.0)
    journey = coop.chain_runs([first, second])
    assert journey.arrival_s == pytest.approx(second.arrival_s)
    assert journey.traction_kwh == pytest.approx(2 * first.traction_kwh)
    assert journey.position_m[-1] == pytest.approx(2700.0)
    with pytest.raises(ValueError, match="before the previous one arrives"):
        coop.chain_runs([second, first])
