"""The closed-loop study's pieces: seeded worlds, one row per world and controller, the summary."""

import numpy as np
import pytest

from pymoo_rail.cases import load_case
from pymoo_rail.control import OptimalPolicy
from pymoo_rail.control.study import (
    STUDY_CONTROLLERS,
    can_be_on_time,
    draw_loop_disturbances,
    loop_runs,
    loop_summary,
    make_loop_controller,
)
from pymoo_rail.model.errors import FieldError


@pytest.fixture(scope="module")
def metro():
    return load_case("metro-a")


def test_worlds_are_seeded_and_on_the_line(metro):
    a = draw_loop_disturbances(metro, 30, seed=3, planned_time_s=80.0)
    assert a == draw_loop_disturbances(metro, 30, seed=3, planned_time_s=80.0)
    assert a != draw_loop_disturbances(metro, 30, seed=4, planned_time_s=80.0)
    restricted = [w for w in a if w.restriction is not None]
    delayed = [w for w in a if w.departure_delay_s > 0]
    assert 5 <= len(restricted) <= 25 and 5 <= len(delayed) <= 25
    for w in restricted:
        assert 0 <= w.announce_m <= w.restriction.start_m < w.restriction.end_m <= metro.line.length_m
        assert w.restriction.limit_kmh < 80.0
    assert max(w.departure_delay_s for w in a) <= 0.06 * 80.0


def test_one_world_gives_a_row_per_controller(metro):
    policy = OptimalPolicy(metro, 80.0)
    runs = loop_runs(metro, 1, seed=2, policy=policy, planned_time_s=80.0)
    assert list(runs["controller"]) == list(STUDY_CONTROLLERS)
    assert (runs["reached"] == 1.0).all() and (runs["stop_error_m"] < 0.5).all()
    price = policy.lambda_w / 3.6e6
    np.testing.assert_allclose(runs["cost_kwh"], runs["net_kwh"] + price * runs["lateness_s"])
    assert np.isfinite(runs.loc[runs["controller"] == "advice", "advice_changes"]).all()
    # the real train's exact optimum at each run's own time is a lower bound (up to its certificate)
    assert (runs["gap_pct"] > -0.5).all(), runs[["controller", "gap_pct"]]
    summary = loop_summary(runs)
    assert summary.shape[0] == len(STUDY_CONTROLLERS) and (summary["n"] == 1).all()


def test_a_world_too_late_for_the_plan_is_told_apart(metro):
    world = draw_loop_disturbances(metro, 1, seed=0)[0]
    late = type(world)(departure_delay_s=30.0)
    assert not can_be_on_time(metro, late, 80.0)
    assert can_be_on_time(metro, type(world)(), 80.0)


def test_unknown_controller_name(metro):
    with pytest.raises(FieldError, match="'controller' = 'magic'"):
        make_loop_controller("magic", metro, None)


def test_tuned_trackers_need_their_gains(metro):
    policy = OptimalPolicy(metro, 80.0)
    with pytest.raises(FieldError, match="'controller' = 'tracking_tuned_pid'"):
        make_loop_controller("tracking_tuned_pid", metro, policy)
