"""CooperativeSeedProblem (seed 001): shared energy, separation, punctuality, physics, bad input."""

import math
import pickle
from dataclasses import replace

import numpy as np
import pytest
from pymoo.algorithms.soo.nonconvex.de import DE
from pymoo.core.evaluator import Evaluator
from pymoo.core.population import Population
from pymoo.optimize import minimize

from pymoo_rail.cases import load_case
from pymoo_rail.model import CaseError
from pymoo_rail.problems.cooperative import scale_gradients
from pymoo_rail.problems.cooperative_seed import (
    BrakingDistanceProblem,
    CooperativeSeedProblem,
    PartialProblem,
    PunctualityRepair,
    SubsectionProblem,
    alternating_minimize,
    clocked_pair,
    nested_minimize,
    train_genes,
)
from pymoo_rail.sim import cooperation as coop

J_PER_KWH = 3.6e6


@pytest.fixture(scope="module")
def pair():
    return load_case("cooperative-pair")


@pytest.fixture(scope="module")
def problem(pair):
    return CooperativeSeedProblem(pair, 45.0)


@pytest.fixture(scope="module")
def absolute(pair):
    return CooperativeSeedProblem(pair, 45.0, speed_genes="absolute")


def _vector(problem, brake_a, brake_b, genes_a, genes_b):
    """A decision vector from (gamma, v_kmh, q) per subsection of A and of B."""
    x = [brake_a, brake_b]
    for gamma, v_kmh, q in list(genes_a) + list(genes_b):
        x += [gamma, v_kmh, q]
    x = np.asarray(x, dtype=float)
    assert x.shape == (problem.n_var,)
    return x


# Plausible hand-made driving strategies of both trains (7 subsections of A, 5 of B), as
# (gamma, exit speed, time share): exit speeds in km/h for speed_genes="absolute", and as positions
# in the reachable range for the default relative genes.
GENES_A = [(0.7, 55, 1), (0.7, 65, 1), (0.5, 60, 1), (0.5, 70, 1), (0.5, 70, 1), (0.6, 60, 1), (0.5, 55, 1)]
GENES_B = [(0.7, 55, 1), (0.5, 65, 1), (0.5, 65, 1), (0.6, 60, 1), (0.5, 55, 1)]
REL_A = [(0.7, 0.8, 1), (0.7, 0.6, 0.5), (0.5, 0.3, 1), (0.5, 0.7, 1), (0.5, 0.5, 1), (0.6, 0.4, 1), (0.5, 0.3, 1)]
REL_B = [(0.7, 0.8, 1), (0.5, 0.6, 1), (0.5, 0.5, 1), (0.6, 0.4, 0.5), (0.5, 0.3, 1)]


def _population(problem, n=60, seed=0):
    rng = np.random.default_rng(seed)
    return problem.xl + rng.random((n, problem.n_var)) * (problem.xu - problem.xl)


@pytest.fixture(scope="module")
def optimised(problem):
    """A short DE run with the seed's repair: its final population holds feasible solutions."""
    return minimize(problem, DE(pop_size=40, repair=PunctualityRepair()), ("n_gen", 15), seed=3)


# ---------------------------------------------------------------------- set-up from the seed
def test_subsections_follow_the_gradient_changes(problem, pair):
    a, b = problem.trains
    # leg 0 changes gradient at 200, 700, 950, 1650, 1750, 2450 m; leg 1 at 250, 600, 660, 1210 m
    np.testing.assert_allclose(a.model.position_m[a.sub_start], [0, 200, 700, 950, 1650, 1750, 2450])
    np.testing.assert_allclose(b.model.position_m[b.sub_start], [0, 250, 600, 660, 1210])
    # the -16 and -14 permille descents are type 3: coasting accelerates even at 80 km/h
    # (W0(22.2 m/s) = 18.2 kN < 16e-3 * 280 t * g = 43.9 kN)
    assert a.sub_kind[3] == 3 and b.sub_kind[1] == 3
    # level track and climbs are type 2
    assert a.sub_kind[0] == a.sub_kind[1] == a.sub_kind[5] == 2
    assert b.sub_kind[0] == b.sub_kind[3] == 2
    # braking range: r * v_lim^2 / (2 b) = 1.5 * (80 / 3.6)^2 / 2 = 370.4 m (section 3.2)
    assert a.brake_bounds_m[1] == pytest.approx(1.5 * (80 / 3.6) ** 2 / 2.0)
    assert problem.n_var == 2 + 3 * (7 + 5)


