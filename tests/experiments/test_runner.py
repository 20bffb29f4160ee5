"""Running studies: local pool, Dask, in-process; resume after a kill; failures; the store."""

from __future__ import annotations

import os
import signal
import subprocess
import sys
import time
from pathlib import Path

import numpy as np
import pytest

from pymoo_rail.experiments import ResultStore, Study, algorithm, execute_run, load_results, problem, run_study
from pymoo_rail.experiments.stats import write_tables
from pymoo_rail.experiments.store import RECORD_FORMAT
from tests.experiments.studies import small_study

REPO = Path(__file__).resolve().parents[2]


def _fronts_equal(a, b) -> None:
    """Two results frames hold bit-identical runs (wall time aside)."""
    assert list(a["run_id"]) == list(b["run_id"])
    for column in ("problem", "algorithm", "seed", "n_eval", "n_gen", "igd", "gd", "hv", "spacing"):
        assert a[column].equals(b[column]), column
    for F1, F2 in zip(a["F"], b["F"]):
        np.testing.assert_array_equal(F1, F2)
    for X1, X2 in zip(a["X"], b["X"]):
        np.testing.assert_array_equal(X1, X2)
    for h1, h2 in zip(a["history"], b["history"]):
        assert h1 == h2


def test_study_on_dask_local_cluster_equals_local_pool_and_gives_tables(pool_study_dir, tmp_path):
    """Issue 5 done-when: 3 x 3 x 5 on a 2-worker LocalCluster and on the local pool, identical
    results, then the statistics tables."""
    distributed = pytest.importorskip("distributed")
    study = small_study()
    with distributed.LocalCluster(n_workers=2, threads_per_worker=1, processes=True, host="127.0.0.1",
                                  dashboard_address=None) as cluster:
        report = run_study(study, tmp_path / "dask", scheduler=cluster.scheduler_address, progress=False)
    assert (report.n_runs, report.n_finished, report.failures) == (45, 45, [])
    pool, dask = load_results(pool_study_dir), load_results(tmp_path / "dask")
    assert len(pool) == 45
    _fronts_equal(pool, dask)

    written = {p.name for p in write_tables(dask, tmp_path / "tables", baseline="nsga2")}
    assert {"summary.csv", "summary.md", "igd.md", "hv.md", "ranksum.csv", "verdicts.md"} <= written
    summary = (tmp_path / "tables" / "summary.md").read_text()
    assert "## igd" in summary and "| zdt3 | sms-emoa | 5 |" in summary


def test_in_process_run_equals_pool(pool_study_dir, tmp_path):
    study = small_study()
    one = Study(study.name, study.problems[:1], study.algorithms, seeds=[2, 5], budget=study.budget)
    run_study(one, tmp_path, workers=1, progress=False)
    serial = load_results(tmp_path)
    pool = load_results(pool_study_dir)
    pool = pool[pool["run_id"].isin(serial["run_id"])].reset_index(drop=True)
    assert len(serial) == 6
    _fronts_equal(serial, pool)


def test_same_seed_same_run_other_seed_other_run():
    run_a, run_b = small_study().runs()[:2]  # zdt1 / nsga2, seeds 1 and 2
    first, again, other = execute_run(run_a), execute_run(run_a), execute_run(run_b)
    assert first["front"] == again["front"] and first["history"] == again["history"]
    assert first["front"]["F"] != other["front"]["F"]


