"""The closed-loop study run at full size: one record per world in a result store, resumable, on a process pool.

:func:`run_loop_study` hands the worlds of :mod:`pymoo_rail.control.study` out in chunks (one
case's policy is built once per chunk) and stores each world's rows (every controller, the exact
optima) as one checksummed record of a :class:`~pymoo_rail.experiments.store.ResultStore`: written
atomically, computed by the process holding its claim, never computed again, so a study stopped
at any time goes on where it was. :func:`tuned_trackers` tunes the PID and fuzzy PID on a case's
plan (:func:`pymoo_rail.problems.controller_tuning.tune_controller`) for the study's tuned trackers.
"""

from __future__ import annotations

import json
import time as _time
from concurrent.futures import ProcessPoolExecutor
from dataclasses import dataclass, field
from multiprocessing import get_context
from pathlib import Path
from typing import Callable, Mapping, Sequence

import pandas as pd

from pymoo_rail.control.closed_loop import LoopDisturbance
from pymoo_rail.control.controllers import Controller
from pymoo_rail.control.policy import OptimalPolicy
from pymoo_rail.control.study import (STUDY_CONTROLLERS, TUNED_CONTROLLERS, draw_loop_disturbances, study_planned_time,
                                      world_rows)
from pymoo_rail.experiments.inputs import versions_input
from pymoo_rail.experiments.report import fixed, markdown_rows
from pymoo_rail.experiments.stats import signed_rank_vs
from pymoo_rail.experiments.store import STALE_DIR, ResultStore, record_checksum
from pymoo_rail.model import Case
from pymoo_rail.model.errors import FieldError
from pymoo_rail.problems.controller_tuning import tune_controller
from pymoo_rail.sim import Trajectory

# One record of the result store holds the rows of one world of one case
LOOP_RECORD_FORMAT = "pymoo-rail/loop-world/1"
# The package parts a world's rows are computed by (the fingerprint of a record, :func:`loop_code`):
# a change elsewhere in the package (another engineer's study, the CLI) keeps the stored worlds
LOOP_CODE_PARTS = ("control", "optimal", "sim", "model", "cases", "constants.py", "problems/controller_tuning.py",
                   "experiments/loop_study.py")


def loop_code() -> dict[str, str]:
    """The fingerprint of the code computing a world: the digest of :data:`LOOP_CODE_PARTS` and library versions."""
    return versions_input(LOOP_CODE_PARTS)


def tuned_trackers(case: Case, plan: Trajectory, seed: int = 1) -> dict[str, Controller]:
    """The PID and fuzzy PID tuned on ``plan`` with the same training set and budget (keys ``pid``, ``fuzzy_pid``)."""
    return {family: tune_controller(case, family, plan, seed=seed) for family in ("pid", "fuzzy_pid")}


@dataclass(frozen=True)
class LoopStudyCase:
    """One case of a closed-loop study: its planned time, worlds and the tuned trackers (if any)."""

    case: Case
    planned_time_s: float
    n_runs: int
    tuned: Mapping[str, Controller] = field(default_factory=dict)


def world_run_id(case_name: str, seed: int, run: int) -> str:
    """The result store's id of one world of a case."""
    return f"{case_name}-seed{seed}-world{run:04d}"


def _loop_chunk(item: LoopStudyCase, runs: list[int], seed: int, directory: str,
                controllers: tuple[str, ...]) -> int:
    """Compute and store the worlds ``runs`` of one case (skipping those stored or claimed); returns how many."""
    store = ResultStore(directory)
    planned = item.planned_time_s
    policy = None
    worlds = draw_loop_disturbances(item.case, max(runs) + 1, seed, planned)
    done = 0
    for run in runs:
        run_id = world_run_id(item.case.name, seed, run)
        lock = store.claim(run_id)
        if lock is None:
            continue
        try:
            if store.path(run_id).is_file():
                continue
            policy = OptimalPolicy(item.case, planned) if policy is None else policy
            started = _time.process_time()
            rows = world_rows(item.case, run, worlds[run], policy, planned, controllers, True, item.tuned)
            world_cpu_s = _time.process_time() - started  # every controller and the exact optima
            rows = [dict(row, world_cpu_s=world_cpu_s) for row in rows]
            store.write({"format": LOOP_RECORD_FORMAT, "run_id": run_id, "case": item.case.name, "seed": seed,
                         "planned_time_s": planned, "controllers": list(controllers), "code": loop_code(),
                         "rows": rows})
            done += 1
        finally:
            lock.release()
    return done


