"""SpeedProfileProblem: objectives against hand-computed runs, forms, encodings, pickling, bad input."""

import copy
import math
import pickle

import numpy as np
import pytest
from pymoo.algorithms.moo.nsga2 import NSGA2
from pymoo.algorithms.soo.nonconvex.de import DE
from pymoo.optimize import minimize

from pymoo_rail.model import InfeasibleCaseError
from pymoo_rail.problems import SEED_002_WEIGHTS, DecisionError, SpeedProfileProblem
from tests.conftest import make_case

# A flat line, no resistance, 100 kN traction and braking on 100 t: a = +-1 m/s^2 (closed form).
FLAT = dict(train={"max_speed_kmh": 300.0}, line={"speed_limits": [[0.0, 2000.0, 300.0]]},
            run={"planned_time_s": 100.0})


def _flat_problem(**kwargs):
    kwargs.setdefault("encoding", "switching_points")
    kwargs.setdefault("regimes", ("traction", "brake"))
    return SpeedProfileProblem(make_case(**FLAT), **kwargs)


def test_objectives_against_a_hand_computed_run():
    # traction to 600 m then full braking: stops at 1200 m, 800 m short of the platform
    p = _flat_problem(objectives=("energy", "running_time", "time_error", "jerk", "stop_error"),
                      stop_tolerance_m=None)
    out = p.evaluate(np.array([[600.0]]), return_as_dictionary=True)
    energy_kwh = 100e3 * 600.0 / 3.6e6
    t_run = 2 * math.sqrt(2 * 600.0 / 1.0)
    jerk = 1.0 + 2.0 + 1.0  # 0 -> +1 -> -1 -> 0 m/s^2
    expected = [energy_kwh, t_run, abs(t_run - 100.0), jerk, 800.0]
    np.testing.assert_allclose(out["F"][0], expected, rtol=1e-9, atol=1e-6)


def test_objective_order_follows_the_request():
    p1 = _flat_problem(objectives=("energy", "stop_error"), stop_tolerance_m=None)
    p2 = _flat_problem(objectives=("stop_error", "energy"), stop_tolerance_m=None)
    x = np.array([[500.0], [900.0]])
    np.testing.assert_array_equal(p1.evaluate(x, return_values_of=["F"])[:, ::-1], p2.evaluate(x, return_values_of=["F"]))


def test_stop_constraint_and_no_nan_for_infeasible_decisions():
    p = _flat_problem(objectives=("energy",))
    out = p.evaluate(np.array([[300.0], [1000.0], [1900.0]]), return_as_dictionary=True)
    g_stop = out["G"][:, 1]
    assert g_stop[0] > 0                      # braked too early: stops 1400 m short
    assert g_stop[1] <= 0 and g_stop[2] <= 0  # late braking: the envelope stops it on the platform
    assert np.all(np.isfinite(out["F"])) and np.all(np.isfinite(out["G"]))


def test_constrained_single_objective_form(yizhuang):
    p = SpeedProfileProblem(yizhuang, objectives=("energy",), time_tolerance_s=2.0)
    assert p.n_obj == 1 and p.n_ieq_constr == 3
    X = np.array([[55, 80, 80, 80, 80, 80, 80, 55], [40, 60, 60, 60, 60, 60, 40, 40]], dtype=float)
    out = p.evaluate(X, return_as_dictionary=True)
    t = out["running_time_s"]
    np.testing.assert_allclose(out["G"][:, 2], np.abs(t - 150.0) - 2.0)
    np.testing.assert_allclose(out["F"][:, 0], out["energy_kwh"])


def test_weighted_sum_of_seed_002(yizhuang):
    names = tuple(SEED_002_WEIGHTS)
    weights = [SEED_002_WEIGHTS[n] for n in names]
    pw = SpeedProfileProblem(yizhuang, objectives=names, weights=weights)
    pp = SpeedProfileProblem(yizhuang, objectives=names)
    assert pw.n_obj == 1 and math.isclose(sum(weights), 1.0)
    X = np.array([[50, 70, 70, 60, 70, 60, 30, 40], [30, 50, 50, 50, 50, 50, 30, 30]], dtype=float)
    raw = pp.evaluate(X, return_values_of=["F"])
    fastest = pw.simulator.flat_out()
    scales = np.array([fastest.energy.net_kwh, fastest.jerk_ms2, 0.25, 0.05 * 150.0])
    np.testing.assert_allclose(pw.evaluate(X, return_values_of=["F"])[:, 0], (raw / scales) @ np.array(weights), rtol=1e-12)


def test_speed_code_bounds_follow_the_limits(yizhuang):
    p = SpeedProfileProblem(yizhuang)
    np.testing.assert_array_equal(p.encoding.boundaries_m, [0, 130, 248, 568, 938, 1378, 2058, 2155, 2265])
    np.testing.assert_array_equal(p.xu, [55, 80, 80, 80, 80, 80, 80, 55])
    np.testing.assert_array_equal(p.xl, np.full(8, 10.0))
    eq = SpeedProfileProblem(yizhuang, partition="equal", n_sections=30)  # 75.5 m sections
    assert eq.n_var == 30 and eq.xu[0] == 55.0 and eq.xu[-1] == 55.0 and eq.xu[1] == 80.0
    fine = SpeedProfileProblem(yizhuang, max_section_m=100.0)
    assert np.all(np.diff(fine.encoding.boundaries_m) <= 100.0 + 1e-9)


