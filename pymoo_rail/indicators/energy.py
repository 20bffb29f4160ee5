"""Gap of an energy / running-time front to the optimal front of the case.

The reference is the exact solver's front (``pymoo_rail.optimal.optimal_front``): convex and
decreasing in the running time, so between its points it is interpolated linearly. The chord lies
above the true curve, so interpolation understates gaps, most near the minimum running time where
the front is steep (measured: 1.55 % by interpolation against 2.07 % solved at the point's own
time). For exact gaps, :func:`pymoo_rail.optimal.solved_energy_gap` solves the optimum at each
point's own running time, with its certificate.
"""

from __future__ import annotations

import numpy as np
import pandas as pd
from pymoo.indicators.hv import HV

TIME_COLUMN = "running_time_s"
ENERGY_COLUMN = "energy_kwh"
_DENSE_POINTS = 2000


def as_front(name: str, front) -> np.ndarray:
    """(n, 2) float array of (running time s, energy kWh) from an array or a DataFrame."""
    if isinstance(front, pd.DataFrame):
        missing = [c for c in (TIME_COLUMN, ENERGY_COLUMN) if c not in front.columns]
        if missing:
            raise ValueError(f"{name} lacks the column(s) {missing}: give {TIME_COLUMN} and {ENERGY_COLUMN}")
        points = front[[TIME_COLUMN, ENERGY_COLUMN]].to_numpy(dtype=float)
    else:
        points = np.asarray(front, dtype=float)
        if points.ndim == 1 and points.shape[0] == 2:
            points = points[None, :]
    if points.ndim != 2 or points.shape[1] != 2 or points.shape[0] == 0:
        raise ValueError(f"{name} has shape {points.shape}: expected (n, 2) rows of ({TIME_COLUMN}, {ENERGY_COLUMN})")
    bad = np.argwhere(~np.isfinite(points))
    if bad.size:
        r, c = bad[0]
        col = (TIME_COLUMN, ENERGY_COLUMN)[c]
        raise ValueError(f"{name}[{r}] has {col} = {points[r, c]}: every value must be finite")
    return points


def _reference_curve(reference: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    order = np.argsort(reference[:, 0])
    t, e = reference[order, 0], reference[order, 1]
    if t.shape[0] < 2 or np.any(np.diff(t) <= 0):
        raise ValueError("reference needs at least two points with distinct running times")
    return t, e



def gap_summary(table: pd.DataFrame) -> dict:
    """Mean, largest and smallest relative gap of the points in range, and how many are out of range.

    Parameters
    ----------
    table : pandas.DataFrame
        One row per front point with the columns ``gap_rel`` and ``in_range`` (bool).

    Returns
    -------
    dict
        ``points`` (the table), ``mean_gap_rel``, ``max_gap_rel``, ``min_gap_rel`` (NaN when no
        point is in range) and ``n_out_of_range``.
    """
    in_range = table["in_range"].to_numpy(dtype=bool)
    stats = table.loc[in_range, "gap_rel"]
    return {
        "points": table,
        "mean_gap_rel": float(stats.mean()) if len(stats) else float("nan"),
        "max_gap_rel": float(stats.max()) if len(stats) else float("nan"),
        "min_gap_rel": float(stats.min()) if len(stats) else float("nan"),
        "n_out_of_range": int((~in_range).sum()),
    }

def energy_gap(front, reference, ref_point=None) -> dict:
    """Energy of each front point above the optimal front at its running time, and the HV ratio.

    Parameters
    ----------
    front : array (n, 2) or DataFrame
        An optimiser's points, (running time s, net energy kWh) or columns ``running_time_s`` and
        ``energy_kwh``.
    reference : array (m, 2) or DataFrame
        The optimal front, e.g. from :func:`pymoo_rail.optimal.optimal_front` (m >= 2).
    ref_point : (2,) optional
        Hypervolume reference point (s, kWh); default: the reference front's largest time and
        energy plus 10 % of its ranges.

    Returns
    -------
    dict
        ``points``: DataFrame with ``running_time_s``, ``energy_kwh``, ``optimal_kwh`` (interpolated
        reference), ``gap_kwh``, ``gap_rel`` (``gap_kwh / optimal_kwh``) and ``in_range`` (False
        where the running time lies outside the reference's range: gap columns are NaN there, and
        left out of the statistics); ``mean_gap_rel``, ``max_gap_rel``, ``min_gap_rel`` over the
        points in range (NaN if none) and ``n_out_of_range``; ``hv`` of the front,
        ``hv_reference`` of the reference curve (densely interpolated, so the ratio measures the
        distance to the continuous optimum), ``hv_ratio = hv / hv_reference`` and ``ref_point``.
    """
    points = as_front("front", front)
    t_ref, e_ref = _reference_curve(as_front("reference", reference))
    t, e = points[:, 0], points[:, 1]
    in_range = (t >= t_ref[0]) & (t <= t_ref[-1])
    optimal = np.where(in_range, np.interp(t, t_ref, e_ref), np.nan)
    gap = e - optimal
    table = pd.DataFrame({TIME_COLUMN: t, ENERGY_COLUMN: e, "optimal_kwh": optimal, "gap_kwh": gap,
                          "gap_rel": gap / optimal, "in_range": in_range})

    if ref_point is None:
        span_t, span_e = t_ref[-1] - t_ref[0], e_ref.max() - e_ref.min()
        ref_point = np.array([t_ref[-1] + 0.1 * span_t, e_ref.max() + 0.1 * span_e])
    ref_point = np.asarray(ref_point, dtype=float)
    if ref_point.shape != (2,) or not np.all(np.isfinite(ref_point)):
        raise ValueError(f"ref_point = {ref_point!r}: expected two finite numbers (s, kWh)")
    indicator = HV(ref_point=ref_point)
    dense_t = np.linspace(t_ref[0], t_ref[-1], _DENSE_POINTS)
    dense = np.column_stack([dense_t, np.interp(dense_t, t_ref, e_ref)])
    hv_reference = float(indicator(dense))
    hv = float(indicator(points))
    return {
        **gap_summary(table),
        "hv": hv,
        "hv_reference": hv_reference,
        "hv_ratio": hv / hv_reference if hv_reference > 0 else float("nan"),
        "ref_point": ref_point,
    }
