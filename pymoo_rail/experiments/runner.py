"""Running a study: every pending run, on a local process pool or a Dask cluster.

The same function, :func:`execute_run`, runs in every worker: it rebuilds the problem and the
algorithm from their specs, calls pymoo's ``minimize`` with the run's seed and returns a plain
record. On the local pool (and in-process) the worker stores its own record atomically before it
returns (:func:`execute_and_store`), so a run a worker finished is kept even if the driver dies;
with Dask, whose workers may not see the study directory, the driver stores each record the
moment it arrives. The driver claims each run (a file lock, see :mod:`.store`) before starting
it, checks the stored record and its input fingerprint (:mod:`.inputs`), and redoes a run whose
record is corrupt, of an older format or whose inputs changed, saying why. Pool workers watch
their parent and exit within a second when it dies.

Before anything else, :func:`run_study` refuses a study that names code to import unless it is
trusted (:func:`.registry.check_trust`), reads each case once (:func:`.inputs.resolve_run`: the
runs get the loaded case with its fingerprint), and checks every parameter and builds every
problem and algorithm once (:func:`check_study`).
"""

from __future__ import annotations

import datetime as _dt
import multiprocessing
import os
import platform
import socket
import sys
import threading
import time
import traceback
from collections import deque
from concurrent.futures import FIRST_COMPLETED, Executor, Future, ProcessPoolExecutor, wait
from concurrent.futures.process import BrokenProcessPool
from contextlib import ExitStack
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, Mapping

import numpy as np

from pymoo_rail.experiments.fronts import distinct_front
from pymoo_rail.experiments.inputs import RunInputs, changed_inputs, resolve_run
from pymoo_rail.experiments.metrics import (convergence_point, front_indicators, true_front_and_reason,
                                            unavailable_indicators)
from pymoo_rail.experiments.penalty import DEFAULT_PENALTY, PenalisedConstraints, handles_constraints
from pymoo_rail.experiments.registry import (build_algorithm, build_problem, check_parameters, check_trust,
                                             is_suite_family)
from pymoo_rail.experiments.spec import RunSpec, Study, StudyError
from pymoo_rail.experiments.store import (CORRUPT_DIR, RECORD_FORMAT, STALE_DIR, STUDY_FILE, LegacyRecordError,
                                          RecordError, ResultStore, writing)
from pymoo_rail.lockfiles import release_removing

# per-individual outputs a rail problem puts next to F (DESIGN.md section 3); kept with the front
EXTRA_KEYS = ("energy_kwh", "running_time_s", "stop_error_m")
RAW_RECORD_REASON = ("a suite family run keeps raw objective vectors; the report scores them against the front of "
                     "its version (pymoo_rail.experiments.baseline)")


def versions() -> dict[str, str]:
    """Versions of pymoo-rail, pymoo, numpy and Python, stored with every run record."""
    import pymoo

    import pymoo_rail

    return {"pymoo": pymoo.__version__, "pymoo_rail": pymoo_rail.__version__, "numpy": np.__version__,
            "python": platform.python_version()}


def _extras(problem, opt, X: np.ndarray) -> dict[str, list[float]]:
    """Running time, energy and stop error of each front member, when the problem knows them."""
    extras: dict[str, list[float]] = {}
    for key in EXTRA_KEYS:
        values = opt.get(key)
        if values is not None and len(values) and all(v is not None for v in values):
            extras[key] = [float(v) for v in values]
    if not extras and hasattr(problem, "trajectory") and len(X):
        trajectories = [problem.trajectory(x) for x in X]
        extras = {"energy_kwh": [t.energy.net_kwh for t in trajectories],
                  "running_time_s": [t.running_time_s for t in trajectories],
                  "stop_error_m": [t.stop_error_m for t in trajectories]}
    return extras


CHECKPOINTS_EVAL = (200, 500, 1000, 2000, 5000)
"""Evaluations at which a suite family run keeps its non-dominated feasible objective vectors
(the final front, at the budget, is the record's ``front``)."""
CHECKPOINT_DIGITS = 10
"""Significant digits of the objective vectors kept at the checkpoints (a record stays small)."""


