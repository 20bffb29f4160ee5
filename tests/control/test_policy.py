"""The optimal policy: re-plans from any state against fresh exact solves, reuse, restrictions, bad input."""

import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from pymoo_rail.cases import load_case
from pymoo_rail.control import OptimalPolicy, SpeedRestriction
from pymoo_rail.control.policy import merged_tables, restricted_model
from pymoo_rail.model.errors import FieldError
from pymoo_rail.optimal import OptimalSolver, dp

PLANNED_S = 80.0


@pytest.fixture(scope="module")
def metro():
    return load_case("metro-a")


@pytest.fixture(scope="module")
def policy(metro):
    return OptimalPolicy(metro, PLANNED_S)


def energy_at(run, time_s, lambda_w):
    """A run's energy moved along the front's slope (price of time) to another running time (kWh)."""
    return run.energy.net_kwh + lambda_w / 3.6e6 * (run.running_time_s - time_s)


def test_replan_at_departure_is_the_plan(policy):
    rest = policy.replan(0.0, 0.0, 0.0)
    plan = policy.plan
    assert abs(rest.running_time_s - PLANNED_S) <= 0.3 and rest.summary["on_time"] == 1.0
    # at the plan's own time (the price of time is its slope), within the certificates
    gap = energy_at(rest, plan.running_time_s, policy.lambda_w) - plan.energy.net_kwh
    assert abs(gap) <= rest.summary["energy_bound_kwh"] + plan.summary["energy_bound_kwh"]


@pytest.mark.parametrize("delay_s", [3.0, 8.0])
def test_late_departure_is_the_exact_optimum_of_the_shorter_run(metro, policy, delay_s):
    rest = policy.replan(0.0, 0.0, delay_s)
    assert abs(rest.running_time_s - PLANNED_S) <= 0.3
    assert rest.time_s[0] == delay_s and rest.position_m[0] == 0.0
    fresh = OptimalSolver(metro).profile(PLANNED_S - delay_s)
    # the re-plan is the exact optimum at its own arrival, within both certificates
    at_fresh_time = energy_at(rest, fresh.running_time_s + delay_s, fresh.summary["lambda_w"])
    assert abs(at_fresh_time - fresh.energy.net_kwh) <= rest.summary["energy_bound_kwh"] + fresh.summary[
        "energy_bound_kwh"]
    assert rest.summary["energy_bound_kwh"] < 0.01 * rest.energy.net_kwh


def test_on_the_plan_the_rest_is_the_rest_of_the_plan(policy):
    plan = policy.plan
    i = plan.position_m.shape[0] // 3
    rest = policy.replan(plan.position_m[i], plan.speed_ms[i], plan.time_s[i])
    spent = plan.energy.net_kwh - rest.energy.net_kwh  # energy of the plan's first third
    assert abs(rest.running_time_s - PLANNED_S) <= 0.3
    # driving the rest differently from the plan cannot save more than the certificate
    first = plan.to_frame().iloc[: i + 1]
    assert spent > 0 and first.shape[0] == i + 1
    assert rest.energy.net_kwh <= plan.energy.net_kwh - spent + rest.summary["energy_bound_kwh"] + 1e-9


def test_a_replan_close_to_the_last_one_sweeps_nothing(policy):
    plan = policy.plan
    i = plan.position_m.shape[0] // 2
    policy.replan(plan.position_m[i], plan.speed_ms[i], plan.time_s[i] + 1.0)
    before = policy.n_sweeps
    rest = policy.replan(plan.position_m[i + 20], plan.speed_ms[i + 20], plan.time_s[i + 20] + 1.0)
    assert policy.n_sweeps == before
    assert abs(rest.running_time_s - PLANNED_S) <= 0.3


def test_a_late_train_that_cannot_be_on_time_runs_just_behind_the_fastest_run(policy):
    from pymoo_rail.control.policy import ARRIVAL_TOL_S

    rest = policy.replan(0.0, 0.0, 25.0)
    fastest = policy.fastest(0.0, 0.0, 25.0)
    assert fastest.running_time_s == pytest.approx(25.0 + policy.solver.min_running_time_s(), abs=1e-6)
    assert rest.summary["on_time"] == 0.0 and rest.summary["lateness_s"] > 1.0
    # a quarter of a second behind the earliest arrival, for clearly less energy than flat out
    assert 0.0 < rest.running_time_s - fastest.running_time_s <= ARRIVAL_TOL_S + 0.1
    assert rest.energy.net_kwh < 0.97 * fastest.energy.net_kwh
    past = policy.fastest(500.0, 10.0, 100.0)  # past the plan: the earliest arrival still exists
    assert past.running_time_s > 100.0 and past.summary["on_time"] == 0.0


def test_a_restriction_ahead_is_kept_and_the_run_is_still_on_time(metro, policy):
    restriction = SpeedRestriction(600.0, 700.0, 50.0)
    plan = policy.plan
    i = plan.position_m.shape[0] // 5
    rest = policy.replan(plan.position_m[i], plan.speed_ms[i], plan.time_s[i] - 2.0, restriction=restriction)
    inside = (rest.position_m >= 600.0) & (rest.position_m < 700.0 + metro.train.length_m)
    assert rest.speed_ms[inside].max() * 3.6 <= 50.0 + 1e-6
    assert plan.speed_ms[(plan.position_m >= 600.0) & (plan.position_m <= 700.0)].max() * 3.6 > 50.0
    assert abs(rest.running_time_s - PLANNED_S) <= 0.3


