"""pymoo_rail.control.compare_tracking: every curve by every controller, train and period, in one table."""

from __future__ import annotations

import pytest

from pymoo_rail.cases import load_case
from pymoo_rail.control import PID, TRACKING_METRICS, Hysteresis, compare_tracking, track, tracking_metrics
from pymoo_rail.sim import Simulator


def test_the_table_holds_one_row_per_combination_with_the_tracked_runs_metrics():
    case = load_case("yizhuang")
    ideal = Simulator(case).flat_out()
    table, runs = compare_tracking({"flat out": ideal}, {"hysteresis": Hysteresis(2, 4), "PID": PID()},
                                   {"nominal": case}, (0.2, 1.0))
    assert list(table.columns) == ["curve", "train", "period_s", "controller", *TRACKING_METRICS]
    assert list(zip(table.period_s, table.controller)) == [(0.2, "hysteresis"), (0.2, "PID"), (1.0, "hysteresis"),
                                                           (1.0, "PID")]
    again = track(case, ideal, PID(), control_period_s=1.0)
    assert tracking_metrics(runs["flat out", "nominal", 1.0, "PID"]) == tracking_metrics(again) == \
        table.iloc[3][list(TRACKING_METRICS)].to_dict()
    assert (table.stop_error_m < 0.5).all() and (table.energy_kwh > 0).all()


def test_an_empty_input_is_refused_by_name():
    case = load_case("yizhuang")
    with pytest.raises(ValueError, match="must not be empty, got 1, 1, 1, 0"):
        compare_tracking({"x": Simulator(case).flat_out()}, {"PID": PID()}, {"nominal": case}, ())
