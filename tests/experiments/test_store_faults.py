"""The study store under the faults a careless user causes: an edited case, a damaged record,
two studies on one folder, a killed study process (its pool workers must not outlive it)."""

from __future__ import annotations

import json
import os
import signal
import subprocess
import sys
import time
from pathlib import Path

import pytest

from pymoo_rail.cases import case_path
from pymoo_rail.experiments import ResultStore, Study, algorithm, load_results, problem, run_study
from pymoo_rail.experiments.store import RECORD_FORMAT, RecordError

REPO = Path(__file__).resolve().parents[2]
STUDIES = "tests.experiments.studies"


def _tiny_study(n_seeds: int = 3, **problem_params) -> Study:
    return Study("tiny", problems=[problem("zdt1", n_var=4, **problem_params)],
                 algorithms=[algorithm("nsga2", pop_size=8)], seeds=n_seeds, budget={"n_gen": 3})


# ------------------------------------------------------------------------- stale inputs


def test_an_edited_case_file_is_rerun_and_the_message_says_why(tmp_path, capsys):
    case_file = tmp_path / "my-case.toml"
    original = case_path("metro-a").read_text(encoding="utf-8")
    case_file.write_text(original, encoding="utf-8")
    study = Study("case", problems=[problem(f"{STUDIES}:case_sphere", case=str(case_file))],
                  algorithms=[algorithm("nsga2", pop_size=8)], seeds=2, budget={"n_gen": 3})
    out = tmp_path / "out"
    first = run_study(study, out, workers=1, progress=False, trusted=True)
    assert first.n_finished == 2
    before = load_results(out, trusted=True)

    # a comment changes nothing the result depends on: still stored
    case_file.write_text("# a note\n" + original, encoding="utf-8")
    assert run_study(study, out, workers=1, progress=False, trusted=True).n_skipped == 2

    # the mass (332 t) does: the same study file now recomputes both runs, and says so
    assert "mass_t = 332.0" in original
    case_file.write_text(original.replace("mass_t = 332.0", "mass_t = 300.0"), encoding="utf-8")
    again = run_study(study, out, workers=1, progress=False, trusted=True)
    assert (again.n_skipped, again.n_finished) == (0, 2)
    assert len(again.redone) == 2 and all("problem.case" in note and "changed" in note for note in again.redone)
    assert "REDO" in capsys.readouterr().err
    after = load_results(out, trusted=True)
    assert len(after) == 2 and len(list((out / "stale").iterdir())) == 2
    # each stored front was computed from the case as it was then: f1 = |x - mass / 1000|^2
    for frame, centre in ((before, 0.332), (after, 0.300)):
        X, F = frame["X"].iloc[0], frame["F"].iloc[0]
        assert F[:, 0] == pytest.approx(((X - centre) ** 2).sum(axis=1), rel=1e-12)


def test_a_new_package_version_reruns_a_stored_run(tmp_path, monkeypatch):
    import pymoo_rail

    study = _tiny_study(n_seeds=1)
    run_study(study, tmp_path, workers=1, progress=False)
    monkeypatch.setattr(pymoo_rail, "__version__", pymoo_rail.__version__ + ".post1")
    report = run_study(study, tmp_path, workers=1, progress=False)
    assert report.n_finished == 1 and "pymoo-rail version changed" in report.redone[0]


# ----------------------------------------------------------------------- damaged records


