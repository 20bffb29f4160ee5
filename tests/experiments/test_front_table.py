"""Front statistics for paper tables: the punctual member, the exact front's energy, the gaps."""

import numpy as np
import pandas as pd
import pytest

from pymoo_rail.experiments.front_table import (exact_energy_kwh, exact_front_table, front_statistics, most_punctual,
                                               punctual_choice)

EXACT = pd.DataFrame({"running_time_s": [100.0, 110.0, 120.0], "energy_kwh": [30.0, 20.0, 15.0]})


def test_most_punctual_is_the_closest_to_the_plan_and_ties_go_to_the_lower_energy():
    F = np.array([[25.0, 104.0], [22.0, 108.0], [21.0, 112.0], [18.0, 118.0]])
    assert most_punctual(F, 109.0) == 1
    assert most_punctual(F, 110.0) == 2  # 108 and 112 are 2 s off: the lower energy wins


def test_exact_energy_interpolates_inside_and_is_nan_outside():
    assert exact_energy_kwh(EXACT, 105.0) == pytest.approx(25.0)
    assert exact_energy_kwh(EXACT, 120.0) == pytest.approx(15.0)
    assert np.isnan(exact_energy_kwh(EXACT, 99.0)) and np.isnan(exact_energy_kwh(EXACT, 121.0))


def test_front_statistics_extent_on_time_and_gap_of_the_punctual_member():
    F = np.array([[33.0, 100.0], [22.0, 110.0], [16.5, 120.0]])
    row = front_statistics(F, 110.0, EXACT)
    assert (row["e_min"], row["e_max"], row["t_min"], row["t_max"]) == (16.5, 33.0, 100.0, 120.0)
    assert (row["punctual_e"], row["punctual_t"], row["e_at_plan"]) == (22.0, 110.0, 22.0)
    assert row["punctual_gap_pct"] == pytest.approx(10.0)  # 22 kWh against 20 kWh exact
    assert row["gap_min_pct"] == pytest.approx(10.0) and row["gap_max_pct"] == pytest.approx(10.0)
    assert "gap_mean_pct" not in front_statistics(F, 110.0)
    assert np.isnan(front_statistics(F, 90.0)["e_at_plan"])  # no member on time


def test_median_run_is_the_middle_by_the_indicator_and_names_a_missing_pair():
    from pymoo_rail.experiments.stats import median_run

    rows = [{"problem": "p", "algorithm": "a", "seed": s, "hv_ref": hv} for s, hv in
            ((1, 0.5), (2, 0.9), (3, np.nan), (4, 0.7))]
    assert median_run(rows, "p", "a")["seed"] == 4  # 0.9, 0.7 | 0.5, nan: the better middle one
    assert median_run(rows[:3], "p", "a")["seed"] == 1
    assert median_run(rows, "p", "a", lower_better=True)["seed"] == 4  # 0.5, 0.7 | 0.9, nan
    with pytest.raises(ValueError, match="'b'.*'p'"):
        median_run(rows, "p", "b")


def test_describe_comparison_words_the_verdict_of_compare_means():
    from pymoo_rail.experiments.stats import compare_means, describe_comparison

    a, b = [1.0, 1.1, 0.9, 1.05, 0.95], [2.0, 2.1, 1.9, 2.05, 1.95]
    assert describe_comparison(compare_means(a, b)).startswith("better (-50.0 %, p = ")
    assert describe_comparison(compare_means(b, a)).startswith("worse (+100.0 %")
    assert describe_comparison((True, -0.5, 0.2)) == "no significant difference (-0.50 %, p = 0.2)"


def test_signed_percent_keeps_two_decimals_under_one_percent():
    from pymoo_rail.experiments.stats import signed_percent

    assert (signed_percent(0.456), signed_percent(-12.34), signed_percent(1.0)) == ("+0.46 %", "-12.3 %", "+1.0 %")


def test_punctual_choice_is_the_least_energy_within_the_window_and_none_outside():
    row = {"algorithm": "MOABC", "problem": "non-equal", "seed": 3, "n_eval": 200, "wall_time_s": 1.5,
           "F": np.array([[20.0, 0.5], [19.0, 2.0], [21.0, 0.0], [10.0, 0.2]]),
           "CV": np.array([0.0, 0.0, 0.0, 1.0]),  # the cheapest member is infeasible
           "X": np.array([[1.0], [2.0], [3.0], [4.0]]),
           "extras": {"energy_kwh": [20.0, 19.0, 21.0, 10.0], "running_time_s": [150.5, 152.0, 150.0, 150.2],
                      "stop_error_m": [0.1, 0.2, 0.3, 0.4]}}
    chosen = punctual_choice(row, 150.0, 1.0)
    assert (chosen["energy_kwh"], chosen["running_time_s"], chosen["stop_error_m"], chosen["x"]) == (20.0, 150.5, 0.1, [1.0])
    assert (chosen["n_front"], chosen["n_feasible"], chosen["n_within"]) == (4, 3, 2)
    assert (chosen["front_time_error_min_s"], chosen["front_time_error_max_s"]) == (0.0, 2.0)
    assert (chosen["front_energy_min_kwh"], chosen["front_energy_max_kwh"]) == (19.0, 21.0)
    missed = punctual_choice(row, 160.0, 1.0)
    assert missed["x"] is None and np.isnan(missed["energy_kwh"]) and missed["n_within"] == 0


def test_the_exact_front_table_has_a_row_per_requested_time():
    exact = pd.DataFrame({"requested_time_s": [990.0, 1050.0], "running_time_s": [990.004, 1049.996],
                          "energy_kwh": [700.123, 640.5], "traction_kwh": [800.0, 720.0], "regen_kwh": [100.0, 79.5],
                          "lambda_kwh_per_s": [0.5, 0.25], "neutral_traction_j": [0.0, 0.0],
                          "limit_excess_ms": [1e-9, 0.0], "stop_error_m": [0.01, 0.02], "solve_s": [12.4, 30.6]})
    lines = exact_front_table(exact).splitlines()
    assert len(lines) == 2 + 2 and lines[0].startswith("| requested (s) | running time (s) | net energy (kWh)")
    assert lines[2].startswith("| 990 | 990.00 | 700.12 | 800.0 / 100.0 | 0.500 |")
    assert lines[3].endswith("| 31 |")