@pytest.mark.parametrize("encoding", ["relative", "absolute"])
def test_work_balance_and_planned_time(problem, absolute, encoding):
    p = problem if encoding == "relative" else absolute
    genes = (REL_A, REL_B) if encoding == "relative" else (GENES_A, GENES_B)
    sol = p.decode(_vector(p, 250, 200, *genes))
    for run in (sol.a, sol.b):
        s = run.summary
        # traction work - braking work = resistance work + line work (from rest to rest); coasting
        # cells carry exactly zero force over speeds from the two-stage integration: 1e-4 relative
        residual = s["traction_work_j"] - s["brake_work_j"] - s["davis_work_j"] - s["line_work_j"]
        assert abs(residual) < 1e-4 * s["traction_work_j"]
        tr = run.trajectory
        assert tr.speed_ms[-1] == 0.0 and tr.position_m[-1] == pytest.approx(run.trajectory.position_m[-1])
        assert np.all(tr.speed_ms <= tr.limit_ms + 1e-9)
        # constant-deceleration braking from v_m over dS takes 2 dS / v_m (eq. 1)
        brake_len = tr.position_m[-1] - s["brake_start_m"]
        i_p = int(np.searchsorted(tr.position_m, s["brake_start_m"]))
        assert tr.time_s[-1] - tr.time_s[i_p] == pytest.approx(2 * brake_len / s["brake_speed_ms"], rel=1e-9)
        assert s["brake_decel_ms2"] == pytest.approx(s["brake_speed_ms"] ** 2 / (2 * brake_len))
        # the subsections take the times allotted to them, and the run their sum plus braking
        table = run.subsections
        assert table["time_s"].sum() + 2 * brake_len / s["brake_speed_ms"] == pytest.approx(s["running_time_s"])
        assert np.all(table["time_s"] >= table["time_min_s"] - 1e-6)
        assert np.all(table["time_s"] <= table["time_max_s"] + 1e-6)


def test_traction_coefficient_scales_the_force(pair):
    # a level leg without resistance: traction at gamma * 280 kN accelerates at gamma m/s^2 on 280 t
    flat = replace(pair, train=replace(pair.train, resistance=replace(pair.train.resistance, a=0.0, b=0.0, c=0.0)),
                   line=replace(pair.line, gradients=((0.0, pair.line.length_m, 0.0),)))
    p = CooperativeSeedProblem(flat, 45.0, max_accel_change_ms2=None, speed_genes="absolute")
    a = p.trains[0]
    x = _vector(p, 250, 200, [(0.5, 60, 1)] * a.n_sub, [(0.5, 55, 1)] * p.trains[1].n_sub)
    tr = p.decode(x).a.trajectory
    # the first 200 m: traction at 0.5 m/s^2 up to 60 km/h (reached after 277.8 m, so not yet)
    i = int(np.searchsorted(tr.position_m, 100.0))
    assert tr.speed_ms[i] == pytest.approx(math.sqrt(2 * 0.5 * 100.0), rel=1e-3)
    assert tr.time_s[i] == pytest.approx(math.sqrt(2 * 100.0 / 0.5), rel=1e-3)


# ---------------------------------------------------------------------- shared energy
def test_bins_preserve_energy_and_spread_it_evenly():
    out = np.zeros(5)
    coop.bin_energy(np.array([0.0, 0.05, 0.35]), np.array([0.0, 3.0]), 0.0, 0.0, 0.1, out)
    np.testing.assert_allclose(out, [0.5, 1.0, 1.0, 0.5, 0.0])
    shifted = np.zeros(5)
    coop.bin_energy(np.array([0.0, 0.05, 0.35]), np.array([0.0, 3.0]), 0.1, 0.0, 0.1, shifted)
    np.testing.assert_allclose(shifted, [0.0, 0.5, 1.0, 1.0, 0.5])


def test_shared_energy_of_two_overlapping_pulses():
    # A draws 2 kW over [0, 10) s, B regenerates 1 kW over [5, 20) s: B feeds A 1 kW for 5 s
    t_a = np.array([0.0, 10.0])
    t_b = np.array([0.0, 15.0])
    bins = {k: np.zeros(300) for k in ("ta", "ra", "tb", "rb")}
    coop.bin_energy(t_a, np.array([20e3]), 0.0, 0.0, 0.1, bins["ta"])
    coop.bin_energy(t_b, np.array([15e3]), 5.0, 0.0, 0.1, bins["rb"])
    shared = coop.shared_energy_bins(np.vstack([bins["ta"], bins["tb"]]), np.vstack([bins["ra"], bins["rb"]]), 1.0)
    assert shared.sum() == pytest.approx(5e3)
    # through a supply that delivers 60 %: 0.6 kW for 5 s
    lossy = coop.shared_energy_bins(np.vstack([bins["ta"], bins["tb"]]), np.vstack([bins["ra"], bins["rb"]]), 0.6)
    assert lossy.sum() == pytest.approx(3e3)


