"""Recommended curves for the tracking studies, found quickly with scipy's differential evolution.

The decision is one target speed per section (seed 000's speed codes, non-equal partition of
fig. 4-4), the score is the net energy of a run plus a steep penalty for every second beyond the
planned running time. ``score="ideal"`` scores the simulator's run of the codes; a controller
scores the run of that controller tracking it (seed 000 optimises the tracked curve).
"""

from __future__ import annotations

import numpy as np
from scipy.optimize import differential_evolution

from pymoo_rail.control import Tracker
from pymoo_rail.sim import Simulator, gradient_limit_partition, speed_code_programs
from pymoo_rail.sim.kernel import OUT_NET_KWH, OUT_REACHED, OUT_RUNNING_TIME_S

PENALTY_KWH_PER_S = 5.0


def best_speed_codes(case, planned_time_s=None, controller=None, *, low_kmh=20.0, seed=1, maxiter=150,
                     popsize=15, control_period_s=0.2):
    """(codes_ms, program, objective) of the best speed-code curve DE finds in ``maxiter`` generations."""
    planned = case.planned_time_s if planned_time_s is None else planned_time_s
    bounds_m = gradient_limit_partition(case.line)
    n_sec = bounds_m.shape[0] - 1
    if controller is None:
        batch = Simulator(case).run_batch
    else:
        batch = Tracker(case, controller, control_period_s).run_batch

    def score(codes_kmh_t):  # vectorized: (n_var, S)
        out = batch(speed_code_programs(bounds_m, codes_kmh_t.T / 3.6))
        late = np.maximum(out[:, OUT_RUNNING_TIME_S] - planned, 0.0)
        stall = 1e3 * (1.0 - out[:, OUT_REACHED])
        return out[:, OUT_NET_KWH] + PENALTY_KWH_PER_S * late + stall

    res = differential_evolution(score, [(low_kmh, case.train.max_speed_kmh)] * n_sec, seed=seed,
                                 maxiter=maxiter, popsize=popsize, tol=1e-8, polish=False,
                                 vectorized=True, updating="deferred")
    codes_ms = res.x / 3.6
    return codes_ms, speed_code_programs(bounds_m, codes_ms)[0], float(res.fun)
