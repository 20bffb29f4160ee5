"""The running-time allocation as a pymoo problem, to compare metaheuristics with the exact split."""

from __future__ import annotations

from typing import Sequence

import numpy as np
import pandas as pd
from pymoo.core.problem import Problem
from pymoo.core.repair import Repair

from pymoo_rail.journeys.fronts import convex_fronts
from pymoo_rail.model import CaseError, InfeasibleCaseError


class RunningTimeAllocationProblem(Problem):
    """Minimise ``sum_k E_k(t_k)`` over section running times with ``sum_k t_k = T``.

    Decision variables are the section running times (s), bounded by each front's time range;
    the single objective is the line's net energy (kWh) on the convex fronts; the equality
    constraint ``H = sum_k t_k - T`` (s) is met within pymoo's equality tolerance (1e-4), or exactly
    with :class:`BudgetRepair`. :func:`~pymoo_rail.journeys.allocate_running_time` gives the exact
    optimum of the same problem.

    Parameters
    ----------
    fronts : sequence of DataFrame
        One energy-time front per section (columns ``running_time_s``, ``energy_kwh``), e.g. from
        :func:`~pymoo_rail.journeys.section_fronts`; their lower convex hulls are used.
    total_time_s : float
        The running-time budget.
    """

    def __init__(self, fronts: Sequence[pd.DataFrame], total_time_s: float, **kwargs):
        self.fronts = convex_fronts(fronts)
        if not self.fronts:
            raise CaseError("fronts", [], "needs at least one section front")
        self._t = [f["running_time_s"].to_numpy(dtype=float) for f in self.fronts]
        self._e = [f["energy_kwh"].to_numpy(dtype=float) for f in self.fronts]
        xl = np.array([t[0] for t in self._t])
        xu = np.array([t[-1] for t in self._t])
        total = float(total_time_s)
        if not (xl.sum() - 1e-9 <= total <= xu.sum() + 1e-9):
            raise InfeasibleCaseError("total_time_s", total_time_s,
                                      f"must lie in [{xl.sum():.2f}, {xu.sum():.2f}] s (the fronts' ranges)")
        self.total_time_s = total
        super().__init__(n_var=len(self.fronts), n_obj=1, n_eq_constr=1, xl=xl, xu=xu, vtype=float, **kwargs)

    def section_energies(self, x: np.ndarray) -> np.ndarray:
        """Energy of each section (N, n_sections) at running times x (N, n_sections)."""
        x = np.atleast_2d(np.asarray(x, dtype=float))
        return np.column_stack([np.interp(x[:, k], self._t[k], self._e[k]) for k in range(self.n_var)])

    def _evaluate(self, x, out, *args, **kwargs):
        out["F"] = self.section_energies(x).sum(axis=1, keepdims=True)
        out["H"] = x.sum(axis=1, keepdims=True) - self.total_time_s


def project_to_budget(x: np.ndarray, xl: np.ndarray, xu: np.ndarray, total: float, iters: int = 100) -> np.ndarray:
    """Euclidean projection of each row of x onto ``{xl <= y <= xu, sum(y) = total}``.

    The projection is ``clip(x + tau, xl, xu)`` with the shift tau that meets the sum, found by a
    vectorised bisection (the sum is monotone in tau).
    """
    x = np.atleast_2d(np.asarray(x, dtype=float))
    lo = np.full(x.shape[0], (xl - x).min(axis=1).min() - 1.0)
    hi = np.full(x.shape[0], (xu - x).max(axis=1).max() + 1.0)
    for _ in range(iters):
        mid = 0.5 * (lo + hi)
        s = np.clip(x + mid[:, None], xl, xu).sum(axis=1)
        below = s < total
        lo = np.where(below, mid, lo)
        hi = np.where(below, hi, mid)
    return np.clip(x + 0.5 * (lo + hi)[:, None], xl, xu)


class BudgetRepair(Repair):
    """Repair for :class:`RunningTimeAllocationProblem`: project onto the budget simplex in the box."""

    def _do(self, problem, X, **kwargs):
        return project_to_budget(X, problem.xl, problem.xu, problem.total_time_s)