def true_objectives(pop, penalised: bool) -> tuple[np.ndarray, np.ndarray]:
    """Objectives and constraint violation of ``pop`` on the problem itself (not the penalised one)."""
    if not penalised:
        F, CV = pop.get("F", "CV")
        return np.asarray(F, dtype=float), np.asarray(CV, dtype=float).reshape(-1)
    from pymoo.core.individual import calc_cv

    F, G, H = pop.get("__F__", "__G__", "__H__")  # kept by PenalisedConstraints next to the penalised F
    G = None if G is None or np.size(G) == 0 else np.asarray(G, dtype=float).reshape(len(pop), -1)
    H = None if H is None or np.size(H) == 0 else np.asarray(H, dtype=float).reshape(len(pop), -1)
    return np.asarray(F, dtype=float), np.asarray(calc_cv(G=G, H=H), dtype=float).reshape(-1)


def non_dominated_feasible(F: np.ndarray, CV: np.ndarray, digits: int = CHECKPOINT_DIGITS) -> np.ndarray:
    """The distinct non-dominated objective vectors among the feasible rows of ``F``, rounded to ``digits``
    significant digits (rows sorted)."""
    from pymoo.util.nds.non_dominated_sorting import NonDominatedSorting

    F = np.asarray(F, dtype=float)[np.asarray(CV).reshape(-1) <= 0.0]
    if len(F) == 0:
        return F.reshape(0, np.shape(F)[1] if np.ndim(F) == 2 else 0)
    F = np.unique(np.array([[float(f"{v:.{digits}g}") for v in row] for row in F]), axis=0)
    return F[NonDominatedSorting().do(F, only_non_dominated_front=True)] if len(F) > 1 else F


class _History:
    """pymoo callback: per generation, evaluations so far and cheap indicators of the feasible front.

    Given ``checkpoints`` (evaluations, a suite family run: :data:`CHECKPOINTS_EVAL`), it also keeps
    the non-dominated feasible objective vectors of the first generation at or past each of them,
    raw, for the report to score against the front of its time; ``pf`` is then None, so nothing of
    the record depends on the front. ``snapshots`` (the record's ``checkpoints``): ``target_n_eval``
    (the largest checkpoint a generation reached), ``n_eval`` (that generation's) and ``F``.
    """

    def __init__(self, pf: np.ndarray | None, checkpoints: tuple[int, ...] = (), penalised: bool = False):
        self.pf = pf
        self.rows: list[dict[str, float]] = []
        self.targets = sorted(checkpoints)
        self.penalised = penalised
        self.snapshots: dict[str, list] = {"target_n_eval": [], "n_eval": [], "F": []}

    def __call__(self, algorithm) -> None:
        opt = algorithm.opt
        n_eval = int(algorithm.evaluator.n_eval)
        row: dict[str, float] = {"n_gen": float(algorithm.n_iter), "n_eval": float(n_eval)}
        if opt is not None and len(opt):
            F, CV = true_objectives(opt, self.penalised)
            row.update(convergence_point(F[CV <= 0.0], self.pf))
            reached = [t for t in self.targets if t <= n_eval]
            if reached:
                self.targets = self.targets[len(reached):]
                self.snapshots["target_n_eval"].append(reached[-1])
                self.snapshots["n_eval"].append(n_eval)
                self.snapshots["F"].append(non_dominated_feasible(F, CV).tolist())
        self.rows.append(row)

    def columns(self) -> dict[str, list[float | None]]:
        keys: list[str] = []
        for row in self.rows:
            keys += [k for k in row if k not in keys]
        return {k: [row.get(k) for row in self.rows] for k in keys}


def run_counters(algorithm) -> dict[str, float]:
    """What the algorithm counts over a run (``algorithm.run_counters()``, if it has one).

    Any algorithm can report totals that are not indicators of its front, such as the
    local-search points GR-NSGA-II accepted or the scouts a bee colony sent; the study keeps
    them with the run. Values must be numbers.
    """
    method = getattr(algorithm, "run_counters", None)
    if not callable(method):
        return {}
    counters = {}
    for key, value in method().items():
        number = float(value)
        if not np.isfinite(number):
            raise ValueError(f"run counter {key!r} = {value!r} is not a finite number")
        counters[str(key)] = int(number) if number.is_integer() else number
    return counters


