"""Certified fronts of rail problems: pymoo's pareto_front(), the disk cache, the certificate."""

from dataclasses import replace

import numpy as np
import pytest
from pymoo.algorithms.moo.nsga2 import NSGA2
from pymoo.indicators.igd import IGD
from pymoo.optimize import minimize
from pymoo.util.display.output import pareto_front_if_possible

from pymoo_rail.cases import load_case
from pymoo_rail.problems import SpeedProfileProblem
from pymoo_rail.optimal import reference as ref
from pymoo_rail.optimal.reference import compute, store


@pytest.fixture(scope="module")
def cache(tmp_path_factory):
    """A private cache directory, so the tests compute (and then read) their own fronts."""
    path = tmp_path_factory.mktemp("front-cache")
    mp = pytest.MonkeyPatch()
    mp.setenv(ref.CACHE_ENV, str(path))
    mp.setattr(store, "SHIPPED_DIR", path / "none")
    ref.forget_fronts()
    yield path
    ref.forget_fronts()
    mp.undo()


@pytest.fixture(scope="module")
def metro(cache):
    return load_case("metro-a")


def test_front_is_the_solvers_and_cached_by_content(cache, metro):
    problem = SpeedProfileProblem(metro, objectives=("energy", "running_time"), time_window_s="default")
    front = problem.certified_front()
    table = front.table
    # decreasing and convex in time (more time, less energy, diminishing returns)
    assert np.all(np.diff(table["energy_kwh"]) < 0)
    assert np.all(np.diff(table["lambda_kwh_per_s"]) <= 0)  # runs moved at one price share a slope
    assert (table["energy_bound_kwh"] > 0).all()
    assert front.certificate in ("two-grid", "solver")
    files = list((cache / "fronts").glob("*.csv"))
    assert len(files) == 1 and ref.case_hash(metro)[:16] in files[0].name
    # the same content under another name hits the cache; other content does not share the key
    renamed = replace(metro, name="another-name", description="x")
    assert ref.front_key(renamed, 1.0, 17) == ref.front_key(metro, 1.0, 17)
    assert ref.case_hash(metro.with_planned_time(75.0)) != ref.case_hash(metro)
    ref.forget_fronts()
    again = ref.certified_front(renamed, front.dx_m)
    assert again.table.equals(front.table) or np.allclose(again.table.to_numpy(), table.to_numpy(), rtol=1e-8)
    assert len(list((cache / "fronts").glob("*.csv"))) == 1


def test_pareto_front_in_objective_space(cache, metro):
    both = SpeedProfileProblem(metro, objectives=("energy", "running_time"), time_window_s="default")
    pf = both.pareto_front()
    lo, hi = both.time_window_s
    assert pf.shape[1] == 2 and len(pf) >= 100
    assert pf[:, 1].min() >= lo - 0.5 and pf[:, 1].max() <= hi + 0.5
    err = SpeedProfileProblem(metro, objectives=("time_error", "energy"), time_window_s="default")
    pf_err = err.pareto_front()
    # time error mirrors the front about the plan: every point is |T - T_plan| of a front point
    assert np.all(pf_err[:, 0] >= 0)
    e, _ = err.certified_front().energy_at(np.clip(metro.planned_time_s + pf_err[:, 0], lo, hi))
    assert np.allclose(pf_err[:, 1], e)
    single = SpeedProfileProblem(metro, objectives=("energy",), time_tolerance_s=2.0)
    (best,), = single.pareto_front()
    energy, bound, t = ref.constrained_optimum(single.certified_front(), 2.0)
    assert best == energy and t == pytest.approx(metro.planned_time_s + 2.0)


def test_pareto_front_honours_n_pareto_points(cache, metro):
    """pymoo's argument: n evenly spaced points on the front, in both objective spaces."""
    both = SpeedProfileProblem(metro, objectives=("energy", "running_time"), time_window_s="default")
    nodes = len(both.certified_front().table)
    assert len(both.pareto_front()) > 100  # by default the front's nodes are added to 100 points
    pf = both.pareto_front(n_pareto_points=10, use_cache=False)
    lo, hi = both.certified_front().clip(both.time_window_s)  # the window inside the front's range
    assert pf.shape == (10, 2) and nodes > 10
    np.testing.assert_allclose(np.sort(pf[:, 1]), np.linspace(lo, hi, 10))
    e, _ = both.certified_front().energy_at(pf[:, 1])
    np.testing.assert_allclose(pf[:, 0], e)
    err = SpeedProfileProblem(metro, objectives=("energy", "time_error"), time_window_s="default")
    pf_err = err.pareto_front(n_pareto_points=7, use_cache=False)
    assert 2 <= len(pf_err) <= 7  # mirrored: errors on the slower side may be dominated
    for bad in (1, 2.5, True, "10"):
        with pytest.raises(ValueError, match="n_pareto_points"):
            both.pareto_front(n_pareto_points=bad, use_cache=False)


