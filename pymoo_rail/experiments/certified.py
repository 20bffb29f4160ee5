"""How far an optimiser's result lies from a certified optimum (the rail suite's fronts).

Works on what a study record stores of a run: the running time and net energy of each member of
the final front (``extras``) and the front in objective space (``F``).
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pandas as pd

from pymoo_rail.cases import load_case
from pymoo_rail.cases.ttobench import BEIJING_SUBWAY_TRAIN, YIZHUANG_STOP_NAMES, YIZHUANG_TRACK
from pymoo_rail.experiments.metrics import normalised_hv
from pymoo_rail.journeys import journey_from_ttobench
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


def committed_members(reports_dir: str | Path) -> pd.DataFrame:
    """Every optimiser member the committed study CSVs in ``reports_dir`` hold (``benchmarks/reports``).

    Returns
    -------
    pandas.DataFrame
        One row per member: ``source``, ``case``, ``label`` (run / algorithm), ``seed``, ``member``,
        ``running_time_s`` and ``energy_kwh``; the cases are named as :func:`member_cases` names them.
    """
    reports_dir = Path(reports_dir)
    rows = []
    y = pd.read_csv(reports_dir / "yizhuang_seed000.csv")
    for r in y.itertuples():
        rows.append(("yizhuang_seed000", "yizhuang", f"{r.algorithm} {r.partition}", r.seed, "best",
                     r.running_time_s, r.energy_kwh))
    w = pd.read_csv(reports_dir / "emu_wuguang_runs.csv")
    for r in w.itertuples():
        for kind, t, e in (("fastest", r.t_min, r.e_max), ("slowest", r.t_max, r.e_min),
                           ("punctual", r.punctual_t, r.punctual_e)):
            rows.append(("emu_wuguang", "wuguang-crh3", f"{r.algorithm} {r.problem}", r.seed, kind, t, e))
    j = pd.read_csv(reports_dir / "journeys_fronts_simulated.csv")
    for r in j.itertuples():
        rows.append(("journeys", f"section {int(r.section)}", r.case, int(r.section), "strategy",
                     r.running_time_s, r.energy_kwh))
    return pd.DataFrame(rows, columns=["source", "case", "label", "seed", "member", "running_time_s", "energy_kwh"])


def member_cases() -> dict:
    """The cases the members of :func:`committed_members` ran on, by the names it gives them."""
    journey = journey_from_ttobench(YIZHUANG_TRACK, BEIJING_SUBWAY_TRAIN, stop_names=YIZHUANG_STOP_NAMES)
    cases = {"yizhuang": load_case("yizhuang"), "wuguang-crh3": load_case("wuguang-crh3")}
    cases.update({f"section {k}": c for k, c in enumerate(journey.sections)})
    return cases
