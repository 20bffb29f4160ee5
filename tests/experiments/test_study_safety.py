"""A study or a results folder runs nothing the user did not mean to run, serves nothing stale, writes
nowhere else, and refuses a misspelt parameter before any run (issues 30 and 34)."""

from __future__ import annotations

import errno
import json
import re
import shutil
import textwrap
from pathlib import Path

import numpy as np
import pytest

import pymoo_rail
from pymoo_rail.cases import case_path
from pymoo_rail.cli import main
from pymoo_rail.experiments import (ResultStore, RunSpec, Study, StudyError, algorithm, execute_run, load_results,
                                    problem, read_study, run_study, write_study)
from pymoo_rail.experiments import inputs as inputs_module
from pymoo_rail.experiments import runner as runner_module
from pymoo_rail.experiments import stats
from pymoo_rail.experiments.registry import UntrustedCodeError
from pymoo_rail.experiments.store import LegacyRecordError, RecordError, StoreError, record_checksum

STUDIES = "tests.experiments.studies"


def _zdt_study(name: str = "tiny", seeds: int = 1, **algorithm_params) -> Study:
    return Study(name, problems=[problem("zdt1", n_var=4)],
                 algorithms=[algorithm("nsga2", pop_size=8, **algorithm_params)], seeds=seeds, budget={"n_gen": 2})


# ----------------------------------------------------------------------------- no code runs


def _evil_toml(marker: Path, where: str) -> str:
    touch = f"touch {marker}"
    problem_entry = f'problem = "os:system"\ncommand = "{touch}"' if where == "problem" else 'problem = "zdt1"'
    algorithm_entry = {
        "problem": 'algorithm = "nsga2"',
        "algorithm": f'algorithm = "subprocess:getoutput"\ncmd = "{touch}"',
        "crossover": f'algorithm = "nsga2"\ncrossover = {{operator = "os:system", command = "{touch}"}}',
    }[where]
    return (f'name = "evil"\n[budget]\nn_gen = 1\n[[problems]]\n{problem_entry}\n'
            f"[[algorithms]]\n{algorithm_entry}\n")


@pytest.mark.parametrize("where, field", [("problem", "problems[0].problem"),
                                          ("algorithm", "algorithms[0].algorithm"),
                                          ("crossover", "algorithms[0].crossover.operator")])
def test_a_study_file_naming_code_runs_nothing_without_trust(tmp_path, capsys, where, field):
    marker = tmp_path / "pwned"
    study_file = tmp_path / "evil.toml"
    study_file.write_text(_evil_toml(marker, where))
    study = read_study(study_file)  # reading names nothing to import
    with pytest.raises(UntrustedCodeError, match=rf"{re.escape(field)}' = '(os:system|subprocess:getoutput)'"
                                                 r".*trusted=True.*--trust"):
        run_study(study, tmp_path / "out", workers=1, progress=False)
    assert not marker.exists() and not (tmp_path / "out").exists()
    code = main(["study", str(study_file), "--workers", "1", "--out", str(tmp_path / "cli"), "-q"])
    err = capsys.readouterr().err
    assert code == 2 and "--trust" in err and field in err and not marker.exists()


def test_finding_an_untrusted_module_imports_nothing(tmp_path, monkeypatch):
    """Looking a module up (for its digest) imports its parent package: not before trust is given."""
    package = tmp_path / "evilpkg"
    package.mkdir()
    marker = tmp_path / "imported"
    (package / "__init__.py").write_text(f"open({str(marker)!r}, 'w').close()\n")
    (package / "problems.py").write_text("from pymoo.problems import get_problem\n"
                                         "def zdt(n_var=4):\n    return get_problem('zdt1', n_var=n_var)\n")
    monkeypatch.syspath_prepend(str(tmp_path))
    study = Study("plugin", problems=[problem("evilpkg.problems:zdt")], algorithms=[algorithm("nsga2", pop_size=6)],
                  budget={"n_gen": 1})
    with pytest.raises(UntrustedCodeError, match="problems\\[0\\].problem"):
        run_study(study, tmp_path / "out", workers=1, progress=False)
    assert not marker.exists()
    report = run_study(study, tmp_path / "out", workers=1, progress=False, trusted=True)  # the user says so
    assert report.n_finished == 1 and marker.exists()
    marker.unlink()
    with pytest.raises(UntrustedCodeError):
        load_results(tmp_path / "out")
    assert not marker.exists()
    assert len(load_results(tmp_path / "out", trusted=True)) == 1


