"""pymoo-rail's exact solver beside the continuous optimal-control solvers, on the same model.

For each case: pymoo-rail's energy at the requested running time, its certificate (the bound on the
error, ``OptimalSolver.energy_bound_kwh``), the running time of its run and its CPU time (tables,
lambda search, replay and certificate; ``time.process_time``, so both cores of a parallel sweep
count), beside

- ms-eetc (Kouzoupis et al., direct multiple shooting with CasADi/IPOPT; not on the package index):
  run here when ``--mseetc PATH`` gives a checkout and ``--mseetc-python`` an interpreter with its
  dependency casadi (``pip install casadi``; pandas >= 2 is bridged by the driver); otherwise its figures recorded on this machine (date below);
- GPOPS-II (hp-adaptive pseudospectral), the published figure of the ms-eetc paper for the 48.5 km
  case: 440.14 kWh in 7.0 s;
- the closed form (Pontryagin, ``pymoo_rail.optimal.flat``) on the level case.

Usage: ``python benchmarks/peers.py [--mseetc PATH --mseetc-python PYTHON] [--quick] [--breakdown]``, or
``python benchmarks/peers.py --generated N [--first-seed S] [--intervals 300 1000] [--repeats R] --mseetc PATH``:
the reference and ms-eetc on N generated intercity lines (``pymoo_rail.cases.generate_case``) x 3
running times, with differences in % of traction energy, CPU ratios and every certificate violation
(report ``benchmarks/reports/peers_generated.md``, its table beside it as CSV). ms-eetc at a large N is slow
(minutes per answer): ``--mseetc-only --intervals 2000 --cache FILE.csv`` fills a cache in the background
(resumable), and a run with ``--intervals 300 2000 --cache FILE.csv`` reads N=2000 from it (NaN where missing)
while running N=300 side by side; ``--refresh`` rewrites the report from its CSV with the cache read again.
(``--quick``: only the two intercity cases; ``--breakdown``: also where pymoo-rail's CPU time goes, per
Numba kernel of the exact solver, from a second run under cProfile; ``--sweep-cpu SEED FACTOR``: only one DP sweep
and forward run on a generated line, with and without the singular speeds). Writes ``benchmarks/reports/peers.md``.
"""


from __future__ import annotations

import argparse
import os
import sys
from pathlib import Path

import pandas as pd

from pymoo_rail.experiments.peers import (
    generated_rows,
    generated_summary,
    mseetc_only,
    named_rows,
    refresh_cached,
    speed_ratios,
    sweep_cpu,
    warm_up,
)
from pymoo_rail.experiments.report import fill_template, markdown, write_filled, write_report

HERE = Path(__file__).resolve().parent
REPORT = HERE / "reports" / "peers.md"
TEMPLATES = HERE / "templates"
CASES = [  # (case, running time s, ms-eetc track id or None)
    (str(HERE / "cases" / "intercity-var-limit-100.toml"), 1541.0, "00_var_speed_limit_100"),
    (str(HERE / "cases" / "intercity-level-10km.toml"), 400.0, "level_10km"),
    ("yizhuang", 150.0, None),
    ("wuguang-crh3", 1050.0, None),
]


def main_generated(args) -> None:
    """``--generated N``: the reference and ms-eetc side by side on generated lines."""
    warm_up()
    load_at_start = os.getloadavg()[0]
    seeds = args.seeds if args.seeds else range(args.first_seed, args.first_seed + args.generated)
    intervals = tuple(args.intervals)
    cache = {max(intervals): args.cache} if args.cache else {}  # the slow N: read, never run here
    if args.refresh:  # the table of an earlier run, with the slow N's answers cached since
        table = refresh_cached(pd.read_csv(args.report.with_suffix(".csv")), cache)
    else:
        table = generated_rows(seeds, args.mseetc, args.mseetc_python, intervals, args.repeats, cache)
    table.to_csv(args.report.with_suffix(".csv"), index=False)
    provenance = (" Rewritten with `--refresh` from the table of that run (its CSV beside this report), the largest N"
                  " read again from `--cache`." if args.refresh else
                  f" Load average (1 min) at the start and the end: {load_at_start:.2f} / {os.getloadavg()[0]:.2f}.")
    selection = (f"--seeds {' '.join(map(str, seeds))}" if args.seeds else
                 f"--generated {args.generated} --first-seed {args.first_seed}")
    features = table.groupby("seed")["features"].first().items()
    print(write_filled(args.report, TEMPLATES / "peers_generated.md", {
        "selection": selection, "intervals": " ".join(map(str, intervals)), "repeats": args.repeats,
        "provenance": provenance, "summary": "\n".join(generated_summary(table, intervals)),
        "table": markdown(table.drop(columns=["features"])),
        "features": "\n".join(f"- seed {s}: {f}" for s, f in features)}))


