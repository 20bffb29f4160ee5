"""A study on a real Dask cluster: scheduler and workers as separate processes, one worker killed.

The processes are started with the commands a user types on a cluster (``dask scheduler``,
``dask worker``), on the loopback interface. Killing a worker's process group (nanny and worker,
SIGKILL) while it computes is what losing a machine looks like to the scheduler: its tasks go to
the surviving worker, and the study still stores every run once, bit-identical to the local pool.
"""

from __future__ import annotations

import os
import signal
import subprocess
import sys
import threading
import time
from pathlib import Path

import pytest

from pymoo_rail.experiments import ResultStore, Study, load_results, run_study
from tests.experiments.studies import small_study
from tests.experiments.test_runner import _fronts_equal

REPO = Path(__file__).resolve().parents[2]
STARTUP_TIMEOUT_S = 120.0


def _cluster_study() -> Study:
    """12 runs of 0.2-0.8 s each: long enough that a worker dies with a run in hand."""
    base = small_study(n_gen=150, name="zdt-cluster")
    return Study(base.name, base.problems[:2], base.algorithms[:2], seeds=[1, 2, 3], budget=base.budget,
                 baseline=base.baseline)


def _dask(*args: str, log: Path) -> subprocess.Popen:
    """Start ``dask <args>`` in its own process group, with this checkout importable."""
    env = dict(os.environ, PYTHONPATH=os.pathsep.join(filter(None, [str(REPO), os.environ.get("PYTHONPATH")])))
    return subprocess.Popen([sys.executable, "-m", "dask", *args], cwd=REPO, env=env, start_new_session=True,
                            stdout=log.open("w"), stderr=subprocess.STDOUT)


def _stop(process: subprocess.Popen) -> None:
    if process.poll() is None:
        os.killpg(process.pid, signal.SIGKILL)
    process.wait(timeout=30)


def _kill_when_stored(store_dir: Path, n_stored: int, worker: subprocess.Popen, log: dict) -> None:
    """Kill the worker's whole process group once ``n_stored`` runs are in the store."""
    runs = store_dir / "runs"
    deadline = time.monotonic() + STARTUP_TIMEOUT_S
    while time.monotonic() < deadline:
        done = len(list(runs.glob("*.json"))) if runs.exists() else 0
        if done >= n_stored:
            log["stored_at_kill"] = done
            os.killpg(worker.pid, signal.SIGKILL)
            return
        time.sleep(0.02)


@pytest.mark.slow
def test_study_survives_a_killed_worker_on_a_real_cluster(tmp_path):
    distributed = pytest.importorskip("distributed")
    study = _cluster_study()
    n_runs = len(study.runs())
    scheduler_file = tmp_path / "scheduler.json"
    processes = [_dask("scheduler", "--host", "127.0.0.1", "--port", "0", "--no-dashboard",
                       "--scheduler-file", str(scheduler_file), log=tmp_path / "scheduler.log")]
    try:
        deadline = time.monotonic() + STARTUP_TIMEOUT_S
        while not scheduler_file.exists() and time.monotonic() < deadline:
            time.sleep(0.1)
        for name in ("w1", "w2"):
            processes.append(_dask("worker", "--scheduler-file", str(scheduler_file), "--host", "127.0.0.1",
                                   "--nthreads", "1", "--nworkers", "1", "--no-dashboard", "--name", name,
                                   log=tmp_path / f"{name}.log"))
        with distributed.Client(scheduler_file=str(scheduler_file), timeout="60s") as client:
            client.wait_for_workers(2, timeout=STARTUP_TIMEOUT_S)
            out = tmp_path / "cluster"
            kill_log: dict = {}
            killer = threading.Thread(target=_kill_when_stored, args=(out, 2, processes[2], kill_log))
            killer.start()
            report = run_study(study, out, scheduler=client, progress=False)
            killer.join()
            n_workers_after = len(client.scheduler_info()["workers"])
    finally:
        for process in processes:
            _stop(process)

    assert 2 <= kill_log["stored_at_kill"] < n_runs, kill_log  # the worker died mid-study
    assert n_workers_after == 1
    assert (report.n_runs, report.n_finished, report.failures) == (n_runs, n_runs, [])
    store = ResultStore(out)
    stored = sorted(p.stem for p in (out / "runs").glob("*.json"))
    assert stored == sorted(run.run_id for run in study.runs())  # every run exactly once
    assert store.done_ids() == set(stored)
    assert not (out / "failed").exists() or not any((out / "failed").iterdir())

    run_study(study, tmp_path / "pool", workers=2, progress=False)
    _fronts_equal(load_results(tmp_path / "pool"), load_results(out))
