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

The CPU time of the exact optimum against line length (``--check grid-steps``, whose conclusion
docs/ttobench.md gives) is in the script's last version with it: ``git show be39f07:benchmarks/reference_check.py``.

Usage::

    nice -n 10 python benchmarks/reference_check.py                      # about 70 CPU seconds
    python benchmarks/reference_check.py --report-only                   # report from reference_check.csv
    nice -n 10 python benchmarks/reference_check.py --check coverage     # about 4 CPU minutes
    python benchmarks/reference_check.py --check parts                   # about a minute
"""

from __future__ import annotations

import argparse
import time
from functools import partial
from pathlib import Path

import numpy as np
import pandas as pd
from tqdm import tqdm

from pymoo_rail.cases import load_case
from pymoo_rail.experiments.reference_audit import (DERIVED, certificate_parts, check_members, coverage_summary,
                                                     coverage_table, members_summary, with_derived_columns)
from pymoo_rail.experiments.report import committed_members, lower_priority, markdown, member_cases, write_filled

REPORTS = Path(__file__).resolve().parent / "reports"
TEMPLATES = Path(__file__).resolve().parent / "templates"
PROGRESS = partial(tqdm, desc="cases", unit="case")
PARTS_VARIANTS = ({"n_speeds": 100}, {"n_speeds": 400}, {"n_speeds": 800}, {"tie_j": 0.0})


def show(path: Path, values: dict) -> None:
    """Fill the report's template (``benchmarks/templates/<name>``), write it and print it."""
    print(write_filled(path, TEMPLATES / path.name, values))


def members(args) -> int:
    """Check every committed member (or report from the stored CSV); the number below the reference."""
    csv_path = args.out / "reference_check.csv"
    if args.report_only:
        if not csv_path.is_file():
            raise SystemExit(f"--report-only: no {csv_path}; run without --report-only first")
        table = with_derived_columns(pd.read_csv(csv_path))
    else:
        table = check_members(committed_members(REPORTS, args.limit), member_cases(), progress=PROGRESS)
        # 9 digits (1 mWh on 1000 kWh), far below any gap quoted; the derived columns are rebuilt on reading
        table.drop(columns=list(DERIVED)).to_csv(csv_path, index=False, float_format="%.9g")
    s = members_summary(table)
    n_below = int(s["below_reference"].sum())
    show(args.out / "reference_check.md", {"in_range": int(table["in_range"].sum()), "members": len(table),
                                            "below": n_below, "table": markdown(s)})
    return n_below


def coverage(args) -> int:
    """The certificate against other grids at every member time; the number of misses."""
    start = time.process_time()
    result = coverage_table(committed_members(REPORTS, args.limit), member_cases(), progress=PROGRESS)
    cpu = time.process_time() - start
    s, sentences = coverage_summary(result)
    misses = int(s["misses"].sum())
    show(args.out / "certificate_coverage.md", {"times": int(np.isfinite(result["default_kwh"]).sum()),
                                                 "misses": misses, "cpu_s": f"{cpu:.0f}",
                                                 "sentences": "\n".join(sentences), "table": markdown(s)})
    return misses


def parts(args) -> int:
    """The certificate's parts beside finer grids where the members came closest; writes certificate.md."""
    from pymoo_rail.cases.ttobench import BEIJING_SUBWAY_TRAIN, YIZHUANG_STOP_NAMES, YIZHUANG_TRACK
    from pymoo_rail.journeys import journey_from_ttobench

    section = journey_from_ttobench(YIZHUANG_TRACK, BEIJING_SUBWAY_TRAIN, stop_names=YIZHUANG_STOP_NAMES).sections[1]
    points = [("wuguang-crh3", load_case("wuguang-crh3"), 1050.53), ("Yizhuang section 1-2", section, 119.432943)]
    table = certificate_parts(points, PARTS_VARIANTS).set_index("case").T.reset_index().rename(
        columns={"index": "figure"})
    show(args.out / "certificate.md", {"table": markdown(table)})
    return 0


def main(argv=None) -> int:
    """Run one check; exit status 1 when a member lies below the reference or the certificate misses."""
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--check", choices=("members", "coverage", "parts"), default="members")
    parser.add_argument("--out", type=Path, default=REPORTS, help="report folder")
    parser.add_argument("--report-only", action="store_true", help="members: report from the stored CSV")
    parser.add_argument("--limit", type=int, default=None, help="only the first N members of each case (a quick run)")
    args = parser.parse_args(argv)
    lower_priority()
    check = {"members": members, "coverage": coverage, "parts": parts}[args.check]
    return 1 if check(args) else 0


if __name__ == "__main__":
    raise SystemExit(main())
