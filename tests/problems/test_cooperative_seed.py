"""CooperativeSeedProblem (Chen et al. 2017's encoding on the one kernel): physics, constraints, searches."""

import math
import pickle
from dataclasses import replace

import numpy as np
import pytest

from pymoo_rail.cases import load_case
from pymoo_rail.model import CaseError
from pymoo_rail.problems.cooperative import scale_gradients
from pymoo_rail.problems.cooperative_seed import (
    BrakingDistanceProblem,
    CooperativeSeedProblem,
    PartialProblem,
    alternating_minimize,
    comfort_and_braking,
    nested_minimize,
    train_genes,
)
from pymoo_rail.sim import Simulator
from pymoo_rail.sim.kernel import MODE_STOP, MODE_TOWARD, OUT_REACHED, OUT_RUNNING_TIME_S
from pymoo_rail.sim.pacing import PacedSubsections, solve_pace


@pytest.fixture(scope="module")
def pair():
    return load_case("cooperative-pair")


@pytest.fixture(scope="module")
def problem(pair):
    return CooperativeSeedProblem(pair, 45.0)


def _population(problem, n=24, seed=0):
    rng = np.random.default_rng(seed)
    return problem.xl + rng.random((n, problem.n_var)) * (problem.xu - problem.xl)


@pytest.fixture(scope="module")
def evaluated(problem):
    X = _population(problem)
    return X, problem.evaluate(X, return_as_dictionary=True)


def _flat(pair):
    """The pair on level track without running resistance."""
    return replace(pair, train=replace(pair.train, resistance=replace(pair.train.resistance, a=0.0, b=0.0, c=0.0)),
                   line=replace(pair.line, gradients=((0.0, pair.line.length_m, 0.0),)))


# ---------------------------------------------------------------------- set-up from the paper
def test_subsections_follow_the_gradient_changes(problem):
    a, b = (tr.encoding for tr in problem.trains)
    # leg 0 changes gradient at 200, 700, 950, 1650, 1750, 2450 m; leg 1 at 250, 600, 660, 1210 m
    np.testing.assert_allclose(a.boundaries_m[:-1], [0, 200, 700, 950, 1650, 1750, 2450])
    np.testing.assert_allclose(b.boundaries_m[:-1], [0, 250, 600, 660, 1210])
    # the -16 and -14 permille descents are type 3: coasting accelerates even at 80 km/h
    # (W0(22.2 m/s) = 18.2 kN < 16e-3 * 280 t * g = 43.9 kN); level track and climbs are type 2
    assert a.descent[3] and b.descent[1]
    assert not (a.descent[0] or a.descent[1] or a.descent[5] or b.descent[0] or b.descent[3])
    # braking range: r * v_lim^2 / (2 b) = 1.5 * (80 / 3.6)^2 / 2 = 370.4 m (section 3.2)
    assert a.brake_bounds_m[1] == pytest.approx(1.5 * (80 / 3.6) ** 2 / 2.0)
    assert problem.n_var == 2 + 3 * (7 + 5)
    np.testing.assert_array_equal(problem.brake_columns, [0, 1 + 3 * 7])
    assert problem.variable_names[:4] == ("brake_a_m", "gamma_a1", "turn_a1", "last_a1")


# ---------------------------------------------------------------------- physics of the rows
def test_every_vector_is_on_time_and_stops_at_the_platform(problem, evaluated):
    X, out = evaluated
    assert np.all(out["G"][:, 1] <= 0)  # the time guard
    # to 0.02 s, except where the pace moves a row's end across a grid cell (a step of a few cm/v)
    for key, plan in (("running_time_a_s", 190.0), ("running_time_b_s", 100.0)):
        err = np.abs(out[key] - plan)
        assert np.median(err) <= 0.02 and err.max() <= 0.2
    sol = problem.decode(X[0])
    for tr in (sol.a, sol.b):
        s = tr.summary
        assert s["reached"] == 1.0 and tr.speed_ms[-1] == 0.0
        assert np.all(tr.speed_ms <= tr.limit_ms + 1e-9)
        # traction - braking = resistance + line work, from rest to rest, to rounding
        residual = s["traction_work_j"] - s["brake_work_j"] - s["davis_work_j"] - s["line_work_j"]
        assert abs(residual) < 1e-9 * s["traction_work_j"]