def _received_folder(tmp_path: Path, marker: Path) -> Path:
    """A results folder as someone could send it: records with valid checksums whose spec runs a command."""
    folder = tmp_path / "received"
    honest = _zdt_study()
    evil = Study("evil", problems=[problem("os:system", command=f"touch {marker}")], algorithms=honest.algorithms,
                 budget=honest.budget)
    run_study(honest, folder, workers=1, progress=False)
    store = ResultStore(folder)
    record = store.read(honest.runs()[0].run_id)
    store.path(record["run_id"]).unlink()
    run = evil.runs()[0]
    record.update(run_id=run.run_id, problem=run.problem.identity())
    record.pop("checksum")
    record["checksum"] = record_checksum(record)
    store.path(run.run_id).write_text(json.dumps(record))
    write_study(evil, folder / "study.toml")
    return folder


def test_a_received_results_folder_runs_nothing_when_read_or_plotted(tmp_path, capsys):
    marker = tmp_path / "pwned"
    folder = _received_folder(tmp_path, marker)
    with pytest.raises(UntrustedCodeError, match=r"problems\[0\].problem' = 'os:system'.*--trust"):
        load_results(folder)
    code = main(["plot", "study", str(folder), "--out", str(tmp_path / "figures")])
    err = capsys.readouterr().err
    assert code == 2 and "--trust" in err and "os:system" in err
    # every record, with the labels it carries: nothing is rebuilt, and plotting draws no true front
    from pymoo_rail.plotting import plot_study

    results = load_results(folder, all_runs=True)
    with pytest.warns(UserWarning, match="true front of problem 'os:system' is not drawn.*trusted=True"):
        written = plot_study(results, tmp_path / "figures")
    assert written and not marker.exists()


# ------------------------------------------------------------------------ nothing stale


def test_a_case_edited_while_a_study_runs_never_reaches_a_run(tmp_path, monkeypatch):
    """Every run uses the case as it was read when the study started, and carries its digest."""
    case_file = tmp_path / "line.toml"
    original = case_path("metro-a").read_text(encoding="utf-8")
    assert "mass_t = 332.0" in original
    case_file.write_text(original, encoding="utf-8")
    study = Study("edit", problems=[problem("speed_profile", case=str(case_file), encoding="switching_points",
                                            objectives=["energy", "running_time"])],
                  algorithms=[algorithm("nsga2", pop_size=6)], seeds=2, budget={"n_gen": 2})
    calm = run_study(study, tmp_path / "calm", workers=1, progress=False)
    assert calm.n_finished == 2

    real_pending = runner_module.pending_runs

    def edit_then_run(*args, **kwargs):  # the user saves an edit once the study has started
        case_file.write_text(original.replace("mass_t = 332.0", "mass_t = 300.0"), encoding="utf-8")
        return real_pending(*args, **kwargs)

    monkeypatch.setattr(runner_module, "pending_runs", edit_then_run)
    busy = run_study(study, tmp_path / "busy", workers=1, progress=False)
    monkeypatch.undo()
    assert busy.n_finished == 2
    calm_records = {r["run_id"]: r for r in ResultStore(tmp_path / "calm").records()}
    for record in ResultStore(tmp_path / "busy").records():
        same = calm_records[record["run_id"]]
        assert record["front"] == same["front"] and record["inputs"] == same["inputs"]
    # the file now holds the edit: the stored runs are redone on it, never served
    again = run_study(study, tmp_path / "busy", workers=1, progress=False)
    assert (again.n_skipped, again.n_finished) == (0, 2)
    assert all("problem.case" in note for note in again.redone)
    case_file.write_text(original, encoding="utf-8")  # reverted: what is stored now is the edited content
    assert run_study(study, tmp_path / "busy", workers=1, progress=False).n_finished == 2


