"""Whole-line journeys: the Yizhuang line from TTOBench, fronts, the exact running-time split."""

from __future__ import annotations

import numpy as np
import pandas as pd
import pytest
from scipy.optimize import linprog

from pymoo_rail.cases.ttobench import BEIJING_SUBWAY_TRAIN, YIZHUANG_STOP_NAMES, YIZHUANG_TRACK, from_ttobench
from pymoo_rail.journeys import (
    BudgetRepair,
    Journey,
    journey_from_ttobench,
    journey_to_ttobench,
    RunningTimeAllocationProblem,
    allocate_on_fronts,
    allocate_running_time,
    as_journey,
    convex_front,
    front_energy,
    project_to_budget,
    strategy_front,
    strategy_programs,
    supplement_split,
)
from pymoo_rail.model import Case, CaseError, InfeasibleCaseError
from pymoo_rail.sim import Simulator
from pymoo_rail.sim import kernel as k


@pytest.fixture(scope="module")
def journey():
    return journey_from_ttobench(YIZHUANG_TRACK, BEIJING_SUBWAY_TRAIN, stop_names=YIZHUANG_STOP_NAMES)


@pytest.fixture(scope="module")
def fronts(journey):
    # a coarser search than the default keeps the test fast; any convex front will do for the algebra
    return [strategy_front(c, n_speeds=17, n_coast=17) for c in journey.sections]


def front(points):
    t, e = zip(*points)
    return pd.DataFrame({"running_time_s": t, "energy_kwh": e})


def lp_optimum(fronts, total):
    """The same allocation as a linear programme on the epigraph (scipy HiGHS): an independent check."""
    n = len(fronts)
    c = np.r_[np.zeros(n), np.ones(n)]  # variables t_0..t_n-1, z_0..z_n-1
    a_ub, b_ub = [], []
    for i, f in enumerate(fronts):
        t, e = f["running_time_s"].to_numpy(), f["energy_kwh"].to_numpy()
        for j in range(len(t) - 1):
            s = (e[j + 1] - e[j]) / (t[j + 1] - t[j])
            row = np.zeros(2 * n)
            row[i], row[n + i] = s, -1.0  # e_j + s (t - t_j) <= z
            a_ub.append(row)
            b_ub.append(s * t[j] - e[j])
    bounds = [(f["running_time_s"].iloc[0], f["running_time_s"].iloc[-1]) for f in fronts] + [(None, None)] * n
    res = linprog(c, A_ub=np.array(a_ub) if a_ub else None, b_ub=b_ub or None,
                  A_eq=[np.r_[np.ones(n), np.zeros(n)]], b_eq=[total], bounds=bounds, method="highs")
    assert res.success
    return res.fun


# ------------------------------------------------------------------------------ the journey


def test_whole_yizhuang_line_as_13_sections(journey):
    assert journey.n_sections == 13
    assert journey.length_m == 22728.0
    assert journey.stops_m[9:11] == (15757.0, 18022.0)
    assert journey.section_label(9) == "Tongjinan Rd -> Jinghai Rd"
    assert journey.dwell_s == (30.0,) * 12
    assert journey.trip_time_s(1500.0) == 1500.0 + 12 * 30.0
    assert journey.sections[9].line == from_ttobench(YIZHUANG_TRACK, BEIJING_SUBWAY_TRAIN, 9, 10, 1.0).line
    # default plans: minimum running time + 10 %
    t_min = journey.min_running_times_s()
    np.testing.assert_allclose(journey.planned_running_times_s, 1.1 * t_min, rtol=1e-12)


