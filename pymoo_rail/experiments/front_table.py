"""Statistics of one (energy, running time) front for paper tables: extent, most punctual member,
least energy on time and, against an exact front, the energy gaps; :func:`front_rows` makes them
one row per stored run, with the indicators against the union front and every member checked;
:func:`punctual_choice` is a run's recommended member (least energy within the window) and its front's extent;
:func:`exact_front_table` is the markdown table of an exact front."""

from __future__ import annotations

import numpy as np

from pymoo_rail.experiments.fronts import choose_member, punctual_member
from pymoo_rail.experiments.metrics import gd_van_veldhuizen
from pymoo_rail.experiments.report import markdown_rows, significant
from pymoo_rail.experiments.stats import add_reference_indicators, reference_fronts
from pymoo_rail.experiments.verify import check_members
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


def front_rows(results, problems: dict, exact=None):
    """One dict per run: indicators against the union front, extent, gaps to ``exact``, checks of every member.

    ``results`` are stored runs of (energy, running time) problems (``load_results``), ``problems``
    their built problems by display name. Returns ``results`` with the reference indicators
    (:func:`~pymoo_rail.experiments.stats.add_reference_indicators`) and the rows: ``hv_ref``,
    ``igd_ref``, ``gd_ref``, ``gd_seed`` (Van Veldhuizen's GD to the union front), ``spacing``,
    :func:`front_statistics` and :func:`~pymoo_rail.experiments.verify.check_members` of the feasible members.
    """
    results = add_reference_indicators(results)
    refs = reference_fronts(results)
    rows = []
    for _, run in results.iterrows():
        feasible = run["CV"] <= 0
        F, X = run["F"][feasible], run["X"][feasible]
        row = {"problem": run["problem"], "algorithm": run["algorithm"], "seed": int(run["seed"]),
               "n_eval": int(run["n_eval"]), "n_gen": int(run["n_gen"]), "wall_time_s": float(run["wall_time_s"]),
               "cpu_time_s": float(run.get("cpu_time_s", np.nan)), "n_points": len(F),
               "n_infeasible": int((~feasible).sum()), "hv_ref": run["hv_ref"], "igd_ref": run["igd_ref"],
               "gd_ref": run["gd_ref"], "gd_seed": gd_van_veldhuizen(F, refs[run["problem"]]) if len(F) else np.nan,
               "spacing": run.get("spacing", np.nan)}
        if len(F):
            row.update(front_statistics(F, problems[run["problem"]].case.planned_time_s, exact))
            row.update(check_members(problems[run["problem"]], X, F[:, 0], F[:, 1]))
        rows.append(row)
    return results, rows


def punctual_choice(row, planned_s: float, tolerance_s: float) -> dict:
    """A stored run's recommended solution and the extent of its final set.

    The least-energy feasible member with ``|T - planned_s| <= tolerance_s``
    (:func:`~pymoo_rail.experiments.fronts.punctual_member`, on the record's ``energy_kwh`` and
    ``running_time_s`` extras): its ``energy_kwh``, ``running_time_s``, ``stop_error_m`` and
    decision vector ``x`` (NaN and None when no member is within the window); the run's counts of
    front, feasible and in-window members and, for a front of two or more objectives, the ranges of
    its feasible members' time error and energy.
    """
    ex, F = row["extras"], np.asarray(row["F"], dtype=float)
    energy, time_s = np.asarray(ex["energy_kwh"], dtype=float), np.asarray(ex["running_time_s"], dtype=float)
    CV = np.asarray(row["CV"], dtype=float).reshape(-1)
    feasible, window_s = CV <= 0.0, tolerance_s + 1e-9
    out = {"algorithm": row["algorithm"], "partition": row["problem"], "seed": int(row["seed"]),
           "n_eval": int(row["n_eval"]), "wall_time_s": float(row["wall_time_s"]), "n_front": int(len(F)),
           "n_feasible": int(feasible.sum()),
           "n_within": int((feasible & (np.abs(time_s - planned_s) <= window_s)).sum())}
    if F.shape[1] >= 2 and feasible.any():
        err = np.abs(time_s[feasible] - planned_s)
        out.update(front_time_error_min_s=float(err.min()), front_time_error_max_s=float(err.max()),
                   front_energy_min_kwh=float(energy[feasible].min()), front_energy_max_kwh=float(energy[feasible].max()))
    i = punctual_member(time_s, energy, planned_s, window_s, CV)
    out.update(energy_kwh=np.nan, running_time_s=np.nan, stop_error_m=np.nan, x=None) if i is None else out.update(
        energy_kwh=float(energy[i]), running_time_s=float(time_s[i]), stop_error_m=float(ex["stop_error_m"][i]),
        x=[float(v) for v in np.asarray(row["X"], dtype=float)[i]])
    return out


def exact_front_table(exact) -> str:
    """A markdown table of an exact front (``pymoo_rail.optimal.reference.exact_points``), one row per requested time."""
    return markdown_rows(["requested (s)", "running time (s)", "net energy (kWh)", "traction / regen (kWh)",
                          "lambda (kWh/s)", "neutral traction (J)", "limit excess (m/s)", "stop error (m)", "solve (s)"],
                         [[f"{r.requested_time_s:g}", f"{r.running_time_s:.2f}", f"{r.energy_kwh:.2f}",
                           f"{r.traction_kwh:.1f} / {r.regen_kwh:.1f}", f"{r.lambda_kwh_per_s:.3f}",
                           significant(r.neutral_traction_j), significant(r.limit_excess_ms), significant(r.stop_error_m),
                           f"{r.solve_s:.0f}"] for r in exact.itertuples()])
