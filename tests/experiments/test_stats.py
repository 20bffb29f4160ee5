"""Statistics and indicators: hand-computed values, closed forms, and the tables of a small study."""

from __future__ import annotations

import math

import numpy as np
import pandas as pd
import pytest

from pymoo_rail.experiments import load_results
from pymoo_rail.experiments.metrics import front_indicators, gd_van_veldhuizen, normalised_hv, true_front
from pymoo_rail.experiments.stats import (
    add_reference_indicators,
    indicator_table,
    nondominated,
    rank_sum,
    rank_sum_tests,
    reference_fronts,
    summarize,
    to_markdown,
    write_tables,
)


def _frame(values: dict[str, list[float]], indicator: str = "igd", problem: str = "P") -> pd.DataFrame:
    rows = [{"problem": problem, "algorithm": a, "seed": s + 1, indicator: v}
            for a, vs in values.items() for s, v in enumerate(vs)]
    return pd.DataFrame(rows)


def test_summary_statistics_by_hand():
    results = _frame({"A": [1.0, 2.0, 3.0, 4.0, 5.0], "B": [2.0, 2.0, 2.0, 2.0, 2.0]})
    summary = summarize(results, ["igd"])
    a = summary.loc[("P", "A")]
    assert (a[("runs", "n")], a[("igd", "min")], a[("igd", "mean")], a[("igd", "median")], a[("igd", "max")]) \
        == (5, 1.0, 3.0, 3.0, 5.0)
    assert a[("igd", "std")] == pytest.approx(math.sqrt(2.5))  # sample std: sum of squares 10 / (5 - 1)
    assert summary.loc[("P", "B"), ("igd", "std")] == 0.0


def test_summary_counts_runs_where_an_indicator_is_missing():
    results = _frame({"A": [1.0, np.nan, 3.0]})
    summary = summarize(results, ["igd"])
    assert summary.loc[("P", "A"), ("igd", "n")] == 2 and summary.loc[("P", "A"), ("runs", "n")] == 3
    assert summary.loc[("P", "A"), ("igd", "mean")] == 2.0


def test_rank_sum_exact_p_value_and_direction():
    # fully separated samples of 5 and 5: two-sided exact p = 2 / C(10, 5) = 2 / 252
    u, p, verdict = rank_sum([1, 2, 3, 4, 5], [6, 7, 8, 9, 10], lower_better=True)
    assert (u, verdict) == (0.0, "+") and p == pytest.approx(2 / 252)
    assert rank_sum([1, 2, 3, 4, 5], [6, 7, 8, 9, 10], lower_better=False)[2] == "-"  # e.g. HV
    assert rank_sum([6, 7, 8, 9, 10], [1, 2, 3, 4, 5], lower_better=True)[2] == "-"
    # 3 and 3 separated: p = 2 / C(6, 3) = 0.1 >= 0.05, no significant difference
    u, p, verdict = rank_sum([1, 2, 3], [4, 5, 6])
    assert p == pytest.approx(0.1) and verdict == "="
    assert rank_sum([2.0, 2.0, 2.0], [2.0, 2.0]) == (3.0, 1.0, "=")
    u, p, verdict = rank_sum([1.0], [2.0, 3.0])
    assert verdict == "n/a" and math.isnan(p)


def test_rank_sum_tests_and_indicator_table():
    results = _frame({"base": [6, 7, 8, 9, 10], "good": [1, 2, 3, 4, 5], "same": [6, 7, 8, 9, 10.5]})
    tests = rank_sum_tests(results, "base", ["igd"])
    verdicts = dict(zip(tests["algorithm"], tests["verdict"]))
    assert verdicts == {"good": "+", "same": "="}
    table = indicator_table(results, "igd", baseline="base")
    assert list(table.columns) == ["base", "good", "same"]  # baseline first
    assert table.loc["P", "good"] == "*3 (1.581) +"          # best mean marked, verdict appended
    assert table.loc["P", "base"] == "8 (1.581)"
    markdown = to_markdown(table)
    assert "| P | 8 (1.581) | **3 (1.581) +** |" in markdown
    with pytest.raises(ValueError, match="baseline 'nope'"):
        rank_sum_tests(results, "nope")
    with pytest.raises(ValueError, match="indicator 'hv' is not in the results"):
        summarize(results, ["hv"])


def test_indicators_of_the_true_zdt1_front():
    from pymoo.problems import get_problem

    pf = true_front(get_problem("zdt1"))
    values = front_indicators(pf, pf)
    assert values["igd"] == pytest.approx(0.0, abs=1e-12) and values["gd"] == pytest.approx(0.0, abs=1e-12)
    # normalised front f2 = 1 - sqrt(f1) on [0, 1], reference point (1.1, 1.1):
    # HV = 1.1 * 1.1 - integral_0^1 (1 - sqrt(f1)) df1 - 0.1 * 0 ... = 0.1 + 2/3 + 0.11
    assert values["hv"] == pytest.approx(0.1 + 2 / 3 + 0.11, abs=1e-3)