def test_journey_with_chosen_stops_and_times():
    j = journey_from_ttobench(YIZHUANG_TRACK, BEIJING_SUBWAY_TRAIN, stops=["Tongjinan Rd", "Jinghai Rd", -1],
                              stop_names=YIZHUANG_STOP_NAMES, planned_times_s=[150.0, 300.0], dwell_s=[40.0])
    assert j.n_sections == 2 and j.length_m == 22728.0 - 15757.0
    assert j.stop_names == ("Tongjinan Rd", "Jinghai Rd", "Yizhuang Railway Station")
    assert list(j.planned_running_times_s) == [150.0, 300.0] and j.dwell_s == (40.0,)
    assert j.sections[1].line.length_m == 22728.0 - 18022.0  # passes Ciqu South and Ciqu


def test_journey_round_trips_through_ttobench(journey, tmp_path):
    track_path, train_path = journey_to_ttobench(journey, tmp_path)
    back = journey_from_ttobench(track_path, train_path, planned_times_s=list(journey.planned_running_times_s),
                                 stop_names=YIZHUANG_STOP_NAMES)
    assert back.stops_m == journey.stops_m and back.altitude_m == journey.altitude_m
    for a, b in zip(back.sections, journey.sections):
        assert a.train == b.train and a.line == b.line


@pytest.mark.parametrize("kwargs, field", [
    ({"dwell_s": (30.0, 30.0)}, "dwell_s"),
    ({"dwell_s": (-1.0,)}, "dwell_s[0]"),
    ({"stops_m": (0.0, 10.0, 20.0)}, "stops_m[1]"),
    ({"stop_names": ("a", "b")}, "stop_names"),
])
def test_bad_journeys(journey, kwargs, field):
    base = dict(name="j", sections=journey.sections[:2], dwell_s=(30.0,))
    base.update(kwargs)
    with pytest.raises(CaseError) as err:
        Journey.from_sections(**base)
    assert err.value.field == field


def test_journey_needs_one_train(journey):
    other = journey.sections[1].train.__class__(**{**journey.train.__dict__, "mass_t": 300.0})
    mixed = (journey.sections[0], journey.sections[1].__class__(**{**journey.sections[1].__dict__, "train": other}))
    with pytest.raises(CaseError) as err:
        Journey.from_sections(name="mixed", sections=mixed, dwell_s=(30.0,))
    assert err.value.field == "sections[1].train"


# ------------------------------------------------------------------------------------- fronts


def test_convex_front_is_the_lower_hull():
    raw = front([(10, 10), (15, 9.5), (20, 4), (20, 6), (25, 3.5), (30, 2), (30, 2.5)])
    hull = convex_front(raw)
    assert list(zip(hull.running_time_s, hull.energy_kwh)) == [(10, 10), (20, 4), (30, 2)]
    assert front_energy(hull, 25.0) == pytest.approx(3.0)
    with pytest.raises(CaseError, match="outside"):
        front_energy(hull, 31.0)


@pytest.mark.parametrize("bad, field", [
    (pd.DataFrame({"running_time_s": [1.0]}), "front.energy_kwh"),
    (front([(10, 1.0), (20, np.nan)]), "front.energy_kwh[1]"),
    (front([(-1, 1.0)]), "front.running_time_s[0]"),
    (pd.DataFrame({"running_time_s": [], "energy_kwh": []}), "front"),
])
def test_bad_fronts(bad, field):
    with pytest.raises(CaseError) as err:
        convex_front(bad)
    assert err.value.field == field


def test_section_front_vertices_are_simulated_runs(journey, fronts):
    case, f = journey.sections[9], fronts[9]
    sim = Simulator(case)
    fastest = sim.flat_out()
    assert f.running_time_s.iloc[0] == fastest.running_time_s
    assert f.energy_kwh.iloc[0] == fastest.energy.net_kwh
    out = sim.run_batch(strategy_programs(case.line.length_m, f.cruise_kmh.to_numpy()[1:] / 3.6,
                                          f.coast_from_m.to_numpy()[1:]))
    np.testing.assert_allclose(out[:, k.OUT_RUNNING_TIME_S], f.running_time_s.to_numpy()[1:], rtol=1e-12)
    np.testing.assert_allclose(out[:, k.OUT_NET_KWH], f.energy_kwh.to_numpy()[1:], rtol=1e-12)
    assert (out[:, k.OUT_REACHED] == 1).all() and (out[:, k.OUT_LIMIT_EXCESS_MS] < 1e-6).all()
    assert f.energy_kwh.iloc[0] == f.energy_kwh.max()  # the fastest run costs the most