def _as_inputs(inputs: RunInputs | Mapping[str, str] | None, run: RunSpec) -> RunInputs:
    if inputs is None:
        return resolve_run(run)
    if isinstance(inputs, RunInputs):
        return inputs
    return RunInputs(dict(inputs))  # a bare fingerprint: the run loads its case itself


def execute_run(run: RunSpec, inputs: RunInputs | Mapping[str, str] | None = None,
                trusted: bool = False) -> dict[str, Any]:
    """Run one study run and return its record (a JSON-ready dict).

    ``inputs`` (:func:`.inputs.resolve_run`, computed here when not given) holds the fingerprint
    of the run's inputs, stored with the record so a later start can tell a stale record, and the
    cases the fingerprint was computed from, which the run uses instead of reading the files again.
    ``trusted`` allows specs that name code to import (``"module:callable"``).
    The record holds the final front (``F``, ``X``, constraint violation and, for rail problems,
    energy, running time and stop error of each member), its indicators and why any is missing
    (``unavailable``), the evaluations used, the wall and CPU time (CPU time of this process, all
    its threads), the algorithm's :func:`run_counters`, the per-generation history and the versions
    of pymoo and pymoo-rail.

    A suite family run reads no front: no front indicator, no IGD / HV in ``history``, but ``checkpoints``
    (:class:`_History`), which :mod:`pymoo_rail.experiments.baseline` scores against the front of its time.
    """
    from pymoo.core.evaluator import Evaluator
    from pymoo.core.population import Population
    from pymoo.optimize import minimize

    inputs = _as_inputs(inputs, run)
    problem = build_problem(run.problem, trusted, inputs.cases)
    algorithm = build_algorithm(run.algorithm, problem, trusted)
    # an algorithm without constraint handling (MOEA/D) searches the penalised problem; its front is
    # then evaluated again on the problem itself, so the record holds true objectives and violations
    penalised = problem.has_constraints() and not handles_constraints(algorithm)
    # a suite run keeps raw vectors, scored by the report: a better exact solver keeps the record
    raw = is_suite_family(run.problem)
    pf, front_reason = (None, RAW_RECORD_REASON) if raw else true_front_and_reason(problem)
    history = _History(pf, CHECKPOINTS_EVAL if raw else (), penalised) if run.history else None
    start, start_cpu = time.perf_counter(), time.process_time()
    # pymoo 0.6.2 calls algorithm.callback unconditionally once given one: pass it only when recording
    callback = {"callback": history} if history is not None else {}
    searched = PenalisedConstraints(problem, DEFAULT_PENALTY) if penalised else problem
    res = minimize(searched, algorithm, run.budget.termination, seed=run.seed, verbose=False,
                   copy_algorithm=False, **callback)
    wall_time_s = time.perf_counter() - start
    cpu_time_s = time.process_time() - start_cpu

    opt = res.algorithm.opt
    if penalised and opt is not None and len(opt):
        opt = Evaluator().eval(problem, Population.new(X=opt.get("X")))
    opt = distinct_front(opt)  # one member per objective vector
    X = np.asarray(opt.get("X"), dtype=float) if len(opt) else np.empty((0, problem.n_var))
    F = np.asarray(opt.get("F"), dtype=float) if len(opt) else np.empty((0, problem.n_obj))
    CV = np.asarray(opt.get("CV"), dtype=float).reshape(-1) if len(opt) else np.empty(0)
    feasible = CV <= 0.0
    indicators = front_indicators(F[feasible], pf)
    unavailable = {k: v for k, v in unavailable_indicators(int(problem.n_obj), int(feasible.sum()),
                                                           front_reason).items() if k not in indicators}
    return {
        "format": RECORD_FORMAT,
        "run_id": run.run_id,
        "problem": run.problem.identity(),
        "problem_label": run.problem.display,
        "algorithm": run.algorithm.identity(),
        "algorithm_label": run.algorithm.display,
        "seed": run.seed,
        "budget": run.budget.to_dict(),
        "n_var": int(problem.n_var),
        "n_obj": int(problem.n_obj),
        "n_eval": int(res.algorithm.evaluator.n_eval),
        "n_gen": int(res.algorithm.n_iter - 1),
        "wall_time_s": wall_time_s,
        "cpu_time_s": cpu_time_s,
        "feasible": bool(feasible.any()),
        "indicators": indicators,
        "unavailable": unavailable,
        "counters": run_counters(res.algorithm),
        "front": {"F": F.tolist(), "X": X.tolist(), "CV": CV.tolist(),
                  "extras": _extras(problem, opt, X) if len(X) else {}},
        "history": history.columns() if history is not None else None,
        **({"checkpoints": history.snapshots} if raw and history is not None else {}),
        "versions": versions(),
        "inputs": dict(inputs.fingerprint),
        "host": socket.gethostname(),
        "finished_at": _dt.datetime.now(_dt.timezone.utc).isoformat(timespec="seconds"),
    }


