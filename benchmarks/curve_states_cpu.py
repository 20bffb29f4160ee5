"""CPU of ``OptimalSolver.profile`` with and without the DP's curve states (``dp.coast_curves``).

Both variants run interleaved in one process (the order alternating per line, so load drifts hit both
alike) on generated lines 0, 4, 7 and 13 at 1.05 / 1.2 / 1.5 x the minimum time; prints each pair, the
total and median ratio, and the CPU of computing the curves of one line.

    python benchmarks/curve_states_cpu.py
"""

from __future__ import annotations

import time

import numpy as np

from pymoo_rail.experiments.peers import comparable_case
from pymoo_rail.optimal import OptimalSolver, dp, min_running_time

SEEDS = (0, 4, 7, 13)
FACTORS = (1.05, 1.2, 1.5)


def no_curves(model, *args, **kwargs) -> tuple[np.ndarray, np.ndarray]:
    """``dp.coast_curves`` without a curve: the solver of version 3."""
    n = model.position_m.shape[0]
    return np.zeros((n, 0)), np.full((n, 0), -1.0)


def main() -> None:
    with_curves = dp.coast_curves
    warm = comparable_case(0)
    OptimalSolver(warm, n_speeds=20).profile(1.3 * min_running_time(warm))  # compile outside the timing
    cpu = {"curves": [], "none": []}
    for seed in SEEDS:
        case = comparable_case(seed)
        t_min = min_running_time(case)
        variants = [("curves", with_curves), ("none", no_curves)]
        for factor in FACTORS:
            for name, curves in variants if seed % 2 == 0 else variants[::-1]:
                dp.coast_curves = curves
                start = time.process_time()
                OptimalSolver(case).profile(factor * t_min)
                cpu[name].append(time.process_time() - start)
            print(f"seed {seed} x{factor}: curves {cpu['curves'][-1]:.3f} s, none {cpu['none'][-1]:.3f} s", flush=True)
    dp.coast_curves = with_curves
    a, b = np.array(cpu["curves"]), np.array(cpu["none"])
    print(f"total: curves {a.sum():.2f} s, none {b.sum():.2f} s, ratio {a.sum() / b.sum():.3f};"
          f" median ratio per answer {np.median(a / b):.3f}")
    model = OptimalSolver(comparable_case(4)).simulator.model
    start = time.process_time()
    for _ in range(5):
        dp.coast_curves(model, 20.0, 200, 0.5)
    print(f"coast_curves of generated line 4: {(time.process_time() - start) / 5:.3f} s per call")


if __name__ == "__main__":
    main()