# --------------------------------------------------------------------------------- allocation


def test_hand_computed_allocation():
    a = front([(10, 10), (20, 4), (30, 2)])  # slopes -0.6, -0.2 kWh/s
    b = front([(10, 8), (20, 5), (30, 4.5)])  # slopes -0.3, -0.05 kWh/s
    # 15 s to hand out: 10 s to a's first segment (-0.6), then 5 s to b's first (-0.3)
    times, energies, price = allocate_on_fronts([a, b], 35.0)
    np.testing.assert_allclose(times, [20.0, 15.0])
    np.testing.assert_allclose(energies, [4.0, 6.5])
    assert price == pytest.approx(0.3)


def test_identical_sections_split_evenly():
    f = front([(60, 20), (70, 14), (80, 11), (90, 9.5), (100, 9)])
    times, _, _ = allocate_on_fronts([f, f, f], 240.0)
    np.testing.assert_allclose(times, [80.0, 80.0, 80.0])


@pytest.mark.parametrize("extra", [0.0, 0.04, 0.10, 0.20])
def test_line_allocation_beats_equal_supplement_and_meets_the_marginal_condition(journey, fronts, extra):
    t_min = sum(f.running_time_s.iloc[0] for f in fronts)
    total = t_min * (1 + extra)
    best = allocate_running_time(journey, total, fronts=fronts)
    equal = supplement_split(journey, total, fronts=fronts, rule="equal")
    assert best.total_time_s == pytest.approx(total, rel=1e-12)
    assert best.energy_kwh <= equal.energy_kwh + 1e-9
    assert best.marginal_violation() <= 1e-12
    assert best.energy_kwh == pytest.approx(lp_optimum(fronts, total), rel=1e-7, abs=1e-7)
    table = best.table
    assert (table.running_time_s >= table.min_time_s - 1e-9).all()
    assert (table.running_time_s <= table.max_time_s + 1e-9).all()
    inside = (table.running_time_s > table.min_time_s + 1e-6) & (table.running_time_s < table.max_time_s - 1e-6)
    # every section strictly inside its range pays the same marginal price
    assert (table.slope_left_kwh_per_s[inside] <= -best.price_kwh_per_s + 1e-12).all()
    assert (table.slope_right_kwh_per_s[inside] >= -best.price_kwh_per_s - 1e-12).all()


def test_allocation_range_ends(journey, fronts):
    lo = np.array([f.running_time_s.iloc[0] for f in fronts])
    hi = np.array([f.running_time_s.iloc[-1] for f in fronts])
    np.testing.assert_allclose(allocate_running_time(journey, lo.sum(), fronts=fronts).running_times_s, lo)
    np.testing.assert_allclose(allocate_running_time(journey, hi.sum(), fronts=fronts).running_times_s, hi)
    with pytest.raises(InfeasibleCaseError) as err:
        allocate_running_time(journey, lo.sum() - 1.0, fronts=fronts)
    assert err.value.field == "total_time_s"
    with pytest.raises(CaseError, match="wider"):
        allocate_running_time(journey, hi.sum() + 1.0, fronts=fronts)
    with pytest.raises(CaseError, match="one front per section"):
        allocate_running_time(journey, lo.sum(), fronts=fronts[:3])
    with pytest.raises(CaseError, match="unknown front source"):
        allocate_running_time(journey, lo.sum(), fronts="guess")