def test_neutral_section_genes_are_fixed():
    case = make_case(line={"neutral_sections": [[800.0, 1100.0]]})
    p = SpeedProfileProblem(case, objectives=("energy", "running_time"))
    fixed = p.encoding.fixed()
    assert fixed.sum() == 1
    k = int(np.flatnonzero(fixed)[0])
    assert tuple(p.encoding.boundaries_m[k:k + 2]) == (800.0, 1100.0)


@pytest.mark.parametrize("encoding", ["speed_codes", "switching_points"])
def test_pickle_deepcopy_and_population_size(yizhuang, encoding):
    p = SpeedProfileProblem(yizhuang, encoding=encoding)
    rng = np.random.default_rng(0)
    X = p.xl + rng.random((30, p.n_var)) * (p.xu - p.xl)
    F = p.evaluate(X, return_values_of=["F"])
    for clone in (pickle.loads(pickle.dumps(p)), copy.deepcopy(p)):
        np.testing.assert_array_equal(clone.evaluate(X, return_values_of=["F"]), F)
    # one at a time (an elementwise evaluation) gives the same as the whole population
    single = np.vstack([p.evaluate(X[i:i + 1], return_values_of=["F"]) for i in range(X.shape[0])])
    np.testing.assert_array_equal(single, F)


def test_trajectory_matches_evaluation(yizhuang):
    p = SpeedProfileProblem(yizhuang, objectives=("energy", "running_time", "stop_error"))
    x = np.array([50, 75, 70, 60, 75, 65, 30, 45], dtype=float)
    tr = p.trajectory(x)
    F = p.evaluate(x[None, :], return_values_of=["F"])[0]
    assert F.tolist() == [tr.energy.net_kwh, tr.running_time_s, tr.stop_error_m]


@pytest.mark.parametrize("kwargs,match", [
    (dict(objectives=("energy", "speed")), "objective 'speed' is unknown"),
    (dict(objectives=()), "at least one objective"),
    (dict(objectives=("energy", "energy")), "repeats"),
    (dict(encoding="bitstring"), "encoding = 'bitstring'"),
    (dict(partition="random"), "partition = 'random'"),
    (dict(time_tolerance_s=-1.0), "time_tolerance_s = -1.0"),
    (dict(objectives=("energy", "time_error"), weights=[1.0]), "weights"),
    (dict(objectives=("energy", "time_error"), weights=[1.0, math.nan]), "weights"),
    (dict(stop_tolerance_m=0.0), "stop_tolerance_m = 0.0"),
])
def test_bad_arguments(yizhuang, kwargs, match):
    with pytest.raises(ValueError, match=match):
        SpeedProfileProblem(yizhuang, **kwargs)


def test_nan_decision_vector_names_the_row_and_entry(yizhuang):
    p = SpeedProfileProblem(yizhuang)
    X = np.full((6, 8), 50.0)
    X[2, 5] = np.nan
    X[4, 1] = np.inf
    with pytest.raises(DecisionError, match=r"decision row 2, variable 5 = nan km/h is not a finite number") as raised:
        p.evaluate(X)
    assert raised.value.rows == [2, 4] and "2 of 6 rows" in str(raised.value)
    good = np.delete(X, raised.value.rows, axis=0)  # what a caller can do with the rows it is told
    assert np.all(np.isfinite(p.evaluate(good)))
    with pytest.raises(ValueError, match="n_var = 8"):
        p.summaries(np.ones((2, 5)))


def test_out_of_bound_decisions_are_refused_not_clipped(yizhuang):
    p = SpeedProfileProblem(yizhuang)
    X = np.tile(p.xu, (3, 1))
    X[1, 3] = p.xu[3] + 1.0
    with pytest.raises(DecisionError, match=rf"row 1, variable 3 = {float(p.xu[3]) + 1.0!r} km/h is outside its bounds"):
        p.evaluate(X)
    with pytest.raises(DecisionError, match="outside its bounds"):
        p.trajectory(X[1])
    p.evaluate(np.tile(p.xl, (2, 1)))  # the bounds themselves are fine


def test_a_negative_speed_code_is_reported_in_kmh(yizhuang):
    p = SpeedProfileProblem(yizhuang)
    X = np.full((1, 8), 50.0)
    X[0, 2] = -36.0
    with pytest.raises(DecisionError, match="= -36.0 km/h"):
        p.evaluate(X)
    with pytest.raises(ValueError, match=r"speed_codes\[0, 2\] = -36.0 km/h"):  # the encoding alone
        p.encoding.programs(X)


def test_impossible_planned_time(yizhuang):
    with pytest.raises(InfeasibleCaseError, match="planned_time_s"):
        SpeedProfileProblem(yizhuang.with_planned_time(100.0), objectives=("energy", "time_error"))