def test_record_holds_front_indicators_budget_and_versions(pool_study_dir):
    import pymoo

    store = ResultStore(pool_study_dir)
    run = small_study().runs()[0]
    record = store.read(run.run_id)
    assert record["problem"] == {"problem": "zdt1", "n_var": 8}
    assert record["algorithm"] == {"algorithm": "nsga2", "pop_size": 12}
    assert record["seed"] == 1 and record["budget"] == {"n_gen": 8}
    assert record["n_gen"] == 8 and record["n_eval"] == 8 * 12  # NSGA-II: pop_size per generation
    F = np.asarray(record["front"]["F"])
    assert F.shape[1] == 2 and len(record["front"]["X"]) == len(F) and len(record["front"]["X"][0]) == 8
    assert set(record["indicators"]) >= {"igd", "gd", "gd_vv", "hv", "spacing", "n_front"}
    assert record["versions"]["pymoo"] == pymoo.__version__ and "pymoo_rail" in record["versions"]
    assert record["wall_time_s"] > 0 and record["cpu_time_s"] > 0
    assert record["counters"] == {}  # NSGA-II reports no run counters
    history = record["history"]
    assert history["n_gen"] == [float(g) for g in range(1, 9)]
    assert history["n_eval"] == [12.0 * g for g in range(1, 9)]
    assert history["igd"][-1] == pytest.approx(record["indicators"]["igd"])


def test_record_keeps_the_run_counters_an_algorithm_reports():
    """GR-NSGA-II's local-search totals and ABC's scouts reach the record and the DataFrame, and
    equal what the same seeded run reports (scouts counted independently, cycle by cycle)."""
    from pymoo.optimize import minimize
    from pymoo.problems import get_problem

    from pymoo_rail.algorithms import ABC, GoldenRatioNSGA2
    from pymoo_rail.experiments import Budget, RunSpec, records_frame
    from pymoo_rail.experiments.functions import Sphere

    gr = execute_run(RunSpec(problem("zdt1", n_var=6), algorithm("grnsga2", pop_size=20, local_size=8), 3,
                             Budget("n_gen", 10)))
    res = minimize(get_problem("zdt1", n_var=6), GoldenRatioNSGA2(pop_size=20, local_size=8), ("n_gen", 10), seed=3)
    assert gr["counters"] == {"n_local_evals": res.algorithm.n_local_evals,
                              "n_accepted_total": res.algorithm.n_accepted_total}
    assert 0 < gr["counters"]["n_accepted_total"] <= gr["counters"]["n_local_evals"]

    scouts: list[int] = []
    minimize(Sphere(3), ABC(pop_size=10, limit=2), ("n_gen", 30), seed=4,
             callback=lambda algorithm: scouts.append(algorithm.n_scouts))
    abc = execute_run(RunSpec(problem("sphere", n_var=3), algorithm("abc", pop_size=10, limit=2), 4,
                              Budget("n_gen", 30)))
    assert abc["counters"] == {"n_scouts_total": sum(scouts[1:])} and sum(scouts) > 0  # [0]: the initial colony

    frame = records_frame([gr, abc], fronts=False).set_index("algorithm")
    assert frame.loc["grnsga2", "n_accepted_total"] == gr["counters"]["n_accepted_total"]
    assert np.isnan(frame.loc["abc", "n_accepted_total"]) and frame.loc["abc", "cpu_time_s"] > 0
    assert frame.loc["abc", "n_scouts_total"] == sum(scouts[1:])


def test_seed_major_order_starts_every_cell_of_a_seed_before_the_next_seed():
    from pymoo_rail.experiments.runner import pending_runs

    study = small_study()
    done = {r.run_id for r in study.runs() if r.seed == 1 or (r.seed == 2 and r.problem.name == "zdt1")}
    by_seed = pending_runs(study, done, seed_major=True)
    assert [r.seed for r in by_seed] == [2] * 6 + [3] * 9 + [4] * 9 + [5] * 9
    assert [(r.problem.name, r.algorithm.name) for r in by_seed[6:15]] == \
        [(p.name, a.name) for p in study.problems for a in study.algorithms]
    default = pending_runs(study, done)
    assert {r.run_id for r in default} == {r.run_id for r in by_seed} and default[0].problem.name == "zdt1"


