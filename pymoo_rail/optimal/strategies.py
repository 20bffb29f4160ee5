"""Direct search over traction-hold-coast-brake strategies: an independent check of the DP.

Every strategy here is a simulator program; the braking onto the platform is the simulator's
own (the latest moment the braking curve allows). Two families:

- ``hold_coast``: maximum traction to a hold speed ``v_h`` (coasting whenever a descent carries the
  train above it), hold, then coast from ``x_c`` to the brake point; the optimal structure on level
  track (Pontryagin), with one free parameter once the running time fixes ``x_c``;
- ``two_holds``: hold ``v_1`` until ``x_1``, coast until ``x_2``, hold ``v_2`` until ``x_3``, coast to
  the brake point: room for a second push before a climb; three free parameters plus ``x_3``.

The running time fixes the last switching point (the run gets faster as it moves on), found by a
vectorised bisection; the energy at exactly the requested time is interpolated between the two
adjacent runs that bracket it (switching points move in whole grid cells).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from scipy.optimize import differential_evolution, minimize_scalar

from pymoo_rail.model import Case
from pymoo_rail.sim import Simulator
from pymoo_rail.sim.kernel import MODE_COAST, MODE_TOWARD, OUT_NET_KWH, OUT_REACHED, OUT_RUNNING_TIME_S


@dataclass(frozen=True)
class StrategyResult:
    """The best strategy of a family found for one running time."""

    family: str
    energy_kwh: float  # at exactly the requested time (interpolated between adjacent runs)
    running_time_s: float  # of the run returned in ``program``
    program: np.ndarray  # simulator program (rows end_m, mode, target_ms)
    params: tuple


def fit_last_switch(sim: Simulator, programs: np.ndarray, row: int, start_m: np.ndarray,
                    running_time_s: float, iterations: int | None = None) -> tuple[np.ndarray, np.ndarray]:
    """Move ``programs[:, row, 0]`` within ``[start_m, line end]`` until each run takes the time.

    Returns ``(energy_kwh, programs)``: the energy at exactly ``running_time_s`` (interpolated
    between the two bracketing runs; +inf where the time is out of reach or the train stops
    short) and the programs at the slower bracketing switch point.
    """
    programs = np.array(programs, dtype=float)
    n = programs.shape[0]
    if iterations is None:  # until the bracket is a fraction of a cell: adjacent switch cells
        iterations = int(np.ceil(np.log2(sim.length_m / sim.grid.dx_m))) + 4
    lo = np.asarray(start_m, dtype=float).copy()  # slow side (switch early)
    hi = np.full(n, sim.length_m)  # fast side (switch late)

    def run(at):
        programs[:, row, 0] = at
        return sim.run_batch(programs)

    out_lo, out_hi = run(lo), run(hi)
    # a run that stops short of the platform counts as too slow
    feasible = (((out_lo[:, OUT_RUNNING_TIME_S] >= running_time_s) | (out_lo[:, OUT_REACHED] == 0))
                & (out_hi[:, OUT_RUNNING_TIME_S] <= running_time_s) & (out_hi[:, OUT_REACHED] > 0))
    for _ in range(iterations):
        mid = 0.5 * (lo + hi)
        out = run(mid)
        slow = (out[:, OUT_RUNNING_TIME_S] > running_time_s) | (out[:, OUT_REACHED] == 0)
        lo = np.where(slow, mid, lo)
        hi = np.where(slow, hi, mid)
        out_lo = np.where(slow[:, None], out, out_lo)
        out_hi = np.where(slow[:, None], out_hi, out)
    ok = feasible & (out_lo[:, OUT_REACHED] > 0) & (out_hi[:, OUT_REACHED] > 0)
    t_lo, t_hi = out_lo[:, OUT_RUNNING_TIME_S], out_hi[:, OUT_RUNNING_TIME_S]
    e_lo, e_hi = out_lo[:, OUT_NET_KWH], out_hi[:, OUT_NET_KWH]
    with np.errstate(invalid="ignore", divide="ignore"):
        w = np.where(t_lo > t_hi, (t_lo - running_time_s) / (t_lo - t_hi), 0.0)
    energy = np.where(ok, e_lo + w * (e_hi - e_lo), np.inf)
    programs[:, row, 0] = lo
    return energy, programs


def _hold_coast_programs(case: Case, hold_ms: np.ndarray) -> np.ndarray:
    length = case.line.length_m
    programs = np.zeros((hold_ms.shape[0], 2, 3))
    programs[:, 0] = (0.0, MODE_TOWARD, 0.0)
    programs[:, 0, 2] = hold_ms
    programs[:, 1] = (length, MODE_COAST, 0.0)
    return programs


def hold_coast_search(case: Case, running_time_s: float, dx_m: float | None = None,
                      n_grid: int = 40) -> StrategyResult:
    """Best hold speed (grid, then a bounded scalar search) of the hold-then-coast family."""
    sim = Simulator(case, dx_m)
    v_max = case.train.max_speed_ms

    def energies(hold_ms):
        hold_ms = np.atleast_1d(hold_ms)
        progs = _hold_coast_programs(case, hold_ms)
        return fit_last_switch(sim, progs, 0, np.zeros(hold_ms.shape[0]), running_time_s)

    grid = np.linspace(0.2 * v_max, v_max, n_grid)
    e, _ = energies(grid)
    k = int(np.argmin(e))
    if not np.isfinite(e[k]):
        raise ValueError(f"running_time_s = {running_time_s}: no hold-coast strategy takes this time")
    lo, hi = grid[max(k - 1, 0)], grid[min(k + 1, n_grid - 1)]
    res = minimize_scalar(lambda v: float(energies(v)[0][0]), bounds=(lo, hi), method="bounded",
                          options={"xatol": 1e-3})
    best_v = res.x if res.fun < e[k] else grid[k]
    e1, progs = energies(best_v)
    out = sim.run_batch(progs)[0]
    return StrategyResult("hold_coast", float(e1[0]), float(out[OUT_RUNNING_TIME_S]), progs[0], (float(best_v),))


def _two_hold_programs(case: Case, params: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """params (N, 4): v1, x1, coast length, v2 -> programs (N, 4, 3) and the start of the last row."""
    length = case.line.length_m
    v1, x1, gap, v2 = params.T
    x2 = np.minimum(x1 + gap, length)
    programs = np.zeros((params.shape[0], 4, 3))
    programs[:, 0] = np.column_stack([x1, np.full_like(x1, MODE_TOWARD), v1])
    programs[:, 1] = np.column_stack([x2, np.full_like(x1, MODE_COAST), np.zeros_like(x1)])
    programs[:, 2] = np.column_stack([x2, np.full_like(x1, MODE_TOWARD), v2])
    programs[:, 3] = (length, MODE_COAST, 0.0)
    return programs, x2


def two_holds_search(case: Case, running_time_s: float, dx_m: float | None = None, pop_size: int = 32,
                     max_generations: int = 60, seed: int = 0, start: StrategyResult | None = None) -> StrategyResult:
    """Differential evolution over (v1, x1, coast length, v2), every generation one batch of runs.

    ``start`` (a hold-coast result) seeds the population with its strategy: hold ``v_h`` to ``x_c``
    with no gap, which the two-hold family contains.
    """
    sim = Simulator(case, dx_m)
    length = case.line.length_m
    v_max = case.train.max_speed_ms
    lower = np.array([0.2 * v_max, 0.0, 0.0, 0.2 * v_max])
    upper = np.array([v_max, length, length, v_max])

    def energies(params):
        params = np.clip(np.atleast_2d(params), lower, upper)
        progs, x2 = _two_hold_programs(case, params)
        return fit_last_switch(sim, progs, 2, x2, running_time_s)

    def batch(z):  # scipy passes (n_params, S)
        e = energies(z.T)[0]
        return np.where(np.isfinite(e), e, 1e6)

    rng = np.random.default_rng(seed)
    init = lower + rng.random((pop_size, 4)) * (upper - lower)
    if start is not None:
        v_h, x_c = start.params[0], start.program[0, 0]
        init[0] = (v_h, 0.5 * x_c, 0.0, v_h)
    res = differential_evolution(batch, list(zip(lower, upper)), init=init, maxiter=max_generations, tol=1e-8,
                                 polish=False, vectorized=True, updating="deferred", rng=rng)
    best_p = np.clip(res.x, lower, upper)
    e1, progs = energies(best_p)
    if not np.isfinite(e1[0]):
        raise ValueError(f"running_time_s = {running_time_s}: no two-hold strategy found that takes this time")
    out = sim.run_batch(progs)[0]
    return StrategyResult("two_holds", float(e1[0]), float(out[OUT_RUNNING_TIME_S]), progs[0],
                          tuple(float(p) for p in best_p))