def _loop_records(store: ResultStore):
    """(path, record) of every stored world, checked; a record whose checksum does not match is a FieldError."""
    for path in sorted(store.runs_dir.glob("*.json")) if store.runs_dir.is_dir() else []:
        record = json.loads(path.read_text(encoding="utf-8"))
        checksum = record.pop("checksum", None)
        if record.get("format") != LOOP_RECORD_FORMAT or checksum != record_checksum(record):
            raise FieldError("record", str(path), "is not a checked closed-loop record (altered or damaged): "
                                                  "delete it and run the study again")
        yield path, record


def load_loop_rows(directory: str | Path) -> pd.DataFrame:
    """Every world stored by :func:`run_loop_study` in ``directory`` by the current code (:func:`loop_code`),
    one row per world and controller.

    A record whose checksum does not match its content is a :class:`FieldError` naming the file;
    a record of other code is left out (:func:`run_loop_study` sets it aside and computes it again).
    """
    code = loop_code()
    rows = []
    for _, record in _loop_records(ResultStore(directory)):
        if record.get("code") == code:
            rows += record["rows"]
    return pd.DataFrame(rows)


def set_aside_stale(store: ResultStore) -> int:
    """Move the worlds computed by other code than the current (:func:`loop_code`) to ``stale/``; returns how many."""
    code = loop_code()
    stale = [path.stem for path, record in _loop_records(store) if record.get("code") != code]
    for run_id in stale:
        store.set_aside(run_id, STALE_DIR)
    return len(stale)


def run_loop_study(items: Sequence[LoopStudyCase], seed: int, directory: str | Path, workers: int = 1,
                   chunk: int = 5, controllers: Sequence[str] | None = None,
                   say: Callable[[str], None] = print) -> pd.DataFrame:
    """The closed-loop study of several cases, resumable: one record per world in a result store.

    Worlds already stored in ``directory`` by the current code (:func:`loop_code`: the package parts
    of :data:`LOOP_CODE_PARTS` and the library versions) are not computed again, so a study stopped
    at any time goes on where it was by running it again; worlds of other code are set aside
    (:func:`set_aside_stale`) and computed again. Work is handed out in chunks of ``chunk`` worlds of
    one case (a chunk builds its case's policy once), chunk by chunk across the cases, so that a
    study stopped early has about as many worlds of every case; ``workers`` processes of a pool.
    Returns :func:`load_loop_rows` of the directory.
    """
    if isinstance(workers, bool) or not isinstance(workers, int) or workers < 1:
        raise FieldError("workers", workers, "must be a positive integer")
    if isinstance(chunk, bool) or not isinstance(chunk, int) or chunk < 1:
        raise FieldError("chunk", chunk, "must be a positive integer")
    store = ResultStore(directory)
    store.prepare()
    stale = set_aside_stale(store)
    if stale:
        say(f"{stale} worlds computed by other code set aside in {store.directory / STALE_DIR}")
    done = store.done_ids()
    tasks = []
    for first in range(0, max(item.n_runs for item in items), chunk):
        for item in items:
            names = tuple(controllers or STUDY_CONTROLLERS + tuple(
                n for n in TUNED_CONTROLLERS if n.removeprefix("tracking_tuned_") in item.tuned))
            runs = [r for r in range(first, min(first + chunk, item.n_runs))
                    if world_run_id(item.case.name, seed, r) not in done]
            if runs:
                tasks.append((item, runs, seed, str(directory), names))
    say(f"{len(done)} worlds stored, {sum(len(t[1]) for t in tasks)} to compute in {len(tasks)} chunks")
    if workers == 1:
        for task in tasks:
            _report_chunk(task, _loop_chunk(*task), say)
    else:
        with ProcessPoolExecutor(workers, mp_context=get_context("spawn")) as pool:
            futures = [(task, pool.submit(_loop_chunk, *task)) for task in tasks]
            for task, future in futures:
                _report_chunk(task, future.result(), say)
    return load_loop_rows(directory)


