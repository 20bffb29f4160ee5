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
    nice python benchmarks/suite_baseline.py --study single --workers 2           # the one-objective families
    python benchmarks/suite_baseline.py --study trip --workers 1                  # the -trip families, repaired

``--study single`` does the same for ``benchmarks/suite_baseline_single.toml`` (the ``-single``
families, scored by the gap to the optimum) into ``suite_baseline_single.md``; ``--study trip`` for
``benchmarks/suite_baseline_trip.toml`` (the ``-trip`` families, the same algorithms repaired onto the
budget by ``pymoo_rail.journeys.repaired``) into ``suite_baseline_trip.md``.
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
from pymoo_rail.experiments.baseline import (archive_records, convergence, cpu_per_evaluation_ms, cut_study,
                                             frame_indicators, indicator_frame, performance_profile, projected_cpu_h,
                                             report_values)
from pymoo_rail.experiments.report import write_filled
from pymoo_rail.experiments.results import load_records
from pymoo_rail.experiments.run_cost import PARTS, cpu_profile, cpu_shares
from pymoo_rail.plotting import plot_cell_convergence, plot_performance_profile

ROOT = Path(__file__).resolve().parent.parent
STUDIES = {"table": "suite_baseline", "single": "suite_baseline_single", "trip": "suite_baseline_trip"}
"""``--study``: the name of its study file (benchmarks/), template (benchmarks/templates/) and report."""


def figures(history, frame, out: Path, name: str) -> list[str]:
    """Median of the profile indicator (IGD+; the gap for one objective) vs evaluations per (family, n_var),
    from the records' checkpoints scored now (``history``), and the performance profile on it (PNG files)."""
    import matplotlib.pyplot as plt

    scores = frame_indicators(frame)
    plot_cell_convergence(history, scores.profile).savefig(out / f"{name}_convergence.png", dpi=110)
    plot_performance_profile(performance_profile(frame), scores.label).savefig(out / f"{name}_profile.png", dpi=110)
    plt.close("all")
    return [f"{name}_convergence.png", f"{name}_profile.png"]


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
    parser.add_argument("--study", choices=sorted(STUDIES), default="table", help="the study file (default: table)")
    parser.add_argument("--families", nargs="+", default=None, help="families of the study file (default: all)")
    parser.add_argument("--ladder", nargs="+", type=int, default=None, help="n_var values (default: 10 30 100 300 1000)")
    parser.add_argument("--seeds", type=int, default=None, help="seeds 1..N (default: the study file's 31)")
    parser.add_argument("--n-eval", type=int, default=None, help="evaluations per run (default: the study file's)")
    parser.add_argument("--workers", type=int, default=None)
    parser.add_argument("--dask", action="store_true", help="run on a local Dask cluster of --workers processes")
    parser.add_argument("--work", default=None, help="study directory (records; default out/<study file's name>)")
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
    name = STUDIES[args.study]
    full, work = read_study(ROOT / "benchmarks" / f"{name}.toml"), args.work or str(ROOT / "out" / name)
    if args.profile:
        return profile(cut_study(full, args.families, args.ladder or [300, 1000], 1, args.n_eval),
                       args.algorithms, args.threads)
    study = cut_study(full, args.families, args.ladder, args.seeds, args.n_eval)
    # the trip study names the package's own repaired algorithms by import path: this script trusts
    # that file only (it reads no other); a user's study with import paths still needs --trust
    trusted = args.study == "trip"
    if not args.report_only:
        run_study(study, work, workers=args.workers, scheduler="local" if args.dask else None, seed_major=True,
                  trusted=trusted)
    records = load_records(work, study, trusted=trusted, decisions=False)  # scored on objective vectors alone
    if not records:
        raise SystemExit(f"no stored runs in {work}")
    frame, out = indicator_frame(records), Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    command = "python benchmarks/suite_baseline.py " + " ".join(argv if argv is not None else sys.argv[1:])
    history = convergence(records)
    values = report_values(study, full, frame, records, figures(history, frame, out, name), command.strip(),
                           f"benchmarks/{name}.toml", history)
    write_filled(out / f"{name}.md", ROOT / "benchmarks" / "templates" / f"{name}.md", values)
    print(f"wrote {out / f'{name}.md'}")
    if args.estimate:
        hours, sizes = projected_cpu_h(frame, full)
        print("median CPU ms per evaluation\n" + cpu_per_evaluation_ms(frame).round(3).to_string())
        print(f"the whole study (measured n_var {sizes}): {hours:.1f} CPU hours, {hours / 2:.1f} h on 2 cores; "
              f"{projected_cpu_h(frame, full, per_family=True)[0]:.1f} CPU hours from each family's own medians")
    if args.archive:
        print(f"archive {args.archive}: sha256 {archive_records(work, args.archive, name)}")
    return 0


if __name__ == "__main__":
    # runs made in this process (--workers 1) get one Numba thread, as each worker of the pool has:
    # the kernel's second thread saves little wall time and its spin-waits count as CPU of the run
    # (twice the kernel's CPU, ten times the history's, measured by --profile)
    numba.set_num_threads(1)
    raise SystemExit(main())