def main_named(args) -> None:
    """The named cases (``CASES``) beside ms-eetc (run here or recorded), GPOPS-II and the closed form."""
    warm_up()
    load_at_start = os.getloadavg()[0]
    ours, theirs, breakdown = named_rows(CASES[:2] if args.quick else CASES, args.mseetc, args.mseetc_python,
                                         args.breakdown)
    ratios = speed_ratios(ours, theirs)
    text = fill_template(TEMPLATES / "peers.md", {
        "load_start": f"{load_at_start:.2f}", "load_end": f"{os.getloadavg()[0]:.2f}", "ours": markdown(ours),
        "theirs": markdown(theirs) if len(theirs) else "(none)",
        "ratios": markdown(ratios) if len(ratios) else "(none)"})
    if len(breakdown):
        text += "\n" + fill_template(TEMPLATES / "peers_breakdown.md", {"table": markdown(breakdown)})
    write_report(REPORT, [text], newline=False)
    print(text)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--mseetc", type=Path, help="an ms-eetc checkout to run here")
    parser.add_argument("--mseetc-python", default=sys.executable, help="interpreter with ms-eetc's dependencies")
    parser.add_argument("--quick", action="store_true", help="only the two intercity cases")
    parser.add_argument("--breakdown", action="store_true", help="also pymoo-rail's CPU time per solver kernel")
    parser.add_argument("--generated", type=int, default=0, help="instead: N generated intercity lines x 3 times")
    parser.add_argument("--first-seed", type=int, default=0, help="seed of the first generated line")
    parser.add_argument("--seeds", type=int, nargs="+", help="instead of --generated/--first-seed: these seeds")
    parser.add_argument("--intervals", type=int, nargs="+", default=[300, 1000], help="ms-eetc's N on generated lines")
    parser.add_argument("--repeats", type=int, default=1, help="ms-eetc solves per answer (best CPU time)")
    parser.add_argument("--report", type=Path, default=HERE / "reports" / "peers_generated.md",
                        help="where the generated lines' report goes")
    parser.add_argument("--cache", type=Path, nargs="+", default=[],
                        help="CSVs of ms-eetc's answers at the largest N: read (not run) with --generated/--seeds,"
                             " filled (the first) with --mseetc-only")
    parser.add_argument("--mseetc-only", action="store_true", help="only fill --cache with ms-eetc's answers")
    parser.add_argument("--refresh", action="store_true",
                        help="rewrite the report from its CSV (an earlier run), reading --cache again")
    parser.add_argument("--sweep-cpu", type=float, nargs=2, metavar=("SEED", "FACTOR"),
                        help="only: CPU of one DP sweep and forward run with and without the singular speeds")
    args = parser.parse_args()
    if args.sweep_cpu:
        print("\n".join(sweep_cpu(int(args.sweep_cpu[0]), args.sweep_cpu[1], repeats=3)))
        return
    if args.mseetc_only:
        seeds = args.seeds if args.seeds else range(args.first_seed, args.first_seed + args.generated)
        mseetc_only(seeds, args.mseetc, args.mseetc_python, tuple(args.intervals), args.cache[0])
        return
    if args.generated or args.seeds:
        main_generated(args)
        return
    main_named(args)


if __name__ == "__main__":
    main()
