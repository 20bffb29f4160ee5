"""The braking-onset encoding: stop position as a consequence of the decision, both ways."""

import math
import warnings

import numpy as np
import pytest

from pymoo_rail.cases import load_case
from pymoo_rail.problems import ConstantObjectiveWarning, SpeedProfileProblem
from tests.conftest import make_case

# Flat, no resistance, 100 kN on 100 t: traction +1 m/s^2, so v^2 = 2 x at the onset (closed form).
FLAT = dict(train={"max_speed_kmh": 300.0}, line={"speed_limits": [[0.0, 2000.0, 300.0]]},
            run={"planned_time_s": 100.0})


def _flat(**kwargs):
    return SpeedProfileProblem(make_case(**FLAT), objectives=("energy", "stop_error"), encoding="braking_onset",
                               regimes=("traction",), stop_tolerance_m=None, **kwargs)


@pytest.mark.parametrize("onset_m, decel_ms2", [(990.0, 0.99), (1005.0, 0.995), (600.0, 0.8)])
def test_stop_position_is_onset_plus_braking_distance(onset_m, decel_ms2):
    p = _flat()
    tr = p.trajectory(np.array([onset_m, decel_ms2]))
    stop_m = onset_m + 2.0 * onset_m / (2.0 * decel_ms2)  # v^2 = 2 * 1.0 * onset
    assert tr.position_m[-1] == pytest.approx(stop_m, abs=1e-6)
    assert tr.stop_error_m == pytest.approx(abs(stop_m - 2000.0), abs=1e-6)
    s = tr.summary
    # work balance from rest to rest: traction = braking + resistance + line (all zero but braking here)
    assert s["traction_work_j"] - s["brake_work_j"] - s["davis_work_j"] - s["line_work_j"] == pytest.approx(
        0.0, abs=1e-6 * s["traction_work_j"])
    t_expected = math.sqrt(2 * onset_m) + math.sqrt(2 * onset_m) / decel_ms2
    assert tr.running_time_s == pytest.approx(t_expected, rel=1e-9)


def test_overshoot_beyond_the_overrun_zone_is_caught_by_the_envelope():
    p = _flat()
    tr = p.trajectory(np.array([1500.0, 0.6]))  # would stop at 4000 m
    assert tr.position_m[-1] == pytest.approx(2020.0)
    assert tr.stop_error_m == pytest.approx(20.0)
    assert np.all(tr.speed_ms <= tr.limit_ms + 1e-9)


def test_stop_error_varies_and_limits_hold_under_the_whole_train():
    case = load_case("metro-a")
    p = SpeedProfileProblem(case, objectives=("energy", "jerk", "stop_error", "time_error"), encoding="braking_onset")
    X = np.array([[400.0, 500.0, 780.0, 1.0], [400.0, 500.0, 800.0, 1.05], [300.0, 450.0, 700.0, 0.9]])
    out = p.evaluate(X, return_as_dictionary=True)
    assert np.ptp(out["F"][:, 2]) > 0.1
    for x in X:
        tr = p.trajectory(x)
        limit_kmh = np.array([case.line.limit_kmh_at(min(max(pos - d, 0.0), 999.999))
                              for pos in tr.position_m for d in (0.0, case.train.length_m)]).reshape(-1, 2).min(1)
        assert np.all(tr.speed_kmh <= limit_kmh + 1e-6)


def test_constant_objective_warning_names_it():
    case = load_case("metro-a")
    with pytest.warns(ConstantObjectiveWarning, match="stop_error"):
        SpeedProfileProblem(case, objectives=("energy", "jerk", "stop_error", "time_error"))
    with warnings.catch_warnings():
        warnings.simplefilter("error", ConstantObjectiveWarning)
        SpeedProfileProblem(case, objectives=("energy", "stop_error"), encoding="braking_onset")
        SpeedProfileProblem(case, objectives=("energy", "time_error"))


def test_bad_input():
    with pytest.raises(ValueError, match="decel_range_ms2"):
        _flat(decel_range_ms2=(0.0, 1.0))
    p = _flat()
    with pytest.raises(ValueError, match="-1.0"):
        p.evaluate(np.array([[500.0, -1.0]]))
    from pymoo_rail.sim import braking_programs

    with pytest.raises(ValueError, match="braking_decel_ms2"):
        braking_programs(np.array([[500.0]]), ("traction",), np.array([-1.0]), 2000.0)


def test_nsga2_front_has_a_live_stop_error_axis():
    # the done-when of the four-objective form: stop error spans >= 0.1 m, every axis is live
    from pymoo.algorithms.moo.nsga2 import NSGA2
    from pymoo.optimize import minimize

    p = SpeedProfileProblem(load_case("metro-a"), objectives=("energy", "jerk", "stop_error", "time_error"),
                            encoding="braking_onset")
    res = minimize(p, NSGA2(pop_size=40), ("n_gen", 60), seed=1)
    assert np.ptp(res.F[:, 2]) >= 0.1
    assert np.all(np.ptp(res.F, axis=0) > 0)
