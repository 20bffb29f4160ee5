"""TimetableProblem: several trains, departures in a window, sharing in one supply section."""

import numpy as np
import pytest

from pymoo_rail.cases import load_case
from pymoo_rail.problems import TimetableProblem
from pymoo_rail.problems.timetable import mean_waiting_time_s


@pytest.fixture(scope="module")
def pair():
    return load_case("cooperative-pair")


@pytest.fixture(scope="module")
def problem(pair):
    return TimetableProblem(pair, 3, 120.0, dx_m=2.0)


def test_waiting_time_of_regular_and_bunched_departures():
    # regular: everyone waits half a headway on average
    assert mean_waiting_time_s(np.array([[0.0, 120.0, 240.0]]), 360.0)[0] == pytest.approx(60.0)
    # two trains together and one alone: gaps 0, 180, 180 -> (2 * 180^2) / (2 * 360) = 90 s
    assert mean_waiting_time_s(np.array([[0.0, 0.0, 180.0]]), 360.0)[0] == pytest.approx(90.0)


def test_layout_and_punctuality(problem, pair):
    assert problem.n_var == 2 + 3 * problem.n_shape
    X = problem.xl + np.random.default_rng(2).random((6, problem.n_var)) * (problem.xu - problem.xl)
    out = problem.evaluate(X, return_as_dictionary=True)
    assert np.all(out["G"][:, 1] < 0)  # every leg of every train on time
    np.testing.assert_allclose(out["F"][:, 0], out["traction_kwh"] - out["shared_kwh"], rtol=1e-12)
    assert np.all(out["shared_kwh"] >= 0.0)
    dep = problem.departures_s(X)
    np.testing.assert_allclose(dep[:, 0], 0.0)
    np.testing.assert_allclose(dep[:, 1:] - np.array([120.0, 240.0]), X[:, :2])


def test_a_train_s_journey_is_its_legs_and_a_dwell(problem):
    x = np.concatenate([np.zeros(2), np.full(3 * problem.n_shape, 0.5)])[None, :]
    sim = problem.simulate(x)
    journey = sim["journeys"][0][0]
    # leg 0 (190 s) + dwell at station 2 + leg 1 (100 s)
    assert journey.arrival_s == pytest.approx(190.0 + problem.dwell_s + 100.0, abs=0.05)
    assert journey.position_m[-1] == pytest.approx(3950.0)
    # identical trains: the traction of three journeys
    assert sim["traction_kwh"][0] == pytest.approx(3 * journey.traction_kwh, rel=1e-12)


def test_lossless_supply_shares_at_least_as_much(pair):
    lossy = TimetableProblem(pair, 2, 120.0, transmission_efficiency=0.5, dx_m=2.0)
    ideal = TimetableProblem(pair, 2, 120.0, transmission_efficiency=1.0, dx_m=2.0)
    X = lossy.xl + np.random.default_rng(3).random((4, lossy.n_var)) * (lossy.xu - lossy.xl)
    a = lossy.evaluate(X, return_as_dictionary=True)["shared_kwh"]
    b = ideal.evaluate(X, return_as_dictionary=True)["shared_kwh"]
    assert np.all(a <= b + 1e-12)
    assert b.max() > 0


def test_trains_too_close_violate_separation(pair):
    # 20 s apart on a 190 s leg: the follower runs into the leader at station 2
    p = TimetableProblem(pair, 2, 20.0, window_s=0.0, dx_m=2.0)
    x = np.clip(np.full((1, p.n_var), 0.5), p.xl, p.xu)
    assert p.evaluate(x, return_values_of=["G"])[0, 0] > 0


def test_bad_input_names_the_field(pair):
    with pytest.raises(ValueError, match="n_trains = 1"):
        TimetableProblem(pair, 1, 120.0)
    with pytest.raises(ValueError, match="transmission_efficiency = 1.5"):
        TimetableProblem(pair, 2, 120.0, transmission_efficiency=1.5)
    with pytest.raises(ValueError, match="objectives"):
        TimetableProblem(pair, 2, 120.0, objectives=("comfort",))
    with pytest.raises(ValueError, match="headway_s = -1"):
        TimetableProblem(pair, 2, -1.0)


def test_opposite_direction_mirrors_the_line(pair):
    from pymoo_rail.problems.timetable import opposite_direction

    down = opposite_direction(pair)
    L = pair.line.length_m
    # the -16 permille descent of 950-1650 m is a +16 climb at L - 1650 .. L - 950 the other way
    assert (L - 1650.0, L - 950.0, 16.0) in down.line.gradients
    assert [(leg.start_m, leg.end_m, leg.planned_time_s) for leg in down.legs] == [
        (0.0, 1350.0, 100.0), (1350.0, 3950.0, 190.0)]
    assert opposite_direction(down).line == pair.line


def test_both_directions_alternate_and_share_across(pair):
    both = TimetableProblem(pair, 2, 120.0, directions=2, dx_m=2.0)
    assert np.array_equal(both.direction_of, [0, 1]) and len(both.routes) == 2
    X = both.xl + np.random.default_rng(4).random((3, both.n_var)) * (both.xu - both.xl)
    out = both.evaluate(X, return_as_dictionary=True)
    assert np.all(out["G"][:, 1] < 0)  # on time both ways
    assert np.all(out["G"][:, 0] == -np.inf)  # one train per direction: nobody to follow
    sim = both.simulate(X[:1])
    down = sim["journeys"][0][1]
    assert down.position_m[-1] == pytest.approx(3950.0)
    # the down train's first leg is the short one (1350 m in 100 s), then a dwell, then 190 s
    assert down.arrival_s - down.departure_s == pytest.approx(100.0 + both.dwell_s + 190.0, abs=0.05)
    with pytest.raises(ValueError, match=r"directions = 3"):
        TimetableProblem(pair, 2, 120.0, directions=3)


@pytest.mark.slow
def test_reference_counts_each_train_in_its_own_direction(pair):
    from pymoo_rail.problems.cooperative_baseline import exact_baseline
    from pymoo_rail.problems.timetable import opposite_direction

    both = TimetableProblem(pair, 3, 120.0, directions=2, dx_m=2.0)
    up, down = (exact_baseline(c, dx_m=2.0).energy_kwh for c in (pair, opposite_direction(pair)))
    assert up != pytest.approx(down, rel=1e-3)  # descents become climbs
    assert both.reference_kwh() == pytest.approx(2 * up + down, rel=1e-12)
