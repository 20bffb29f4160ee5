"""Energy gaps of optimisers' runs to the optimum: solved at each run's own time, or on a certified front.

:func:`solved_energy_gap` measures every front point against the optimum solved at its own running
time (:class:`ReferenceAtTime`); :func:`certified_gap` against a certified front, interpolated with
its certificate. Both flag a run below the optimum by more than the certificate (a defect of the
reference); :func:`gap_columns` is the relative gap and that flag for stored tables.

Interpolating a reference front linearly between its points overstates the optimum between them
(the front is convex) and so understates gaps, most near the minimum running time where the front
is steep. Here each point's running time gets its own DP solve (one solver per case, so the
transition tables are built once, and a cache by running time), with the solve's certificate.

The solve's run lands within the solver's time tolerance of the request (or, across a jump of the
discrete optimum, up to 0.5 s off it); its energy is moved to the request along the front's slope.
"""

from __future__ import annotations

import math

import numpy as np
import pandas as pd

from pymoo_rail.constants import J_PER_KWH
from pymoo_rail.indicators.energy import ENERGY_COLUMN, TIME_COLUMN, as_front, gap_summary
from pymoo_rail.model import Case, InfeasibleCaseError
from pymoo_rail.optimal.reference.front import CertifiedFront
from pymoo_rail.optimal.solver import OptimalSolver


class ReferenceAtTime:
    """The optimum of one case at any running time, solved on demand and cached.

    Parameters
    ----------
    case : Case
    decimals : int
        Running times are cached rounded to this many decimals of a second.
    **settings
        Settings of :class:`~pymoo_rail.optimal.OptimalSolver`.
    """

    def __init__(self, case: Case, decimals: int = 3, **settings):
        self.solver = OptimalSolver(case, **settings)
        self.decimals = int(decimals)
        self._cache: dict[float, dict] = {}
        self._last_lambda_w: float | None = None

    def at(self, running_time_s: float) -> dict:
        """``optimal_kwh`` at exactly ``running_time_s``, its ``energy_bound_kwh``, ``lambda_kwh_per_s``.

        The DP's run is moved to the request along the front's slope ``lambda`` (the supporting
        line there), and the bound grows by the chord above that line
        (:meth:`OptimalSolver.move_remainder_j`, also given alone as ``move_remainder_kwh``: the
        optimum lies between ``optimal_kwh`` and ``optimal_kwh + move_remainder_kwh`` on the solver's
        grid). NaNs below the minimum running time.
        """
        key = round(float(running_time_s), self.decimals)
        if key in self._cache:
            return self._cache[key]
        out = {"optimal_kwh": math.nan, "energy_bound_kwh": math.nan, "lambda_kwh_per_s": math.nan,
               "move_remainder_kwh": math.nan}
        try:
            tr = self.solver.profile(key, lambda_guess_w=self._last_lambda_w)
        except InfeasibleCaseError:
            self._cache[key] = out
            return out
        lam = tr.summary["lambda_w"]
        self._last_lambda_w = lam
        remainder_kwh = self.solver.move_remainder_j(tr.running_time_s, lam, key) / J_PER_KWH
        out = {"optimal_kwh": tr.energy.net_kwh + lam * (tr.running_time_s - key) / J_PER_KWH,
               "energy_bound_kwh": tr.summary.get("energy_bound_kwh", math.nan) + remainder_kwh,
               "lambda_kwh_per_s": lam / J_PER_KWH, "move_remainder_kwh": remainder_kwh}
        self._cache[key] = out
        return out


def gap_columns(gap_kwh, optimal_kwh, energy_bound_kwh, in_range) -> dict:
    """The relative gap of points to the optimum at their running time, and whether each lies below it.

    Parameters
    ----------
    gap_kwh, optimal_kwh, energy_bound_kwh : array_like
        The points' energies minus the optimum at their running times, that optimum and its
        certificate (kWh).
    in_range : array_like of bool
        False where no run exists at that time (below the minimum running time).

    Returns
    -------
    dict
        ``gap_rel`` (gap / optimum) and ``below_reference`` (in range and below the optimum by more
        than the certificate: a defect of the reference).
    """
    gap = np.asarray(gap_kwh)
    return {"gap_rel": gap / np.asarray(optimal_kwh),
            "below_reference": np.asarray(in_range) & (gap < -np.asarray(energy_bound_kwh))}


