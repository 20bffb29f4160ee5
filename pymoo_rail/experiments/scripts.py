"""What every study script shares: the standard options and a polite process priority.

The scripts in ``benchmarks/`` are thin calls of :func:`pymoo_rail.experiments.run_study`; they take
the same three options (where the records go, where the report goes, and whether to only rebuild
the report from stored records) and run at a lower priority so that a long study leaves an
interactive machine usable.
"""

from __future__ import annotations

import argparse
import os
from pathlib import Path


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