def test_more_time_never_costs_more_energy_on_this_line(journey, fronts):
    t_min = sum(f.running_time_s.iloc[0] for f in fronts)
    energies = [allocate_running_time(journey, t_min * (1 + x), fronts=fronts).energy_kwh
                for x in np.linspace(0, 0.3, 7)]
    assert (np.diff(energies) < 0).all()
    prices = [allocate_running_time(journey, t_min * (1 + x), fronts=fronts).price_kwh_per_s
              for x in np.linspace(0, 0.3, 7)]
    assert (np.diff(prices) <= 1e-12).all()  # convexity: the marginal saving falls as time grows


# ------------------------------------------------------------------------------- pymoo problem


def test_problem_evaluates_like_the_exact_allocation(journey, fronts):
    total = sum(f.running_time_s.iloc[0] for f in fronts) * 1.1
    best = allocate_running_time(journey, total, fronts=fronts)
    problem = RunningTimeAllocationProblem(fronts, total)
    out = problem.evaluate(best.running_times_s[None, :], return_as_dictionary=True)
    assert out["F"][0, 0] == pytest.approx(best.energy_kwh, rel=1e-12)
    assert abs(out["H"][0, 0]) < 1e-9
    rng = np.random.default_rng(3)
    x = project_to_budget(rng.uniform(problem.xl, problem.xu, size=(200, problem.n_var)),
                          problem.xl, problem.xu, total)
    np.testing.assert_allclose(x.sum(axis=1), total, rtol=1e-12)
    assert ((x >= problem.xl - 1e-9) & (x <= problem.xu + 1e-9)).all()
    f_random = problem.evaluate(x, return_as_dictionary=True)["F"][:, 0]
    assert (f_random >= best.energy_kwh - 1e-9).all()
    # vectorised evaluation = one row at a time
    singles = np.array([problem.evaluate(row[None, :], return_as_dictionary=True)["F"][0, 0] for row in x[:5]])
    np.testing.assert_array_equal(singles, f_random[:5])


def test_metaheuristic_with_repair_approaches_the_exact_split(journey, fronts):
    from pymoo.algorithms.soo.nonconvex.de import DE
    from pymoo.optimize import minimize

    total = sum(f.running_time_s.iloc[0] for f in fronts) * 1.1
    best = allocate_running_time(journey, total, fronts=fronts)
    problem = RunningTimeAllocationProblem(fronts, total)
    res = minimize(problem, DE(pop_size=40, repair=BudgetRepair()), ("n_gen", 150), seed=1)
    assert abs(res.X.sum() - total) < 1e-6
    assert best.energy_kwh - 1e-9 <= res.F[0] <= best.energy_kwh * 1.01


def test_callable_front_source_gets_times_above_the_minimum_and_the_flat_out_point(journey):
    short = Journey.from_sections(name="two", sections=journey.sections[9:11], dwell_s=(30.0,))
    seen = []

    def source(case, running_times):  # the signature of pymoo_rail.optimal.optimal_front
        seen.append((case.name, np.asarray(running_times)))
        return pd.DataFrame({"running_time_s": running_times, "energy_kwh": 4000.0 / running_times})

    from pymoo_rail.journeys import section_fronts

    fronts = section_fronts(short, source, n_times=5, max_time_factor=1.4)
    assert [name for name, _ in seen] == [c.name for c in short.sections]
    for case, (_, times), f in zip(short.sections, seen, fronts):
        fastest = Simulator(case).flat_out()
        u = np.linspace(0.0, 1.0, 5)
        np.testing.assert_allclose(times, fastest.running_time_s * (1.005 + 0.395 * u * u))
        assert (f.running_time_s.iloc[0], f.energy_kwh.iloc[0]) == (fastest.running_time_s, fastest.energy.net_kwh)
    best = allocate_running_time(short, sum(f.running_time_s.iloc[0] for f in fronts) + 20.0, fronts=fronts)
    assert best.marginal_violation() <= 1e-12