def _report_chunk(task: tuple, n_done: int, say: Callable[[str], None]) -> None:
    item, runs = task[0], task[1]
    say(f"{item.case.name}: worlds {runs[0]}-{runs[-1]} stored ({n_done} computed here)")


def loop_tests(runs: pd.DataFrame, tracking: Sequence[str]) -> pd.DataFrame:
    """Each controller against the best curve tracking of its case (lowest median ``gap_pct``), world by world.

    Paired Wilcoxon signed-rank tests (every controller drove the same worlds) of ``gap_pct``,
    ``cost_kwh`` and the absolute lateness; verdict ``+`` significantly lower (better) at p < 0.05,
    ``-`` higher, ``=`` no significant difference.
    """
    rows = []
    for case, g in runs.groupby("case", sort=False):
        medians = g.groupby("controller")["gap_pct"].median()
        best = min((n for n in tracking if n in medians.index), key=lambda n: medians[n])
        base = g[g["controller"] == best].set_index("run")
        for name in dict.fromkeys(g["controller"]):
            if name == best:
                continue
            mine = g[g["controller"] == name].set_index("run")
            for measure in ("gap_pct", "cost_kwh", "lateness_abs_s"):
                a, b = (frame["lateness_s"].abs() if measure == "lateness_abs_s" else frame[measure]
                        for frame in (mine, base))
                b = b.reindex(a.index)
                p, verdict = signed_rank_vs((a - b).to_numpy(), 0.0)
                rows.append({"case": case, "controller": name, "against": best, "measure": measure,
                             "median": float(a.median()), "median_against": float(b.median()), "p_value": p,
                             "verdict": verdict})
    return pd.DataFrame(rows)


def study_items(cases: Sequence[Case], runs: int, runs_long: int, tune: bool,
                say: Callable[[str], None] = print) -> list[LoopStudyCase]:
    """Each case with its planned time, worlds (``runs``, ``runs_long`` over 10 km) and, with ``tune``,
    the PID and fuzzy PID tuned on its plan (:func:`tuned_trackers`)."""
    items = []
    for case in cases:
        planned = study_planned_time(case)
        n = runs if case.line.length_m <= 10_000 else runs_long
        tuned = {}
        if tune:
            tuned = tuned_trackers(case, OptimalPolicy(case, planned, certify=False).plan)
            say(f"{case.name}: tuned {tuned}")
        items.append(LoopStudyCase(case, planned, n, tuned))
    return items


def _na(value, digits: int = 2) -> str:
    return fixed(value, digits, missing="n/a")


def summary_markdown(summary: pd.DataFrame) -> str:
    """The per case and controller table of :func:`pymoo_rail.control.study.loop_summary`, as markdown."""
    header = ["case", "controller", "median gap to exact %", "median cost kWh", "median energy kWh",
              "median lateness s", "on time (of possible)", "late", "median stop error m",
              "median accel. variation m/s^2", "s per advice change", "ms per re-plan"]
    rows = [[r["case"], r["controller"], _na(r["median_gap_pct"]), _na(r["median_cost_kwh"], 3),
             _na(r["median_net_kwh"], 3), _na(r["median_lateness_s"]),
             f"{_na(100 * r['on_time_share'], 0)} % of {int(r['n_can_be_on_time'])}",
             f"{_na(100 * r['late_share'], 0)} %",
             _na(r["median_stop_error_m"], 3), _na(r["median_jerk_ms2"]), _na(r["median_seconds_per_change"], 1),
             _na(r["median_decision_cpu_ms"], 1)] for _, r in summary.iterrows()]
    return markdown_rows(header, rows)


