"""The exact reference checked: committed optimiser results against it, its certificate, its cost.

``--check members`` (default): every front member the project's studies committed
(``committed_members``: the 180 best members of ``yizhuang_seed000.csv``, the fastest, slowest and
punctual member of each of the 58 runs of ``emu_wuguang_runs.csv``, the strategy-search fronts of
``journeys_fronts_simulated.csv``) against the optimum solved at its own running time and that
solve's certificate ``energy_bound_kwh``; a member below the optimum by more than the certificate
is a defect of the reference (exit status 1). Not read: the cooperative and timetable studies (no
single-train optimum applies), the metro table-3 runs (the paper's kinematic model) and the
tracking runs (no front). Writes ``reference_check.csv`` (one row per member) and ``reference_check.md``.

``--check coverage``: at every distinct running time of those members, the default optimum and its
certificate against the optimum solved with the speed nodes uniform in ``v^2`` (``top_bias = 0``)
and with twice the speed nodes; a *miss* is another solve lower by more than the certificate
(exit status 1). Writes ``certificate_coverage.md``.

``--check parts``: the certificate's parts where the members came closest to the reference
(wuguang-crh3 at 1050.53 s, Yizhuang section 1-2 at 119.43 s) beside finer grids and the run
without the tie rule. Writes ``certificate.md``.

``--check grid-steps``: CPU time of the exact optimum against line length with the default grid
step (first stretches of the TTOBench 48.5 km reference track, VIRM6, 1.15 x the minimum time);
prints a table.

Usage::

    nice -n 10 python benchmarks/reference_check.py                      # about 70 CPU seconds
    python benchmarks/reference_check.py --report-only                   # report from reference_check.csv
    nice -n 10 python benchmarks/reference_check.py --check coverage     # about 4 CPU minutes
    python benchmarks/reference_check.py --check parts                   # about a minute
    python benchmarks/reference_check.py --check grid-steps
"""

from __future__ import annotations

import argparse
import time
import warnings
from pathlib import Path

import numpy as np
import pandas as pd
from tqdm import tqdm

from pymoo_rail.cases import load_case
from pymoo_rail.cases.ttobench import TTOBenchWarning, case_between, read_track, read_train
from pymoo_rail.experiments.reference_audit import (DERIVED, certificate_parts, check_members, coverage_summary,
                                                     coverage_table, members_summary, with_derived_columns)
from pymoo_rail.experiments.report import committed_members, lower_priority, markdown, member_cases, write_report
from pymoo_rail.model.grid import default_dx_m
from pymoo_rail.optimal import min_running_time, optimal_profile

REPORTS = Path(__file__).resolve().parent / "reports"
TTOBENCH = Path(__file__).resolve().parents[1] / "tests" / "data" / "ttobench"
PARTS_VARIANTS = ({"n_speeds": 100}, {"n_speeds": 400}, {"n_speeds": 800}, {"tie_j": 0.0})


def progress(items):
    """A progress bar over the cases."""
    return tqdm(items, desc="cases", unit="case")


def chosen_members(limit: int | None):
    """The committed members, or the first ``limit`` of each case (a quick run)."""
    table = committed_members(REPORTS)
    return table if limit is None else table.groupby("case", sort=False).head(limit)


def show(path: Path, lines: list[str]) -> None:
    """Write a report (no newline after its last line, as committed) and print it."""
    write_report(path, lines, newline=False)
    print("\n".join(lines))


def members(args) -> int:
    """Check every committed member (or report from the stored CSV); the number below the reference."""
    csv_path = args.out / "reference_check.csv"
    if args.report_only:
        if not csv_path.is_file():
            raise SystemExit(f"--report-only: no {csv_path}; run without --report-only first")
        table = with_derived_columns(pd.read_csv(csv_path))
    else:
        table = check_members(chosen_members(args.limit), member_cases(), progress=progress)
        # 9 digits (1 mWh on 1000 kWh), far below any gap quoted; the derived columns are rebuilt on reading
        table.drop(columns=list(DERIVED)).to_csv(csv_path, index=False, float_format="%.9g")
    s = members_summary(table)
    n_below = int(s["below_reference"].sum())
    lines = ["# Committed optimiser results against the exact optimum at their own running time", "",
             "Written by `python benchmarks/reference_check.py` (it reads the study CSVs of `benchmarks/reports`, "
             "see its docstring for which members). Each member is compared with the optimum solved at its own "
             "running time (`pymoo_rail.optimal.solved_energy_gap`, default grid) and with that solve's certificate "
             "`energy_bound_kwh`. *margin* = gap + certificate: a negative margin is a member below the optimum by "
             "more than the certificate, a defect of the reference.", "",
             f"Members in range: {int(table['in_range'].sum())} of {len(table)}; below the reference beyond the "
             f"certificate: **{n_below}**.", "", markdown(s), ""]
    show(args.out / "reference_check.md", lines)
    return n_below