def test_killed_study_resumes_without_losing_or_duplicating_runs(pool_study_dir, tmp_path):
    """Kill a study (driver and pool workers) mid-way; the rerun keeps every stored run untouched,
    runs only the missing ones, ends with each run exactly once, and equals an uninterrupted run."""
    study = small_study()
    script = (
        "import sys\n"
        f"sys.path.insert(0, {str(REPO)!r})\n"
        "from tests.experiments.studies import small_study\n"
        "from pymoo_rail.experiments import run_study\n"
        "if __name__ == '__main__':\n"
        f"    run_study(small_study(), {str(tmp_path)!r}, workers=2, progress=False)\n"
    )
    env = {**os.environ, "PYTHONPATH": os.pathsep.join([str(REPO), os.environ.get("PYTHONPATH", "")])}
    proc = subprocess.Popen([sys.executable, "-c", script], env=env, start_new_session=True,
                            stdout=subprocess.DEVNULL, stderr=subprocess.PIPE)
    runs_dir = tmp_path / "runs"
    deadline = time.monotonic() + 120
    try:
        while time.monotonic() < deadline and proc.poll() is None:
            if runs_dir.is_dir() and len(list(runs_dir.glob("*.json"))) >= 5:
                break
            time.sleep(0.02)
        still_running = proc.poll() is None
    finally:
        try:
            os.killpg(proc.pid, signal.SIGKILL)  # the driver and its pool workers
        except ProcessLookupError:
            pass
        proc.wait(timeout=30)
    assert still_running, f"the study ended before it could be killed: {proc.stderr.read().decode()[-2000:]}"

    before = {p.name: p.read_bytes() for p in runs_dir.glob("*.json")}
    assert 5 <= len(before) < 45
    for name in before:  # every stored record is complete and passes its checksum
        assert ResultStore(tmp_path).check(runs_dir / name)["format"] == RECORD_FORMAT

    report = run_study(study, tmp_path, workers=2, progress=False)
    assert report.n_skipped == len(before)
    assert report.n_finished == 45 - len(before) and not report.failures
    after = {p.name: p.read_bytes() for p in runs_dir.glob("*.json")}
    assert {name: after[name] for name in before} == before  # nothing stored was redone
    assert set(after) == {f"{r.run_id}.json" for r in study.runs()}
    assert not [p for p in tmp_path.rglob(".tmp-*")]
    results = load_results(tmp_path)
    assert len(results) == 45
    assert not results.duplicated(["problem", "algorithm", "seed"]).any()

    _fronts_equal(results, load_results(pool_study_dir))  # the same as the uninterrupted study

    again = run_study(study, tmp_path, workers=2, progress=False)  # a complete study: nothing to do
    assert (again.n_skipped, again.n_finished) == (45, 0)


def test_a_failing_run_is_recorded_and_retried_while_the_others_are_stored(tmp_path):
    # ZDT1 with no variables cannot be built: the error happens inside the run (check=False)
    study = Study("fails", problems=[problem("zdt1", n_var=4), problem("zdt1", label="broken", n_var=0)],
                  algorithms=[algorithm("nsga2", pop_size=8)], seeds=2, budget={"n_gen": 2})
    report = run_study(study, tmp_path, workers=1, progress=False, check=False)
    assert report.n_finished == 2 and len(report.failures) == 2
    assert all("broken" in f["run"] and "Traceback" in f["traceback"] for f in report.failures)
    store = ResultStore(tmp_path)
    assert len(store.done_ids()) == 2 and len(store.failures()) == 2
    again = run_study(study, tmp_path, workers=1, progress=False, check=False)
    assert (again.n_skipped, again.n_finished, len(again.failures)) == (2, 0, 2)  # retried, failed again


def test_check_refuses_a_bad_study_before_any_work(tmp_path):
    from pymoo_rail.experiments import StudyError

    study = Study("bad", problems=[problem("zdt1")], algorithms=[algorithm("de")], seeds=1, budget={"n_gen": 2})
    with pytest.raises(StudyError, match=r"algorithms\[0\] \('de'\).*single-objective"):
        run_study(study, tmp_path, workers=1, progress=False)
    assert not (tmp_path / "runs").exists() or not list((tmp_path / "runs").iterdir())


