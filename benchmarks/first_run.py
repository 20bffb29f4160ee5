"""First run of the README's main command: cold (Numba compiles, empty cache) and warm.

Runs ``python -m pymoo_rail.cli optimize yizhuang --algorithm nsga2 --out DIR -q`` in a child
process, first with an empty ``NUMBA_CACHE_DIR`` (what a fresh installation does) and then again
with the cache it left (every later run). Prints the child's wall time and CPU time (user + system,
all threads), and whether the compile message appeared. On a loaded machine the wall time grows
with the load; the CPU time is what the run costs.

    python benchmarks/first_run.py [--repeat 1] [--note "fresh clone"] [--no-report]

Each measurement is appended to ``benchmarks/reports/first_run.csv`` (date, commit, CPUs, load
averages, run, wall and CPU time, compile message) and ``benchmarks/reports/first_run.md`` is
rebuilt from that file, newest first: the README's first-run figures are rows of it.
"""

from __future__ import annotations

import argparse
import os
from pathlib import Path

import pandas as pd

from pymoo_rail.experiments.first_run import LOG_COLUMNS, cold_and_warm, git_commit, measurement_rows, newest_first
from pymoo_rail.experiments.report import fill_template, write_report

ROOT = Path(__file__).resolve().parents[1]
REPORT_CSV = ROOT / "benchmarks" / "reports" / "first_run.csv"
TEMPLATES = Path(__file__).resolve().parent / "templates"


def write_reports(rows: list[dict]) -> None:
    """``first_run.csv`` with every measurement and ``first_run.md`` from it, newest first."""
    table = pd.DataFrame(rows, columns=list(LOG_COLUMNS)).fillna("")
    table.to_csv(REPORT_CSV, index=False, lineterminator="\r\n")  # the line ends csv.writer wrote
    lines = [f"| {r['date']} | {r['commit']} | {r['note']} | {r['cpus']} | {r['load_start']} / {r['load_end']} | "
             f"{r['run']} | {r['wall_s']} | {r['cpu_s']} | {r['compile_message']} |" for r in newest_first(rows)]
    write_report(REPORT_CSV.with_suffix(".md"), [fill_template(TEMPLATES / "first_run.md", {"rows": "\n".join(lines)})],
                 newline=False)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--repeat", type=int, default=1, help="cold/warm pairs to run")
    parser.add_argument("--note", default="", help="what the report should say about this run (e.g. 'fresh clone')")
    parser.add_argument("--no-report", action="store_true", help="print only; leave the report files alone")
    args = parser.parse_args()
    load, commit = os.getloadavg()[0], git_commit(ROOT)  # the commit before the runs: the code they ran
    print(f"load average at start: {load:.1f} on {os.cpu_count()} CPUs\nrun   wall s   CPU s   compile message")
    measured = []
    for label, wall, cpu, said in cold_and_warm(ROOT, repeat=args.repeat):
        print(f"{label:5} {wall:7.1f} {cpu:7.1f}   {'yes' if said else 'no'}")
        measured.append((label, wall, cpu, said))
    load_end = os.getloadavg()[0]
    print(f"load average at end: {load_end:.1f}")
    if not args.no_report:
        old = pd.read_csv(REPORT_CSV, dtype=str, keep_default_na=False).to_dict("records") if REPORT_CSV.is_file() else []
        write_reports(old + measurement_rows(measured, commit, args.note, load, load_end))
        print(f"wrote {REPORT_CSV.relative_to(ROOT)} and {REPORT_CSV.with_suffix('.md').relative_to(ROOT)}")


if __name__ == "__main__":
    main()
