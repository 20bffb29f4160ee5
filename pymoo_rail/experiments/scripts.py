"""What every study script shares: the standard options, a polite process priority and the
per-run table a report is written from.

The scripts in ``benchmarks/`` are thin calls of :func:`pymoo_rail.experiments.run_study`; they take
the same three options (where the records go, where the report goes, and whether to only rebuild
the report from stored records) and run at a lower priority so that a long study leaves an
interactive machine usable. Their run records stay out of git; the per-run CSV a report exports
is committed, so :func:`report_runs` rebuilds a report from that CSV when the records are absent.
"""

from __future__ import annotations

import argparse
import os
from pathlib import Path
from typing import Callable, Mapping, Sequence


def add_study_options(parser: argparse.ArgumentParser, work_dir: Path, reports_dir: Path, *,
                      runs: int | None = None, workers: bool = False) -> None:
    """Add ``--work`` (the study's record folder), ``--out`` (the report folder) and ``--report-only``.

    Parameters
    ----------
    parser : argparse.ArgumentParser
        The script's parser.
    work_dir, reports_dir : pathlib.Path
        The defaults of ``--work`` and ``--out``.
    runs : int, optional
        Also add ``--runs`` (seeds per cell) with this default.
    workers : bool
        Also add ``--workers`` (process pool size, default 2: the shared machine's cores).
    """
    if runs is not None:
        parser.add_argument("--runs", type=int, default=runs, help="runs (seeds) per problem and algorithm")
    if workers:
        parser.add_argument("--workers", type=int, default=2, help="process pool size (at most 2)")
    parser.add_argument("--work", type=Path, default=work_dir, help="study folder (one record per run)")
    parser.add_argument("--out", type=Path, default=reports_dir, help="report folder")
    parser.add_argument("--report-only", action="store_true", help="rebuild the report from the stored records")


def lower_priority(niceness: int = 10) -> None:
    """Raise this process's nice value to at least ``niceness`` (never lower it).

    Pool workers started afterwards inherit it.
    """
    current = os.nice(0)
    if current < niceness:
        os.nice(niceness - current)


def count_range(counts) -> str:
    """``"30"`` when every cell of a study has the same number of runs, else ``"28 to 30"``.

    Parameters
    ----------
    counts : pandas.Series or sequence of int
        Runs per cell (e.g. ``df.groupby(["problem", "algorithm"]).size()``).

    Returns
    -------
    str
    """
    low, high = int(min(counts)), int(max(counts))
    return f"{low}" if low == high else f"{low} to {high}"


def report_runs(results, run_row: Callable[[Mapping], dict], columns: Sequence[str],
                committed_csv: Path) -> tuple:
    """The per-run table of a study report and the fronts behind it: from the records, else the CSV.

    With stored records (``results`` of :func:`pymoo_rail.experiments.load_results` not empty),
    each run becomes one row by ``run_row`` and the fronts are returned for the figures. Without
    them, the table is read from ``committed_csv``, the per-run CSV the report exported when it
    was last built from records (every digit of a float survives the round trip), and there are
    no fronts: the report's numbers are rebuilt, the figures drawn from fronts are not.

    Parameters
    ----------
    results : pandas.DataFrame
        The stored runs, with fronts (``load_results(..., fronts=True)``); may be empty.
    run_row : callable
        One run (a row of ``results``) -> a dict with the ``columns``.
    columns : sequence of str
        The table's columns, in the CSV's order.
    committed_csv : pathlib.Path
        The per-run CSV next to the report.

    Returns
    -------
    (pandas.DataFrame, dict, bool)
        The table, ``{(problem, algorithm, seed): F}`` (empty without records), and whether the
        table came from the records (then the caller exports it to ``committed_csv``).

    Raises
    ------
    FileNotFoundError
        Neither records nor ``committed_csv``.
    ValueError
        The CSV lacks one of ``columns`` (written by another version of the script).
    """
    import pandas as pd

    if len(results):
        table = pd.DataFrame([run_row(row) for _, row in results.iterrows()], columns=list(columns))
        fronts = {(r.problem, r.algorithm, int(r.seed)): r.F for r in results.itertuples()}
        return table, fronts, True
    committed_csv = Path(committed_csv)
    if not committed_csv.is_file():
        raise FileNotFoundError(f"no run records to report and no per-run table {committed_csv}: run the study first")
    # every digit must come back: pandas >= 3 parses floats round-trip by default (and deprecates the option)
    exact = {} if int(pd.__version__.split(".")[0]) >= 3 else {"float_precision": "round_trip"}
    table = pd.read_csv(committed_csv, **exact)
    missing = [c for c in columns if c not in table.columns]
    if missing:
        raise ValueError(f"{committed_csv} lacks the column(s) {', '.join(missing)}: rerun the study to rebuild it")
    return table[list(columns)], {}, False