def execute_run_safely(run: RunSpec, inputs: RunInputs | Mapping[str, str] | None = None,
                       trusted: bool = False) -> tuple[str, dict[str, Any]]:
    """:func:`execute_run` that returns an error as data (with its traceback) instead of raising."""
    try:
        return "ok", execute_run(run, inputs, trusted)
    except Exception as err:  # noqa: BLE001 - reported per run; the study goes on
        return "error", {"run_id": run.run_id, "run": run.describe(), "error": f"{type(err).__name__}: {err}",
                         "traceback": traceback.format_exc(),
                         "finished_at": _dt.datetime.now(_dt.timezone.utc).isoformat(timespec="seconds")}


# held while a worker writes a record, so the parent-death watcher never cuts a write short
_WRITE_LOCK = threading.Lock()
PARENT_POLL_S = 0.5


def execute_and_store(run: RunSpec, directory: str, inputs: RunInputs | Mapping[str, str],
                      trusted: bool = False) -> tuple[str, dict[str, Any]]:
    """:func:`execute_run_safely`, then store the record (or the failure) in ``directory`` at once.

    Returns ``("ok", {"run_id": ...})`` or ``("error", failure)``: the record itself never has to
    travel back to the driver, so a run finished here is kept even if the driver is gone.
    """
    status, payload = execute_run_safely(run, inputs, trusted)
    store = ResultStore(directory)
    with _WRITE_LOCK:
        if status == "ok":
            store.write(payload)
            return "ok", {"run_id": run.run_id}
        store.write_failure(run.run_id, payload)
    return status, payload


def _watch_parent(parent_pid: int) -> None:
    while True:
        time.sleep(PARENT_POLL_S)
        if os.getppid() != parent_pid:  # re-parented: the study process is gone
            with _WRITE_LOCK:  # let a record being written finish
                os._exit(0)


def _worker_init(parent_pid: int | None = None) -> None:
    # One Numba thread per worker process: the pool already uses every core. Numba re-reads
    # NUMBA_NUM_THREADS at every compile and refuses a change once its threads run, so the
    # environment is left alone and the count is set on the worker's thread instead.
    import numba

    numba.set_num_threads(1)
    if parent_pid is not None:
        # a pool worker outlives a killed driver (waiting on its queue forever): exit instead
        threading.Thread(target=_watch_parent, args=(parent_pid,), daemon=True, name="parent-watch").start()


class _InProcess(Executor):
    """An executor that runs each task at submission, in this process (``workers=1``)."""

    def submit(self, fn, /, *args, **kwargs) -> Future:
        future: Future = Future()
        try:
            future.set_result(fn(*args, **kwargs))
        except BaseException as err:  # noqa: BLE001 - delivered through the future, as a pool would
            future.set_exception(err)
        return future


@dataclass
class StudyReport:
    """What :func:`run_study` did."""

    directory: Path
    n_runs: int
    n_skipped: int
    n_finished: int
    failures: list[dict] = field(default_factory=list)
    n_elsewhere: int = 0  # stored meanwhile by another process working on the same directory
    redone: list[str] = field(default_factory=list)  # why stored records were set aside and redone

    @property
    def complete(self) -> bool:
        """True when every run of the study is stored (skipped, finished here or by another process)."""
        return self.n_skipped + self.n_finished + self.n_elsewhere == self.n_runs

    def __str__(self) -> str:
        elsewhere = f", {self.n_elsewhere} stored by another process" if self.n_elsewhere else ""
        text = (f"{self.n_runs} runs: {self.n_skipped} already stored, {self.n_finished} run now{elsewhere}, "
                f"{len(self.failures)} failed; results in {self.directory}")
        for note in self.redone:
            text += f"\n  REDONE {note}"
        for f in self.failures:
            text += f"\n  FAILED {f['run']}: {f['error']}"
        return text