def test_merged_tables_give_the_cost_to_go_of_fresh_tables(policy):
    solver = policy.solver
    model = solver.simulator.model
    restricted = restricted_model(model, SpeedRestriction(400.0, 450.0, 40.0), 120.0)
    merged = merged_tables(model, solver.transition_tables(), restricted, solver.n_speeds, solver.max_targets,
                           solver.top_bias)
    fresh = dp.transitions(restricted, solver.n_speeds, solver.max_targets, solver.top_bias)
    assert merged[0].shape[0] > solver.transition_tables()[0].shape[0]  # rows appended, old ones kept
    n = model.position_m.shape[0]
    values = []
    for tables in (merged, fresh):
        value = np.empty((n, solver.n_speeds))
        dp.solve(restricted, tables, policy.lambda_w, solver.max_targets, solver.top_bias, solver.tie_j, value)
        values.append(value)
    np.testing.assert_array_equal(values[0], values[1])


def test_a_measured_mass_replans_with_the_heavier_train(metro, policy):
    plan = policy.plan
    i = 100  # still pulling: the rest of the run has traction to pay
    heavy = policy.replan(plan.position_m[i], plan.speed_ms[i], plan.time_s[i], mass_t=metro.train.mass_t * 1.1)
    nominal = policy.replan(plan.position_m[i], plan.speed_ms[i], plan.time_s[i])
    assert abs(heavy.running_time_s - PLANNED_S) <= 0.3
    assert heavy.energy.net_kwh > nominal.energy.net_kwh


def test_a_known_low_adhesion_brakes_earlier_and_is_still_on_time(metro, policy):
    plan = policy.plan
    i = 100
    low = policy.replan(plan.position_m[i], plan.speed_ms[i], plan.time_s[i], adhesion_factor=0.85)
    nominal = policy.replan(plan.position_m[i], plan.speed_ms[i], plan.time_s[i])
    assert abs(low.running_time_s - PLANNED_S) <= 0.3
    # weaker brakes: the ATP's envelope, and so the planner's, is lower before the platform
    assert policy.envelope_ms(900.0, adhesion_factor=0.85) < policy.envelope_ms(900.0)
    assert np.max(low.accel_ms2) < np.max(nominal.accel_ms2) + 1e-9


@pytest.mark.parametrize("kwargs, field", [
    ({"position_m": -1.0}, "position_m"), ({"position_m": 1000.5}, "position_m"),
    ({"position_m": 1000.0}, "position_m"), ({"position_m": math.nan}, "position_m"),
    ({"speed_ms": 40.0}, "speed_ms"), ({"speed_ms": -1.0}, "speed_ms"), ({"speed_ms": "fast"}, "speed_ms"),
    ({"elapsed_s": PLANNED_S + 1.0}, "elapsed_s"), ({"elapsed_s": -1.0}, "elapsed_s"),
    ({"restriction": SpeedRestriction(900.0, 1200.0, 40.0)}, "restriction.end_m"),
    ({"restriction": (100, 200, 40)}, "restriction"), ({"mass_t": 0.0}, "mass_t"),
    ({"adhesion_factor": 0.0}, "adhesion_factor"), ({"adhesion_factor": 1.2}, "adhesion_factor"),
])
def test_bad_input_names_the_field_and_the_value(policy, kwargs, field):
    state = {"position_m": 300.0, "speed_ms": 15.0, "elapsed_s": 20.0, **kwargs}
    with pytest.raises(FieldError, match=f"'{field}' = "):
        policy.replan(**state)


@pytest.mark.parametrize("args, field", [((100.0, 50.0, 40.0), "restriction.end_m"),
                                         ((-5.0, 50.0, 40.0), "restriction.start_m"),
                                         ((100.0, 200.0, 0.0), "restriction.limit_kmh")])
def test_bad_restrictions(args, field):
    with pytest.raises(FieldError, match=f"'{field}'"):
        SpeedRestriction(*args)


def test_restriction_from_text():
    assert SpeedRestriction.parse("3000:3600:40") == SpeedRestriction(3000.0, 3600.0, 40.0)
    with pytest.raises(FieldError, match="'restriction' = '3000:40'"):
        SpeedRestriction.parse("3000:40")


@settings(max_examples=25, deadline=None)
@given(st.floats(allow_nan=False, allow_infinity=False).filter(lambda x: x < 0 or x >= 1000.0))
def test_generated_positions_off_the_line_are_refused(policy, position_m):
    with pytest.raises(FieldError, match="'position_m'"):
        policy.replan(position_m, 10.0, 10.0)


def test_line_variants_are_kept_within_bounds(metro, policy):
    from pymoo_rail.control.policy import MAX_LINES_KEPT

    for k in range(MAX_LINES_KEPT + 2):
        policy.replan(300.0, 15.0, 25.0, mass_t=metro.train.mass_t * (1.0 + 0.01 * (k + 1)))
    assert len(policy._lines) <= MAX_LINES_KEPT
    assert (metro.train.mass_t, 1.0, 1.0, None) in policy._lines  # the case's own line stays
