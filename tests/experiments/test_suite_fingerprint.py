"""A suite family run's fingerprint covers exactly the code it executes, and not its front (raw records).

The first test runs suite runs in a fresh interpreter (``suite_run_probe.py``) and checks that
every package file a run executes is inside the parts its ``pymoo-rail code`` digest covers
(:func:`pymoo_rail.experiments.inputs.code_parts`) or listed below with why its output is
fingerprinted otherwise, and that every other package module loaded is listed as only imported,
with the reason. The others check that a change outside the parts keeps stored records current
and a change inside redoes them, while a new front (content or version) keeps them and changes their scores.
"""

from __future__ import annotations

import json
import os
import shutil
import subprocess
import sys
from dataclasses import replace
from pathlib import Path

import pandas as pd
import pytest

import pymoo_rail
from pymoo_rail.experiments import inputs as inputs_module
from pymoo_rail.experiments.inputs import (SUITE_RUN_PARTS, TRIP_RUN_PARTS, code_parts, front_digest, in_parts,
                                           resolve_run)
from pymoo_rail.experiments.baseline import front_versions, fronts_statement, indicator_frame
from pymoo_rail.experiments.results import load_records, records_frame
from pymoo_rail.experiments.runner import execute_run, run_study
from pymoo_rail.experiments.spec import Budget, RunSpec, Study, algorithm, problem
from pymoo_rail.suite import get_problem
from pymoo_rail.suite import families as families_module
from pymoo_rail.suite.families import FamilyProblem

PACKAGE = Path(pymoo_rail.__file__).resolve().parent
PROBE = Path(__file__).with_name("suite_run_probe.py")
FAMILY = "generated-metro-bi"

# executed by a run, but what they give it is fingerprinted by content, or is not one of its numbers
EXECUTED_OUTSIDE = {
    "cases": "generate the instance's line and train, whose content is in the instance checksum (case_hash)",
    "optimal/reference": "the planner's window and the time tolerance are in the instance checksum (a run never "
                         "reads the front: its record holds raw objective vectors)",
    "experiments/inputs.py": "computes the fingerprint itself, not a number of the run",
}
# loaded with the modules a run uses, but never on a run's path (a run calling them fails the test)
IMPORTED_ONLY = {
    "__init__.py": "the version string, in the fingerprint as 'pymoo-rail version'",
    "control": "problems/speed_profile.py imports Tracker for a tracked problem; a suite instance has no tracker",
    "journeys": "suite/families.py imports the trip module; only the -trip families run it (TRIP_RUN_PARTS)",
    "optimal": "the exact solver, imported by optimal.reference; a run gets its front by content (above)",
    "suite/__init__.py": "re-exports the suite's names",
    "suite/coco_logger.py": "a logger callback a study run does not use",
    "suite/ioh_logger.py": "a logger callback a study run does not use",
    "suite/run_log.py": "the loggers' base",
    "suite/fronts_io.py": "the named problems' shipped fronts (re-exported by suite/__init__.py)",
    "rowcache.py": "the exact solver's row cache (optimal)",
    "lockfiles.py": "the study store's locks, not a number of a run",
    "atomic.py": "atomic file writes (the study store, the fronts' caches); a run reads no front and writes no cache",
    "experiments/__init__.py": "re-exports the study runner's names",
    "experiments/results.py": "reads stored records (imported by experiments/__init__.py)",
    "experiments/store.py": "stores records, not their numbers",
    "experiments/study_file.py": "reads and writes study files (imported by experiments/__init__.py)",
}
# one run of each algorithm of the baseline table, and one run of each other form
PROBE_RUNS = [
    *[[FAMILY, name, params] for name, params in (
        ("nsga2", {"pop_size": 10}), ("sms-emoa", {"pop_size": 10}), ("nsga3", {"pop_size": 10}),
        ("ctaea", {"pop_size": 10}), ("moead", {"pop_size": 10}), ("age-moea", {"pop_size": 10}),
        ("moabc", {}), ("grnsga2", {"pop_size": 20}), ("random", {"n_points_per_iteration": 10}))],
    ["generated-metro-3obj", "nsga2", {"pop_size": 10}],
    ["generated-metro-single", "ga", {"pop_size": 10}],
    ["generated-metro-trip", "ga", {"pop_size": 10}],
]


