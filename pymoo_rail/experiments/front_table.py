"""Statistics of one (energy, running time) front for paper tables: extent, most punctual member,
least energy on time and, against an exact front, the energy gaps."""

from __future__ import annotations

import numpy as np

from pymoo_rail.experiments.fronts import choose_member
from pymoo_rail.indicators.energy import energy_gap


def most_punctual(F: np.ndarray, planned_time_s: float) -> int:
    """Index of the (energy, running time) member closest to the planned time (ties: the lower energy)."""
    return choose_member(F, np.zeros(len(F)), F[:, 1], F[:, 0], planned_time_s, window_s=0.0)


def exact_energy_kwh(exact, time_s: float) -> float:
    """The exact front's energy at ``time_s`` (linear between its points; NaN outside them).

    ``exact`` is a DataFrame with ascending ``running_time_s`` and its ``energy_kwh``.
    """
    t, e = exact["running_time_s"].to_numpy(float), exact["energy_kwh"].to_numpy(float)
    return float(np.interp(time_s, t, e)) if t[0] <= time_s <= t[-1] else float("nan")


def front_statistics(F: np.ndarray, planned_time_s: float, exact=None) -> dict:
    """Extent, most punctual member, least energy on time and (with ``exact``) the gaps of one feasible front.

    Parameters
    ----------
    F : array (n, 2)
        Feasible members' (energy kWh, running time s).
    planned_time_s : float
        The planned running time (s).
    exact : pandas.DataFrame, optional
        The exact front (``running_time_s``, ``energy_kwh``, ascending time).

    Returns
    -------
    dict
        ``e_min, e_max, t_min, t_max, punctual_e, punctual_t, e_at_plan`` (NaN when no member is on
        time) and, with ``exact``, ``gap_mean_pct, gap_min_pct, gap_max_pct, hv_ratio_exact,
        punctual_gap_pct``.
    """
    k = most_punctual(F, planned_time_s)
    inside = F[:, 1] <= planned_time_s
    row = dict(e_min=F[:, 0].min(), e_max=F[:, 0].max(), t_min=F[:, 1].min(), t_max=F[:, 1].max(), punctual_e=F[k, 0],
               punctual_t=F[k, 1], e_at_plan=float(F[inside, 0].min()) if inside.any() else float("nan"))
    if exact is not None:
        gap = energy_gap(F[:, ::-1], exact[["running_time_s", "energy_kwh"]].to_numpy(float))
        row.update(gap_mean_pct=100 * gap["mean_gap_rel"], gap_min_pct=100 * gap["min_gap_rel"],
                   gap_max_pct=100 * gap["max_gap_rel"], hv_ratio_exact=gap["hv_ratio"],
                   punctual_gap_pct=100 * (F[k, 0] / exact_energy_kwh(exact, F[k, 1]) - 1))
    return row