def test_changed_package_code_with_the_same_version_reruns(tmp_path, monkeypatch):
    study = _zdt_study()
    run_study(study, tmp_path, workers=1, progress=False)
    assert run_study(study, tmp_path, workers=1, progress=False).n_skipped == 1
    monkeypatch.setattr(inputs_module, "package_digest", lambda parts=None: "sha256:" + "0" * 32)
    report = run_study(study, tmp_path, workers=1, progress=False)
    assert report.n_finished == 1 and "pymoo-rail code changed" in report.redone[0]
    assert "same version string" in report.redone[0]


def test_the_package_digest_follows_every_source_file(tmp_path, monkeypatch):
    """The audit's case: GRAVITY_MS2 = 9.0 with the version string unchanged."""
    root = Path(pymoo_rail.__file__).parent
    copy = tmp_path / "pymoo_rail"
    shutil.copytree(root, copy, ignore=shutil.ignore_patterns("__pycache__"))
    monkeypatch.setattr(pymoo_rail, "__file__", str(copy / "__init__.py"))
    digest = inputs_module.package_digest.__wrapped__
    before = digest()
    assert before == digest()  # the same files, the same digest
    source = next(p for p in sorted(copy.rglob("*.py")) if "GRAVITY_MS2 = " in p.read_text())
    text = source.read_text()
    source.write_text(text.replace("GRAVITY_MS2 = ", "GRAVITY_MS2 = 9.0  # ", 1))
    assert digest() != before
    keys = inputs_module.versions_input()
    assert {"pymoo-rail code", "pymoo-rail version", "pymoo version", "numpy version", "numba version"} <= set(keys)


def test_a_format_1_record_is_never_served_and_is_redone(tmp_path):
    study = _zdt_study()
    run_study(study, tmp_path, workers=1, progress=False)
    store = ResultStore(tmp_path)
    run_id = study.runs()[0].run_id
    intact = store.read(run_id)
    legacy = {**intact, "format": "pymoo-rail/run-record/1"}
    legacy.pop("checksum")
    legacy["front"] = {**legacy["front"], "F": np.zeros_like(legacy["front"]["F"]).tolist()}  # a zeroed front
    store.path(run_id).write_text(json.dumps(legacy))
    with pytest.raises(LegacyRecordError, match=rf"{run_id}.json: field 'format' = 'pymoo-rail/run-record/1'"):
        load_results(tmp_path)
    report = run_study(study, tmp_path, workers=1, progress=False)
    assert (report.n_skipped, report.n_finished) == (0, 1)
    assert "older record" in report.redone[0] and "stale" in report.redone[0]
    assert store.read(run_id)["front"] == intact["front"]


def test_a_checksum_mismatch_is_redone(tmp_path):
    study = _zdt_study()
    run_study(study, tmp_path, workers=1, progress=False)
    store = ResultStore(tmp_path)
    run_id = study.runs()[0].run_id
    record = store.read(run_id)
    record["indicators"]["igd"] = 0.0
    store.path(run_id).write_text(json.dumps(record))
    report = run_study(study, tmp_path, workers=1, progress=False)
    assert report.n_finished == 1 and "checksum" in report.redone[0]


def test_a_record_whose_id_is_not_its_own_is_refused(tmp_path):
    study = _zdt_study(seeds=2)
    run_study(study, tmp_path, workers=1, progress=False)
    store = ResultStore(tmp_path)
    first, second = (r.run_id for r in study.runs())
    record = store.read(first)
    record.update(run_id=second, checksum=None)
    record["checksum"] = record_checksum(record)
    store.path(second).write_text(json.dumps(record))  # a valid checksum on another run's content
    with pytest.raises(RecordError, match=rf"{second}.json: field 'run_id' = .*own problem"):
        store.read(second)


# -------------------------------------------------------------------------- where it writes