def test_store_ignores_temporary_files_and_cleans_only_those_of_ended_processes(tmp_path):
    store = ResultStore(tmp_path)
    store.prepare()
    ended = subprocess.run([sys.executable, "-c", "import os; print(os.getpid())"], capture_output=True,
                           text=True, check=True)
    dead_pid = int(ended.stdout)
    (store.runs_dir / f".tmp-{dead_pid}-abc.json.x1").write_text("{half a rec")  # what a kill mid-write leaves
    alive = store.runs_dir / f".tmp-{os.getppid()}-def.json.x2"  # a live process is writing it
    alive.write_text("{being written")
    run = Study("tmp", [problem("zdt1", n_var=2)], [algorithm("nsga2", pop_size=4)], budget={"n_gen": 1}).runs()[0]
    record = execute_run(run)
    assert record["format"] == RECORD_FORMAT
    store.write(record)
    assert store.done_ids() == {run.run_id}
    assert [r["run_id"] for r in store.records()] == [run.run_id]
    store.prepare()
    assert sorted(p.name for p in store.runs_dir.iterdir()) == sorted([f"{run.run_id}.json", alive.name])


def test_results_follow_the_current_study(pool_study_dir):
    study = small_study()
    relabelled = Study(study.name, study.problems[:1],
                       [algorithm("nsga2", label="NSGA-II", pop_size=12)], seeds=[1, 2, 3], budget=study.budget)
    results = load_results(pool_study_dir, study=relabelled)
    assert len(results) == 3 and set(results["algorithm"]) == {"NSGA-II"}
    edited = Study(study.name, study.problems[:1], [algorithm("nsga2", pop_size=14)], seeds=[1],
                   budget=study.budget)
    assert load_results(pool_study_dir, study=edited).empty  # other parameters: not the same runs
    assert len(load_results(pool_study_dir, all_runs=True)) == 45


@pytest.mark.slow
def test_scheduler_local_starts_its_own_cluster(pool_study_dir, tmp_path):
    pytest.importorskip("distributed")
    report = run_study(small_study(), tmp_path, workers=2, scheduler="local", progress=False)
    assert report.n_finished == 45
    _fronts_equal(load_results(pool_study_dir), load_results(tmp_path))



def test_pool_workers_compile_after_running_a_cached_parallel_kernel(tmp_path):
    """A worker that first runs a kernel from Numba's disk cache on Numba's threads and then has to
    compile must not fail: the worker's thread count is set without touching NUMBA_NUM_THREADS,
    which Numba re-reads at every compile (before, every such run failed with "Cannot set
    NUMBA_NUM_THREADS to a different value once the threads have been launched"). A script of its
    own, as a user runs a study: the driver has run the kernel before the pool starts."""
    script = (
        "import sys\n"
        f"sys.path.insert(0, {str(REPO)!r})\n"
        "import numpy as np\n"
        "from tests.experiments.studies import parallel_spheres\n"
        "from pymoo_rail.experiments import Study, algorithm, problem, run_study\n"
        "if __name__ == '__main__':\n"
        "    parallel_spheres(np.zeros((2, 3)))\n"
        "    study = Study('jitted', problems=[problem('tests.experiments.studies:jitted_sphere')],\n"
        "                  algorithms=[algorithm('nsga2', pop_size=8)], seeds=[1, 2], budget={'n_gen': 3})\n"
        f"    report = run_study(study, {str(tmp_path / 'study')!r}, workers=2, progress=False, check=False,\n"
        "                       trusted=True)\n"
        "    print(report.n_finished, report.failures)\n"
    )
    env = {k: v for k, v in os.environ.items() if k != "NUMBA_NUM_THREADS"}
    env["PYTHONPATH"] = os.pathsep.join([str(REPO), os.environ.get("PYTHONPATH", "")])
    path = tmp_path / "study.py"  # a file: the pool's fresh interpreters import it, and Numba with it
    path.write_text(script)
    done = subprocess.run([sys.executable, str(path)], env=env, capture_output=True, text=True, timeout=300)
    assert done.returncode == 0, done.stderr[-2000:]
    assert done.stdout.strip().splitlines()[-1] == "2 []", done.stdout[-2000:]