def check_study(study: Study, trusted: bool = False, cases: Mapping[str, Any] | None = None) -> None:
    """Check a study before any run starts: trust, every parameter name, every problem and
    (algorithm, problem) pair built once.

    Raises :class:`StudyError` naming the entry (``problems[0]``, ``algorithms[1].pop_sise``) and
    the value; :class:`~.registry.UntrustedCodeError` for an import path without ``trusted``.
    ``cases``: cases already loaded, by the specs' ``case`` values (see :func:`.registry.build_problem`).
    """
    check_trust(study, trusted)
    for i, p in enumerate(study.problems):
        check_parameters(p, f"problems[{i}]", trusted)
    for i, a in enumerate(study.algorithms):
        check_parameters(a, f"algorithms[{i}]", trusted)
    for i, p in enumerate(study.problems):
        try:
            problem = build_problem(p, trusted, cases)
        except StudyError:
            raise
        except Exception as err:
            raise StudyError(f"problems[{i}] ('{p.display}')", p.to_dict(), f"cannot be built: {err}") from err
        for j, a in enumerate(study.algorithms):
            try:
                build_algorithm(a, problem, trusted)
            except StudyError as err:
                raise StudyError(f"algorithms[{j}] ('{a.display}')", a.to_dict(),
                                 f"cannot run on problem '{p.display}': {err.reason}") from None
            except Exception as err:
                raise StudyError(f"algorithms[{j}] ('{a.display}')", a.to_dict(), f"cannot be built: {err}") \
                    from err


def _dask_executor(stack: ExitStack, scheduler: Any, workers: int) -> Executor:
    try:
        from distributed import Client, LocalCluster
    except ImportError:
        raise StudyError("scheduler", scheduler, "needs dask.distributed: pip install 'pymoo-rail[distributed]'") \
            from None
    if isinstance(scheduler, Client):
        client = scheduler
    elif scheduler == "local":
        cluster = stack.enter_context(LocalCluster(
            n_workers=workers, threads_per_worker=1, processes=True, host="127.0.0.1",
            dashboard_address=None, env={"NUMBA_NUM_THREADS": "1", "OMP_NUM_THREADS": "1"}))
        client = stack.enter_context(Client(cluster))
    else:
        try:
            client = stack.enter_context(Client(scheduler, timeout="20s"))
        except (OSError, TimeoutError) as err:
            raise StudyError("scheduler", scheduler, f"cannot connect to the Dask scheduler: {err}") from None
    return client.get_executor(pure=False)


def pending_runs(study: Study, done_ids: set[str], seed_major: bool = False) -> list[RunSpec]:
    """The runs of ``study`` not in ``done_ids``, in the order :func:`run_study` starts them."""
    pending = [r for r in study.runs() if r.run_id not in done_ids]
    if seed_major:
        pending.sort(key=lambda r: study.seeds.index(r.seed))  # stable: problem, algorithm order kept
    return pending


