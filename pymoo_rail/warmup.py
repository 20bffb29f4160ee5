"""Compile the kernels a command uses ahead of time (``pymoo-rail warmup``).

For container images and clusters whose workers share Numba's cache directory: the first real run
then starts at once. It runs the kernels of the simulator, the exact solver and the ATO controllers
on a built-in case, so it sits above all of them (beside the CLI).
"""

from __future__ import annotations

import time

WARMUP_PARTS = ("simulator", "reference", "tracking")


def warmup(parts: tuple[str, ...] = ("simulator",), case: str = "yizhuang") -> dict[str, float]:
    """Compile (or load from the cache) the kernels a command uses, ahead of time.

    Parameters
    ----------
    parts : tuple of str
        Any of ``"simulator"`` (the kernels of ``pymoo-rail optimize`` and of
        ``SpeedProfileProblem``: both encodings, batches and traces), ``"reference"`` (the exact
        solver of ``pymoo-rail reference``), ``"tracking"`` (the ATO controllers).
    case : str
        A built-in case to run them on.

    Returns
    -------
    dict
        Wall time (s) per part.
    """
    import numpy as np

    from pymoo_rail.cases import load_case

    unknown = [p for p in parts if p not in WARMUP_PARTS]
    if unknown:
        raise ValueError(f"warm-up part {unknown[0]!r} is unknown (known: {', '.join(WARMUP_PARTS)})")
    the_case = load_case(case)
    seconds: dict[str, float] = {}
    for part in parts:
        start = time.perf_counter()
        if part == "simulator":
            from pymoo_rail.problems import SpeedProfileProblem

            for encoding in ("speed_codes", "switching_points"):
                problem = SpeedProfileProblem(the_case, encoding=encoding)
                X = np.random.default_rng(0).uniform(problem.xl, problem.xu, (4, problem.n_var))
                problem.evaluate(X)
                problem.trajectory(X[0])
        elif part == "reference":
            from pymoo_rail.optimal import min_running_time, optimal_profile

            optimal_profile(the_case, 1.1 * min_running_time(the_case))
        else:
            from pymoo_rail.control import PID, track
            from pymoo_rail.sim import Simulator

            track(the_case, Simulator(the_case).flat_out(), PID())
        seconds[part] = time.perf_counter() - start
    return seconds