def _listed(path: str, listing) -> bool:
    return in_parts(path, tuple(listing))


def test_every_part_and_listed_path_exists():
    for path in (*TRIP_RUN_PARTS, *EXECUTED_OUTSIDE, *IMPORTED_ONLY):
        assert (PACKAGE / path).exists(), f"{path} is not a file or folder of the package"


def test_a_suite_run_executes_only_code_its_fingerprint_covers():
    env = {**os.environ, "PYTHONPATH": os.pathsep.join([str(PACKAGE.parent), os.environ.get("PYTHONPATH", "")])}
    done = subprocess.run([sys.executable, str(PROBE), json.dumps(PROBE_RUNS)], capture_output=True, text=True,
                          env=env, timeout=600)
    assert done.returncode == 0, done.stderr[-3000:]
    probe = json.loads(done.stdout.splitlines()[-1])
    for (family, name, params), executed in zip(PROBE_RUNS, probe["executed"]):
        parts = code_parts(problem("suite_family", family=family))
        # the probe sees the run: the simulator, or for a trip the journeys' allocation problem
        assert ("journeys/problem.py" if family.endswith("-trip") else "sim/simulator.py") in executed, executed
        missed = [path for path in executed if not in_parts(path, parts) and not _listed(path, EXECUTED_OUTSIDE)]
        assert not missed, f"{family} / {name} executes {missed}: add them to the parts or list them here with why"
    modules = set(probe["modules"])
    unlisted = sorted(path for path in modules if not in_parts(path, TRIP_RUN_PARTS)
                      and not _listed(path, EXECUTED_OUTSIDE) and not _listed(path, IMPORTED_ONLY))
    assert not unlisted, f"loaded but neither in the parts nor listed with a reason: {unlisted}"
    # journeys is a part for the -trip runs only: the other runs never execute it
    others = [set(e) for (family, _, _), e in zip(PROBE_RUNS, probe["executed"]) if not family.endswith("-trip")]
    assert not any(in_parts(path, ("journeys",)) for e in others for path in e)


def test_code_parts_per_problem_kind():
    assert code_parts(problem("suite_family", family=FAMILY)) == SUITE_RUN_PARTS
    assert code_parts(problem("suite_family", family="generated-suburban-trip")) == TRIP_RUN_PARTS
    assert code_parts(problem("suite_family", family="atlantis-bi")) == SUITE_RUN_PARTS  # the run reports it
    assert code_parts(problem("zdt1")) is None
    assert code_parts(problem("rail_suite", suite_problem="yizhuang-bi")) is None
    for path in ("control", "optimal/dp.py", "optimal/reference/store.py", "cli", "plotting", "journeys", "cases",
                 "suite/coco_logger.py"):
        assert not in_parts(path, SUITE_RUN_PARTS)
    assert in_parts("journeys/problem.py", TRIP_RUN_PARTS)


@pytest.mark.parametrize("edited, suite_changes, trip_changes", [
    ("control/controllers.py", False, False), ("optimal/dp.py", False, False), ("cli/app.py", False, False),
    ("optimal/reference/store.py", False, False), ("optimal/reference/front.py", False, False),
    ("plotting/fronts.py", False, False), ("suite/coco_logger.py", False, False), ("cases/railjson.py", False, False),
    ("journeys/allocation.py", False, True), ("journeys/repaired.py", False, True),
    ("sim/kernel.py", True, True), ("constants.py", True, True), ("algorithms/moabc.py", True, True),
    ("experiments/penalty.py", True, True), ("problems/encodings/speed_codes.py", True, True),
    ("suite/families.py", True, True), ("indicators/spacing.py", True, True)])
