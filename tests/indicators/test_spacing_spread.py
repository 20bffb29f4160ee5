"""Spacing (Schott) and Spread (Deb) against values computed by hand."""

import numpy as np
import pytest
from pymoo.core.indicator import Indicator
from pymoo.indicators.spacing import SpacingIndicator

from pymoo_rail.indicators import Spacing, Spread


def line_front(n):
    f1 = np.linspace(0.0, 1.0, n)
    return np.column_stack([f1, 1.0 - f1])


def test_are_pymoo_indicators():
    assert isinstance(Spacing(), Indicator)
    assert isinstance(Spread(line_front(5)), Indicator)


def test_spacing_evenly_spaced_is_zero():
    assert Spacing()(line_front(7)) == pytest.approx(0.0, abs=1e-12)


def test_spacing_three_points_by_hand():
    # nearest L1 neighbours: d = (3, 3, 5), mean 11/3, squared deviations 4/9 + 4/9 + 16/9
    # = 24/9; Schott divides by n - 1 = 2 -> SP = sqrt(4/3)
    F = np.array([[0.0, 4.0], [1.0, 2.0], [4.0, 0.0]])
    assert Spacing()(F) == pytest.approx(np.sqrt(4.0 / 3.0), rel=1e-12)


def test_spacing_differs_from_pymoo_by_sqrt_n_over_n_minus_1():
    F = np.array([[0.0, 4.0], [1.0, 2.0], [4.0, 0.0]])
    assert SpacingIndicator()(F) == pytest.approx(np.sqrt(8.0 / 9.0), rel=1e-12)
    assert Spacing()(F) / SpacingIndicator()(F) == pytest.approx(np.sqrt(3.0 / 2.0), rel=1e-12)


def test_spacing_uses_city_block_distance():
    # L1 gaps are 2, 2, 2 although the Euclidean gaps differ (sqrt(2) vs 2)
    F = np.array([[0.0, 0.0], [1.0, 1.0], [2.0, 2.0], [4.0, 2.0]])
    assert Spacing()(F) == pytest.approx(0.0, abs=1e-12)


def test_spacing_normalised():
    F = np.array([[0.0, 40.0], [1.0, 20.0], [4.0, 0.0]])
    sp = Spacing(zero_to_one=True, ideal=np.array([0.0, 0.0]), nadir=np.array([4.0, 40.0]))
    # normalised points (0, 1), (0.25, 0.5), (1, 0): d = (0.75, 0.75, 1.25)
    d = np.array([0.75, 0.75, 1.25])
    assert sp(F) == pytest.approx(np.sqrt(np.sum((d - d.mean()) ** 2) / 2), rel=1e-12)


def test_spread_uniform_front_with_extremes_is_zero():
    pf = line_front(101)
    assert Spread(pf)(line_front(11)) == pytest.approx(0.0, abs=1e-12)


def test_spread_by_hand():
    # s = sqrt(0.02): d_f = s, d_l = 0, d = (s, 8 s), mean 4.5 s, sum |d - mean| = 7 s
    # Delta = (s + 7 s) / (s + 2 * 4.5 s) = 0.8
    F = np.array([[0.1, 0.9], [0.2, 0.8], [1.0, 0.0]])
    assert Spread(line_front(101))(F) == pytest.approx(0.8, rel=1e-12)


def test_spread_order_of_points_does_not_matter():
    F = np.array([[1.0, 0.0], [0.1, 0.9], [0.2, 0.8]])
    assert Spread(line_front(3))(F) == pytest.approx(0.8, rel=1e-12)


def test_spread_collapsed_set_is_one():
    # all points on one spot: d = 0, so Delta = (d_f + d_l) / (d_f + d_l) = 1
    F = np.array([[0.5, 0.5], [0.5, 0.5]])
    assert Spread(line_front(11))(F) == pytest.approx(1.0)


def test_generalized_spread_three_objectives():
    # the three unit vectors: the true-front extremes, pairwise distance sqrt(2) -> 0
    pf = np.eye(3)
    assert Spread(pf)(np.eye(3)) == pytest.approx(0.0, abs=1e-12)
    # drop the extreme (0, 0, 1), add the midpoint of the first two:
    # nearest distances (s/2, s/2, s/2) with s = sqrt(2) -> deviation 0;
    # extreme term: distance of (0, 0, 1) to its nearest point (0.5, 0.5, 0) = sqrt(1.5)
    F = np.array([[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.5, 0.5, 0.0]])
    s, e = np.sqrt(2.0), np.sqrt(1.5)
    assert Spread(pf)(F) == pytest.approx(e / (e + 3 * s / 2), rel=1e-12)


@pytest.mark.parametrize("ind", [Spacing(), Spread(line_front(5))])
def test_fewer_than_two_points(ind):
    with pytest.raises(ValueError, match="at least 2 points"):
        ind(np.array([[0.5, 0.5]]))
    with pytest.raises(ValueError, match="at least 2 points"):
        ind(np.empty((0, 2)))


@pytest.mark.parametrize("ind", [Spacing(), Spread(line_front(5))])
def test_nan_rejected(ind):
    with pytest.raises(ValueError, match="NaN"):
        ind(np.array([[0.0, 1.0], [np.nan, 0.5], [1.0, 0.0]]))


def test_spread_bad_reference():
    with pytest.raises(ValueError, match="pf"):
        Spread(np.array([[0.0, 1.0]]))
    with pytest.raises(ValueError, match="distinct"):
        Spread(np.array([[0.0, 1.0], [0.0, 1.0]]))
    with pytest.raises(ValueError, match="objectives"):
        Spread(line_front(5))(np.eye(3))