@pytest.mark.parametrize("name", ["/abs/dir", "../../x", "a/b", "..", ".hidden", "x\\y", "C:x", " pad"])
def test_a_study_name_is_a_name_not_a_path(tmp_path, name):
    with pytest.raises(StudyError, match=r"field 'name' = .*must be a name, not a path"):
        Study(name, problems=[problem("zdt1")], algorithms=[algorithm("nsga2")])
    study_file = tmp_path / "s.toml"
    study_file.write_text(f'name = {json.dumps(name)}\n[budget]\nn_gen = 1\n[[problems]]\nproblem = "zdt1"\n'
                          '[[algorithms]]\nalgorithm = "nsga2"\n')
    with pytest.raises(StudyError, match=rf"{study_file}: field 'name'"):
        read_study(study_file)


def test_a_planted_symlink_as_lock_file_is_named(tmp_path):
    study = _zdt_study(seeds=2)
    target = tmp_path / "elsewhere"
    target.write_text("")
    locks = tmp_path / "out" / "locks"
    locks.mkdir(parents=True)
    lock = locks / f"{study.runs()[1].run_id}.lock"
    lock.symlink_to(target)
    with pytest.raises(StoreError, match=rf"{lock}: the lock file is not a regular file"):
        run_study(study, tmp_path / "out", workers=1, progress=False)
    assert target.read_text() == ""


def test_a_full_disk_stops_naming_the_file_and_keeps_finished_runs(tmp_path, monkeypatch):
    from pymoo_rail.experiments import store as store_module

    study = _zdt_study(seeds=3)
    real_write = store_module.atomic_write_text
    calls = []

    def fill_up(path, text):
        calls.append(path)
        if len(calls) >= 2:
            raise OSError(errno.ENOSPC, "No space left on device", str(path))
        return real_write(path, text)

    monkeypatch.setattr(store_module, "atomic_write_text", fill_up)
    with pytest.raises(StoreError) as raised:
        run_study(study, tmp_path, workers=1, progress=False)
    message = str(raised.value)
    assert str(calls[1]) in message and "no space left" in message and "kept in runs/" in message
    assert raised.value.errno == errno.ENOSPC
    monkeypatch.undo()
    report = run_study(study, tmp_path, workers=1, progress=False)
    assert (report.n_skipped, report.n_finished) == (1, 2)


# -------------------------------------------------------------------------- strict files


@pytest.mark.parametrize("spec, field, hint", [
    ({"algorithm": algorithm("nsga2", pop_sise=40)}, r"algorithms\[0\].pop_sise' = 40", "pop_size"),
    ({"problem": problem("zdt1", n_vars=8)}, r"problems\[0\].n_vars' = 8", "n_var"),
    ({"problem": problem("speed_profile", case="yizhuang", objective=["energy"])},
     r"problems\[0\].objective' = \['energy'\]", "objectives"),
    ({"algorithm": algorithm("de", CR=0.5, FF=0.3)}, r"algorithms\[0\].FF' = 0.3", "F"),
    ({"algorithm": algorithm("nsga2", mutation={"operator": "pm", "etaa": 3})},
     r"algorithms\[0\].mutation.etaa' = 3", "eta"),
])
def test_a_misspelt_parameter_is_refused_before_any_run(tmp_path, spec, field, hint):
    p = spec.get("problem", problem("zdt1", n_var=4))
    a = spec.get("algorithm", algorithm("nsga2", pop_size=6))
    if a.name == "de":
        p = problem("sphere", n_var=3)
    study = Study("typo", problems=[p], algorithms=[a], budget={"n_gen": 1})
    with pytest.raises(StudyError, match=rf"{field}: unknown parameter .*did you mean '{hint}'"):
        run_study(study, tmp_path / "out", workers=1, progress=False)
    assert not (tmp_path / "out").exists()  # nothing started, nothing written


