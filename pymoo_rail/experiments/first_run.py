"""The first run of a command, cold (Numba compiles into an empty cache) and warm (the cache it left).

:func:`cold_and_warm` times a command in child processes; :func:`measurement_rows` stamps what it
measured (date, commit, CPUs, load averages) as rows of a log that keeps every measurement, and
:func:`newest_first` orders that log for a report. ``benchmarks/first_run.py`` runs the README's
main command with them and keeps ``benchmarks/reports/first_run.csv``.
"""

from __future__ import annotations

import datetime as dt
import os
import resource
import subprocess
import sys
import tempfile
import time
from pathlib import Path
from typing import Iterator, Sequence

LOG_COLUMNS = ("date", "commit", "note", "cpus", "load_start", "load_end", "run", "wall_s", "cpu_s", "compile_message")
STAMP = LOG_COLUMNS[:6]
MAIN_COMMAND = ("-m", "pymoo_rail.cli", "optimize", "yizhuang", "--algorithm", "nsga2", "-q")
COMPILE_MESSAGE = "compiling the simulator"


def timed_child(args: Sequence[str], cwd: str | Path, env: dict) -> tuple[float, float, str]:
    """``(wall s, CPU s of the child (user + system, all threads), stderr)`` of ``python ARGS``.

    Raises
    ------
    RuntimeError
        The child failed (the message holds its exit code and stderr).
    """
    before = resource.getrusage(resource.RUSAGE_CHILDREN)
    start = time.perf_counter()
    done = subprocess.run([sys.executable, *args], cwd=cwd, env=env, capture_output=True, text=True)
    wall = time.perf_counter() - start
    after = resource.getrusage(resource.RUSAGE_CHILDREN)
    if done.returncode != 0:
        raise RuntimeError(f"the command {' '.join(args)} failed ({done.returncode}):\n{done.stderr}")
    return wall, (after.ru_utime - before.ru_utime) + (after.ru_stime - before.ru_stime), done.stderr


def cold_and_warm(cwd: str | Path, command: Sequence[str] = MAIN_COMMAND, repeat: int = 1) -> Iterator[tuple]:
    """Run ``python COMMAND --out DIR`` cold then warm, ``repeat`` times, each pair with a fresh cache.

    Yields
    ------
    (str, float, float, bool)
        ``("cold" or "warm", wall s, CPU s, whether the compile message appeared)``, as each run ends.
    """
    for _ in range(repeat):
        with tempfile.TemporaryDirectory() as cache, tempfile.TemporaryDirectory() as out:
            env = dict(os.environ, NUMBA_CACHE_DIR=cache, MPLBACKEND="Agg")
            for label in ("cold", "warm"):
                wall, cpu, err = timed_child([*command, "--out", out], cwd, env)
                yield label, wall, cpu, COMPILE_MESSAGE in err


def git_commit(root: str | Path) -> str:
    """The short commit of the checkout at ``root`` (``+`` when it has uncommitted changes)."""
    def git(*args: str) -> str:
        return subprocess.run(["git", *args], cwd=root, capture_output=True, text=True).stdout.strip()
    head = git("rev-parse", "--short", "HEAD") or "unknown"
    return head + ("+" if git("status", "--porcelain", "--untracked-files=no") else "")


def measurement_rows(measured: Sequence[tuple], commit: str, note: str, load_start: float,
                     load_end: float) -> list[dict]:
    """Rows of the log (:data:`LOG_COLUMNS`, as text) for the runs of one measurement (:func:`cold_and_warm`)."""
    stamp = dict(date=dt.date.today().isoformat(), commit=commit, note=note, cpus=os.cpu_count(),
                 load_start=f"{load_start:.1f}", load_end=f"{load_end:.1f}")
    return [dict(stamp, run=label, wall_s=f"{wall:.1f}", cpu_s=f"{cpu:.1f}", compile_message="yes" if said else "no")
            for label, wall, cpu, said in measured]


def newest_first(rows: Sequence[dict]) -> list[dict]:
    """The log's rows, newest measurement first (a measurement: consecutive rows with the same stamp)."""
    blocks: list[list[dict]] = []
    for row in rows:
        if blocks and all(blocks[-1][0][k] == row[k] for k in STAMP):
            blocks[-1].append(row)
        else:
            blocks.append([row])
    return [r for block in reversed(blocks) for r in block]
