"""Case loading against the number of gradient rows: does it grow linearly?

Writes the Yizhuang case (2265 m) with its gradients cut into n rows of random gradients
(seeded), then times, in this one run, ``load_case`` (read, parse, check) and ``build_grid``
(the simulator's distance grid) on each file, in wall-clock and CPU seconds (CPU time is what
a shared machine does not inflate). Prints one line per size and the CPU time per 100 000 rows,
which stays flat when the cost is linear in the rows (before the fix the grid build grew with the
square of them: 200 000 rows took minutes).

Usage: ``python benchmarks/case_loading.py [--max-rows 1200000]`` (a few minutes on a shared
machine at 1.2 M rows, most of it writing the files).
"""

from __future__ import annotations

import argparse
import tempfile
import time
from dataclasses import replace
from pathlib import Path

import numpy as np

from pymoo_rail.cases import load_case, write_case
from pymoo_rail.model import build_grid

ROWS = (16_000, 32_000, 64_000, 200_000, 600_000, 1_200_000)


def case_with_rows(n_rows: int):
    """Yizhuang with ``n_rows`` gradient rows of -30 to +30 permille."""
    case = load_case("yizhuang")
    edges = np.linspace(0.0, case.line.length_m, n_rows + 1)
    permille = np.round(np.random.default_rng(n_rows).uniform(-30.0, 30.0, n_rows), 3)
    rows = tuple(zip(edges[:-1].tolist(), edges[1:].tolist(), permille.tolist()))
    return replace(case, name=f"yizhuang-{n_rows}-rows", line=replace(case.line, gradients=rows))


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--max-rows", type=int, default=ROWS[-1])
    args = parser.parse_args()
    print(f"{'rows':>10} {'file MB':>8} {'load s':>8} {'load CPU s':>10} {'grid s':>8} {'grid CPU s':>10} "
          f"{'load CPU s/100k':>16} {'grid CPU s/100k':>16}")
    build_grid(load_case("yizhuang"))  # compiles (or loads) the grid's Numba helper before timing
    with tempfile.TemporaryDirectory() as folder:
        for n_rows in (n for n in ROWS if n <= args.max_rows):
            path = write_case(case_with_rows(n_rows), Path(folder) / f"rows{n_rows}.toml")
            start, start_cpu = time.perf_counter(), time.process_time()
            case = load_case(path)
            loaded, loaded_cpu = time.perf_counter(), time.process_time()
            build_grid(case)
            gridded, gridded_cpu = time.perf_counter(), time.process_time()
            load_cpu, grid_cpu = loaded_cpu - start_cpu, gridded_cpu - loaded_cpu
            print(f"{n_rows:>10} {path.stat().st_size / 1e6:>8.1f} {loaded - start:>8.2f} {load_cpu:>10.2f} "
                  f"{gridded - loaded:>8.2f} {grid_cpu:>10.2f} {load_cpu / n_rows * 1e5:>16.3f} "
                  f"{grid_cpu / n_rows * 1e5:>16.3f}", flush=True)
            path.unlink()


if __name__ == "__main__":
    main()