def test_traction_share_scales_the_force(pair):
    # level, no resistance: traction at gamma * 280 kN accelerates 280 t at gamma m/s^2
    sim = Simulator(_flat(pair).leg(0))
    enc = PacedSubsections.build(sim)
    genes = np.concatenate([[250.0], np.tile([0.5, 1.0, 0.0], enc.n_sub)])
    program = enc.programs(genes[None, :], np.array([0.0]))[0]
    assert program.shape == (2 * enc.n_sub + 1, 4) and program[0, 1] == MODE_TOWARD and program[0, 3] == 0.5
    tr = sim.run(program)
    i = int(np.searchsorted(tr.position_m, 100.0))
    assert tr.speed_ms[i] == pytest.approx(math.sqrt(2 * 0.5 * 100.0), rel=1e-3)
    assert tr.time_s[i] == pytest.approx(math.sqrt(2 * 100.0 / 0.5), rel=1e-3)


def test_braking_phase_is_one_constant_deceleration_onto_the_platform(pair):
    sim = Simulator(pair.leg(1))
    enc = PacedSubsections.build(sim)
    genes = np.concatenate([[300.0], np.tile([0.8, 0.7, 0.1], enc.n_sub)])
    program = enc.programs(genes[None, :], np.array([0.0]))[0]
    assert program[-1, 1] == MODE_STOP
    tr = sim.run(program)
    x_p = enc.length_m - 300.0
    i_p = int(round(x_p / sim.model.dx_m))
    v_m = tr.speed_ms[i_p]
    # v^2 falls linearly to zero over dS (eq. 3), in 2 dS / v_m
    rest = tr.position_m[i_p:] - x_p
    np.testing.assert_allclose(tr.speed_ms[i_p:] ** 2, v_m ** 2 * (1 - rest / 300.0), atol=1e-6 * v_m ** 2)
    assert tr.time_s[-1] - tr.time_s[i_p] == pytest.approx(2 * 300.0 / v_m, rel=1e-6)
    assert tr.reached and tr.stop_error_m < 1e-6
    _, decel = comfort_and_braking(enc, genes, tr.position_m, tr.speed_ms, sim.model.dx_m)
    assert decel == pytest.approx(v_m ** 2 / 600.0)


def test_pace_meets_the_plan_and_time_falls_with_the_pace(pair):
    sim = Simulator(pair.leg(0))
    enc = PacedSubsections.build(sim)
    rng = np.random.default_rng(3)
    genes = enc.xl + rng.random((6, enc.n_var)) * (enc.xu - enc.xl)
    genes[:, 1::3] = 0.05  # tiny traction shares: only paces above 1 (gamma raised) make the plan
    runs = solve_pace(sim, enc, genes)
    np.testing.assert_allclose(runs.running_time_s, 190.0, atol=0.2)
    assert np.all(runs.pace > 1.0)
    out = [sim.run_batch(enc.programs(genes[:1], np.array([p])))[0] for p in (0.5, 1.0, 1.25, 1.5, 2.0)]
    times = [o[OUT_RUNNING_TIME_S] if o[OUT_REACHED] else np.inf for o in out]  # a stalled run never arrives
    assert all(a >= b for a, b in zip(times, times[1:])) and np.isfinite(times[-1])


def test_comfort_measures_the_acceleration_change_at_a_gradient_change(pair):
    # a trace with v^2 rising at 2 * 0.2 m/s^2 before the 200 m change and 2 * 1.1 m/s^2 after it
    enc = PacedSubsections.build(Simulator(pair.leg(0)))
    x = np.arange(0.0, enc.length_m + 0.5)
    u = np.where(x < 200, 100 + 0.4 * x, 100 + 80 + 2.2 * (x - 200))
    genes = np.concatenate([[300.0], np.zeros(3 * enc.n_sub)])
    change, _ = comfort_and_braking(enc, genes, x, np.sqrt(u), 1.0)
    assert change == pytest.approx(0.9)


# ---------------------------------------------------------------------- sharing and constraints
@pytest.mark.parametrize("offset_s", [-1000.0, 1000.0])
def test_no_energy_is_shared_when_the_runs_do_not_overlap(pair, offset_s):
    p = CooperativeSeedProblem(pair, offset_s)
    out = p.evaluate(_population(p, 8), return_as_dictionary=True)
    assert np.all(out["shared_kwh"] == 0.0)
    np.testing.assert_array_equal(out["F"][:, 0], out["traction_a_kwh"] + out["traction_b_kwh"])


