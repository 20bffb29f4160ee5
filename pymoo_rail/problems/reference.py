"""Certified fronts in a pymoo problem's objective space.

The certified fronts themselves (computing, caching, reading and writing them, gaps to them) live
in :mod:`pymoo_rail.optimal.reference`; their names are importable from here as well. This module
adds what a problem needs: :func:`mirrored` maps a front into the problem's objectives (energy with
running time or with time error).
"""

from __future__ import annotations

import numpy as np

from pymoo_rail.optimal.reference import (
    BOUND_FLOOR_REL,
    CACHE_ENV,
    COARSE_FACTOR,
    COLUMNS,
    DEFAULT_N_TIMES,
    EXACT_POINT_COLUMNS,
    FRONT_SPAN,
    FRONT_VERSION,
    LONG_LINE_M,
    LONG_LINE_N_TIMES,
    PROGRESS_DELAY_S,
    PUNCTUAL_TOLERANCE_MIN_S,
    PUNCTUAL_TOLERANCE_REL,
    SHIPPED_DIR,
    CertifiedFront,
    NoExactFrontError,
    Progress,
    cache_dir,
    case_hash,
    certified_front,
    certified_gap,
    commented_csv_text,
    compute_front,
    constrained_optimum,
    default_dx_m,
    default_window,
    exact_points,
    exact_points_key,
    find_front,
    forget_fronts,
    front_key,
    front_progress_bar,
    front_times,
    n_times_for,
    punctual_tolerance_s,
    read_commented_csv,
)


def mirrored(front: CertifiedFront, objectives: tuple[str, ...], n_points: int | None = None,
             window_s: tuple[float, float] | None = None) -> tuple[np.ndarray, np.ndarray]:
    """The front in a problem's objective space and the energy bound of each point.

    ``n_points=None`` gives the front's nodes (its vertices) plus 100 evenly spaced points; a number
    gives at most that many evenly spaced points (fewer where some are dominated or outside the front).

    ``objectives`` is ``("energy", "running_time")`` or ``("energy", "time_error")`` in any order.
    Time error ``e = |T - T_plan|`` mirrors the front about the planned time: the least energy at
    error ``e`` is the smaller of the optima at ``T_plan + e`` and ``T_plan - e`` (where the front
    covers them). Dominated points (e.g. energy rising with time under auxiliary power) drop out.
    ``window_s`` restricts the running times to the problem's window (see :meth:`CertifiedFront.clip`).
    """
    from pymoo.util.nds.non_dominated_sorting import find_non_dominated

    if "time_error" in objectives:
        lo, hi = front.clip(window_s)
        plan = front.planned_time_s
        e_max = max(hi - plan, plan - lo)
        e_min = max(lo - plan, 0.0)  # a plan faster than the front's first node: errors start there
        nodes = front.table["running_time_s"].to_numpy()
        nodes = nodes[(nodes >= lo) & (nodes <= hi)]
        err = np.linspace(e_min, e_max, max(int(n_points or 100), 2))
        if n_points is None:
            err = np.union1d(err, np.abs(nodes - plan))
        energy = np.full(err.shape, np.inf)
        bound = np.zeros(err.shape)
        for side in (plan + err, plan - err):
            inside = (side >= lo - 1e-9) & (side <= hi + 1e-9)
            e, b = front.energy_at(np.clip(side[inside], lo, hi))
            better = e < energy[inside]
            energy[np.flatnonzero(inside)[better]] = e[better]
            bound[np.flatnonzero(inside)[better]] = b[better]
        ok = np.isfinite(energy)
        columns = {"energy": energy[ok], "time_error": err[ok]}
        bound = bound[ok]
    else:
        dense = front.dense(n_points or 100, window_s, with_nodes=n_points is None)
        columns = {"energy": dense["energy_kwh"].to_numpy(), "running_time": dense["running_time_s"].to_numpy()}
        bound = dense["energy_bound_kwh"].to_numpy()
    F = np.column_stack([columns[name] for name in objectives])
    keep = find_non_dominated(F)
    keep = keep[np.argsort(F[keep, 0], kind="stable")]
    return F[keep], bound[keep]


__all__ = ["CertifiedFront", "NoExactFrontError", "case_hash", "cache_dir", "certified_front", "compute_front",
           "constrained_optimum", "default_window", "exact_points", "exact_points_key", "find_front", "forget_fronts",
           "front_key", "front_times", "mirrored", "punctual_tolerance_s", "EXACT_POINT_COLUMNS", "FRONT_VERSION",
           "PUNCTUAL_TOLERANCE_MIN_S", "PUNCTUAL_TOLERANCE_REL", "BOUND_FLOOR_REL", "CACHE_ENV", "COARSE_FACTOR",
           "COLUMNS", "DEFAULT_N_TIMES", "FRONT_SPAN", "LONG_LINE_M", "LONG_LINE_N_TIMES", "PROGRESS_DELAY_S",
           "SHIPPED_DIR", "Progress", "certified_gap", "commented_csv_text", "default_dx_m", "front_progress_bar",
           "n_times_for", "read_commented_csv"]
