"""study_results: a benchmark script's study run, read back, and refused when a run is missing."""

from __future__ import annotations

import argparse

import pytest

from pymoo_rail.experiments import Study, algorithm, problem
from pymoo_rail.experiments.script import study_results

STUDY = Study("tiny", problems=[problem("zdt1")], algorithms=[algorithm("nsga2", pop_size=8)], seeds=2,
              budget={"n_gen": 2})


def _args(work, report_only):
    return argparse.Namespace(work=work, report_only=report_only, workers=1)


def test_a_report_without_the_runs_is_refused_naming_them(tmp_path):
    with pytest.raises(SystemExit, match="no stored record of 2 of the 2 runs"):
        study_results(STUDY, _args(tmp_path / "none", report_only=True))


def test_the_runs_are_stored_then_read_back_without_running(tmp_path):
    first = study_results(STUDY, _args(tmp_path, report_only=False))
    again = study_results(STUDY, _args(tmp_path, report_only=True))
    assert sorted(first["seed"]) == sorted(again["seed"]) == [1, 2]