def test_shared_energy_is_bounded_and_some_is_shared(problem, evaluated):
    X, out = evaluated
    assert np.all(out["shared_kwh"] >= 0.0) and out["shared_kwh"].sum() > 0.0
    np.testing.assert_allclose(out["F"][:, 0], out["traction_a_kwh"] + out["traction_b_kwh"] - out["shared_kwh"])
    frame = problem.power_profiles(X[:1])
    assert frame["shared_kw"].sum() * problem.time_step_s / 3600 == pytest.approx(out["shared_kwh"][0], rel=1e-9)


def test_separation_is_enforced(pair):
    # B still stands at station 2 when A arrives there (x = 200 s > 190 s): short by L_t + L_s = 180 m
    blocked = CooperativeSeedProblem(pair, 200.0)
    g = blocked.evaluate(_population(blocked, 4), return_as_dictionary=True)["G"]
    assert np.all(g[:, 0] >= 180.0 - 1e-6)


def test_vectorised_and_row_by_row_evaluation_agree(problem):
    X = _population(problem, 6, seed=5)
    together = problem.evaluate(X, return_as_dictionary=True)
    for i in range(X.shape[0]):
        alone = problem.evaluate(X[i:i + 1], return_as_dictionary=True)
        np.testing.assert_allclose(alone["F"][0], together["F"][i], rtol=1e-12)


def test_pickling_keeps_the_problem(problem):
    X = _population(problem, 4)
    copy = pickle.loads(pickle.dumps(problem))
    np.testing.assert_array_equal(copy.evaluate(X, return_values_of=["F"]), problem.evaluate(X, return_values_of=["F"]))


def test_gradient_scaling_leaves_no_steep_descent(pair):
    p = CooperativeSeedProblem(scale_gradients(pair, 0.0), 45.0)
    assert not any(tr.encoding.descent.any() for tr in p.trains)


# ---------------------------------------------------------------------- searches
def test_nested_ga_is_a_composition_of_pymoo_runs(problem):
    from pymoo.algorithms.soo.nonconvex.ga import GA

    kwargs = dict(outer_pop_size=3, outer_n_gen=1, inner_algorithm=GA(pop_size=6), inner_n_gen=2, seed=7)
    x1, f1, res = nested_minimize(problem, **kwargs)
    x2, f2, _ = nested_minimize(problem, **kwargs)
    assert x1.shape == (problem.n_var,)
    np.testing.assert_array_equal(x1, x2)  # randomness only from the seeded random_state
    assert isinstance(res.problem, BrakingDistanceProblem)
    assert problem.evaluate(x1[None, :], return_values_of=["F"])[0, 0] == pytest.approx(f1)


def test_partial_problem_and_alternating_search(problem):
    x0 = _population(problem, 1, seed=9)[0]
    free = train_genes(problem, 1)
    assert free.sum() == 1 + 3 * 5 and free[problem.brake_columns[1]] and not free[0]
    part = PartialProblem(problem, free, x0)
    np.testing.assert_array_equal(part.full(x0[free])[0], x0)
    f0 = problem.evaluate(x0[None, :], return_values_of=["F"])[0, 0]
    x1, f1 = alternating_minimize(problem, x0, rounds=1, n_evals=(24, 24), pop_size=6, seed=4)
    assert f1 <= f0 + 1e-12
    assert problem.evaluate(x1[None, :], return_values_of=["F"])[0, 0] == pytest.approx(f1)


# ---------------------------------------------------------------------- bad input
def test_bad_input_names_the_field_and_value(pair, yizhuang):
    with pytest.raises(ValueError, match=r"offset_s = nan"):
        CooperativeSeedProblem(pair, float("nan"))
    with pytest.raises(ValueError, match=r"max_accel_change_ms2 = -1"):
        CooperativeSeedProblem(pair, 0.0, max_accel_change_ms2=-1.0)
    with pytest.raises(CaseError, match=r"run\.legs.*0 legs"):
        CooperativeSeedProblem(yizhuang, 45.0)


@pytest.mark.parametrize("name", ["de", "nsga2"])
def test_de_and_nsga2_work_unchanged(problem, name):
    from pymoo.algorithms.moo.nsga2 import NSGA2
    from pymoo.algorithms.soo.nonconvex.de import DE
    from pymoo.optimize import minimize

    algorithm = DE(pop_size=6) if name == "de" else NSGA2(pop_size=6)
    res = minimize(problem, algorithm, ("n_eval", 12), seed=1)
    assert res.pop.get("F").shape == (6, 1) and np.all(res.pop.get("G")[:, 1] <= 0)
