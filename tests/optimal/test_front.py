"""The optimal front: decreasing and convex in the running time, bad input."""

import numpy as np
import pytest

from pymoo_rail.optimal import min_running_time, optimal_front


@pytest.fixture(scope="module")
def front(yizhuang):
    fastest = min_running_time(yizhuang)
    return optimal_front(yizhuang, np.linspace(1.02 * fastest, 1.5 * fastest, 6))


def test_columns_and_times(front):
    for column in ("running_time_s", "energy_kwh", "requested_time_s", "traction_kwh", "regen_kwh", "aux_kwh",
                   "lambda_kwh_per_s", "energy_at_request_kwh"):
        assert column in front.columns
    assert np.all(np.abs(front["running_time_s"] - front["requested_time_s"]) <= 0.5)
    assert np.all(np.isfinite(front.to_numpy(dtype=float)))
    # yizhuang: eta 1, no regeneration, no auxiliary power -> net = traction
    assert np.allclose(front["energy_kwh"], front["traction_kwh"])


def test_decreasing_and_convex(front):
    t = front["running_time_s"].to_numpy()
    e = front["energy_kwh"].to_numpy()
    assert np.all(np.diff(t) > 0)
    slopes = np.diff(e) / np.diff(t)
    assert np.all(slopes < 0)  # more time, less energy
    assert np.all(np.diff(slopes) > 0)  # convex: the saving per second shrinks
    # lambda, the slope at each point, lies between the chords on either side
    lam = front["lambda_kwh_per_s"].to_numpy()
    assert np.all(np.diff(lam) < 0)
    assert np.all(-slopes <= lam[:-1] * 1.05) and np.all(-slopes >= lam[1:] * 0.95)


def test_unsorted_times_come_back_sorted(yizhuang):
    f = optimal_front(yizhuang, [170.0, 150.0], n_speeds=100)
    assert list(f["requested_time_s"]) == [150.0, 170.0]


@pytest.mark.parametrize("times", [[150.0, float("nan")], [], [[150.0, 160.0]], [-1.0]])
def test_bad_times(yizhuang, times):
    with pytest.raises(ValueError, match="running_time"):
        optimal_front(yizhuang, times)


def test_time_below_the_minimum(yizhuang):
    with pytest.raises(ValueError, match="running_time_s.*minimum running time 129.26 s"):
        optimal_front(yizhuang, [125.0, 150.0])
