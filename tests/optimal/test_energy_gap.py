"""energy_gap on hand-made fronts (pymoo_rail.indicators.energy)."""

import numpy as np
import pandas as pd
import pytest

from pymoo_rail.indicators.energy import energy_gap

# a convex, decreasing reference: (100 s, 10 kWh), (110 s, 6 kWh), (130 s, 4 kWh)
REFERENCE = pd.DataFrame({"running_time_s": [100.0, 110.0, 130.0], "energy_kwh": [10.0, 6.0, 4.0]})


def test_gaps_by_hand():
    front = np.array([[105.0, 8.8], [120.0, 5.5], [110.0, 6.0]])
    result = energy_gap(front, REFERENCE)
    points = result["points"]
    # the reference at 105 s is 8 kWh, at 120 s 5 kWh, at 110 s 6 kWh (linear between its points)
    assert np.allclose(points["optimal_kwh"], [8.0, 5.0, 6.0])
    assert np.allclose(points["gap_kwh"], [0.8, 0.5, 0.0])
    assert np.allclose(points["gap_rel"], [0.1, 0.1, 0.0])
    assert result["mean_gap_rel"] == pytest.approx(0.2 / 3)
    assert result["max_gap_rel"] == pytest.approx(0.1)
    assert result["min_gap_rel"] == pytest.approx(0.0)
    assert result["n_out_of_range"] == 0


def test_hypervolumes_by_hand():
    ref_point = (133.0, 10.6)
    front = np.array([[105.0, 8.8], [120.0, 5.5]])
    result = energy_gap(front, REFERENCE, ref_point=ref_point)
    # staircase of the two points: 28 x 1.8 + 13 x 3.3
    assert result["hv"] == pytest.approx(28 * 1.8 + 13 * 3.3)
    # area between the reference's polyline and the box: 10 s x (10.6 - 8) + 20 s x (10.6 - 5)
    # + the last point's rectangle 3 s x 6.6
    exact = 10 * 2.6 + 20 * 5.6 + 3 * 6.6
    assert result["hv_reference"] == pytest.approx(exact, rel=2e-3)
    assert result["hv_ratio"] == pytest.approx(result["hv"] / result["hv_reference"])
    assert 0.0 < result["hv_ratio"] < 1.0


def test_the_reference_itself_has_no_gap_and_full_hypervolume():
    t = np.linspace(100.0, 130.0, 3001)
    dense = np.column_stack([t, np.interp(t, REFERENCE["running_time_s"], REFERENCE["energy_kwh"])])
    result = energy_gap(dense, REFERENCE)
    assert np.allclose(result["points"]["gap_kwh"], 0.0, atol=1e-12)
    assert result["hv_ratio"] == pytest.approx(1.0, abs=2e-3)


def test_default_reference_point_and_dataframe_input():
    front = pd.DataFrame({"running_time_s": [105.0], "energy_kwh": [9.0], "other": [1]})
    result = energy_gap(front, REFERENCE.to_numpy())
    # largest time and energy of the reference plus 10 % of its ranges
    assert np.allclose(result["ref_point"], [133.0, 10.6])
    assert result["points"]["gap_kwh"].iloc[0] == pytest.approx(1.0)


def test_points_outside_the_reference_are_marked_not_invented():
    front = np.array([[95.0, 12.0], [140.0, 3.0], [120.0, 6.0]])
    result = energy_gap(front, REFERENCE)
    points = result["points"]
    assert list(points["in_range"]) == [False, False, True]
    assert points["gap_kwh"].isna().tolist() == [True, True, False]
    assert result["n_out_of_range"] == 2
    assert result["mean_gap_rel"] == pytest.approx(0.2)  # only the point in range counts


def test_a_single_point_as_a_flat_pair():
    result = energy_gap([110.0, 6.6], REFERENCE)
    assert result["points"]["gap_rel"].iloc[0] == pytest.approx(0.1)


@pytest.mark.parametrize("front, message", [
    (np.array([[100.0, np.nan]]), r"front\[0\] has energy_kwh = nan"),
    (np.array([[np.inf, 1.0]]), r"front\[0\] has running_time_s = inf"),
    (np.ones((2, 3)), "shape"),
    (np.empty((0, 2)), "shape"),
    (pd.DataFrame({"time": [1.0], "energy_kwh": [1.0]}), "running_time_s"),
])
def test_bad_fronts(front, message):
    with pytest.raises(ValueError, match=message):
        energy_gap(front, REFERENCE)


def test_bad_reference():
    with pytest.raises(ValueError, match="reference"):
        energy_gap([[110.0, 6.0]], [[110.0, 6.0]])
    with pytest.raises(ValueError, match="ref_point"):
        energy_gap([[110.0, 6.0]], REFERENCE, ref_point=(1.0, np.nan))