def test_front_cache_keeps_finished_sections(journey, tmp_path):
    short = Journey.from_sections(name="two", sections=journey.sections[4:6], dwell_s=(30.0,))
    calls = []

    def source(case, running_times):
        calls.append(case.name)
        return pd.DataFrame({"running_time_s": running_times, "energy_kwh": 3000.0 / running_times})

    from pymoo_rail.journeys import section_fronts

    cache = tmp_path / "fronts.csv"
    first = section_fronts(short, source, n_times=4, cache_path=cache)
    assert len(calls) == 2 and cache.is_file()
    again = section_fronts(short, source, n_times=4, cache_path=cache)
    assert len(calls) == 2  # both read back
    for a, b in zip(first, again):
        np.testing.assert_allclose(b[["running_time_s", "energy_kwh"]], a[["running_time_s", "energy_kwh"]],
                                   rtol=1e-12)
    section_fronts(short, source, n_times=5, cache_path=cache)  # other settings: computed anew
    assert len(calls) == 4


def test_default_fronts_are_the_exact_solver():
    from pymoo_rail.journeys import DEFAULT_FRONT_SOURCE

    assert DEFAULT_FRONT_SOURCE == "optimal"


@pytest.mark.slow
def test_exact_fronts_on_two_sections(journey):
    from pymoo_rail.journeys import section_fronts

    short = Journey.from_sections(name="two", sections=journey.sections[4:6], dwell_s=(30.0,))
    exact = section_fronts(short, "optimal", n_times=6)
    simulated = [strategy_front(c) for c in short.sections]
    for fe, fs in zip(exact, simulated):
        assert fe.running_time_s.iloc[0] == fs.running_time_s.iloc[0]  # both start at the flat-out run
        # at the solver's own points (between them its chords lie above a convex front): the strategy
        # search is an upper estimate of the optimum, the exact solver within 0.5 % of it
        t = fe.running_time_s.to_numpy()[1:]
        t = t[t <= fs.running_time_s.iloc[-1]]
        assert t.size >= 4
        assert (fe.energy_kwh.to_numpy()[1:1 + t.size] <= front_energy(fs, t) * 1.005).all()
    total = sum(f.running_time_s.iloc[0] for f in exact) * 1.1
    best = allocate_running_time(short, total, fronts=exact)
    assert best.energy_kwh <= supplement_split(short, total, fronts=exact).energy_kwh + 1e-9
    assert best.marginal_violation() <= 1e-12
    # the combined hull lies on or below both
    combined = section_fronts(short, "combined", n_times=6)
    for fc, fe, fs in zip(combined, exact, simulated):
        t = np.linspace(fc.running_time_s.iloc[0], min(fe.running_time_s.iloc[-1], fs.running_time_s.iloc[-1]), 25)
        assert (front_energy(fc, t) <= np.minimum(front_energy(fe, t), front_energy(fs, t)) + 1e-9).all()


def test_a_journey_is_a_case_with_legs(journey, fronts):
    case = journey.case
    assert isinstance(case, Case) and len(case.legs) == journey.n_sections == 13
    assert [leg.dwell_s for leg in case.legs] == [30.0] * 12 + [0.0]
    assert case.line.length_m == journey.length_m and case.planned_time_s == pytest.approx(
        journey.planned_running_times_s.sum())
    for j in (0, 9, 12):  # each section is the case's leg
        assert journey.sections[j].line == case.leg(j).line
        assert journey.sections[j].line == from_ttobench(YIZHUANG_TRACK, BEIJING_SUBWAY_TRAIN, j, j + 1, 1.0).line
    total = journey.running_time_s(30 * 60)
    by_case = allocate_running_time(case, total, fronts=fronts)  # the case itself, no Journey needed
    by_journey = allocate_running_time(journey, total, fronts=fronts)
    np.testing.assert_array_equal(by_case.running_times_s, by_journey.running_times_s)
    assert as_journey(case).stops_m == tuple(s - journey.stops_m[0] for s in journey.stops_m)