def coverage(args) -> int:
    """The certificate against other grids at every member time; the number of misses."""
    start = time.process_time()
    result = coverage_table(chosen_members(args.limit), member_cases(), progress=progress)
    cpu = time.process_time() - start
    s, sentences = coverage_summary(result)
    misses = int(s["misses"].sum())
    lines = ["# The default solver's certificate against other node placements and a finer grid", "",
             "Written by `python benchmarks/reference_check.py --check coverage`: at every distinct running time of "
             "the optimiser members `benchmarks/reference_check.py` reads, the default solver's optimum "
             "(`ReferenceAtTime`, the run moved to the time along the front's slope) and its certificate against the "
             "same optimum solved with the speed nodes uniform in v^2 and with twice the speed nodes (each at the "
             "chord between its solves on either side of the time, the energy its runs reach there). A *miss* is "
             "another solve lower than the default by more than the default's certificate; *worst margin* = "
             "certificate - difference.", "",
             f"Times compared: {int(np.isfinite(result['default_kwh']).sum())}; misses: **{misses}**; "
             f"CPU {cpu:.0f} s.", "", *sentences, "", markdown(s), ""]
    show(args.out / "certificate_coverage.md", lines)
    return misses


def parts(args) -> int:
    """The certificate's parts beside finer grids where the members came closest; writes certificate.md."""
    from pymoo_rail.cases.ttobench import BEIJING_SUBWAY_TRAIN, YIZHUANG_STOP_NAMES, YIZHUANG_TRACK
    from pymoo_rail.journeys import journey_from_ttobench

    section = journey_from_ttobench(YIZHUANG_TRACK, BEIJING_SUBWAY_TRAIN, stop_names=YIZHUANG_STOP_NAMES).sections[1]
    points = [("wuguang-crh3", load_case("wuguang-crh3"), 1050.53), ("Yizhuang section 1-2", section, 119.432943)]
    table = certificate_parts(points, PARTS_VARIANTS).set_index("case").T.reset_index().rename(
        columns={"index": "figure"})
    lines = ["# The certificate's parts", "", "Written by `python benchmarks/reference_check.py --check parts`: the "
             "default run (200 speed nodes, `tie_j` = 100 J) and its certificate with its parts, beside finer grids "
             "and the run without the tie rule, all moved to the default run's time along the front's slope. The "
             "certificate is the grid part plus the floor plus the largest of the other three.", "", markdown(table), ""]
    show(args.out / "certificate.md", lines)
    return 0


def grid_steps(args) -> int:
    """Print the CPU time of the exact optimum against line length (the default step grows with length)."""
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", TTOBenchWarning)
        track = read_track(TTOBENCH / "tracks" / "00_reference.json")
        train = read_train(TTOBENCH / "trains" / "NL_Intercity_VIRM6.json")
    warm = case_between(track, train, 0.0, 3000.0, 1.0)
    optimal_profile(warm, 1.15 * min_running_time(warm))  # compile outside the timings
    rows = []
    for km in (5, 8, 10, 12, 15, 20, 30, 40, 48.531):
        case = case_between(track, train, 0.0, km * 1000.0, 1.0)
        start = time.process_time()
        optimal_profile(case, 1.15 * min_running_time(case))
        rows.append({"km": km, "dx m": default_dx_m(case), "cells": case.line.length_m / default_dx_m(case),
                     "CPU s": time.process_time() - start})
    table = pd.DataFrame(rows)
    table["/ 10 km"] = table["CPU s"] / table.loc[table["km"] == 10, "CPU s"].iloc[0]
    print(markdown(table, 2))
    return 0


def main(argv=None) -> int:
    """Run one check; exit status 1 when a member lies below the reference or the certificate misses."""
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--check", choices=("members", "coverage", "parts", "grid-steps"), default="members")
    parser.add_argument("--out", type=Path, default=REPORTS, help="report folder")
    parser.add_argument("--report-only", action="store_true", help="members: report from the stored CSV")
    parser.add_argument("--limit", type=int, default=None, help="only the first N members of each case (a quick run)")
    args = parser.parse_args(argv)
    lower_priority()
    check = {"members": members, "coverage": coverage, "parts": parts, "grid-steps": grid_steps}[args.check]
    return 1 if check(args) else 0


if __name__ == "__main__":
    raise SystemExit(main())
