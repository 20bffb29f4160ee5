"""The exact solver's runs at chosen running times, cached row by row (:func:`exact_points`)."""

from __future__ import annotations

import time
from collections.abc import Callable, Sequence
from pathlib import Path
from typing import Any

import pandas as pd

from pymoo_rail.constants import J_PER_KWH
from pymoo_rail.model import Case
from pymoo_rail.optimal import solver as exact_solver
from pymoo_rail.optimal.reference.front import case_hash
from pymoo_rail.rowcache import RowCache

EXACT_POINT_COLUMNS = ("requested_time_s", "running_time_s", "energy_kwh", "traction_kwh", "regen_kwh",
                       "lambda_kwh_per_s", "neutral_traction_j", "limit_excess_ms", "stop_error_m", "n_speeds",
                       "solve_s")
"""Columns of :func:`exact_points` (then the key columns ``case_hash``, ``solver_version``, ``cache_key``)."""


def exact_points_key(case: Case, n_speeds: int) -> dict[str, object]:
    """The key of :func:`exact_points` rows: the case's content, the solver's version, the speed nodes.

    ``case_hash`` is :func:`case_hash` (names and prose left out, so a renamed case keeps its rows);
    ``solver_version`` is :data:`pymoo_rail.optimal.solver.SOLVER_VERSION`.
    """
    # read at call time: a test bumps the version to see old rows refused
    return {"case_hash": case_hash(case)[:16], "solver_version": exact_solver.SOLVER_VERSION, "n_speeds": int(n_speeds)}


def exact_points(case: Case, running_times_s: Sequence[float], path: str | Path, *, n_speeds: int | None = None,
                 redo_s: Sequence[float] = (), on_run: Callable[[float, Any], None] | None = None) -> pd.DataFrame:
    """The exact solver's runs at chosen running times, cached row by row in a CSV file.

    The resumable form of :func:`~pymoo_rail.optimal.optimal_front` for long lines, where one
    running time costs minutes: each finished time is added to the file at once
    (:class:`pymoo_rail.rowcache.RowCache`: atomic rewrite under a file lock), so an interrupted
    computation resumes where it stopped and two processes on one file lose no row. A row is
    served only under the same key (:func:`exact_points_key`: the case's content hash, the
    solver's :data:`~pymoo_rail.optimal.solver.SOLVER_VERSION` and ``n_speeds``); rows of another
    key are never served, and a new row replaces every row of its requested time. A corrupt file
    is moved aside with a :class:`~pymoo_rail.rowcache.CorruptCacheWarning` and its times solved
    again. The times are solved in increasing order, each warm-started from the slope of the one
    before, as :func:`~pymoo_rail.optimal.optimal_front` does.

    Parameters
    ----------
    case : Case
        The case.
    running_times_s : sequence of float
        Requested running times (s).
    path : str or Path
        The CSV cache (created when missing).
    n_speeds : int, optional
        Speed nodes of the solver (default: the solver's).
    redo_s : sequence of float
        Times to solve again even when cached (and to solve when not requested), e.g. to get the
        run itself through ``on_run``.
    on_run : callable, optional
        Called as ``on_run(requested_time_s, trajectory)`` after each solve.

    Returns
    -------
    pandas.DataFrame
        The rows of ``running_times_s``, sorted by running time: :data:`EXACT_POINT_COLUMNS`
        (``energy_kwh`` is net; ``solve_s`` is the wall seconds of the solve).
    """
    n_speeds = exact_solver.DEFAULT_N_SPEEDS if n_speeds is None else int(n_speeds)
    key = exact_points_key(case, n_speeds)
    cache = RowCache(path, value_columns=EXACT_POINT_COLUMNS, text_columns=("case_hash", "solver_version"))
    rows = {float(r["requested_time_s"]): r for r in cache.rows(key).to_dict("records")}
    done = set(rows) - {float(t) for t in redo_s}
    solver, guess = None, None
    for t in sorted({float(t) for t in running_times_s} | {float(t) for t in redo_s}):
        if t in done:
            continue
        if solver is None:  # built only when a time is missing: the grid and tables cost seconds
            solver = exact_solver.OptimalSolver(case, n_speeds=n_speeds)
        start = time.perf_counter()
        traj = solver.profile(t, lambda_guess_w=guess)
        guess = traj.summary["lambda_w"]
        row = {"requested_time_s": t, "running_time_s": traj.running_time_s, "energy_kwh": traj.energy.net_kwh,
               "traction_kwh": traj.energy.traction_kwh, "regen_kwh": traj.energy.regen_kwh,
               "lambda_kwh_per_s": guess / J_PER_KWH, "neutral_traction_j": traj.summary["neutral_traction_j"],
               "limit_excess_ms": traj.summary["limit_excess_ms"], "stop_error_m": traj.stop_error_m,
               "n_speeds": n_speeds, "solve_s": time.perf_counter() - start}
        cache.add(pd.DataFrame([row]), key, replace=lambda table, t=t: table["requested_time_s"] == t)
        rows[t] = row
        if on_run is not None:
            on_run(t, traj)
    wanted = sorted({float(t) for t in running_times_s})
    frame = pd.DataFrame([rows[t] for t in wanted], columns=list(EXACT_POINT_COLUMNS))
    return frame.sort_values("running_time_s", kind="stable").reset_index(drop=True)
