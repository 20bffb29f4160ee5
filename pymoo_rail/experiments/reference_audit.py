"""Audits of the exact reference: committed optimiser members against it, and its certificate's cover.

:func:`check_members` solves the optimum at each member's own running time
(:func:`pymoo_rail.optimal.solved_energy_gap`) and :func:`members_summary` counts, per source, the
members below it by more than its certificate (a defect of the reference).
:func:`coverage_table` solves the same times again with other speed grids and
:func:`coverage_summary` counts where another solve is lower than the default by more than the
default's certificate (a *miss*). :func:`certificate_parts` sets the certificate's parts beside
finer grids at given running times. The members come from
:func:`pymoo_rail.experiments.report.committed_members`; ``benchmarks/reference_check.py`` writes
the reports.
"""

from __future__ import annotations

import time

import numpy as np
import pandas as pd

from pymoo_rail.constants import J_PER_KWH
from pymoo_rail.optimal import OptimalSolver, ReferenceAtTime, solved_energy_gap
from pymoo_rail.optimal.reference import gap_columns

GAP_COLUMNS = ("optimal_kwh", "gap_kwh", "gap_rel", "energy_bound_kwh", "below_reference", "in_range")
DERIVED = ("gap_rel", "below_reference")  # rebuilt from the others when a stored table is read
COVERAGE_OTHERS = {"uniform": {"top_bias": 0.0}, "fine": {"n_speeds": 400}}


def check_members(table: pd.DataFrame, cases: dict, progress=lambda items: items) -> pd.DataFrame:
    """``table`` (``case``, ``running_time_s``, ``energy_kwh``) with the :data:`GAP_COLUMNS` added.

    Parameters
    ----------
    table : pandas.DataFrame
        One row per member.
    cases : dict
        The cases by the names in ``table["case"]``.
    progress : callable
        Wraps the list of cases (e.g. ``tqdm``).
    """
    parts = []
    for name, group in progress(list(table.groupby("case", sort=False))):
        gap = solved_energy_gap(group[["running_time_s", "energy_kwh"]], ReferenceAtTime(cases[name]))["points"]
        parts.append(pd.concat([group.reset_index(drop=True), gap[list(GAP_COLUMNS)].reset_index(drop=True)], axis=1))
    return pd.concat(parts, ignore_index=True)


def with_derived_columns(table: pd.DataFrame) -> pd.DataFrame:
    """A stored table with ``gap_rel`` and ``below_reference`` as ``solved_energy_gap`` defines them."""
    gaps = gap_columns(table["gap_kwh"], table["optimal_kwh"], table["energy_bound_kwh"], table["in_range"])
    return table.assign(gap_rel=gaps["gap_rel"], below_reference=gaps["below_reference"])


def members_summary(table: pd.DataFrame) -> pd.DataFrame:
    """Per source and label: members, in range, below the reference beyond the certificate, gaps.

    ``least margin kWh`` is the smallest gap + certificate: negative for a member below the
    optimum by more than the certificate.
    """
    t = table[table["in_range"]].copy()
    t["margin_kwh"] = t["gap_kwh"] + t["energy_bound_kwh"]
    g = t.groupby(["source", "label"], sort=False)
    out = pd.DataFrame({
        "members": g.size(),
        "below_reference": g["below_reference"].sum().astype(int),
        "least margin kWh": g["margin_kwh"].min(),
        "largest certificate kWh": g["energy_bound_kwh"].max(),
        "gap best %": 100 * g["gap_rel"].min(),
        "gap mean %": 100 * g["gap_rel"].mean(),
        "gap worst %": 100 * g["gap_rel"].max(),
    }).reset_index()
    out.insert(3, "out of range", table[~table["in_range"]].groupby(["source", "label"]).size()
               .reindex(pd.MultiIndex.from_frame(out[["source", "label"]])).fillna(0).astype(int).to_numpy())
    return out


