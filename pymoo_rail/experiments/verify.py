"""Check every member of an optimiser's front again: re-simulated, against the case and its stored objectives.

A front a study stored says what the optimiser saw. :func:`check_members` replays each member
(``problem.trajectory(x)``), checks the run against the case (``sim.checks.check_run``: no traction
in a neutral section, never above a limit over the train length, stopped at the platform), that
the stored energy and running time are the replayed ones, and that the encoding's fixed genes
kept their value; :func:`worst_checks` sums such checks over many runs for a report.
"""

from __future__ import annotations

from typing import Iterable, Mapping

import numpy as np

from pymoo_rail.sim.checks import check_run

# worst value over the members -> (the RunCheck field, the limit it must stay within)
WORST = {"neutral_traction_j_max": "neutral_traction_j", "neutral_force_n_max": "neutral_max_force_n",
         "limit_excess_ms_max": "limit_excess_ms", "independent_excess_ms_max": "independent_excess_ms",
         "stop_error_m_max": "stop_error_m"}


# a report's table of the checks: (what is checked, the worst value's key, what it must be, its pass/FAIL key)
CHECKS = (("neutral traction work (J)", "neutral_traction_j_max", "0", "neutral_ok"),
          ("largest force in a neutral section (N)", "neutral_force_n_max", "<= 0", "force_ok"),
          ("kernel limit excess (m/s)", "limit_excess_ms_max", "<= 0", "limit_ok"),
          ("independent limit excess over the train length (m/s)", "independent_excess_ms_max", "<= 0",
           "independent_ok"),
          ("stop error (m)", "stop_error_m_max", "<= 0.25", "stop_ok"),
          ("stored vs re-simulated energy (kWh)", "energy_mismatch_kwh", "0", "energy_ok"),
          ("stored vs re-simulated running time (s)", "time_mismatch_s", "0", "time_ok"))


def check_members(problem, X: np.ndarray, energy_kwh: np.ndarray, running_time_s: np.ndarray,
                  stop_tolerance_m: float = 0.25, speed_tolerance_ms: float = 1e-6) -> dict:
    """The worst value of every check over the members ``X`` of one front (at least one member).

    Parameters
    ----------
    problem : pymoo_rail.problems.SpeedProfileProblem
        The problem the front was found on.
    X : numpy.ndarray
        The members' decisions, one row each.
    energy_kwh, running_time_s : numpy.ndarray
        The stored objectives of the members.
    stop_tolerance_m, speed_tolerance_ms : float
        What :meth:`pymoo_rail.sim.checks.RunCheck.passes` allows.

    Returns
    -------
    dict
        ``verified`` (every member passes and kept its fixed genes), ``fixed_genes_ok``, the keys of
        :data:`WORST`, and ``energy_mismatch_kwh`` / ``time_mismatch_s`` (largest stored minus replayed).
    """
    X = np.atleast_2d(np.asarray(X, dtype=float))
    if len(X) == 0:
        raise ValueError("check_members: X has no member to check")
    checks = [check_run(problem.trajectory(x), problem.case) for x in X]
    fixed = problem.encoding.fixed()
    fixed_ok = bool(np.all(X[:, fixed] == problem.xl[fixed]))
    out = {"verified": all(c.passes(stop_tolerance_m, speed_tolerance_ms) for c in checks) and fixed_ok,
           "fixed_genes_ok": fixed_ok}
    out.update({key: max(getattr(c, field) for c in checks) for key, field in WORST.items()})
    out["energy_mismatch_kwh"] = max(abs(c.energy_kwh - e) for c, e in zip(checks, energy_kwh))
    out["time_mismatch_s"] = max(abs(c.running_time_s - t) for c, t in zip(checks, running_time_s))
    return out


def worst_checks(rows: Iterable[Mapping], stop_tolerance_m: float = 0.25, speed_tolerance_ms: float = 1e-6,
                 match_tolerance: float = 1e-9) -> dict:
    """Sum :func:`check_members` over runs: the worst values, and ``"pass"`` / ``"FAIL"`` per check.

    Parameters
    ----------
    rows : iterable of mapping
        One per run; those with a ``verified`` key are counted, ``n_points`` members each.

    Returns
    -------
    dict
        ``n_runs``, ``n_members``, the worst of each value, ``<check>_ok`` for ``neutral``, ``force``,
        ``limit``, ``independent``, ``stop``, ``energy``, ``time`` and ``fixed``, and ``all_ok``.
    """
    checked = [r for r in rows if "verified" in r]
    worst = {"n_runs": len(checked), "n_members": sum(r["n_points"] for r in checked)}
    for key in (*WORST, "energy_mismatch_kwh", "time_mismatch_s"):
        worst[key] = float(max(r[key] for r in checked))
    limits = {"neutral": ("neutral_traction_j_max", 0.0), "force": ("neutral_force_n_max", 0.0),
              "limit": ("limit_excess_ms_max", speed_tolerance_ms),
              "independent": ("independent_excess_ms_max", speed_tolerance_ms),
              "stop": ("stop_error_m_max", stop_tolerance_m), "energy": ("energy_mismatch_kwh", match_tolerance),
              "time": ("time_mismatch_s", match_tolerance)}
    for name, (key, limit) in limits.items():
        worst[f"{name}_ok"] = "pass" if worst[key] <= limit else "FAIL"
    worst["fixed_ok"] = "pass" if all(r["fixed_genes_ok"] for r in checked) else "FAIL"
    worst["all_ok"] = all(r["verified"] for r in checked) and worst["energy_ok"] == worst["time_ok"] == "pass"
    return worst


def check_rows(worst: Mapping, format_value=str) -> list[list[str]]:
    """The rows of a report's check table from :func:`worst_checks`: check, worst value, requirement, result."""
    rows = [[name, format_value(worst[key]), required, worst[ok]] for name, key, required, ok in CHECKS]
    return rows + [["neutral-section genes at their fixed value (10 km/h, coast)", "", "all members", worst["fixed_ok"]]]