def test_an_edit_outside_the_parts_keeps_the_digest_and_one_inside_changes_it(tmp_path, monkeypatch, edited,
                                                                                suite_changes, trip_changes):
    copy = tmp_path / "pymoo_rail"
    shutil.copytree(PACKAGE, copy, ignore=shutil.ignore_patterns("__pycache__"))
    monkeypatch.setattr(pymoo_rail, "__file__", str(copy / "__init__.py"))
    digest = inputs_module.package_digest.__wrapped__
    before = digest(SUITE_RUN_PARTS), digest(TRIP_RUN_PARTS), digest()
    with (copy / edited).open("a", encoding="utf-8") as file:
        file.write("\nEDITED_IN_A_TEST = 1\n")
    after = digest(SUITE_RUN_PARTS), digest(TRIP_RUN_PARTS), digest()
    assert (after[0] != before[0], after[1] != before[1], after[2] != before[2]) == (suite_changes, trip_changes, True)


def test_a_repaired_trip_run_is_fingerprinted_by_the_trip_parts_and_the_repair_module():
    # benchmarks/suite_baseline_trip.toml names its algorithms by import path (pymoo_rail.journeys.repaired)
    run = RunSpec(problem("suite_family", family="generated-metro-trip", n_var=10, seed=1),
                  algorithm("pymoo_rail.journeys.repaired:repaired_algorithm", method="ga", pop_size=10), 1,
                  Budget("n_eval", 20))
    fingerprint = resolve_run(run).fingerprint
    assert in_parts("journeys/repaired.py", TRIP_RUN_PARTS) and not in_parts("journeys/repaired.py", SUITE_RUN_PARTS)
    assert fingerprint["pymoo-rail code"] == inputs_module.package_digest(TRIP_RUN_PARTS)
    assert fingerprint["algorithm module pymoo_rail.journeys.repaired"].startswith("sha256:")


def _suite_study() -> Study:
    return Study("fingerprint", problems=[problem("suite_family", family=FAMILY, n_var=10, seed=1)],
                 algorithms=[algorithm("nsga2", pop_size=10)], seeds=1, budget={"n_eval": 40})


def test_stored_suite_runs_stay_current_after_a_change_outside_and_are_redone_after_one_inside(tmp_path,
                                                                                            monkeypatch):
    study = _suite_study()
    assert run_study(study, tmp_path, workers=1, progress=False).n_finished == 1
    real = inputs_module.package_digest

    def elsewhere(parts=None):  # the whole package changed (a controller fix), the parts did not
        return "sha256:" + "1" * 32 if parts is None else real(parts)

    monkeypatch.setattr(inputs_module, "package_digest", elsewhere)
    assert run_study(study, tmp_path, workers=1, progress=False).n_skipped == 1

    def inside(parts=None):  # the simulator changed
        return "sha256:" + "2" * 32 if parts is not None and "sim" in parts else real(parts)

    monkeypatch.setattr(inputs_module, "package_digest", inside)
    report = run_study(study, tmp_path, workers=1, progress=False)
    assert report.n_finished == 1 and "pymoo-rail code changed" in report.redone[0]


def _scaled_front(front, factor: float):
    """The front with every node's energy times ``factor`` (another solver's answer)."""
    table = front.table.copy()
    table["energy_kwh"] = table["energy_kwh"] * factor
    return replace(front, table=table)


def test_records_loaded_without_decision_vectors_score_the_same(tmp_path):
    study = _suite_study()
    run_study(study, tmp_path, workers=1, progress=False)
    full, lean = load_records(tmp_path, study), load_records(tmp_path, study, decisions=False)
    assert len(full[0]["front"]["X"]) == len(full[0]["front"]["F"]) > 0
    assert "X" not in lean[0]["front"] and lean[0]["front"]["F"] == full[0]["front"]["F"]
    pd.testing.assert_frame_equal(indicator_frame(lean), indicator_frame(full))
    assert "X" not in load_records(tmp_path, all_runs=True, decisions=False)[0]["front"]
    with pytest.raises(ValueError, match="decisions=False.*fronts=False"):
        records_frame(lean)
    assert len(records_frame(lean, fronts=False)) == 1


