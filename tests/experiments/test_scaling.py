"""Scaling measurements: a case cut into many gradient rows, its load/grid timing, and one study on
two backends (same fronts bit for bit). No timed assertion."""

from __future__ import annotations

import numpy as np
import pytest

from pymoo_rail.cases import load_case
from pymoo_rail.experiments import Study, algorithm, problem
from pymoo_rail.experiments.scaling import backend_timings, case_with_rows, load_and_grid_timing


def test_a_case_cut_into_rows_keeps_its_line_and_covers_it():
    base, case = load_case("yizhuang"), case_with_rows(100)
    rows = np.array(case.line.gradients)
    assert len(rows) == 100 and case.name == "yizhuang-100-rows"
    assert rows[0, 0] == 0.0 and rows[-1, 1] == pytest.approx(base.line.length_m)
    assert (rows[1:, 0] == rows[:-1, 1]).all() and (np.abs(rows[:, 2]) <= 30).all()
    assert np.array_equal(np.array(case_with_rows(100).line.gradients), rows)  # seeded


def test_load_and_grid_timing_removes_its_file(tmp_path):
    row = load_and_grid_timing(case_with_rows(50), tmp_path)
    assert set(row) == {"file_mb", "load_s", "load_cpu_s", "grid_s", "grid_cpu_s"} and row["file_mb"] > 0
    assert not list(tmp_path.iterdir())


def test_two_backends_store_the_same_fronts():
    study = Study("tiny", problems=[problem("zdt1")], algorithms=[algorithm("nsga2", pop_size=8)], seeds=1,
                  budget={"n_gen": 2})
    table, run_time = backend_timings(study, {"a": {"workers": 1}, "b": {"workers": 1}})
    assert list(table["backend"]) == ["a", "b"] and table["identical"].all() and run_time > 0
    assert table["speed_up"].iloc[0] == 1.0
