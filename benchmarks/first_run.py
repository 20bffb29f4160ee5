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
import csv
import datetime as dt
import os
import resource
import subprocess
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
REPORT_CSV = ROOT / "benchmarks" / "reports" / "first_run.csv"
REPORT_MD = REPORT_CSV.with_suffix(".md")
COLUMNS = ("date", "commit", "note", "cpus", "load_start", "load_end", "run", "wall_s", "cpu_s", "compile_message")
COMMAND = ["-m", "pymoo_rail.cli", "optimize", "yizhuang", "--algorithm", "nsga2", "-q"]


def run_once(cache_dir: str, out_dir: str) -> tuple[float, float, str]:
    """(wall s, CPU s, stderr) of one run of the main command in a child process."""
    env = dict(os.environ, NUMBA_CACHE_DIR=cache_dir, MPLBACKEND="Agg")
    before = resource.getrusage(resource.RUSAGE_CHILDREN)
    start = time.perf_counter()
    done = subprocess.run([sys.executable, *COMMAND, "--out", out_dir], cwd=ROOT, env=env,
                          capture_output=True, text=True)
    wall = time.perf_counter() - start
    after = resource.getrusage(resource.RUSAGE_CHILDREN)
    if done.returncode != 0:
        raise SystemExit(f"the main command failed ({done.returncode}):\n{done.stderr}")
    cpu = (after.ru_utime - before.ru_utime) + (after.ru_stime - before.ru_stime)
    return wall, cpu, done.stderr


def commit() -> str:
    """The short commit of the checkout measured (``+`` when it has uncommitted changes)."""
    def git(*args: str) -> str:
        return subprocess.run(["git", *args], cwd=ROOT, capture_output=True, text=True).stdout.strip()
    head = git("rev-parse", "--short", "HEAD") or "unknown"
    return head + ("+" if git("status", "--porcelain", "--untracked-files=no") else "")


def write_report(rows: list[dict]) -> None:
    """``first_run.md`` from every measurement in ``first_run.csv``, newest first."""
    lines = ["# First run of the README's main command", "",
             "Written by `python benchmarks/first_run.py` from `first_run.csv` (one row per run; every",
             "measurement appends its rows). The command is `pymoo-rail optimize yizhuang --algorithm nsga2`",
             "(NSGA-II, 40 x 50, energy and time error) in a child process: *cold* with an empty",
             "`NUMBA_CACHE_DIR` (a fresh installation: Numba compiles the kernels), then *warm* with the",
             "cache it left. CPU time is user + system of the child, all threads: what the run costs. Wall",
             "time grows with the load average (other processes on the same cores); compiling runs on one",
             "thread, so on an idle 2-core machine the cold wall time is about its CPU time.", "",
             "| date | commit | note | CPUs | load at start / end | run | wall s | CPU s | compile message |",
             "|---|---|---|---|---|---|---|---|---|"]
    stamp = ("date", "commit", "note", "cpus", "load_start", "load_end")
    blocks: list[list[dict]] = []  # one block per measurement (rows with the same stamp), in run order
    for row in rows:
        if blocks and all(blocks[-1][0][k] == row[k] for k in stamp):
            blocks[-1].append(row)
        else:
            blocks.append([row])
    for row in [r for block in reversed(blocks) for r in block]:
        lines.append(f"| {row['date']} | {row['commit']} | {row['note']} | {row['cpus']} | "
                     f"{row['load_start']} / {row['load_end']} | {row['run']} | {row['wall_s']} | "
                     f"{row['cpu_s']} | {row['compile_message']} |")
    REPORT_MD.write_text("\n".join(lines) + "\n", encoding="utf-8")


def read_rows() -> list[dict]:
    if not REPORT_CSV.is_file():
        return []
    with REPORT_CSV.open(newline="", encoding="utf-8") as handle:
        return list(csv.DictReader(handle))


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--repeat", type=int, default=1, help="cold/warm pairs to run")
    parser.add_argument("--note", default="", help="what the report should say about this run (e.g. 'fresh clone')")
    parser.add_argument("--no-report", action="store_true", help="print only; leave the report files alone")
    args = parser.parse_args()
    load = os.getloadavg()[0]
    measured_commit = commit()  # before the runs: the code they ran
    print(f"load average at start: {load:.1f} on {os.cpu_count()} CPUs")
    print("run   wall s   CPU s   compile message")
    measured = []
    for _ in range(args.repeat):
        with tempfile.TemporaryDirectory() as cache, tempfile.TemporaryDirectory() as out:
            for label in ("cold", "warm"):
                wall, cpu, err = run_once(cache, out)
                said = "compiling the simulator" in err
                print(f"{label:5} {wall:7.1f} {cpu:7.1f}   {'yes' if said else 'no'}")
                measured.append((label, wall, cpu, said))
    load_end = os.getloadavg()[0]
    print(f"load average at end: {load_end:.1f}")
    if args.no_report:
        return
    stamp = dict(date=dt.date.today().isoformat(), commit=measured_commit, note=args.note, cpus=os.cpu_count(),
                 load_start=f"{load:.1f}", load_end=f"{load_end:.1f}")
    rows = read_rows() + [dict(stamp, run=label, wall_s=f"{wall:.1f}", cpu_s=f"{cpu:.1f}",
                               compile_message="yes" if said else "no") for label, wall, cpu, said in measured]
    with REPORT_CSV.open("w", newline="", encoding="utf-8") as handle:
        writer = csv.DictWriter(handle, fieldnames=COLUMNS)
        writer.writeheader()
        writer.writerows({k: row.get(k, "") for k in COLUMNS} for row in rows)
    write_report(rows)
    print(f"wrote {REPORT_CSV.relative_to(ROOT)} and {REPORT_MD.relative_to(ROOT)}")


if __name__ == "__main__":
    main()
