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

from pymoo_rail.cases import load_case
from pymoo_rail.experiments.scaling import case_with_rows, load_and_grid_timing
from pymoo_rail.model import build_grid

ROWS = (16_000, 32_000, 64_000, 200_000, 600_000, 1_200_000)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--max-rows", type=int, default=ROWS[-1])
    args = parser.parse_args()
    print(f"{'rows':>10} {'file MB':>8} {'load s':>8} {'load CPU s':>10} {'grid s':>8} {'grid CPU s':>10} "
          f"{'load CPU s/100k':>16} {'grid CPU s/100k':>16}")
    build_grid(load_case("yizhuang"))  # compiles (or loads) the grid's Numba helper before timing
    with tempfile.TemporaryDirectory() as folder:
        for n_rows in (n for n in ROWS if n <= args.max_rows):
            r = load_and_grid_timing(case_with_rows(n_rows), folder)
            print(f"{n_rows:>10} {r['file_mb']:>8.1f} {r['load_s']:>8.2f} {r['load_cpu_s']:>10.2f} {r['grid_s']:>8.2f} "
                  f"{r['grid_cpu_s']:>10.2f} {r['load_cpu_s'] / n_rows * 1e5:>16.3f} "
                  f"{r['grid_cpu_s'] / n_rows * 1e5:>16.3f}", flush=True)


if __name__ == "__main__":
    main()