def solved_energy_gap(front, reference: Case | ReferenceAtTime, **settings) -> dict:
    """Energy of each front point above the optimum solved at its own running time.

    Parameters
    ----------
    front : array (n, 2) or DataFrame
        (running time s, net energy kWh), or columns ``running_time_s`` and ``energy_kwh``.
    reference : Case or ReferenceAtTime
        The case (a new cached reference is built with ``settings``) or a reference to reuse.

    Returns
    -------
    dict
        ``points``: DataFrame with ``running_time_s``, ``energy_kwh``, ``optimal_kwh``, ``gap_kwh``,
        ``gap_rel``, ``energy_bound_kwh`` (the reference's certificate), ``below_reference`` (the
        point lies below the optimum by more than the certificate: a defect of the reference) and
        ``in_range`` (False below the minimum running time); ``mean_gap_rel``, ``max_gap_rel``,
        ``min_gap_rel`` over the points in range, ``n_out_of_range`` and ``n_below_reference``.
    """
    ref = reference if isinstance(reference, ReferenceAtTime) else ReferenceAtTime(reference, **settings)
    points = as_front("front", front)
    order = np.argsort(points[:, 0])  # solve in increasing time: each solve warm-starts the next
    rows = [None] * points.shape[0]
    for k in order:
        rows[k] = ref.at(points[k, 0])
    t, e = points[:, 0], points[:, 1]
    optimal = np.array([r["optimal_kwh"] for r in rows])
    bound = np.array([r["energy_bound_kwh"] for r in rows])
    gap = e - optimal
    in_range = np.isfinite(optimal)
    gaps = gap_columns(gap, optimal, bound, in_range)
    table = pd.DataFrame({TIME_COLUMN: t, ENERGY_COLUMN: e, "optimal_kwh": optimal, "gap_kwh": gap,
                          "gap_rel": gaps["gap_rel"], "energy_bound_kwh": bound,
                          "below_reference": gaps["below_reference"], "in_range": in_range})
    return {**gap_summary(table), "n_below_reference": int(table["below_reference"].sum())}


def certified_gap(front: CertifiedFront, running_time_s, energy_kwh) -> dict[str, float]:
    """Energy gaps of an optimiser's runs to the optimum at their own running times.

    Parameters
    ----------
    front : CertifiedFront
        The certified front of the case the members ran on.
    running_time_s, energy_kwh : array-like
        Running time and net energy of each feasible member.

    Returns
    -------
    dict
        ``gap_median_kwh`` and ``gap_min_kwh`` (``E - E*(T)`` over the members whose running time
        the front covers; in kWh, since on lines with strong regeneration ``E*`` can be near zero or
        negative and a relative gap means nothing), ``gap_median_pct`` (the median gap in % of the
        front's largest energy, its fastest run), ``n_in_range``, and ``n_below_certificate``:
        members below the optimum by more than its certificate (``E < E*(T) - bound(T)``), which a
        correct certificate never allows. Gaps are NaN when no member lies in the front's range.
    """
    t = np.asarray(running_time_s, dtype=float).reshape(-1)
    e = np.asarray(energy_kwh, dtype=float).reshape(-1)
    inside, below = front.below_certificate(t, e)
    out = {"n_in_range": float(inside.sum()), "n_below_certificate": float(below.sum()),
           "gap_median_kwh": float("nan"), "gap_min_kwh": float("nan"), "gap_median_pct": float("nan")}
    if not inside.any():
        return out
    optimum, _ = front.energy_at(t[inside])
    gap = e[inside] - optimum
    scale = float(front.table["energy_kwh"].abs().max())
    out.update(gap_median_kwh=float(np.median(gap)), gap_min_kwh=float(np.min(gap)),
               gap_median_pct=100.0 * float(np.median(gap)) / scale)
    return out
