"""Friedman ranks and Holm-corrected pairwise signed-rank tests (stats.friedman_holm, stats.holm)."""

import numpy as np
import pandas as pd
import pytest

from pymoo_rail.experiments.stats import friedman_holm, holm


def _table(offsets, n_seeds=10, noise=0.1, seed=3):
    rng = np.random.default_rng(seed)
    return pd.DataFrame({name: offset + noise * rng.standard_normal(n_seeds) for name, offset in offsets.items()})


def test_holm_matches_a_hand_computed_case():
    # sorted 0.005, 0.01, 0.03, 0.04 -> x4, x3, x2, x1 = 0.02, 0.03, 0.06, 0.04 -> running max 0.06
    np.testing.assert_allclose(holm([0.01, 0.04, 0.03, 0.005]), [0.03, 0.06, 0.06, 0.02])


def test_holm_keeps_the_order_of_the_raw_p_values_and_caps_at_one():
    p = np.array([0.2, 0.001, 0.5, 0.04, 0.3])
    adjusted = holm(p)
    order = np.argsort(p)
    assert np.all(np.diff(adjusted[order]) >= 0)
    assert np.all(adjusted >= p) and np.all(adjusted <= 1)


def test_a_clear_winner_is_ranked_first_and_the_others_marked_worse():
    result = friedman_holm(_table({"a": 1.0, "b": 2.0, "c": 3.0}))
    assert result.best == "a"
    assert list(result.mean_ranks.index) == ["a", "b", "c"]
    np.testing.assert_allclose(result.mean_ranks.to_numpy(), [1, 2, 3])
    assert result.p_value < 1e-3
    assert result.mark("a") == "best" and result.mark("b") == "-" and result.mark("c") == "-"
    assert set(result.pairs["better"]) == {"a", "b"}  # a beats b and c, b beats c


def test_higher_is_better_reverses_the_ranks():
    result = friedman_holm(_table({"a": 1.0, "b": 2.0, "c": 3.0}), lower_better=False)
    assert result.best == "c" and result.mark("a") == "-"


def test_ties_share_ranks_and_nothing_is_significant():
    table = pd.DataFrame({"a": [1.0] * 6, "b": [1.0] * 6, "c": [1.0] * 6})
    result = friedman_holm(table)
    np.testing.assert_allclose(result.mean_ranks.to_numpy(), [2, 2, 2])
    assert result.p_value == 1.0
    assert (result.pairs["better"] == "").all()
    assert {result.mark(name) for name in "bc"} <= {"=", "best"}


def test_two_equal_algorithms_and_one_worse():
    table = _table({"a": 1.0, "b": 1.0, "c": 5.0}, n_seeds=12)
    result = friedman_holm(table)
    assert result.mark("c") == "-"
    other = "b" if result.best == "a" else "a"
    assert result.mark(other) == "="


def test_seeds_with_a_missing_value_are_dropped():
    table = _table({"a": 1.0, "b": 2.0, "c": 3.0})
    table.loc[0, "a"] = np.nan
    result = friedman_holm(table)
    assert result.best == "a"


@pytest.mark.parametrize("table, words", [(pd.DataFrame({"a": [1.0, 2.0]}), "at least 2"),
                                          (pd.DataFrame({"a": [1.0], "b": [2.0]}), "seed"),
                                          (pd.DataFrame({"a": [1.0, np.nan], "b": [np.nan, 2.0]}), "seed")])
def test_too_little_data_says_what_is_missing(table, words):
    with pytest.raises(ValueError, match=words):
        friedman_holm(table)


def test_bad_alpha_is_named():
    with pytest.raises(ValueError, match="alpha"):
        friedman_holm(_table({"a": 1.0, "b": 2.0}), alpha=1.5)


@pytest.mark.parametrize("n_seeds, significant", [(5, False), (9, False), (10, True)])
def test_seven_algorithms_need_ten_seeds_for_any_holm_mark(n_seeds, significant):
    # exact two-sided signed-rank p of n same-sign differences is 2 / 2**n; Holm multiplies the
    # smallest of the 21 pairs' p by 21: 21 * 2 / 2**9 = 0.082 > 0.05, 21 * 2 / 2**10 = 0.041 < 0.05
    table = _table({name: float(i) for i, name in enumerate("abcdefg")}, n_seeds=n_seeds, noise=0.01)
    result = friedman_holm(table)
    assert list(result.mean_ranks.index) == list("abcdefg")
    assert result.p_value < 1e-3  # Friedman sees the order at once
    assert (result.mark("g") == "-") is significant
