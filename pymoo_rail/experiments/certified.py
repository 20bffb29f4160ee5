"""How far an optimiser's result lies from a certified optimum (the rail suite's fronts).

Works on what a study record stores of a run: the running time and net energy of each member of
the final front (``extras``) and the front in objective space (``F``).
"""

from __future__ import annotations

import numpy as np

from pymoo_rail.experiments.metrics import normalised_hv
from pymoo_rail.problems.reference import CertifiedFront


def certified_gap(front: CertifiedFront, running_time_s, energy_kwh) -> dict[str, float]:
    """Energy gaps of an optimiser's runs to the optimum at their own running times.

    Parameters
    ----------
    front : CertifiedFront
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


def hv_ratio(F, pf) -> float:
    """Hypervolume of ``F`` over that of the front ``pf`` (both normalised by ``pf``'s ideal and nadir)."""
    F = np.atleast_2d(np.asarray(F, dtype=float))
    pf = np.atleast_2d(np.asarray(pf, dtype=float))
    if F.size == 0:
        return 0.0
    ideal, nadir = pf.min(axis=0), pf.max(axis=0)
    return normalised_hv(F, ideal, nadir) / normalised_hv(pf, ideal, nadir)