@pytest.mark.parametrize("offset_s", [-1000.0, 1000.0])
def test_no_energy_is_shared_when_the_runs_do_not_overlap(pair, offset_s):
    # on-time runs (repaired genes) 1000 s apart cannot overlap
    p = CooperativeSeedProblem(pair, offset_s)
    out = p.evaluate(PunctualityRepair().apply(p, _population(p)), return_as_dictionary=True)
    on_time = np.all(out["G"][:, :2] <= 0, axis=1)
    assert on_time.mean() > 0.8
    assert np.all(out["shared_kwh"][on_time] == 0.0)
    np.testing.assert_array_equal(out["F"][:, 0], out["traction_a_kwh"] + out["traction_b_kwh"])


@pytest.mark.parametrize("offset_s", [-45.0, 0.0, 45.0, 90.0, 135.0])
def test_shared_energy_is_bounded_by_what_one_brakes_back_and_the_other_draws(pair, offset_s):
    p = CooperativeSeedProblem(pair, offset_s)
    X = _population(p)
    sim = p.simulate(X)
    shared = sim["shared_kwh"]
    s_a, s_b = sim["summary_a"], sim["summary_b"]
    tol = 1e-9
    assert np.all(shared >= 0.0)
    assert np.all(shared[:, 0] <= np.minimum(s_a[:, 0], s_b[:, 1]) + tol)  # A from B: A's traction, B's regen
    assert np.all(shared[:, 1] <= np.minimum(s_b[:, 0], s_a[:, 1]) + tol)
    assert shared.sum() > 0.0  # at the seed's offsets braking and traction do overlap
    # the power profiles of one solution give the same shared energy
    frame = p.power_profiles(X[0])
    assert frame["shared_kw"].sum() * p.time_step_s / 3600 == pytest.approx(shared[0].sum(), rel=1e-9, abs=1e-12)
    assert np.all(frame["shared_kw"] <= frame["traction_a_kw"] + frame["traction_b_kw"] + 1e-9)


def test_a_trains_own_regeneration_is_not_credited(pair):
    p = CooperativeSeedProblem(pair, -1000.0)
    out = p.evaluate(PunctualityRepair().apply(p, _population(p, 20)), return_as_dictionary=True)
    on_time = np.all(out["G"][:, :2] <= 0, axis=1)
    assert np.all(out["regen_a_kwh"] > 0)  # the trains do brake regeneratively...
    f, traction = out["F"][on_time, 0], (out["traction_a_kwh"] + out["traction_b_kwh"])[on_time]
    np.testing.assert_array_equal(f, traction)  # ...for nobody


def test_uncoordinated_objective_shares_nothing(pair):
    p = CooperativeSeedProblem(pair, 45.0, share_energy=False)
    out = p.evaluate(_population(p, 20), return_as_dictionary=True)
    np.testing.assert_array_equal(out["F"][:, 0], out["traction_a_kwh"] + out["traction_b_kwh"])


# ---------------------------------------------------------------------- separation (eq. 9)
def test_separation_against_a_hand_computed_case():
    # follower at 10 m/s from 0 to 800 m; the leader stands at 1000 m; L_t + L_s = 180 m, b = 1:
    # the worst moment is the end, v^2 / 2b - (1000 - 800 - 180) = 50 - 20 = 30 m
    x = np.arange(0.0, 801.0)
    t = x / 10.0
    v = np.full(x.shape, 10.0)
    excess = coop.separation_excess(t, x, v, 0.0, 0.0, np.array([0.0, 1.0]), np.array([0.0, 1.0]), 1e9, 1000.0,
                                    180.0, 1.0, 0.0, 0.1, 800)
    assert excess == pytest.approx(30.0)