def run_study(study: Study, directory: str | Path, workers: int | None = None, scheduler: Any = None,
              progress: bool = True, check: bool = True, seed_major: bool = False,
              trusted: bool = False) -> StudyReport:
    """Run every run of ``study`` that is not yet stored in ``directory``.

    Parameters
    ----------
    study : Study
    directory : path
        The study directory (created if needed): ``runs/<run_id>.json`` per finished run.
    workers : int, optional
        Worker processes (default: the number of CPUs). ``1`` runs in this process.
    scheduler : None, "local", str or distributed.Client
        ``None``: a local ``ProcessPoolExecutor``. ``"local"``: a Dask ``LocalCluster`` with
        ``workers`` single-threaded worker processes on the loopback interface. Any other string:
        the address of a running Dask scheduler (``"tcp://host:8786"``). A ``Client`` is used as is.
        Results are the same whichever runs them: each run is seeded by its own seed.
    progress : bool
        Show a progress bar (tqdm, on stderr).
    check : bool
        Build every problem and algorithm once before starting, so a typo fails at once.
    seed_major : bool
        Start the runs seed by seed (every problem and algorithm of the first seed, then of the
        second, ...) instead of problem by problem, so a study stopped early still compares
        every algorithm on every problem over the same seeds. Results do not depend on it.
    trusted : bool
        Allow problems, algorithms and operators given as ``"module:callable"``: importing them
        runs their code, so say so only for a study you trust. Without it such a study is a
        :class:`~.registry.UntrustedCodeError` naming the entry, before anything is imported.

    Returns
    -------
    StudyReport
        Counts of skipped, finished and failed runs, runs another process stored meanwhile
        (``n_elsewhere``) and why stored records were redone (``redone``). Failed runs are stored
        in ``failed/`` with their traceback and are retried at the next start.

    Notes
    -----
    A stored run is skipped only if its record passes its checks and its input fingerprint
    (case content, files and module the specs name, the package's code, library versions) equals
    the current one; a record of an older format is always redone;
    otherwise the record is set aside (``corrupt/`` or ``stale/``), the reason is printed, and
    the run is redone. Each run is claimed with a file lock first, so several processes can work
    on one directory and each run is computed once. See ``docs/experiments.md``.
    """
    from pymoo_rail.experiments.study_file import write_study

    workers = _worker_count(workers)
    check_trust(study, trusted)  # before anything the study names is looked up
    runs = study.runs()
    cache: dict = {}
    inputs = {run.run_id: resolve_run(run, cache) for run in runs}  # each case read once, here
    if check:
        check_study(study, trusted, {k: v for i in inputs.values() for k, v in i.cases.items()})
    store = ResultStore(directory)
    store.prepare()
    with writing(store.directory / STUDY_FILE):
        write_study(study, store.directory / STUDY_FILE)
    stored = {r.run_id for r in runs if _stored_state(store, r, inputs[r.run_id].fingerprint)[0] == "stored"}
    pending = pending_runs(study, stored, seed_major)
    report = StudyReport(store.directory, len(runs), len(runs) - len(pending), 0)
    if pending:
        with ExitStack() as stack:
            bar = stack.enter_context(_progress_bar(study, report, progress))
            executor = _executor(stack, scheduler, workers, len(pending))
            _Dispatch(store, executor, report, bar, inputs, trusted, local=scheduler is None,
                      progress=progress).run(pending, window=2 * workers)
    store.remove_idle_locks()  # a finished study leaves no lock files (and no empty locks/) behind
    return report


def _worker_count(workers: Any) -> int:
    if workers is None:
        return os.cpu_count() or 1
    if isinstance(workers, bool) or not isinstance(workers, int) or workers < 1:
        raise StudyError("workers", workers, "must be a positive integer")
    return workers


def _progress_bar(study: Study, report: StudyReport, progress: bool):
    from tqdm import tqdm

    return tqdm(total=report.n_runs, initial=report.n_skipped, desc=f"study {study.name}", unit="run",
                disable=not progress, dynamic_ncols=True)


def _executor(stack: ExitStack, scheduler: Any, workers: int, n_pending: int) -> Executor:
    """In this process (one worker), a spawned process pool, or Dask (see :func:`run_study`)."""
    if scheduler is not None:
        return _dask_executor(stack, scheduler, workers)
    if workers == 1:
        return _InProcess()
    return stack.enter_context(ProcessPoolExecutor(
        max_workers=min(workers, n_pending), mp_context=multiprocessing.get_context("spawn"),
        initializer=_worker_init, initargs=(os.getpid(),)))


_POOL_DIED = ("a worker process of the local pool died, so the study stopped (finished runs are stored; "
              "run again to resume). If it died at start-up: the pool starts fresh interpreters that "
              "import your main script, so call run_study under `if __name__ == \"__main__\":` and not "
              "from standard input; or use workers=1 or a Dask scheduler.")


