"""The strategy baselines run in the planned time; the exact points are cached and resumed."""

from __future__ import annotations

import dataclasses

import numpy as np
import pandas as pd
import pytest

from pymoo_rail.optimal.baselines import strategy_baselines
from pymoo_rail.problems import SpeedProfileProblem
from pymoo_rail.optimal.reference import exact_points

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


def test_exact_points_are_served_for_the_same_content_and_solver_only(tmp_path, monkeypatch):
    from tests.conftest import make_case

    path = tmp_path / "points.csv"
    case = make_case()  # 2 km level line: a solve takes hundredths of a second
    seen = []

    def solve(c, times=(110.0, 120.0)):
        return exact_points(c, times, path, n_speeds=40, on_run=lambda t, tr: seen.append(t))

    first = solve(case)
    assert seen == [110.0, 120.0]
    # the same content under another name and prose: read back
    again = solve(dataclasses.replace(case, name="renamed", source="elsewhere"))
    assert seen == [110.0, 120.0]
    pd.testing.assert_frame_equal(again, first)
    # another train under the same name at the same path: solved, not the old rows
    heavier = make_case(train={"mass_t": 130.0})
    assert heavier.name == case.name
    other = solve(heavier, (120.0,))
    assert seen == [110.0, 120.0, 120.0] and other["energy_kwh"].iloc[0] > first["energy_kwh"].iloc[1]
    # rows written by another version of the solver: solved again
    monkeypatch.setattr("pymoo_rail.optimal.solver.SOLVER_VERSION", "test-next")
    solve(case, (110.0,))
    assert seen == [110.0, 120.0, 120.0, 110.0]
    table = pd.read_csv(path)
    assert len(table) == 2 and table["requested_time_s"].tolist() == [120.0, 110.0]  # one row per time


def test_a_cut_off_exact_points_file_is_moved_aside_and_solved_again(tmp_path):
    from pymoo_rail.rowcache import CorruptCacheWarning
    from tests.conftest import make_case

    path = tmp_path / "points.csv"
    case = make_case()
    first = exact_points(case, [110.0, 120.0], path, n_speeds=40)
    path.write_text(path.read_text()[:-30])  # a write cut off in its last line
    seen = []
    with pytest.warns(CorruptCacheWarning, match=r"points\.csv: its last line is cut off"):
        again = exact_points(case, [110.0, 120.0], path, n_speeds=40, on_run=lambda t, tr: seen.append(t))
    assert seen == [110.0, 120.0] and len(list(tmp_path.glob("points.csv.corrupt-*"))) == 1
    np.testing.assert_allclose(again["energy_kwh"], first["energy_kwh"], rtol=1e-12)
