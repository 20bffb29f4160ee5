"""The 3-objective families (energy, running time, comfort): kinematic comfort floor, bounded front, identity."""

import numpy as np
import pandas as pd
import pytest
from pymoo.algorithms.moo.nsga3 import NSGA3
from pymoo.core.callback import Callback
from pymoo.optimize import minimize
from pymoo.util.nds.non_dominated_sorting import find_non_dominated
from pymoo.util.ref_dirs import get_reference_directions

from pymoo_rail.suite import get_problem, list_families
from pymoo_rail.suite import comfort
from pymoo_rail.suite.comfort import COMFORT_OBJECTIVES, comfort_floor_ms2

# sha256 of the canonical definition (family version 1, bounded-front version 1)
PINNED_3OBJ = {("generated-metro-3obj", 10, 7): "316681857aa3", ("generated-high-speed-3obj", 300, 7): "98144c7b3557"}


def test_floor_is_the_closed_form_of_a_symmetric_run_from_rest():
    # no speed cap in reach: accelerate at a, decelerate at a, L = a T^2 / 4, so A + D = 8 L / T^2
    t = np.array([100.0, 150.0])
    floor = comfort_floor_ms2(t, length_m=1500.0, boundary_speed_ms=0.0, top_speed_ms=1e3)
    np.testing.assert_allclose(floor, 16.0 * 1500.0 / t**2)
    # a cap at h: the trapezoid h T - h^2 k / 2 = L gives k, A + D = 4 / k
    h, T, L = 20.0, 100.0, 1500.0
    k = 2.0 * (h * T - L) / h**2
    assert comfort_floor_ms2(T, L, 0.0, h)[0] == pytest.approx(2.0 * 4.0 / k)
    # a launch every run makes: A >= launch, and with A unbounded D >= h^2 / (2 (h T - L))
    assert comfort_floor_ms2(T, L, 0.0, h, launch_ms2=1.5)[0] == pytest.approx(2.0 * (1.5 + h**2 / (2 * (h * T - L))))
    assert comfort_floor_ms2(T, L, 0.0, h, launch_ms2=1.0)[0] == pytest.approx(2.0 * 4.0 / k)  # the larger of the two
    assert comfort_floor_ms2(200.0, L, 0.0, h, launch_ms2=1.0)[0] == pytest.approx(2.0 * (1.0 + 2 * L / 200.0**2))
    # a landing every run makes, symmetric to the launch; both together
    assert comfort_floor_ms2(T, L, 0.0, h, landing_ms2=1.5)[0] == pytest.approx(2.0 * (1.5 + h**2 / (2 * (h * T - L))))
    assert comfort_floor_ms2(300.0, 100.0, 0.0, h, launch_ms2=1.0, landing_ms2=0.8)[0] == pytest.approx(3.6)
    # cruising at the boundary speed covers the line: no acceleration needed; too far to reach: infinite
    assert comfort_floor_ms2(100.0, 900.0, 10.0, 20.0)[0] == 0.0
    assert comfort_floor_ms2(100.0, 5000.0, 0.0, 20.0)[0] == np.inf


def test_floor_never_exceeds_the_comfort_of_a_bang_bang_run():
    # accelerate at A to a peak (capped at V), hold, decelerate at D: its closed walk 0 -> A -> -D -> 0 has 2 (A + D)
    rng = np.random.default_rng(4)
    for _ in range(300):
        A, D, V = rng.uniform(0.1, 1.5), rng.uniform(0.1, 1.5), rng.uniform(10.0, 40.0)
        t_up, t_down, t_hold = V / A, V / D, rng.uniform(0.0, 200.0)
        T = t_up + t_down + t_hold
        L = V * T - V * V / (2 * A) - V * V / (2 * D)
        assert comfort_floor_ms2(T, L, 0.0, V)[0] <= 2.0 * (A + D) * (1 + 1e-12)


@pytest.mark.parametrize("kwargs, match", [
    (dict(running_time_s=[10.0, -1.0], length_m=100.0, boundary_speed_ms=0.0, top_speed_ms=20.0), "running_time_s"),
    (dict(running_time_s=10.0, length_m=100.0, boundary_speed_ms=30.0, top_speed_ms=20.0), "top_speed_ms"),
])
def test_bad_floor_arguments_are_named(kwargs, match):
    with pytest.raises(ValueError, match=match):
        comfort_floor_ms2(**kwargs)


def test_the_3obj_families_come_after_the_earlier_ones():
    names = list_families()
    assert names[:10] == [f"generated-{k}-{f}" for f in ("bi", "single") for k in
                          ("metro", "suburban", "intercity", "high-speed")] + ["generated-metro-trip",
                                                                               "generated-suburban-trip"]
    assert names[10:] == [f"generated-{k}-3obj" for k in ("metro", "suburban", "intercity", "high-speed")]


@pytest.mark.parametrize("key", sorted(PINNED_3OBJ))
def test_checksum_pins_the_3obj_definition(key):
    problem = get_problem(key[0], n_var=key[1], seed=key[2])
    assert problem.objectives == COMFORT_OBJECTIVES and problem.n_var == key[1]
    assert problem.checksum[:12] == PINNED_3OBJ[key]
    bi = get_problem(key[0].replace("-3obj", "-bi"), n_var=key[1], seed=key[2])
    assert bi.checksum != problem.checksum and np.array_equal(bi.xl, problem.xl)