def test_separation_is_enforced(pair):
    # B still stands at station 2 when A arrives there (x = 200 s > 190 s): no decision is feasible
    blocked = CooperativeSeedProblem(pair, 200.0)
    free = CooperativeSeedProblem(pair, 45.0)
    x = _vector(free, 250, 200, REL_A, REL_B)[None, :]
    g_blocked = blocked.evaluate(x, return_as_dictionary=True)
    g_free = free.evaluate(x, return_as_dictionary=True)
    col = 4
    assert g_blocked["G"][0, col] > 0
    pop = Population.new(X=x)
    Evaluator().eval(blocked, pop)
    assert pop.get("CV")[0, 0] > 0
    assert g_free["G"][0, col] <= 0
    # A stops at 2600 m with B's tail at 2460 m: short by L_t + L_s = 180 m
    assert g_blocked["G"][0, col] >= 180.0 - 1e-6


# ---------------------------------------------------------------------- punctuality and constraints
def test_every_feasible_solution_stops_both_trains_on_time(problem, optimised):
    pop = optimised.pop
    feasible = pop.get("CV")[:, 0] <= 0
    assert feasible.sum() >= 5
    for x in pop.get("X")[feasible]:
        sol = problem.decode(x)
        assert sol.feasible
        for run, leg in ((sol.a, 0), (sol.b, 1)):
            tr = run.trajectory
            assert abs(tr.running_time_s - problem.case.legs[leg].planned_time_s) <= 1.0
            assert tr.speed_ms[-1] == 0.0
            assert tr.position_m[-1] == pytest.approx(problem.case.legs[leg].end_m - problem.case.legs[leg].start_m)
            assert np.all(tr.speed_ms <= tr.limit_ms + 1e-6)


def test_repair_puts_the_plan_inside_the_time_window(problem):
    X = _population(problem, 40, seed=2)
    before = problem.evaluate(X, return_as_dictionary=True)["G"][:, :2]
    repaired = PunctualityRepair().apply(problem, X)
    after = problem.evaluate(repaired, return_as_dictionary=True)["G"][:, :2]
    assert np.any(before > 0, axis=1).mean() > 0.9  # random genes are rarely on time...
    assert np.all(after <= 0, axis=1).mean() > 0.8  # ...repaired ones mostly are (eq. 1 then hits the plan)
    # genes already on time are left alone, and the braking distances and time shares never change
    np.testing.assert_array_equal(PunctualityRepair().apply(problem, repaired), repaired)
    np.testing.assert_array_equal(repaired[:, :2], X[:, :2])
    np.testing.assert_array_equal(repaired[:, 4::3], X[:, 4::3])


def test_single_train_form(pair):
    solo = SubsectionProblem(pair.leg(1))
    assert solo.n_var == 1 + 3 * 5 and solo.n_ieq_constr == 4
    X = PunctualityRepair().apply(solo, _population(solo, 20))
    out = solo.evaluate(X, return_as_dictionary=True)
    assert np.mean(np.abs(out["running_time_s"] - 100.0) <= 1.0) > 0.8
    both = CooperativeSeedProblem(pair, -1000.0)
    # B alone in the two-train problem gives the same traction energy
    run = solo.decode(X[0])
    assert run.traction_kwh > 0 and run.trajectory.speed_ms[-1] == 0.0
    with pytest.raises(CaseError, match=r"run\.legs.*2 legs"):
        SubsectionProblem(pair)
    assert both.trains[1].n_sub == solo.trains[0].n_sub


def test_comfort_constraint_measures_the_acceleration_change(absolute):
    # from holding 40 km/h into full traction at the +6 permille gradient change: the acceleration
    # jumps by (280 kN - W0 - grade) / 280 t, about 0.9 m/s^2 > delta = 0.8 m/s^2 (eq. 8)
    genes_a = list(GENES_A)
    genes_a[0] = (0.6, 40, 1)
    genes_a[1] = (1.0, 70, 1)
    x = _vector(absolute, 250, 200, genes_a, GENES_B)
    sol = absolute.decode(x)
    assert sol.a.summary["accel_change_ms2"] > 0.8
    assert sol.constraints["comfort"] > 0


def test_vectorised_and_row_by_row_evaluation_agree(problem):
    X = _population(problem, 12, seed=5)
    together = problem.evaluate(X, return_as_dictionary=True)
    for i in range(X.shape[0]):
        alone = problem.evaluate(X[i:i + 1], return_as_dictionary=True)
        np.testing.assert_array_equal(alone["F"][0], together["F"][i])
        np.testing.assert_array_equal(alone["G"][0], together["G"][i])


