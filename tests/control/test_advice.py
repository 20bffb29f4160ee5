"""Driver advice: regimes with switch points, stable in time, followed late at a measured cost."""

import io
import math

import pandas as pd
import pytest

from pymoo_rail.cases import load_case
from pymoo_rail.control import OptimalPolicy
from pymoo_rail.control.advice import (
    Advice,
    AdvisedDriving,
    advice_frame,
    advice_from_run,
    advice_program,
)
from pymoo_rail.control.closed_loop import LoopDisturbance, OptimalControls, closed_loop
from pymoo_rail.control.policy import run_trace
from pymoo_rail.model.errors import FieldError


@pytest.fixture(scope="module")
def yizhuang():
    case = load_case("yizhuang")
    return case, OptimalPolicy(case, case.planned_time_s)


def test_the_plan_reads_as_power_coast_brake(yizhuang):
    _, policy = yizhuang
    advice = advice_from_run(policy.plan, 10.0)
    assert [a.action for a in advice] == ["power", "coast", "brake"]
    assert advice[1].text() == f"coast from km {advice[1].start_m / 1000:.2f}"
    assert advice[0].text().startswith("power to ") and advice[-1].final
    assert Advice(1000.0, "hold", 118.0).text() == "hold 118 km/h from km 1.00"
    # the switch is where the plan stops pulling
    first_coast = policy.plan.position_m[list(policy.plan.regime).index(2)]
    assert abs(advice[1].start_m - first_coast) < 1.0


def test_no_pull_shorter_than_the_minimum_duration(yizhuang):
    _, policy = yizhuang
    rest = policy.replan(300.0, 16.0, 30.0)
    for min_s in (0.0, 5.0, 15.0):
        advice = advice_from_run(rest, min_s)
        times = [float(rest.time_s[abs(rest.position_m - a.start_m).argmin()]) for a in advice] + [rest.time_s[-1]]
        for a, t0, t1 in zip(advice, times, times[1:]):
            assert a.action in ("coast", "brake") or t1 - t0 >= min_s - 1e-9 or a is advice[0]


def test_following_the_plans_advice_costs_under_one_percent(yizhuang):
    case, policy = yizhuang
    plan = policy.plan
    advice = advice_from_run(plan, 10.0)
    model = policy.model_ahead(0.0, 0.0)
    run = run_trace(model, advice_program(advice, lambda x: 0.0, 0.0, case.line.length_m))
    assert run.reached and abs(run.running_time_s - plan.running_time_s) < 0.5
    at_plan_time = run.energy.net_kwh + policy.lambda_w / 3.6e6 * (run.running_time_s - plan.running_time_s)
    assert abs(at_plan_time - plan.energy.net_kwh) <= 0.01 * plan.energy.net_kwh


@pytest.mark.parametrize("world", [LoopDisturbance(), LoopDisturbance(departure_delay_s=5.0)])
def test_advice_followed_late_costs_little_and_changes_rarely(yizhuang, world):
    case, policy = yizhuang
    exact = closed_loop(case, OptimalControls(policy, 10.0), world)
    price = policy.lambda_w / 3.6e6  # kWh per second of lateness

    def cost(run):
        return run.energy.net_kwh + price * run.summary["lateness_s"]

    late = AdvisedDriving(policy, 10.0, reaction_s=1.5)
    run = closed_loop(case, late, world)
    assert run.summary["reached"] == 1.0 and abs(run.summary["lateness_s"]) <= 2.0
    assert cost(run) <= 1.01 * cost(exact)
    assert late.changes(run) <= run.running_time_s / 10.0
    led = AdvisedDriving(policy, 10.0, reaction_s=1.5, lead_s=1.5)
    assert cost(closed_loop(case, led, world)) <= cost(run) + 1e-9


def test_advice_as_csv_and_json(yizhuang):
    case, policy = yizhuang
    driver = AdvisedDriving(policy, 10.0)
    run = closed_loop(case, driver, LoopDisturbance(departure_delay_s=3.0))
    table = advice_frame(driver.seen(run))
    assert table.shape[0] == driver.changes(run) + 1
    assert list(table.columns) == ["shown_s", "shown_m", "start_m", "action", "speed_kmh", "text"]
    assert table.shape[0] >= 3 and set(table["action"]) <= {"power", "hold", "coast", "brake"}
    back = pd.read_csv(io.StringIO(table.to_csv(index=False)))
    assert back["text"].tolist() == table["text"].tolist()
    assert pd.read_json(io.StringIO(table.to_json(orient="records"))).shape == table.shape


@pytest.mark.parametrize("field, value", [("reaction_s", -1.0), ("min_duration_s", math.nan), ("lead_s", "1")])
def test_bad_driver_settings(yizhuang, field, value):
    with pytest.raises(FieldError, match=f"'{field}'"):
        AdvisedDriving(yizhuang[1], **{field: value})


def test_the_run_with_its_advice_is_drawn(yizhuang, tmp_path):
    from pymoo_rail.plotting import plot_advised_run, save_figure

    case, policy = yizhuang
    driver = AdvisedDriving(policy, 10.0)
    run = closed_loop(case, driver, LoopDisturbance(departure_delay_s=3.0))
    fig = plot_advised_run(run, driver.seen(run), case, policy.plan)
    texts = [t.get_text() for t in fig.axes[0].texts]
    assert len(texts) == len(driver.seen(run)) and texts[0].startswith("power to")
    path = save_figure(fig, tmp_path / "advice.png")
    assert path.stat().st_size > 10_000
