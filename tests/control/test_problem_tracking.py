"""SpeedProfileProblem scored by tracked runs (seed 000 optimises the tracked curve)."""

import copy
import pickle

import numpy as np
import pytest
from pymoo.algorithms.soo.nonconvex.de import DE
from pymoo.optimize import minimize

from pymoo_rail.control import FuzzyPID, Hysteresis, Tracker, tracked_summaries
from pymoo_rail.problems import SpeedProfileProblem
from pymoo_rail.sim.kernel import OUT_NAMES, OUT_NET_KWH, OUT_RUNNING_TIME_S

X = np.array([[55, 80, 75, 70, 70, 66, 60, 55], [50, 70, 70, 60, 65, 60, 50, 50], [55, 80, 80, 80, 80, 80, 80, 55]],
             dtype=float)


def test_tracked_problem_scores_the_tracked_runs(yizhuang):
    ideal = SpeedProfileProblem(yizhuang, objectives=("energy", "running_time"))
    tracked = SpeedProfileProblem(yizhuang, objectives=("energy", "running_time"), tracking=Hysteresis(2.0, 4.0))
    f_ideal = ideal.evaluate(X, return_values_of=["F"])
    f_tracked = tracked.evaluate(X, return_values_of=["F"])
    programs = tracked.encoding.programs(X)
    s = tracked_summaries(yizhuang, programs, Hysteresis(2.0, 4.0))
    np.testing.assert_array_equal(f_tracked[:, 0], s[:, OUT_NET_KWH])
    np.testing.assert_array_equal(f_tracked[:, 1], s[:, OUT_RUNNING_TIME_S])
    # the band below the reference: the tracked runs are slower than the ideal ones
    assert np.all(f_tracked[:, 1] > f_ideal[:, 1])
    # trajectory(x) is the tracked run, with the same figures as the batch
    tr = tracked.trajectory(X[1])
    for i, name in enumerate(OUT_NAMES):
        assert tr.summary[name] == s[1, i], name
    assert "speed_error_rms_kmh" in tr.summary


def test_tracked_problem_pickles(yizhuang):
    p = SpeedProfileProblem(yizhuang, objectives=("energy",), time_tolerance_s=2.0, tracking=FuzzyPID())
    for clone in (pickle.loads(pickle.dumps(p)), copy.deepcopy(p)):
        np.testing.assert_array_equal(clone.evaluate(X, return_values_of=["F"]), p.evaluate(X, return_values_of=["F"]))


def test_bad_tracking_option(yizhuang):
    with pytest.raises(ValueError, match="controller"):
        SpeedProfileProblem(yizhuang, tracking="hysteresis")
    with pytest.raises(ValueError, match="'control_period_s' = 0.0"):
        SpeedProfileProblem(yizhuang, tracking=Hysteresis(2.0, 3.0), control_period_s=0.0)


def test_de_on_the_tracked_problem_stops_on_time(yizhuang):
    p = SpeedProfileProblem(yizhuang, objectives=("energy",), time_tolerance_s=1.0, tracking=Hysteresis(2.0, 3.0))
    res = minimize(p, DE(pop_size=30), ("n_gen", 25), seed=3)
    assert res.X is not None and np.all(res.G <= 0.0)
    tr = p.trajectory(res.X)
    assert tr.reached and tr.stop_error_m <= 0.25 and abs(tr.running_time_s - 150.0) <= 1.0
    # the tracked run of the optimum is what the problem scored
    assert tr.energy.net_kwh == pytest.approx(res.F[0])
    # and it is a real tracked run: the ideal run of the same codes differs
    ideal = Tracker(yizhuang, Hysteresis(2.0, 3.0)).simulator.run(p.encoding.programs(res.X[None, :])[0])
    assert ideal.running_time_s != pytest.approx(tr.running_time_s, abs=0.05)