def test_pickling_keeps_the_problem(problem):
    X = _population(problem, 8)
    copy = pickle.loads(pickle.dumps(problem))
    for a, b in zip(copy.evaluate(X, return_values_of=["F", "G"]), problem.evaluate(X, return_values_of=["F", "G"])):
        np.testing.assert_array_equal(a, b)


def test_gradient_scaling(pair):
    flat = scale_gradients(pair, 0.0)
    assert all(g == 0.0 for _, _, g in flat.line.gradients)
    p = CooperativeSeedProblem(flat, 45.0)
    assert all(k == 2 for tr in p.trains for k in tr.sub_kind)  # no steep descent is left
    half = scale_gradients(pair, 0.5)
    assert [g for _, _, g in half.line.gradients] == [0.5 * g for _, _, g in pair.line.gradients]


def test_power_profiles_of_trajectories(pair, problem):
    sol = problem.decode(_vector(problem, 250, 200, REL_A, REL_B))
    frame = coop.power_profiles(clocked_pair(problem, sol), ("a", "b"))
    assert frame["traction_a_kw"].sum() * 0.1 / 3600 == pytest.approx(sol.a.traction_kwh, rel=1e-9)
    assert frame["regen_b_kw"].sum() * 0.1 / 3600 == pytest.approx(sol.b.regen_kwh, rel=1e-9)


# ---------------------------------------------------------------------- nested GA
def test_nested_ga_is_a_composition_of_pymoo_runs(problem):
    from pymoo.algorithms.soo.nonconvex.ga import GA

    kwargs = dict(outer_pop_size=4, outer_n_gen=2, inner_algorithm=GA(pop_size=10), inner_n_gen=3, seed=7)
    x1, f1, res = nested_minimize(problem, **kwargs)
    x2, f2, _ = nested_minimize(problem, **kwargs)
    assert x1.shape == (problem.n_var,)
    np.testing.assert_array_equal(x1, x2)  # randomness only from the seeded random_state
    assert f1 == f2
    assert isinstance(res.problem, BrakingDistanceProblem)
    # the outer value is the full vector's objective
    assert problem.evaluate(x1[None, :], return_values_of=["F"])[0, 0] == pytest.approx(f1)


# ---------------------------------------------------------------------- bad input
def test_bad_offset_names_the_field_and_value(pair):
    with pytest.raises(ValueError, match=r"offset_s = nan"):
        CooperativeSeedProblem(pair, float("nan"))
    with pytest.raises(ValueError, match=r"offset_s = inf"):
        CooperativeSeedProblem(pair, math.inf)
    with pytest.raises(ValueError, match=r"safety_margin_m = -1"):
        CooperativeSeedProblem(pair, 0.0, safety_margin_m=-1.0)


def test_a_case_without_two_legs_is_rejected(yizhuang):
    with pytest.raises(CaseError, match=r"run\.legs.*0 legs"):
        CooperativeSeedProblem(yizhuang, 45.0)


def test_a_nan_decision_names_the_variable(problem):
    x = _vector(problem, 250, 200, REL_A, REL_B)
    x[6] = np.nan
    with pytest.raises(ValueError, match=r"v_a2_rel = nan"):
        problem.evaluate(x[None, :])


def test_partial_problem_holds_the_other_genes(problem):
    x_ref = PunctualityRepair().apply(problem, _vector(problem, 250, 200, REL_A, REL_B))[0]
    free = train_genes(problem, 1)
    assert free.sum() == 1 + 3 * problem.trains[1].n_sub and free[1] and not free[0]
    part = PartialProblem(problem, free, x_ref)
    np.testing.assert_array_equal(part.full(x_ref[free])[0], x_ref)
    f_part = part.evaluate(x_ref[free][None, :], return_values_of=["F"])
    np.testing.assert_array_equal(f_part, problem.evaluate(x_ref[None, :], return_values_of=["F"]))


def test_alternating_minimize_never_makes_things_worse(problem):
    x0 = PunctualityRepair().apply(problem, _vector(problem, 250, 200, REL_A, REL_B))[0]
    f0 = problem.evaluate(x0[None, :], return_values_of=["F"])[0, 0]
    x1, f1 = alternating_minimize(problem, x0, rounds=1, n_evals=(200, 200), pop_size=10, seed=4)
    x2, f2 = alternating_minimize(problem, x0, rounds=1, n_evals=(200, 200), pop_size=10, seed=4)
    np.testing.assert_array_equal(x1, x2)
    assert f1 <= f0 + 1e-12
    assert problem.evaluate(x1[None, :], return_values_of=["F"])[0, 0] == pytest.approx(f1)
