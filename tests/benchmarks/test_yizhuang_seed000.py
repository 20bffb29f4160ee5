"""Seed 000 chapter 5 on yizhuang (benchmarks/yizhuang_seed000.py): the qualitative results the
report states, on a reduced study (slow), and ABC with the seed's colony returning a feasible,
punctual run after a few cycles (fast)."""

from __future__ import annotations

import importlib.util
import sys
from types import SimpleNamespace
from pathlib import Path

import numpy as np
import pytest
from pymoo.optimize import minimize

from pymoo_rail.algorithms import ABC
from pymoo_rail.optimal.baselines import strategy_baselines
from pymoo_rail.problems import SpeedProfileProblem

SCRIPT = Path(__file__).resolve().parents[2] / "benchmarks" / "yizhuang_seed000.py"
PLANNED_S = 150.0  # seed 000 5.1.1: timetable running time Tongjinan Rd -> Jinghai Rd
LENGTH_M = 2265.0  # seed 000 table 5-1
TOLERANCE_S = 1.0  # the window the report uses for T = T_plan
STOP_TOLERANCE_M = 0.25


def _script():
    spec = importlib.util.spec_from_file_location("yizhuang_seed000", SCRIPT)
    module = importlib.util.module_from_spec(spec)
    sys.modules.setdefault("yizhuang_seed000", module)
    spec.loader.exec_module(module)
    return module


def _limit_kmh(position_m: np.ndarray) -> np.ndarray:
    # seed 000 table 5-1: 55 km/h within the first and last stretch, 80 km/h elsewhere
    return np.where((position_m < 130.0) | (position_m > 2155.0), 55.0, 80.0)


@pytest.mark.parametrize("seed", [1, 2, 3])
def test_abc_with_the_seed_colony_returns_a_feasible_punctual_run_after_a_few_cycles(yizhuang, seed):
    problem = SpeedProfileProblem(yizhuang, objectives=("energy",), time_tolerance_s=TOLERANCE_S)
    res = minimize(problem, ABC(pop_size=40, limit=50), ("n_gen", 1 + 2 * 5), seed=seed)  # 5 cycles
    assert res.X is not None and res.CV[0] == 0.0
    run = problem.trajectory(res.X)
    assert abs(run.running_time_s - PLANNED_S) <= TOLERANCE_S
    assert run.stop_error_m <= STOP_TOLERANCE_M
    assert run.position_m[-1] == pytest.approx(LENGTH_M, abs=STOP_TOLERANCE_M)
    assert run.speed_ms[-1] == pytest.approx(0.0, abs=1e-9)
    # the speed profile never exceeds the line's limit at the train's head
    assert np.all(run.speed_kmh <= _limit_kmh(run.position_m) + 1e-6)
    assert res.F[0] == pytest.approx(run.energy.net_kwh)


@pytest.mark.slow
def test_reduced_yizhuang_study_reproduces_the_qualitative_results(tmp_path, yizhuang):
    ys = _script()
    seeds = [1, 2, 3]
    ys.run_studies(tmp_path, seeds, workers=1, tolerance_s=TOLERANCE_S, n_equal=(10,), progress=False)
    results = ys.load(tmp_path, seeds, TOLERANCE_S, (10,))
    ch = ys.choices(results, PLANNED_S, TOLERANCE_S)
    assert len(ch) == 2 * 2 * len(seeds)  # ABC, MOABC x non-equal, equal-10 x seeds
    base = strategy_baselines(ys.make_problem(yizhuang))  # flat-out, constant cruise and coast point at 150 s

    # every run yields a feasible solution within the window of 150 s that stops at the platform
    assert ch["energy_kwh"].notna().all()
    assert (ch["time_error_s"] <= TOLERANCE_S + 1e-9).all()
    assert (ch["stop_error_m"] <= STOP_TOLERANCE_M).all()
    # every optimised run saves energy against the flat-out run and the constant-cruise run at 150 s
    assert (ch["energy_kwh"] < base["flat_out"]["energy_kwh"]).all()
    assert (ch["energy_kwh"] < base["cruise"]["energy_kwh"]).all()

    # the MOABC archive is a front over a range of time errors, not a cluster at 150 s
    mo = ch[ch["algorithm"] == "MOABC"]
    assert (mo["n_front"] >= 10).all()
    assert (mo["front_time_error_min_s"] <= TOLERANCE_S).all()
    assert (mo["front_time_error_max_s"] >= 10.0).all()
    assert (mo["front_energy_max_kwh"] - mo["front_energy_min_kwh"] > 2.0).all()
    for _, run in results["MOABC"].iterrows():  # and mutually non-dominated
        F = np.asarray(run["F"])
        dominated = [(np.all(F <= f, axis=1) & np.any(F < f, axis=1)).any() for f in F]
        assert not any(dominated)

    # ABC's best feasible energy never gets worse from one cycle to the next
    for _, run in results["ABC"].iterrows():
        best = np.array([np.nan if v is None else v for v in run["history"]["f0_min"]], dtype=float)
        best = best[np.isfinite(best)]
        assert len(best) >= 90
        assert np.all(np.diff(best) <= 1e-12)

    # the report and figures are written
    reports = tmp_path / "reports"
    reports.mkdir()
    args = SimpleNamespace(seeds=len(seeds), tolerance=TOLERANCE_S, n_equal=(10,), out=tmp_path, reports=reports)
    ys.write_report_files(args, results)
    text = (reports / "yizhuang_seed000.md").read_text()
    assert "Table 5-5" in text and "Table 5-6" in text
    assert (reports / "yizhuang_seed000_front.png").stat().st_size > 0
    assert (reports / "yizhuang_seed000_convergence.png").stat().st_size > 0
