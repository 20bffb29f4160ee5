"""Disturbed tracking (mass, adhesion, measurement noise, traction lag)."""

import numpy as np
import pytest

from pymoo_rail.cases import load_case
from pymoo_rail.control import PID, Disturbance, draw_disturbances, track, track_disturbed
from pymoo_rail.sim import Simulator


@pytest.fixture(scope="module")
def metro():
    case = load_case("metro-a")
    return case, Simulator(case).flat_out()


def test_nominal_disturbance_is_the_plain_tracker(metro):
    case, ref = metro
    a = track(case, ref, PID())
    b = track_disturbed(case, ref, PID(), Disturbance())
    np.testing.assert_array_equal(a.speed_ms, b.speed_ms)


def test_each_disturbance_changes_the_run_and_limits_hold(metro):
    case, ref = metro
    base = track(case, ref, PID())
    for d in (Disturbance(mass_factor=1.15), Disturbance(adhesion_factor=0.8), Disturbance(speed_noise_kmh=0.5),
              Disturbance(traction_lag_s=0.6)):
        tr = track_disturbed(case, ref, PID(), d)
        assert not np.array_equal(tr.speed_ms, base.speed_ms), d
        assert np.all(tr.speed_ms <= tr.limit_ms + 1e-6)
        s = tr.summary  # work balance from rest to rest
        assert s["traction_work_j"] - s["brake_work_j"] - s["davis_work_j"] - s["line_work_j"] == pytest.approx(
            0.0, abs=1e-6 * s["traction_work_j"])


def test_heavier_train_needs_more_energy(metro):
    case, ref = metro
    light = track_disturbed(case, ref, PID(), Disturbance(mass_factor=0.85))
    heavy = track_disturbed(case, ref, PID(), Disturbance(mass_factor=1.15))
    assert heavy.energy.net_kwh > light.energy.net_kwh


def test_draws_are_reproducible_and_in_range():
    a, b = draw_disturbances(5, seed=3), draw_disturbances(5, seed=3)
    assert a == b and a != draw_disturbances(5, seed=4)
    assert all(0.85 <= d.mass_factor <= 1.15 and 0.8 <= d.adhesion_factor <= 1.0 for d in a)
    with pytest.raises(ValueError, match="mass_factor"):
        Disturbance(mass_factor=0.0)
    with pytest.raises(ValueError, match="unknown keys"):
        draw_disturbances(2, 0, {"wind": (0, 1)})