@pytest.fixture(scope="module")
def metro(tmp_path_factory):
    # seed 1's metro line has a shipped certified front; the inner points go to a fresh cache
    mp = pytest.MonkeyPatch()
    mp.setenv("PYMOO_RAIL_CACHE_DIR", str(tmp_path_factory.mktemp("cache")))
    problem = get_problem("generated-metro-3obj", n_var=10, seed=1)
    yield problem, problem.bounded_front()
    mp.undo()


def test_inner_points_are_feasible_nondominated_runs(metro):
    problem, bounded = metro
    cached = pd.read_csv(comfort.inner_path(problem))  # the recipe's runs, kept with their decisions
    X, F = cached.filter(regex=r"^x\d+$").to_numpy(), cached[list(COMFORT_OBJECTIVES)].to_numpy()
    np.testing.assert_array_equal(F, bounded.inner)
    assert X.shape == (len(F), problem.n_var)
    out = problem.evaluate(X, return_values_of=["F", "G"], return_as_dictionary=True)
    assert np.all(out["G"] <= 0.0)
    np.testing.assert_allclose(out["F"], F, rtol=1e-12)
    assert len(find_non_dominated(F)) == len(F) >= 10
    np.testing.assert_array_equal(problem.pareto_front(), F)


def test_every_inner_point_lies_above_an_outer_corner_and_the_gap_is_stated(metro):
    problem, bounded = metro
    above = np.all(bounded.inner[:, None, :] >= bounded.outer[None, :, :] - 1e-9, axis=2).any(axis=1)
    assert above.all()
    assert 0.0 < bounded.hv_inner < bounded.hv_outer and bounded.hv_gap == pytest.approx(
        1 - bounded.hv_inner / bounded.hv_outer)
    assert 0.0 < bounded.epsilon < 1.0
    # the energy side of the outer bound is the certified front: its least energy is the slowest run's
    front = problem.certified_front()
    lo, hi = front.clip(problem.bi_window_s)
    assert bounded.outer[:, 1].min() == pytest.approx(lo) and bounded.outer[:, 1].max() == pytest.approx(hi)
    assert np.all(bounded.outer[:, 2] > 0) and np.all(np.isfinite(bounded.outer))


def test_no_run_of_a_quick_nsga3_falls_below_the_outer_bound(metro):
    problem, bounded = metro
    seen = []

    class Collect(Callback):
        def notify(self, algorithm):
            off = algorithm.off if algorithm.off is not None else algorithm.pop
            seen.append(np.column_stack([off.get("F"), off.get("CV")]))

    ref_dirs = get_reference_directions("das-dennis", 3, n_partitions=6)
    minimize(problem, NSGA3(ref_dirs=ref_dirs), ("n_eval", 1500), seed=3, callback=Collect())
    runs = np.vstack(seen)
    F = runs[runs[:, 3] <= 0, :3]
    assert len(F) > 100
    above = np.all(F[:, None, :] >= bounded.outer[None, :, :] - 1e-9, axis=2).any(axis=1)
    assert above.all(), F[~above][:5]
    assert np.all(F[:, 2] >= comfort.comfort_floor_ms2(F[:, 1], **comfort.floor_settings(problem)))


@pytest.mark.parametrize("kind", ["metro", "intercity"])
def test_every_run_from_rest_launches_and_lands_as_the_floor_says(kind):
    problem = get_problem(f"generated-{kind}-3obj", n_var=12, seed=1)
    launch, landing = comfort.launch_accel_ms2(problem), comfort.landing_decel_ms2(problem)
    assert launch > 0.3 and landing > 0.3
    rng = np.random.default_rng(0)
    X = np.vstack([problem.xl, problem.xu, rng.uniform(problem.xl, problem.xu, (6, problem.n_var))])
    for x in X:
        trajectory = problem.trajectory(x)
        if trajectory.stop_error_m > problem.stop_tolerance_m:
            continue  # infeasible: the floor speaks of runs that stop at the platform
        assert trajectory.accel_ms2[0] == pytest.approx(launch, rel=1e-12)
        last = trajectory.accel_ms2[len(trajectory.accel_ms2) - 2]  # the last cell (the last node holds 0)
        assert last <= -landing


def test_only_the_3obj_form_has_a_bounded_front():
    with pytest.raises(ValueError, match="only the -3obj families"):
        get_problem("generated-metro-bi", n_var=10, seed=1).bounded_front()


def test_a_line_with_moving_ends_has_neither_launch_nor_landing_and_its_runs_respect_the_floor():
    problem = get_problem("generated-suburban-3obj", n_var=10, seed=4)  # enters and leaves at 36 km/h
    floor = comfort.floor_settings(problem)
    assert floor["launch_ms2"] == 0.0 and floor["landing_ms2"] == 0.0
    assert floor["boundary_speed_ms"] == pytest.approx(problem.case.initial_speed_ms + 0.01)
    X = np.random.default_rng(2).uniform(problem.xl, problem.xu, (40, problem.n_var))
    out = problem.evaluate(X, return_values_of=["F", "G"], return_as_dictionary=True)
    F = out["F"][np.all(out["G"] <= 0, axis=1)]
    assert len(F) >= 5 and np.all(F[:, 2] >= comfort_floor_ms2(F[:, 1], **floor))