def test_stored_suite_runs_stay_current_when_the_front_improves_and_their_scores_follow_it(tmp_path, monkeypatch):
    study = _suite_study()
    run_study(study, tmp_path, workers=1, progress=False)
    records = load_records(tmp_path, study)
    before = indicator_frame(records).iloc[0]
    instance = get_problem(FAMILY, n_var=10, seed=1)
    digest, version = front_digest(instance), instance.front_version
    real = FamilyProblem.certified_front
    # another front (a solver that finds 1 % lower energies) under a new front version: the same code digest
    monkeypatch.setattr(FamilyProblem, "certified_front", lambda self: _scaled_front(real(self), 0.99))
    monkeypatch.setattr(families_module, "FRONT_VERSION", "99")
    instance = get_problem(FAMILY, n_var=10, seed=1)
    assert instance.front_version == "99" != version and front_digest(instance) != digest
    report = run_study(study, tmp_path, workers=1, progress=False)
    assert report.n_skipped == 1 and report.n_finished == 0 and not report.redone
    after = indicator_frame(load_records(tmp_path, study)).iloc[0]
    # the same raw vectors, scored against the lower front: farther from it, less of its hypervolume
    assert after["igd_plus"] > before["igd_plus"] and after["gap_kwh"] > before["gap_kwh"]
    assert after["hv_norm"] != before["hv_norm"]
    fronts = front_versions(records)
    assert fronts["front_version"].tolist() == ["99"] and fronts["front_digest"].tolist() == [front_digest(instance)]
    assert "version 99 (1 instance)" in fronts_statement(fronts)


@pytest.mark.parametrize("family", [FAMILY, "generated-metro-3obj"])
def test_a_suite_run_never_reads_its_front(monkeypatch, family):
    def refuse(self, *args, **kwargs):
        raise AssertionError("a suite run read its front")

    for name in ("certified_front", "bounded_front", "_calc_pareto_front", "hv_reference_point"):
        monkeypatch.setattr(FamilyProblem, name, refuse)
    spec = problem("suite_family", family=family, n_var=10, seed=1)
    record = execute_run(RunSpec(spec, algorithm("nsga2", pop_size=10), 1, Budget("n_eval", 220)))
    assert record["checkpoints"]["target_n_eval"] == [200] and len(record["checkpoints"]["F"][0][0]) == record["n_obj"]


def test_a_front_counts_as_cached_so_the_process_that_computed_it_agrees_with_later_ones(monkeypatch):
    """The cache holds a front's nodes to 9 digits: a difference below that is no change, one above is."""
    problem = get_problem(FAMILY, n_var=10, seed=1)
    before = front_digest(problem)
    real = FamilyProblem.certified_front
    for factor, same in ((1 + 1e-12, True), (1 + 1e-6, False)):
        monkeypatch.setattr(FamilyProblem, "certified_front", lambda self, f=factor: _scaled_front(real(self), f))
        assert (front_digest(get_problem(FAMILY, n_var=10, seed=1)) == before) is same
    monkeypatch.setattr(FamilyProblem, "certified_front", real)
    # a -3obj front is its inner points (cached exactly) with its line's certified front
    inner = front_digest(get_problem("generated-metro-3obj", n_var=10, seed=1))
    assert inner.startswith("sha256:") and inner != before


def test_the_front_digest_is_of_its_content():
    fingerprint = resolve_run(RunSpec(problem("suite_family", family=FAMILY, n_var=10, seed=1), algorithm("nsga2"),
                                      1, Budget("n_eval", 40))).fingerprint
    small, large = get_problem(FAMILY, n_var=10, seed=1), get_problem(FAMILY, n_var=30, seed=1)
    assert "problem reference front" not in fingerprint  # the record holds raw vectors: no front in it
    assert front_digest(small) == front_digest(large)  # every dimension of a line has the same front
    assert front_digest(small) != front_digest(get_problem(FAMILY, n_var=10, seed=7))  # another line