@dataclass
class _Dispatch:
    """The driver's loop: claim each pending run, recheck its record, submit it, store what comes back.

    At most ``window`` runs are in flight; a run another process holds is waited for once this
    process's own runs are done.
    """

    store: ResultStore
    executor: Executor
    report: StudyReport
    bar: Any
    inputs: Mapping[str, RunInputs]
    trusted: bool
    local: bool  # pool or in-process: the worker stores its own record
    progress: bool

    def run(self, pending: list[RunSpec], window: int) -> None:
        queue = deque((run, False) for run in pending)
        busy: list[RunSpec] = []  # claimed by another process: waited for once our own work is done
        in_flight: dict[Future, tuple[RunSpec, Any]] = {}
        try:
            while queue or in_flight or busy:
                if not queue and not in_flight:
                    queue.extend((run, True) for run in busy)
                    busy.clear()
                while queue and len(in_flight) < window:
                    run, blocking = queue.popleft()
                    claimed = self.claim(run, blocking)
                    if claimed == "busy":
                        busy.append(run)
                    elif claimed is not None:
                        in_flight[self.submit(run)] = (run, claimed)
                if in_flight:
                    self.collect(in_flight)
        except BrokenProcessPool as err:
            raise RuntimeError(_POOL_DIED) from err
        except BaseException:
            for future in in_flight:
                future.cancel()
            if isinstance(self.executor, ProcessPoolExecutor):
                self.executor.shutdown(wait=False, cancel_futures=True)
            raise
        finally:
            for _, lock in in_flight.values():
                release_removing(lock)

    def claim(self, run: RunSpec, blocking: bool) -> Any:
        """The run's lock when it is to be computed here; ``"busy"`` (another process holds it) or
        None (another process stored it meanwhile)."""
        lock = self.store.claim(run.run_id, wait=blocking)
        if lock is None:
            return "busy"
        state, reason = _stored_state(self.store, run, self.inputs[run.run_id].fingerprint)
        if state == "stored":  # another process finished it while we were busy
            release_removing(lock)
            self.report.n_elsewhere += 1
            self.bar.update(1)
            return None
        if state in ("corrupt", "stale"):
            moved = self.store.set_aside(run.run_id, CORRUPT_DIR if state == "corrupt" else STALE_DIR)
            self.say(f"{run.describe()}: {reason}; " + (f"moved to {moved}" if state == "corrupt"
                                                         else f"the old record is in {moved}"))
        return lock

    def submit(self, run: RunSpec) -> Future:
        if self.local:  # the worker stores its own record
            return self.executor.submit(execute_and_store, run, str(self.store.directory),
                                        self.inputs[run.run_id], self.trusted)
        return self.executor.submit(execute_run_safely, run, self.inputs[run.run_id], self.trusted)

    def collect(self, in_flight: dict[Future, tuple[RunSpec, Any]]) -> None:
        """Wait for at least one run in flight to end, store it (Dask) and count it."""
        done, _ = wait(in_flight, return_when=FIRST_COMPLETED)
        for future in done:
            run, lock = in_flight.pop(future)
            try:
                self.finish(run, *future.result())
            finally:
                release_removing(lock)

    def finish(self, run: RunSpec, status: str, payload: dict) -> None:
        if status == "ok":
            if not self.local:
                self.store.write(payload)
            self.report.n_finished += 1
        else:
            if not self.local:
                self.store.write_failure(run.run_id, payload)
            self.report.failures.append(payload)
            self.bar.write(f"FAILED {payload['run']}: {payload['error']}")
        self.bar.update(1)

    def say(self, message: str) -> None:
        self.report.redone.append(message)
        if self.progress:
            self.bar.write(f"REDO {message}")
        else:
            print(f"pymoo-rail study: REDO {message}", file=sys.stderr)


def _stored_state(store: ResultStore, run: RunSpec, inputs: Mapping[str, str]) -> tuple[str, str]:
    """``("stored", "")``, ``("missing", "")``, ``("corrupt", why)`` or ``("stale", why)`` for one run."""
    try:
        record = store.load(run.run_id)
    except LegacyRecordError as err:
        return "stale", f"record {err.path} cannot be used ({err.reason})"
    except RecordError as err:
        return "corrupt", f"record {err.path} cannot be used ({err.reason})"
    if record is None:
        return "missing", ""
    reasons = changed_inputs(record.get("inputs"), inputs)
    if reasons:
        return "stale", "inputs changed: " + "; ".join(reasons)
    return "stored", ""
