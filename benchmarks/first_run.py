"""First run of the README's main command: cold (Numba compiles, empty cache) and warm.

Runs ``python -m pymoo_rail.cli optimize yizhuang --algorithm nsga2 --out DIR -q`` in a child
process, first with an empty ``NUMBA_CACHE_DIR`` (what a fresh installation does) and then again
with the cache it left (every later run). Prints the child's wall time and CPU time (user + system,
all threads), and whether the compile message appeared. On a loaded machine the wall time grows
with the load; the CPU time is what the run costs.

    python benchmarks/first_run.py [--repeat 1]
"""

from __future__ import annotations

import argparse
import os
import resource
import subprocess
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
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


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--repeat", type=int, default=1, help="cold/warm pairs to run")
    args = parser.parse_args()
    load = os.getloadavg()[0]
    print(f"load average at start: {load:.1f} on {os.cpu_count()} CPUs")
    print("run   wall s   CPU s   compile message")
    for _ in range(args.repeat):
        with tempfile.TemporaryDirectory() as cache, tempfile.TemporaryDirectory() as out:
            for label in ("cold", "warm"):
                wall, cpu, err = run_once(cache, out)
                said = "compiling the simulator" in err
                print(f"{label:5} {wall:7.1f} {cpu:7.1f}   {'yes' if said else 'no'}")
    print(f"load average at end: {os.getloadavg()[0]:.1f}")


if __name__ == "__main__":
    main()