def advice_markdown(runs: pd.DataFrame) -> str:
    """Per case, the advised run's ``cost_kwh`` over ``optimal_controls``' in the same worlds (median, 90th
    percentile, worlds over 1 %), as markdown."""
    rows = []
    for case, g in runs.groupby("case", sort=False):
        adv = g[g["controller"] == "advice"].set_index("run")["cost_kwh"]
        opt = g[g["controller"] == "optimal_controls"].set_index("run")["cost_kwh"]
        extra = 100.0 * (adv / opt.reindex(adv.index) - 1.0)
        rows.append([case, len(extra), f"{extra.median():+.2f} %", f"{extra.quantile(0.9):+.2f} %",
                     int((extra > 1.0).sum())])
    return markdown_rows(["case", "worlds", "median extra cost", "90th percentile", "worlds over 1 %"], rows)


def tests_markdown(tests: pd.DataFrame) -> str:
    """The tests of :func:`loop_tests` as markdown."""
    rows = [[r["case"], r["controller"], r["against"], r["measure"], _na(r["median"], 3),
             _na(r["median_against"], 3), _na(r["p_value"], 4), r["verdict"]] for _, r in tests.iterrows()]
    return markdown_rows(["case", "controller", "against", "measure", "median", "median of tracking", "p", "verdict"],
                         rows)


def disturbance_rows(cases: Sequence[Case], worlds: Mapping[str, LoopDisturbance],
                     controllers: Sequence[str]) -> pd.DataFrame:
    """Each case (planned as in the closed-loop study) in single worlds of one disturbance each, driven by
    every controller (:func:`pymoo_rail.control.study.world_rows`); column ``world`` holds the world's label."""
    rows = []
    for case in cases:
        planned = study_planned_time(case)
        policy = OptimalPolicy(case, planned)
        for k, (label, world) in enumerate(worlds.items()):
            rows += [dict(r, world=label) for r in world_rows(case, k, world, policy, planned, controllers)]
    return pd.DataFrame(rows)


def disturbance_markdown(runs: pd.DataFrame, controllers: Sequence[str]) -> str:
    """Per case and world, each controller's ``gap_pct`` and lateness, as markdown."""
    rows = []
    for (case, label), g in runs.groupby(["case", "world"], sort=False):
        cells = g.set_index("controller")
        rows.append([case, label, *(f"{cells.loc[c, 'gap_pct']:.2f} % ({cells.loc[c, 'lateness_s']:+.2f} s)"
                                    for c in controllers)])
    return markdown_rows(["case", "disturbance", *controllers], rows)


def latency_markdown(rows: Sequence[Mapping]) -> str:
    """The rows of :func:`pymoo_rail.control.study.replan_latency` as markdown, with fresh solve / warm re-plan."""
    header = ["case", "km", "re-plans (flat out)", "policy built s", "in the loop median / p90 ms",
              "warm median / p90 ms", "warm median, first half of the line ms", "warm median, on-time plans only ms",
              "fresh exact solve s", "fresh / warm median", "fresh / warm first half"]
    return markdown_rows(header, [
        [r["case"], f"{r['length_km']:.1f}", f"{r['replans']} ({r['fastest']})", f"{r['build_s']:.2f}",
         f"{r['loop_median_ms']:.1f} / {r['loop_p90_ms']:.1f}", f"{r['warm_median_ms']:.1f} / {r['warm_p90_ms']:.1f}",
         f"{r['first_half_ms']:.1f}", f"{r['on_time_plans_ms']:.1f}", f"{r['fresh_s']:.2f}",
         f"{1000 * r['fresh_s'] / r['warm_median_ms']:.0f}x", f"{1000 * r['fresh_s'] / r['first_half_ms']:.0f}x"]
        for r in rows])
