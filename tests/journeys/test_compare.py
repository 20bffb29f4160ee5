"""journeys.compare: fronts against a reference, and the optimal split against the rules of thumb."""

from __future__ import annotations

import numpy as np
import pandas as pd
import pytest

from pymoo_rail.cases.ttobench import BEIJING_SUBWAY_TRAIN, YIZHUANG_STOP_NAMES, YIZHUANG_TRACK
from pymoo_rail.journeys import journey_from_ttobench
from pymoo_rail.journeys.compare import front_gaps, on_fronts, rule_energy, split_sweep, supplement_tables
from pymoo_rail.model import CaseError

FLAT = pd.DataFrame({"running_time_s": [60.0, 70.0, 80.0, 90.0, 100.0], "energy_kwh": [20.0, 14.0, 11.0, 9.5, 9.0]})
STEEP = FLAT.assign(energy_kwh=2 * FLAT["energy_kwh"])  # twice the energy and the saving per second
NARROW = pd.DataFrame({"running_time_s": [60.0, 65.0], "energy_kwh": [20.0, 17.0]})


@pytest.fixture(scope="module")
def journey():
    return journey_from_ttobench(YIZHUANG_TRACK, BEIJING_SUBWAY_TRAIN, stop_names=YIZHUANG_STOP_NAMES)


def test_identical_sections_make_every_split_the_optimal_one(journey):
    fronts = [FLAT] * journey.n_sections
    table, cross = supplement_tables(journey, fronts, fronts, fronts, (0.0, 0.1, 0.7))
    assert table["supplement %"].tolist() == [0.0, 10.0]  # 70 % lies beyond the fronts' 100 s
    np.testing.assert_allclose(table["equal kWh"], table["optimal kWh"])
    assert table["optimal kWh"].iloc[0] == pytest.approx(13 * 20.0)
    # 10 % of 13 x 60 s = 78 s: 6 s per section on the first segment (-0.6 kWh/s) each
    assert table["optimal kWh"].iloc[1] == pytest.approx(13 * (20.0 - 6 * 0.6))
    np.testing.assert_allclose(cross["split from simulated fronts kWh"], cross["optimal on combined kWh"])


def test_a_steeper_section_gets_more_time_than_the_equal_supplement_gives(journey):
    fronts = [STEEP] + [FLAT] * (journey.n_sections - 1)
    table, _ = supplement_tables(journey, fronts, fronts, fronts, (0.2,))
    assert table["saving vs equal kWh"].iloc[0] > 0.0
    assert table["optimal kWh"].iloc[0] < table["equal kWh"].iloc[0] <= table["proportional kWh"].iloc[0] + 1e-9


def test_a_rule_that_leaves_a_front_is_nan_and_on_fronts_refuses_it(journey):
    fronts = [NARROW] + [FLAT] * (journey.n_sections - 1)
    total = 13 * 60.0 * 1.1  # 6 s more per section: beyond NARROW's 65 s
    assert np.isnan(rule_energy(journey, total, fronts, "equal"))
    with pytest.raises(CaseError, match="running_time_s"):
        on_fronts(fronts, [66.0] + [60.0] * 12)
    sweep = split_sweep(journey, fronts, n_points=4)
    # the equal supplement stays inside the narrowest front: 5 s per section at most
    assert sweep["running_time_s"].iloc[-1] == pytest.approx(13 * 60.0 + 13 * 5.0)
    assert (sweep["optimal_kwh"] <= sweep["equal_kwh"] + 1e-9).all()


def test_front_gaps_are_relative_to_the_reference_over_the_common_range(journey):
    higher = FLAT.assign(energy_kwh=FLAT["energy_kwh"] * 1.1)
    shorter = FLAT.iloc[:3]  # 60-80 s
    gaps = front_gaps([FLAT] * 2, {"a": [higher] * 2, "b": [shorter] * 2, "combined": [FLAT] * 2}, journey)
    assert gaps["range s"].tolist() == ["60.0-80.0"] * 2
    np.testing.assert_allclose(gaps[["a mean %", "a min %", "a max %"]].to_numpy(), 10.0)
    np.testing.assert_allclose(gaps[["b mean %", "combined max %"]].to_numpy(), 0.0, atol=1e-12)
    assert gaps["label"].iloc[1] == journey.section_label(1)


def test_plot_split_costs_draws_the_sweep_and_one_trip(journey):
    import matplotlib

    matplotlib.use("Agg")
    from pymoo_rail.journeys import allocate_running_time, supplement_split
    from pymoo_rail.plotting.journey import plot_split_costs

    fronts = [STEEP] + [FLAT] * (journey.n_sections - 1)
    sweep = split_sweep(journey, fronts, n_points=5)
    total = 13 * 60.0 * 1.1
    best = allocate_running_time(journey, total, fronts=fronts)
    equal = supplement_split(journey, total, fronts=fronts)
    fig = plot_split_costs(sweep, best, equal, "hand-made fronts")
    first, second, third = fig.axes
    np.testing.assert_allclose(first.lines[0].get_ydata(), sweep["optimal_kwh"])
    np.testing.assert_allclose(second.lines[0].get_ydata(), sweep["equal_kwh"] - sweep["optimal_kwh"])
    assert [p.get_height() for p in third.patches[:journey.n_sections]] == pytest.approx(best.table.supplement_s.tolist())
    assert first.get_title() == "hand-made fronts" and f"{best.trip_time_s / 60:.0f}-min" in third.get_title()


def test_de_with_the_budget_repair_comes_close_to_the_exact_split(journey):
    from pymoo_rail.journeys import allocate_running_time
    from pymoo_rail.journeys.compare import de_allocation_runs

    fronts = [STEEP] + [FLAT] * (journey.n_sections - 1)
    total = 13 * 60.0 + 78.0
    best = allocate_running_time(journey, total, fronts=fronts)
    runs = de_allocation_runs(fronts, total, best.energy_kwh, n_gen=30, seeds=(1,))
    assert list(runs.columns) == ["seed", "DE kWh", "gap to exact %", "evaluations", "time s"]
    assert runs["gap to exact %"].iloc[0] >= -1e-6  # the exact split is the least energy on these fronts
    assert runs["gap to exact %"].iloc[0] < 5.0 and runs["evaluations"].iloc[0] == 40 * 30


@pytest.mark.slow  # 13 sections' strategy fronts
def test_timed_fronts_count_the_sections_read_back_from_the_cache(journey, tmp_path):
    from pymoo_rail.journeys.compare import timed_section_fronts

    cache = tmp_path / "fronts.csv"
    computed, seconds, read = timed_section_fronts(journey, "simulated", cache)
    assert read == 0 and seconds > 0 and len(computed) == journey.n_sections
    again, _, read = timed_section_fronts(journey, "simulated", cache)
    assert read == journey.n_sections
    for a, b in zip(computed, again):
        np.testing.assert_allclose(a["energy_kwh"], b["energy_kwh"])