def test_a_study_file_with_a_typo_names_file_field_and_the_accepted_names(tmp_path, capsys):
    study_file = tmp_path / "typo.toml"
    study_file.write_text(textwrap.dedent("""\
        name = "typo"
        [budget]
        n_gen = 1
        [[problems]]
        problem = "zdt1"
        [[algorithms]]
        algorithm = "nsga2"
        pop_sise = 40
        """))
    code = main(["study", str(study_file), "--workers", "1", "--out", str(tmp_path / "out"), "-q"])
    err = capsys.readouterr().err
    assert code == 2 and "algorithms[0].pop_sise" in err and "pop_size" in err
    assert not (tmp_path / "out" / "runs").exists()


def test_a_missing_indicator_is_a_stated_reason_in_the_table(tmp_path):
    study = Study("why", problems=[problem("zdt1", n_var=4), problem(f"{STUDIES}:case_sphere", label="sphere",
                                                                      case="metro-a")],
                  algorithms=[algorithm("nsga2", pop_size=8)], seeds=2, budget={"n_gen": 3})
    run_study(study, tmp_path, workers=1, progress=False, trusted=True)
    results = load_results(tmp_path, trusted=True)
    table = stats.indicator_table(results, "igd")
    assert set(table.index) == {"zdt1", "sphere"}  # no row dropped
    assert table.loc["sphere", "nsga2"].startswith("n/a: no true front")
    assert table.loc["zdt1", "nsga2"].startswith("*")
    sphere = results[results["problem"] == "sphere"].iloc[0]
    assert np.isnan(sphere["igd"]) and "no true front" in sphere["unavailable"]["igd"]


def test_execute_run_uses_the_case_it_was_given(tmp_path):
    """The run's fingerprint and its case come from one read."""
    case_file = tmp_path / "line.toml"
    original = case_path("metro-a").read_text(encoding="utf-8")
    case_file.write_text(original, encoding="utf-8")
    run = RunSpec(problem("speed_profile", case=str(case_file), encoding="switching_points"),
                  algorithm("nsga2", pop_size=6), 1, _zdt_study().budget)
    resolved = inputs_module.resolve_run(run)
    assert resolved.cases[str(case_file)].train.mass_t == 332.0
    case_file.write_text(original.replace("mass_t = 332.0", "mass_t = 300.0"), encoding="utf-8")
    record = execute_run(run, resolved)
    assert record["inputs"] == dict(resolved.fingerprint)
    fresh = execute_run(run)  # read now: the edited file
    assert fresh["inputs"] != record["inputs"] and fresh["front"]["F"] != record["front"]["F"]


def test_trust_on_the_command_line_runs_and_replots_an_import_path_study(tmp_path, capsys):
    study_file = tmp_path / "plugin.toml"
    study_file.write_text('name = "plugin"\nseeds = 2\n[budget]\nn_gen = 2\n[[problems]]\n'
                          'problem = "pymoo.problems.multi.zdt:ZDT1"\nn_var = 4\n'
                          '[[algorithms]]\nalgorithm = "nsga2"\npop_size = 6\n')
    out = tmp_path / "out"
    assert main(["study", str(study_file), "--workers", "1", "--out", str(out), "-q", "--no-plots"]) == 2
    assert "--trust" in capsys.readouterr().err and not (out / "runs").exists()
    assert main(["study", str(study_file), "--workers", "1", "--out", str(out), "-q", "--no-plots", "--trust"]) == 0
    capsys.readouterr()
    assert main(["plot", "study", str(out), "--out", str(tmp_path / "figures")]) == 2
    assert "--trust" in capsys.readouterr().err
    assert main(["plot", "study", str(out), "--out", str(tmp_path / "figures"), "--trust"]) == 0
    assert list((tmp_path / "figures").rglob("front_*.png"))  # with the true front, rebuilt because trusted


@pytest.mark.parametrize("workers", [1, 2])
def test_run_study_from_python_leaves_no_lock_files(tmp_path, workers):
    # the library call, not only the CLI: each claim's file goes as the claim is released
    report = run_study(_zdt_study(seeds=3), tmp_path / "out", workers=workers, progress=False)
    assert report.n_finished == 3
    assert not (tmp_path / "out" / "locks").exists()
    assert [p.name for p in (tmp_path / "out").rglob("*.lock")] == []