def test_spacing_gd_and_hv_by_hand():
    line = np.column_stack([np.linspace(0, 1, 6), 1 - np.linspace(0, 1, 6)])  # evenly spaced on a line
    assert front_indicators(line, None)["spacing"] == pytest.approx(0.0, abs=1e-12)
    pf = np.array([[0.0, 1.0], [1.0, 0.0]])
    assert gd_van_veldhuizen(np.array([[0.0, 1.3], [1.4, 0.0]]), pf) == pytest.approx(math.sqrt(0.09 + 0.16) / 2)
    # one point at the ideal of [0, 1]^2 dominates 1.1 x 1.1
    assert normalised_hv(np.array([[0.0, 0.0]]), np.zeros(2), np.ones(2)) == pytest.approx(1.21)
    single = front_indicators(np.array([[3.0], [2.5]]), np.array([[2.0]]))
    assert single == {"n_front": 2.0, "f_best": 2.5, "error": 0.5}
    assert "spacing" not in front_indicators(np.array([[1.0, 2.0]]), None)  # undefined for one point


def test_reference_front_indicators():
    F1 = np.array([[0.0, 1.0], [1.0, 0.0]])
    F2 = np.array([[0.5, 0.5], [0.2, 2.0]])
    results = pd.DataFrame({"problem": ["rail", "rail"], "algorithm": ["a", "b"], "seed": [1, 1], "n_obj": [2, 2],
                            "F": [F1, F2], "CV": [np.zeros(2), np.zeros(2)]})
    reference = reference_fronts(results)["rail"]
    np.testing.assert_array_equal(reference, nondominated(np.vstack([F1, F2[:1]])))
    out = add_reference_indicators(results)
    # reference {(0, 1), (1, 0), (0.5, 0.5)}: a misses (0.5, 0.5) by sqrt(0.5)
    assert out.loc[0, "igd_ref"] == pytest.approx(math.sqrt(0.5) / 3, rel=1e-12)
    # each front holds part of the reference only: both HVs are below the union's
    union_hv = normalised_hv(reference, reference.min(axis=0), reference.max(axis=0))
    assert out.loc[1, "hv_ref"] < union_hv and out.loc[0, "hv_ref"] < union_hv
    assert out.loc[1, "gd_ref"] == pytest.approx((0.0 + math.hypot(0.2 - 0.0, 2.0 - 1.0)) / 2)


def test_tables_of_the_small_study(pool_study_dir, tmp_path):
    results = load_results(pool_study_dir)
    written = {p.name for p in write_tables(results, tmp_path, baseline="nsga2")}
    assert {"summary.csv", "summary.md", "igd.csv", "igd.md", "hv.md", "spacing.md", "ranksum.csv", "ranksum.md",
            "verdicts.md"} <= written
    summary = pd.read_csv(tmp_path / "summary.csv", header=[0, 1], index_col=[0, 1])
    assert len(summary) == 9 and (summary[("runs", "n")] == 5).all()
    tests = pd.read_csv(tmp_path / "ranksum.csv")
    assert set(tests["algorithm"]) == {"moead", "sms-emoa"} and set(tests["verdict"]) <= {"+", "-", "="}
    assert len(tests) == 2 * 3 * 5  # 2 algorithms x 3 problems x (igd, gd, gd_vv, hv, spacing)
    igd = (tmp_path / "igd.md").read_text()
    assert igd.count("**") == 2 * 3  # one best mean per problem
    assert "Wilcoxon rank-sum" in igd


def test_compare_means_gives_direction_relative_difference_and_the_rank_sum_p():
    from pymoo_rail.experiments.stats import compare_means, rank_sum

    better, rel, p = compare_means([1.0, 2.0, 3.0], [4.0, 5.0, 6.0])
    assert better and rel == pytest.approx(-60.0) and p == rank_sum([1.0, 2.0, 3.0], [4.0, 5.0, 6.0])[1]
    assert compare_means([1.0, 2.0, 3.0], [4.0, 5.0, 6.0], lower_better=False)[0] is False
    assert compare_means([1.0], [4.0, 5.0]) is None
    assert np.isnan(compare_means([1.0, 2.0], [-1.0, 1.0])[1])  # zero baseline mean: no relative difference


def test_raw_indicators_vanish_on_the_true_front_and_need_two_points_for_spread():
    from pymoo.problems import get_problem

    from pymoo_rail.experiments.metrics import raw_indicators

    pf = get_problem("zdt1").pareto_front(100)
    on = raw_indicators(pf, pf, np.array([1.1, 1.1]))
    assert on["gd"] == on["igd"] == on["gd_vv"] == 0.0 and 0.85 < on["hv"] < 0.88 and on["sp"] >= 0
    one = raw_indicators(pf[:1] + 0.1, pf, np.array([1.1, 1.1]))
    assert np.isnan(one["sp"]) and np.isnan(one["delta"]) and one["gd"] > 0.09
