"""Computing a certified front with the exact solver (no cache: :func:`pymoo_rail.optimal.reference.certified_front`).

The solver is asked for the minimum-energy run at the nodes' running times
(:func:`~pymoo_rail.optimal.reference.nodes.front_times`); each node is a real run of the simulator
with the front's slope there, and a bound on its energy above the optimum: the solver's own
certificate (``certificate = "solver"``), else the difference to a grid of half the speed nodes
(``"two-grid"``), at least :data:`BOUND_FLOOR_REL` of the energy.
"""

from __future__ import annotations

from collections.abc import Callable

import numpy as np
import pandas as pd

from pymoo_rail import __version__
from pymoo_rail.model import Case
from pymoo_rail.optimal.reference.front import FRONT_VERSION, CertifiedFront, case_hash
from pymoo_rail.optimal.reference.nodes import front_times, n_times_for
from pymoo_rail.optimal.solver import DEFAULT_N_SPEEDS, OptimalSolver, min_running_time, optimal_front

BOUND_FLOOR_REL = 5.0e-4
"""Least two-grid bound, relative to the energy: the largest error of the default grid measured against
a direct strategy search and finer grids (``docs/optimal.md``); a small two-grid difference can be luck."""
COARSE_FACTOR = 2
"""The two-grid certificate compares the default grid with one of ``n_speeds / COARSE_FACTOR``."""


Progress = Callable[[int, int], None]
"""A progress callback: ``progress(done, total)`` in solves of the exact solver (``total`` may grow)."""
PROGRESS_DELAY_S = 2.0
"""A front computed in a terminal shows a progress bar once it has taken this long."""


def front_progress_bar(case_name: str):
    """A tqdm bar on standard error for a front's solves, shown after :data:`PROGRESS_DELAY_S` s.

    Returns ``(bar, progress)``: close ``bar`` when done; pass ``progress`` to :func:`compute_front`.
    """
    import sys
    import time

    from tqdm import tqdm

    delay_s = PROGRESS_DELAY_S
    bar = tqdm(total=1, desc=f"certified front of {case_name} (exact solver)", unit="solve",
               delay=delay_s, file=sys.stderr, dynamic_ncols=True, leave=False)
    started_s = time.monotonic()

    def progress(done: int, total: int) -> None:
        bar.total = total
        bar.update(done - bar.n)
        # tqdm throttles its refreshes: show the last count before the bar closes (once it is shown)
        if done == total and time.monotonic() - started_s >= delay_s:
            bar.refresh()

    return bar, progress


def compute_front(case: Case, dx_m: float | None = None, n_times: int | None = None,
                  progress: Progress | None = None) -> CertifiedFront:
    """Compute a case's certified front with the exact solver (no cache; see :func:`certified_front`).

    ``progress(done, total)`` is called after every solve (``total``: the sweep, the solves alone
    and, for a two-grid certificate, the coarse sweep).

    Every node is solved twice: in one sweep over the running times (each solve warm-started from
    the last) and alone. The lower run at the requested time is kept, and the node's bound is raised
    to at least the difference of the two: a warm-started sweep can settle on a worse run than a
    solve started elsewhere (yizhuang, 17 nodes: 9.115 kWh at 171.6 s with a solver bound of 0.011
    kWh, while the solver alone at 171.1 s reached 9.034 kWh), so where they disagree the solver's
    own bound is not trusted.
    """
    t_min = min_running_time(case, dx_m)
    times = front_times(t_min, case.planned_time_s, n_times or n_times_for(case))
    n = len(times)
    total = [2 * n]  # the sweep and the solves alone; a two-grid certificate adds a coarse sweep

    def stage(first: int):
        if progress is None:
            return None
        return lambda done, _: progress(first + done, total[0])

    sweep = optimal_front(case, times, dx_m=dx_m, progress=stage(0))
    alone = pd.concat([optimal_front(case, [t], dx_m=dx_m, progress=stage(n + k))
                       for k, t in enumerate(sweep["requested_time_s"])], ignore_index=True)
    use_alone = (alone["energy_at_request_kwh"] < sweep["energy_at_request_kwh"]).to_numpy()
    fine = sweep.copy()
    fine.loc[use_alone] = alone.loc[use_alone]
    spread = np.abs(sweep["energy_at_request_kwh"] - alone["energy_at_request_kwh"]).to_numpy()
    if "energy_bound_kwh" in fine.columns and fine["energy_bound_kwh"].notna().all():
        bound = fine["energy_bound_kwh"].to_numpy(dtype=float)
        certificate = "solver"
    else:
        total[0] = 3 * n
        coarse = optimal_front(case, times, dx_m=dx_m, n_speeds=DEFAULT_N_SPEEDS // COARSE_FACTOR,
                               progress=stage(2 * n))
        bound = np.abs(fine["energy_at_request_kwh"].to_numpy() - coarse["energy_at_request_kwh"].to_numpy())
        certificate = "two-grid"
    bound = np.maximum.reduce([bound, spread, BOUND_FLOOR_REL * np.abs(fine["energy_kwh"].to_numpy())])
    table = pd.DataFrame({"requested_time_s": fine["requested_time_s"], "running_time_s": fine["running_time_s"],
                          "energy_kwh": fine["energy_kwh"], "lambda_kwh_per_s": fine["lambda_kwh_per_s"],
                          "energy_bound_kwh": bound})
    # two requested times close to the minimum can land on the same run: keep it once
    table = table.sort_values("running_time_s", kind="stable").drop_duplicates("running_time_s").reset_index(drop=True)
    step = OptimalSolver(case, dx_m).dx_m if dx_m is None else float(dx_m)
    return CertifiedFront(table, case_hash(case), case.name, float(case.planned_time_s), float(step), certificate,
                          f"pymoo_rail {__version__} / front {FRONT_VERSION}")


def default_dx_m(case: Case) -> float:
    """The simulator's default step for a case (the step the solver uses when none is given)."""
    from pymoo_rail.sim import Simulator

    return float(Simulator(case).grid.dx_m)
