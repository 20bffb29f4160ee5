"""The suite's baseline table: seven algorithms on the bi-objective families over the dimension ladder.

Runs ``benchmarks/suite_baseline.toml`` through ``pymoo_rail.experiments.run_study`` (process pool,
or Dask with ``--dask``; resumable: stored runs are kept) and writes
``benchmarks/reports/suite_baseline.md``: per (family, n_var) and algorithm the mean +- std of
IGD+, normalised HV and energy gap to the certified front, the mean rank on IGD+ (Friedman) and the
Holm-corrected Wilcoxon mark against the best (``pymoo_rail.experiments.baseline``), and two
figures (IGD vs evaluations; performance profile on IGD+), generated next to it, not tracked.

Usage::

    nice python benchmarks/suite_baseline.py --workers 2                          # the whole table
    nice python benchmarks/suite_baseline.py --families generated-metro-bi --ladder 10 30 --seeds 5 --n-eval 2000
    python benchmarks/suite_baseline.py --report-only --archive out/suite_baseline.tar.gz
    nice python benchmarks/suite_baseline.py --profile                            # n_var 300 and 1000, every family
    nice python benchmarks/suite_baseline.py --profile --ladder 1000 --families generated-metro-bi --n-eval 2000

``--ladder``, ``--seeds``, ``--families`` and ``--n-eval`` reduce the study (the report says so);
``--archive PATH`` packs the study file and raw records into one .tar.gz and prints its SHA-256.
``--profile`` stores nothing: it runs seed 1 (default ``--ladder 300 1000``) in this process with
``--threads`` Numba threads (default 1, as each worker of the pool) and prints where each run's CPU
goes (``pymoo_rail.experiments.run_cost.cpu_profile``: kernel, problem, pymoo, history indicators,
record, report indicators) and per algorithm the shares over all runs printed.
"""

from __future__ import annotations

import argparse
import os
import sys
from pathlib import Path

import numba

from pymoo_rail.experiments import read_study, run_study
from pymoo_rail.experiments.baseline import (INDICATORS, archive_records, baseline_table, checkpoints_kb, convergence,
                                             cpu_per_evaluation_ms, cut_study, front_versions, fronts_statement,
                                             indicator_frame, performance_profile, projected_cpu_h)
from pymoo_rail.experiments.report import write_filled
from pymoo_rail.experiments.results import load_records
from pymoo_rail.experiments.run_cost import PARTS, cpu_profile, cpu_shares
from pymoo_rail.experiments.stats import to_markdown
from pymoo_rail.plotting import plot_cell_convergence, plot_performance_profile

ROOT = Path(__file__).resolve().parent.parent
STUDY_FILE = ROOT / "benchmarks" / "suite_baseline.toml"
TEMPLATE = ROOT / "benchmarks" / "templates" / "suite_baseline.md"


def figures(records, frame, out: Path) -> list[str]:
    """Median IGD+ vs evaluations per (family, n_var) (the records' checkpoints scored now), and the
    performance profile on IGD+ (PNG files)."""
    import matplotlib.pyplot as plt

    plot_cell_convergence(convergence(records)).savefig(out / "suite_baseline_convergence.png", dpi=110)
    profile = plot_performance_profile(performance_profile(frame))
    profile.savefig(out / "suite_baseline_profile.png", dpi=110)
    plt.close("all")
    return ["suite_baseline_convergence.png", "suite_baseline_profile.png"]


def report_values(study, frame, records, pictures, command: str) -> dict:
    """The report's numbers: what ran, its CPU, the table and the figures."""
    table = baseline_table(frame)
    table["friedman_p"] = table["friedman_p"].map(lambda p: f"{p:.2g}")
    full = read_study(STUDY_FILE)
    reduced = (len(study.problems), len(study.seeds), study.budget) != (len(full.problems), len(full.seeds), full.budget)
    return {"reduced": " (reduced run: not the whole table of the study file)" if reduced else "",
            "command": command, "study_file": STUDY_FILE.relative_to(ROOT),
            "cells": frame.groupby(["family", "n_var"]).ngroups, "algorithms": len(study.algorithms),
            "seeds": len(study.seeds), "budget_kind": study.budget.kind, "budget": f"{study.budget.value:,}",
            "runs": len(frame), "cpu_min": f"{frame['cpu_time_s'].sum() / 60:.1f}",
            "cpu_mean": f"{frame['cpu_time_s'].mean():.2f}", "indicators": ", ".join(INDICATORS),
            "table": to_markdown(table, bold_marker=None), "fronts": fronts_statement(front_versions(records)),
            "checkpoints_kb": checkpoints_kb(records),
            "pictures": "\n".join(f"![{n}]({n})" for n in pictures)}


