"""CPU time of the exact optimum against line length with the default grid step.

Usage: python benchmarks/grid_steps.py
Runs first stretches of the TTOBench 48.5 km reference track (level, 140 km/h) with the VIRM6
train: the default step grows from 1 m at 10 km to 5 m at 40 km (``model/grid.py``), so the cost
should grow smoothly with length instead of dropping at one length. Prints length, step, cells and
the CPU seconds of ``optimal_profile`` at 1.15 x the minimum running time, relative to 10 km.
"""

from __future__ import annotations

import time
import warnings
from pathlib import Path

from pymoo_rail.cases.ttobench import TTOBenchWarning, case_between, read_track, read_train
from pymoo_rail.model.grid import default_dx_m
from pymoo_rail.optimal import min_running_time, optimal_profile

ROOT = Path(__file__).resolve().parents[1] / "tests" / "data" / "ttobench"


def main() -> None:
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", TTOBenchWarning)
        track = read_track(ROOT / "tracks" / "00_reference.json")
        train = read_train(ROOT / "trains" / "NL_Intercity_VIRM6.json")
    warm = case_between(track, train, 0.0, 3000.0, 1.0)
    optimal_profile(warm, 1.15 * min_running_time(warm))  # compile outside the timings
    rows = []
    for km in (5, 8, 10, 12, 15, 20, 30, 40, 48.531):
        case = case_between(track, train, 0.0, km * 1000.0, 1.0)
        t0 = time.process_time()
        t_min = min_running_time(case)
        optimal_profile(case, 1.15 * t_min)
        rows.append((km, default_dx_m(case), case.line.length_m / default_dx_m(case), time.process_time() - t0))
    base = next(r[3] for r in rows if r[0] == 10)
    print("| km | dx m | cells | CPU s | / 10 km |")
    print("|---|---|---|---|---|")
    for km, dx, cells, cpu in rows:
        print(f"| {km:g} | {dx:.2f} | {cells:.0f} | {cpu:.2f} | {cpu / base:.2f} |")


if __name__ == "__main__":
    main()
