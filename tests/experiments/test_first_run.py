"""The first-run measurement: child timing, the log's rows and their order (no timed assertion)."""

from __future__ import annotations

import os

import pytest

from pymoo_rail.experiments.first_run import LOG_COLUMNS, measurement_rows, newest_first, timed_child


def test_a_child_is_timed_and_its_stderr_kept(tmp_path):
    wall, cpu, err = timed_child(["-c", "import sys; sys.stderr.write('compiling the simulator')"], tmp_path,
                                 dict(os.environ))
    assert wall > 0 and cpu >= 0 and err == "compiling the simulator"


def test_a_failing_child_names_its_command_and_exit_code(tmp_path):
    with pytest.raises(RuntimeError, match=r"-c raise SystemExit\(3\) failed \(3\)"):
        timed_child(["-c", "raise SystemExit(3)"], tmp_path, dict(os.environ))


def test_rows_of_a_measurement_carry_its_stamp_as_text():
    rows = measurement_rows([("cold", 58.44, 21.81, True), ("warm", 10.5, 3.4, False)], "abc+", "note", 1.04, 2.0)
    assert [tuple(r) for r in rows] == [LOG_COLUMNS] * 2
    assert rows[0]["wall_s"] == "58.4" and rows[0]["compile_message"] == "yes" and rows[1]["compile_message"] == "no"
    assert rows[0]["load_start"] == "1.0" and rows[1]["commit"] == "abc+"


def test_the_newest_measurement_comes_first_and_keeps_its_run_order():
    first = measurement_rows([("cold", 1, 1, True), ("warm", 1, 1, False)], "a", "", 1, 1)
    second = measurement_rows([("cold", 2, 2, True), ("warm", 2, 2, False)], "b", "", 1, 1)
    assert [(r["commit"], r["run"]) for r in newest_first(first + second)] == [
        ("b", "cold"), ("b", "warm"), ("a", "cold"), ("a", "warm")]
    assert newest_first([]) == []