def profile(study, algorithms, threads: int) -> int:
    """Print the CPU of each part of each run of ``study`` (of ``algorithms``), then each algorithm's shares."""
    runs = [r for r in study.runs() if not algorithms or r.algorithm.display in algorithms]
    if not runs:
        raise SystemExit(f"--algorithms {algorithms}: none of the study's")
    previous, rows = numba.get_num_threads(), []
    numba.set_num_threads(threads)
    try:
        print(f"{'problem':28s} {'algorithm':11s} " + " ".join(f"{p:>8s}" for p in PARTS) + "    total  ms/eval")
        for row in cpu_profile(runs):
            print(f"{row['instance']:28s} {row['algorithm']:11s} " + " ".join(f"{row[p]:8.3f}" for p in PARTS)
                  + f" {row['total']:8.2f} {row['ms_per_eval']:8.3f}", flush=True)
            rows.append(row)
    finally:
        numba.set_num_threads(previous)
    print("\nshare of each part in the CPU of the runs above, per algorithm (%)")
    print(f"{'algorithm':11s} " + " ".join(f"{p:>8s}" for p in PARTS) + "  ms/eval")
    for name, share in cpu_shares(rows).iterrows():
        print(f"{name:11s} " + " ".join(f"{share[p]:8.1f}" for p in PARTS) + f" {share['ms_per_eval']:8.3f}")
    return 0


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--families", nargs="+", default=None, help="families of the study file (default: all)")
    parser.add_argument("--ladder", nargs="+", type=int, default=None, help="n_var values (default: 10 30 100 300 1000)")
    parser.add_argument("--seeds", type=int, default=None, help="seeds 1..N (default: the study file's 31)")
    parser.add_argument("--n-eval", type=int, default=None, help="evaluations per run (default: the study file's)")
    parser.add_argument("--workers", type=int, default=None)
    parser.add_argument("--dask", action="store_true", help="run on a local Dask cluster of --workers processes")
    parser.add_argument("--work", default=str(ROOT / "out" / "suite_baseline"), help="study directory (records)")
    parser.add_argument("--out", default=str(ROOT / "benchmarks" / "reports"), help="report directory")
    parser.add_argument("--report-only", action="store_true", help="write the report from stored records")
    parser.add_argument("--archive", type=Path, default=None, help="pack the raw records into this .tar.gz")
    parser.add_argument("--estimate", action="store_true",
                        help="print the whole study's CPU time projected from the stored runs' CPU per evaluation")
    parser.add_argument("--profile", action="store_true", help="print where each run's CPU goes (seed 1)")
    parser.add_argument("--algorithms", nargs="+", default=None, help="algorithm labels (--profile; default: all)")
    parser.add_argument("--threads", type=int, default=1, help="Numba threads (--profile; default 1)")
    args = parser.parse_args(argv)
    os.environ.setdefault("MPLBACKEND", "Agg")
    if args.profile:
        return profile(cut_study(read_study(STUDY_FILE), args.families, args.ladder or [300, 1000], 1, args.n_eval),
                       args.algorithms, args.threads)
    study = cut_study(read_study(STUDY_FILE), args.families, args.ladder, args.seeds, args.n_eval)
    if not args.report_only:
        run_study(study, args.work, workers=args.workers, scheduler="local" if args.dask else None, seed_major=True)
    records = load_records(args.work, study)
    if not records:
        raise SystemExit(f"no stored runs in {args.work}")
    frame, out = indicator_frame(records), Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    command = "python benchmarks/suite_baseline.py " + " ".join(argv if argv is not None else sys.argv[1:])
    pictures = figures(records, frame, out)
    write_filled(out / "suite_baseline.md", TEMPLATE, report_values(study, frame, records, pictures, command.strip()))
    print(f"wrote {out / 'suite_baseline.md'}")
    if args.estimate:
        hours, sizes = projected_cpu_h(frame, read_study(STUDY_FILE))
        print("median CPU ms per evaluation\n" + cpu_per_evaluation_ms(frame).round(3).to_string())
        print(f"the whole study (measured n_var {sizes}): {hours:.1f} CPU hours, {hours / 2:.1f} h on 2 cores")
    if args.archive:
        print(f"archive {args.archive}: sha256 {archive_records(args.work, args.archive)}")
    return 0


if __name__ == "__main__":
    # runs made in this process (--workers 1) get one Numba thread, as each worker of the pool has:
    # the kernel's second thread saves little wall time and its spin-waits count as CPU of the run
    # (twice the kernel's CPU, ten times the history's, measured by --profile)
    numba.set_num_threads(1)
    raise SystemExit(main())