def test_optimiser_never_below_front_by_more_than_certificate(cache, metro):
    problem = SpeedProfileProblem(metro, objectives=("energy", "time_error"), time_window_s="default")
    res = minimize(problem, NSGA2(pop_size=40), ("n_gen", 40), seed=3)
    front = problem.certified_front()
    lo, hi = front.time_range_s
    t = res.pop.get("running_time_s")
    feasible = (res.pop.get("CV")[:, 0] <= 0) & (t >= lo) & (t <= hi)
    energy, bound = front.energy_at(t[feasible])
    assert np.all(res.pop.get("energy_kwh")[feasible] >= energy - bound - 1e-9)
    assert np.isfinite(IGD(problem.pareto_front())(res.F))


def test_no_exact_front_says_why(cache, metro):
    four = SpeedProfileProblem(metro, objectives=("energy", "time_error", "jerk", "stop_error"))
    with pytest.raises(ref.NoExactFrontError, match="best-known front"):
        four.pareto_front()
    assert pareto_front_if_possible(four) is None  # pymoo's display then leaves the IGD column out
    open_ended = SpeedProfileProblem(metro, objectives=("energy", "running_time"))
    with pytest.raises(ref.NoExactFrontError, match="time_window_s"):
        open_ended.pareto_front()


def test_bad_input_names_the_field(cache, metro):
    with pytest.raises(ValueError, match="time_window_s"):
        SpeedProfileProblem(metro, time_window_s=(80.0, 60.0))
    with pytest.raises(ValueError, match="time_window_s"):
        SpeedProfileProblem(metro, time_window_s="wide")
    problem = SpeedProfileProblem(metro, objectives=("energy", "running_time"), time_window_s=(70.5, 400.0))
    with pytest.raises(ValueError, match="covers"):
        problem.pareto_front()
    bad = cache / "broken.csv"
    bad.write_text("# case_hash: x\nrunning_time_s\n1\n")
    with pytest.raises(ValueError, match="broken.csv"):
        ref.CertifiedFront.read_csv(bad)


def test_time_window_constraint(cache, metro):
    problem = SpeedProfileProblem(metro, objectives=("energy", "running_time"), time_window_s=(75.0, 90.0))
    x = np.vstack([problem.xu, np.full(problem.n_var, 30.0)])
    out = problem.evaluate(x, return_as_dictionary=True)
    t = out["running_time_s"]
    assert np.allclose(out["G"][:, -1], np.maximum(75.0 - t, t - 90.0))


@pytest.mark.parametrize("damage", ["not a number", "cut off"])
def test_a_damaged_cached_front_is_set_aside_and_computed_again(cache, metro, damage, monkeypatch):
    from pymoo_rail.rowcache import CorruptCacheWarning

    ref.forget_fronts()
    front = ref.certified_front(metro, n_times=5)
    path = ref.find_front(metro, front.dx_m, 5)
    text = path.read_text()
    last = text.splitlines(keepends=True)[-1]
    cells = last.split(",")
    cells[2] = "x"  # energy_kwh of the last node
    not_a_number = text[: len(text) - len(last)] + ",".join(cells)
    path.write_text(not_a_number if damage == "not a number" else text[: len(text) - len(last) // 2])
    ref.forget_fronts()
    with pytest.warns(CorruptCacheWarning, match=f"{path.name}: .*moved to {path.name}.corrupt-"):
        again = ref.certified_front(metro, n_times=5)
    assert np.allclose(again.table.to_numpy(float), front.table.to_numpy(float), rtol=1e-9)
    assert path.read_text() == text  # rewritten whole
    assert len(list(path.parent.glob(f"{path.name}.corrupt-*"))) >= 1

    # the same damage in a shipped front is an error naming the file, never a silent recompute
    shipped = cache / "shipped"
    shipped.mkdir(exist_ok=True)
    (shipped / path.name).write_text(not_a_number)
    monkeypatch.setattr(store, "SHIPPED_DIR", shipped)
    ref.forget_fronts()
    with pytest.raises(ValueError, match=f"{path.name}: column 'energy_kwh'"):
        ref.certified_front(metro, n_times=5)
    ref.forget_fronts()


def test_front_computation_reports_progress_and_is_quiet_off_a_terminal(cache, metro, capsys, monkeypatch):
    """Every solve is reported (a bar in a terminal, a callback for others); tests and pipes see nothing."""
    from pymoo_rail.optimal import min_running_time

    n = len(ref.front_times(min_running_time(metro, 1.0), metro.planned_time_s, 5))
    calls = []
    ref.compute_front(metro, 1.0, 5, progress=lambda done, total: calls.append((done, total)))
    total = calls[-1][1]
    assert total in (2 * n, 3 * n)  # sweep and solves alone, and a coarse sweep for a two-grid certificate
    assert [d for d, _ in calls] == list(range(1, total + 1))  # one call per solve, in order
    # certified_front: off when standard error is not a terminal (here: captured by pytest)
    ref.certified_front(metro, 1.0, 5, use_cache=False)
    assert capsys.readouterr().err == ""
    # forced on, with the bar's delay at 0 s: the bar names the case and counts the solves
    monkeypatch.setattr(compute, "PROGRESS_DELAY_S", 0.0)
    ref.certified_front(metro, 1.0, 5, use_cache=False, progress=True)
    err = capsys.readouterr().err
    assert "certified front of metro-a" in err and f"{total}/{total}" in err