def test_nsga2_front_on_yizhuang_is_drivable(yizhuang):
    # issue 3, done-when: every front trajectory under every limit and within 0.3 m of the platform
    problem = SpeedProfileProblem(yizhuang, objectives=("energy", "time_error"))
    res = minimize(problem, NSGA2(pop_size=40), ("n_gen", 100), seed=1)
    assert res.X.shape[0] >= 5
    limits = yizhuang.line.speed_limits
    for x in res.X:
        tr = problem.trajectory(x)
        assert tr.stop_error_m <= 0.3 and tr.reached
        for pos, v in zip(tr.position_m[::5], tr.speed_ms[::5]):
            lim = min(l for s, e, l in limits if s <= pos and e > pos - 140.0)  # tail past e: limit lifted
            assert v * 3.6 <= lim + 1e-6
    # the front reaches the planned time and trades energy for it
    assert res.F[:, 1].min() < 1.0
    assert res.F[:, 0].min() < res.F[np.argmin(res.F[:, 1]), 0]


def test_de_constrained_yizhuang_within_a_second(yizhuang):
    problem = SpeedProfileProblem(yizhuang, objectives=("energy",), time_tolerance_s=1.0)
    res = minimize(problem, DE(pop_size=40), ("n_evals", 4000), seed=1)
    tr = problem.trajectory(res.X)
    assert abs(tr.running_time_s - 150.0) <= 1.0 and tr.stop_error_m <= 0.25
    # it saves energy against the flat-out run
    assert tr.energy.net_kwh < 0.8 * problem.simulator.flat_out().energy.net_kwh


@pytest.mark.parametrize("name,planned_s", [("metro-a", 70.0), ("wuguang-crh3", 1050.0)])
def test_de_constrained_other_cases(name, planned_s):
    from pymoo_rail.cases import load_case

    case = load_case(name)
    assert case.planned_time_s == planned_s
    problem = SpeedProfileProblem(case, objectives=("energy",), time_tolerance_s=1.0)
    res = minimize(problem, DE(pop_size=40), ("n_evals", 4000), seed=1)
    tr = problem.trajectory(res.X)
    assert abs(tr.running_time_s - planned_s) <= 1.0 and tr.reached
    # no traction in a neutral section (seed 003): check the trace itself, not just the counter
    for start, end in case.line.neutral_sections:
        inside = (tr.position_m >= start) & (tr.position_m < end)
        assert inside.any() and np.all(tr.force_n[inside] <= 0.0)
    assert tr.summary["neutral_traction_j"] == 0.0


def test_switching_points_with_hold_brake_hold_the_speed_down_a_descent():
    """``regimes`` may use "hold_brake": the problem's F, the trajectory and the simulator agree,
    and down the descent the held run brakes (regenerating) where "hold" coasts faster."""
    case = make_case(
        train={"regen_efficiency": 0.8, "braking": {"max_force_kn": 100.0, "regen_max_force_kn": 60.0}},
        line={"length_m": 5000.0, "speed_limits": [[0.0, 5000.0, 100.0]],
              "gradients": [[0.0, 2000.0, 0.0], [2000.0, 4000.0, -20.0], [4000.0, 5000.0, 0.0]]},
        run={"planned_time_s": 300.0})
    x = np.array([[180.0, 5000.0]])
    runs = {}
    for hold in ("hold", "hold_brake"):
        problem = SpeedProfileProblem(case, objectives=("energy", "running_time"), encoding="switching_points",
                                      regimes=("traction", hold, "brake"))
        out = problem.evaluate(x, return_as_dictionary=True)
        runs[hold] = problem.trajectory(x[0])
        assert out["F"][0, 0] == pytest.approx(runs[hold].energy.net_kwh)
        assert out["F"][0, 1] == pytest.approx(runs[hold].running_time_s)
        assert np.all(out["G"][0] <= 0.0)  # stopped at the platform, under every limit
    down = (runs["hold_brake"].position_m > 2200.0) & (runs["hold_brake"].position_m < 3900.0)
    assert np.ptp(runs["hold_brake"].speed_ms[down]) < 1e-9 and np.all(runs["hold_brake"].force_n[down] < 0.0)
    assert runs["hold"].speed_ms[down].max() > runs["hold_brake"].speed_ms[down].max() + 5.0
    assert runs["hold_brake"].energy.regen_kwh > runs["hold"].energy.regen_kwh


def test_decisions_are_reported_in_each_variables_unit(yizhuang):
    p = SpeedProfileProblem(yizhuang, objectives=("energy", "stop_error"), encoding="braking_onset")
    X = np.tile(p.xl, (2, 1))
    X[1, -1] = p.xu[-1] + 4.0  # the service deceleration
    with pytest.raises(DecisionError, match=rf"row 1, variable {p.n_var - 1} = .* m/s\^2 is outside"):
        p.evaluate(X)
    X[1, -1], X[1, 0] = p.xu[-1], -1.0  # a switching position
    with pytest.raises(DecisionError, match=r"row 1, variable 0 = -1.0 m is outside"):
        p.evaluate(X)
