"""The strategy baselines run in the planned time; the exact points are cached and resumed."""

from __future__ import annotations

import numpy as np
import pytest

from pymoo_rail.optimal.baselines import strategy_baselines
from pymoo_rail.problems import SpeedProfileProblem
from pymoo_rail.problems.reference import exact_points

PLANNED_S = 150.0  # Liu (2019) 5.1.1: Tongjinan Rd -> Jinghai Rd


def test_baselines_run_in_the_planned_time_and_coasting_saves(yizhuang):
    base = strategy_baselines(SpeedProfileProblem(yizhuang, objectives=("energy",)))
    assert base["cruise"]["running_time_s"] == pytest.approx(PLANNED_S, abs=1e-3)
    assert base["coast"]["running_time_s"] == pytest.approx(PLANNED_S, abs=0.2)
    assert base["flat_out"]["running_time_s"] < PLANNED_S - 10.0
    assert base["coast"]["energy_kwh"] < base["cruise"]["energy_kwh"] < base["flat_out"]["energy_kwh"]
    assert 0.0 < base["coast"]["coast_m"] < yizhuang.line.length_m


def test_exact_points_are_cached_row_by_row_and_resumed(tmp_path, yizhuang):
    path = tmp_path / "points.csv"
    seen = []
    first = exact_points(yizhuang, [150.0], path, n_speeds=40, on_run=lambda t, tr: seen.append(t))
    assert seen == [150.0] and first["running_time_s"].iloc[0] == pytest.approx(150.0, abs=0.5)
    # a second time is added; the cached one is read back bit for bit, not solved again
    both = exact_points(yizhuang, [150.0, 170.0], path, n_speeds=40, on_run=lambda t, tr: seen.append(t))
    assert seen == [150.0, 170.0]
    assert both["energy_kwh"].iloc[0] == first["energy_kwh"].iloc[0]
    assert both["energy_kwh"].iloc[1] < both["energy_kwh"].iloc[0]  # slower is cheaper
    # redo_s solves a cached time again; another n_speeds drops the old rows
    exact_points(yizhuang, [150.0], path, n_speeds=40, redo_s=[150.0], on_run=lambda t, tr: seen.append(t))
    assert seen == [150.0, 170.0, 150.0]
    other = exact_points(yizhuang, [170.0], path, n_speeds=41)
    assert np.all(other["n_speeds"] == 41) and len(other) == 1