def test_truncated_empty_and_altered_records_are_detected_named_set_aside_and_redone(tmp_path):
    study = _tiny_study(n_seeds=3)
    run_study(study, tmp_path, workers=1, progress=False)
    store = ResultStore(tmp_path)
    paths = [store.path(r.run_id) for r in study.runs()]
    intact = {p.name: json.loads(p.read_text())["front"] for p in paths}
    text = paths[0].read_text()
    paths[0].write_text(text[: len(text) // 2])                      # truncated
    paths[1].write_text("")                                          # emptied
    record = json.loads(paths[2].read_text())
    record["front"]["F"][0][0] += 1e-3                               # altered, still valid JSON
    paths[2].write_text(json.dumps(record))

    with pytest.raises(RecordError) as raised:                       # tables name the file
        load_results(tmp_path)
    assert raised.value.path in paths and str(raised.value.path) in str(raised.value)
    for path, what in zip(paths, ("not valid JSON", "empty", "checksum")):
        with pytest.raises(RecordError, match=what):
            store.check(path)

    report = run_study(study, tmp_path, workers=1, progress=False)
    assert (report.n_skipped, report.n_finished) == (0, 3)
    for path, note in zip(paths, report.redone):
        assert str(path) in note and "moved to" in note
    assert len(list((tmp_path / "corrupt").iterdir())) == 3
    redone = {p.name: store.check(p)["front"] for p in paths}
    assert redone == intact  # the same seed gives the same run again
    assert len(load_results(tmp_path)) == 3


# ------------------------------------------------------------------- real processes


def _env(**extra) -> dict:
    return {**os.environ, "PYTHONPATH": os.pathsep.join([str(REPO), os.environ.get("PYTHONPATH", "")]),
            "NUMBA_NUM_THREADS": "1", **extra}


def _script(directory: Path, workers: int, n_seeds: int, delay_s: float) -> str:
    return (
        "import sys\n"
        f"sys.path.insert(0, {str(REPO)!r})\n"
        "from pymoo_rail.experiments import Study, algorithm, problem, run_study\n"
        "if __name__ == '__main__':\n"
        f"    study = Study('shared', problems=[problem('{STUDIES}:slow_zdt1', n_var=4, delay_s={delay_s})],\n"
        "                  algorithms=[algorithm('nsga2', pop_size=8)], "
        f"seeds={n_seeds}, budget={{'n_gen': 3}})\n"
        f"    r = run_study(study, {str(directory)!r}, workers={workers}, progress=False, check=False, trusted=True)\n"
        "    print(r.n_finished, r.n_elsewhere, r.n_skipped, len(r.failures))\n"
    )


def test_two_studies_on_one_folder_compute_each_run_once(tmp_path):
    log = tmp_path / "computations.log"
    out = tmp_path / "out"
    script = _script(out, workers=1, n_seeds=8, delay_s=0.3)
    procs = [subprocess.Popen([sys.executable, "-c", script], env=_env(PYMOO_RAIL_TEST_LOG=str(log)),
                              stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True) for _ in range(2)]
    results = [p.communicate(timeout=300) for p in procs]
    for proc, (stdout, stderr) in zip(procs, results):
        assert proc.returncode == 0, stderr[-3000:]
    counts = [tuple(int(v) for v in stdout.split()) for stdout, _ in results]
    assert sum(c[0] for c in counts) == 8 and all(c[3] == 0 for c in counts)   # 8 computed, none failed
    assert all(c[0] + c[1] + c[2] == 8 for c in counts)                           # each saw all 8 stored
    assert len(log.read_text().splitlines()) == 8                                 # built once per run
    pids = set(log.read_text().split())
    assert len(pids) == 2, "both processes should have computed part of the study"
    assert len(ResultStore(out).done_ids()) == 8 and len(load_results(out, trusted=True)) == 8
    assert not list(out.rglob(".tmp-*"))


def _children(pid: int) -> list[int]:
    found = []
    for entry in Path("/proc").iterdir():
        if entry.name.isdigit():
            try:
                stat = (entry / "stat").read_text()
            except OSError:
                continue
            if int(stat.rsplit(")", 1)[1].split()[1]) == pid:
                found.append(int(entry.name))
    return found


def _alive(pid: int) -> bool:
    try:
        state = Path(f"/proc/{pid}/stat").read_text().rsplit(")", 1)[1].split()[0]
    except OSError:
        return False
    return state != "Z"


@pytest.mark.skipif(not Path("/proc/self/stat").exists(), reason="finds the pool workers through /proc")
def test_killed_study_process_its_workers_exit_and_keep_every_run_they_finished(tmp_path):
    """Stop the study process (so it can no longer store anything), let its pool workers finish
    runs, then kill -9 it: the runs the workers finished are stored, and the workers exit."""
    out = tmp_path / "out"
    runs_dir = out / "runs"
    proc = subprocess.Popen([sys.executable, "-c", _script(out, workers=2, n_seeds=10, delay_s=0.4)],
                            env=_env(), start_new_session=True, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE)
    workers: list[int] = []
    try:
        deadline = time.monotonic() + 180
        while time.monotonic() < deadline and proc.poll() is None and not (
                runs_dir.is_dir() and list(runs_dir.glob("*.json"))):
            time.sleep(0.05)
        assert proc.poll() is None, proc.stderr.read().decode()[-3000:]
        workers = _children(proc.pid)
        os.kill(proc.pid, signal.SIGSTOP)  # the driver receives nothing from now on
        stored_by_driver_time = len(list(runs_dir.glob("*.json")))
        deadline = time.monotonic() + 60
        while time.monotonic() < deadline and len(list(runs_dir.glob("*.json"))) <= stored_by_driver_time:
            time.sleep(0.05)
        finished_by_workers = len(list(runs_dir.glob("*.json")))
        assert finished_by_workers > stored_by_driver_time, "the workers stored no run on their own"
        os.kill(proc.pid, signal.SIGKILL)
        proc.wait(timeout=30)
        deadline = time.monotonic() + 30
        while time.monotonic() < deadline and any(_alive(w) for w in workers):
            time.sleep(0.1)
        orphans = [w for w in workers if _alive(w)]
    finally:
        try:
            os.killpg(proc.pid, signal.SIGKILL)
        except (ProcessLookupError, PermissionError):
            pass
    assert workers and not orphans, f"pool workers {orphans} outlived the study process"

    store = ResultStore(out)
    stored = sorted(runs_dir.glob("*.json"))
    assert len(stored) >= finished_by_workers
    for path in stored:
        assert store.check(path)["format"] == RECORD_FORMAT
    again = Study("shared", problems=[problem(f"{STUDIES}:slow_zdt1", n_var=4, delay_s=0.4)],
                  algorithms=[algorithm("nsga2", pop_size=8)], seeds=10, budget={"n_gen": 3})
    report = run_study(again, out, workers=2, progress=False, check=False, trusted=True)
    assert (report.n_skipped, report.n_finished, report.failures) == (len(stored), 10 - len(stored), [])


def test_tables_leave_out_a_record_whose_case_changed_and_say_so(tmp_path):
    case_file = tmp_path / "my-case.toml"
    original = case_path("metro-a").read_text(encoding="utf-8")
    case_file.write_text(original, encoding="utf-8")
    study = Study("case", problems=[problem(f"{STUDIES}:case_sphere", case=str(case_file))],
                  algorithms=[algorithm("nsga2", pop_size=8)], seeds=1, budget={"n_gen": 2})
    run_study(study, tmp_path / "out", workers=1, progress=False, trusted=True)
    case_file.write_text(original.replace("mass_t = 332.0", "mass_t = 300.0"), encoding="utf-8")
    with pytest.warns(UserWarning, match="problem.case .* changed"):
        assert load_results(tmp_path / "out", trusted=True).empty


def test_written_files_get_the_mode_open_gives_them(tmp_path, monkeypatch):
    monkeypatch.setenv("MPLBACKEND", "Agg")
    from pymoo_rail.atomic import atomic_path, atomic_write_text
    from pymoo_rail.plotting.style import new_figure, save_figure

    old = os.umask(0o022)
    try:
        record = atomic_write_text(tmp_path / "a.json", "{}")
        fig, _ = new_figure()
        figure = save_figure(fig, tmp_path / "f.png")
        with open(tmp_path / "plain.txt", "w") as handle:
            handle.write("x")
        os.umask(0o077)
        private = atomic_write_text(tmp_path / "b.json", "{}")
        os.chmod(record, 0o640)
        with atomic_path(record) as tmp:  # overwriting keeps the file's mode, as open() does
            tmp.write_text("[]")
    finally:
        os.umask(old)
    mode = lambda p: os.stat(p).st_mode & 0o777  # noqa: E731
    assert mode(tmp_path / "plain.txt") == 0o644
    assert (mode(figure), mode(private), mode(record)) == (0o644, 0o600, 0o640)
    assert record.read_text() == "[]" and not list(tmp_path.glob(".tmp-*"))