def coverage_table(table: pd.DataFrame, cases: dict, others: dict = COVERAGE_OTHERS,
                   progress=lambda items: items) -> pd.DataFrame:
    """Per case and distinct member time: the default optimum, its certificate, and each other solve's.

    The other solve's value at a time is its supporting line plus ``move_remainder_kwh`` (the chord
    between its solves on either side): the energy its runs reach there. Times are solved in
    increasing order, each warm-starting the next; the CPU seconds per solve go to ``attrs["cpu_s"]``.
    """
    rows, cpu_s = [], {}
    for name, group in progress(list(table.groupby("case", sort=False))):
        times = np.sort(group["running_time_s"].round(3).unique())
        refs = {"default": ReferenceAtTime(cases[name])}
        refs.update({k: ReferenceAtTime(cases[name], certify=False, **s) for k, s in others.items()})
        answers = {}
        for label, ref in refs.items():
            start = time.process_time()
            answers[label] = [ref.at(float(t)) for t in times]
            cpu_s[(name, label)] = time.process_time() - start
        for k, t in enumerate(times):
            d = answers["default"][k]
            rows.append({"case": name, "running_time_s": t, "default_kwh": d["optimal_kwh"],
                         "certificate_kwh": d["energy_bound_kwh"],
                         **{f"{label}_kwh": answers[label][k]["optimal_kwh"] + answers[label][k]["move_remainder_kwh"]
                            for label in others}})
    out = pd.DataFrame(rows)
    out.attrs["cpu_s"] = cpu_s
    return out


def coverage_summary(table: pd.DataFrame, others: dict = COVERAGE_OTHERS) -> tuple[pd.DataFrame, list[str]]:
    """Per case and other solve: times lower, largest difference, misses; and one sentence per solve."""
    t = table[np.isfinite(table["default_kwh"])]
    parts, lines = [], []
    for label in others:
        diff = t["default_kwh"] - t[f"{label}_kwh"]  # > 0: the other solve is lower
        miss = diff - t["certificate_kwh"]  # > 0: the certificate did not cover it
        g = t.assign(diff=diff, rel=diff / t["default_kwh"], miss=miss).groupby("case", sort=False)
        parts.append(pd.DataFrame({
            "other": label, "times": g.size(), "other lower": g["diff"].apply(lambda s: int((s > 1e-9).sum())),
            "largest lower kWh": g["diff"].max(), "largest lower %": 100 * g["rel"].max(),
            "largest certificate kWh": g["certificate_kwh"].max(),
            "misses": g["miss"].apply(lambda s: int((s > 1e-9).sum())), "worst margin kWh": -g["miss"].max(),
        }).reset_index())
        worst, worst_miss = diff.idxmax(), miss.idxmax()
        lines.append(f"- `{label}` ({', '.join(f'{k}={v:g}' for k, v in others[label].items())}): lower than the "
                     f"default at {int((diff > 1e-9).sum())} of {len(t)} times, by up to {diff[worst]:.4f} kWh "
                     f"({t.at[worst, 'case']} at {t.at[worst, 'running_time_s']:.3f} s, "
                     f"certificate {t.at[worst, 'certificate_kwh']:.4f} kWh); not covered by the certificate: "
                     f"**{int((miss > 1e-9).sum())}** (closest: margin {-miss[worst_miss]:.4f} kWh, "
                     f"{t.at[worst_miss, 'case']} at {t.at[worst_miss, 'running_time_s']:.3f} s).")
    return pd.concat(parts, ignore_index=True), lines


def certificate_parts(points, variants) -> pd.DataFrame:
    """Per ``(label, case, running time)``: the default run, its certificate and its parts, and other runs.

    Each of ``variants`` (``OptimalSolver`` settings, e.g. ``{"n_speeds": 400}``) solves the same
    time without a certificate; its energy is moved to the default run's time along its slope.
    One row per point, ``lower_estimate_kwh`` = energy - certificate.
    """
    rows = []
    for label, case, t in points:
        solver = OptimalSolver(case)
        tr = solver.profile(t)
        row = {"case": label, "time_s": tr.running_time_s, "energy_kwh": tr.energy.net_kwh,
               "moved": bool(tr.summary["adjusted"]), "certificate_kwh": tr.summary["energy_bound_kwh"],
               **solver.last_bound_parts}
        row["lower_estimate_kwh"] = row["energy_kwh"] - row["certificate_kwh"]
        for settings in variants:
            other = OptimalSolver(case, certify=False, **settings).profile(t)
            moved = other.summary["lambda_w"] * (other.running_time_s - tr.running_time_s) / J_PER_KWH
            row[", ".join(f"{k}={v:g}" for k, v in settings.items()) + " kWh"] = other.energy.net_kwh + moved
        rows.append(row)
    return pd.DataFrame(rows)
