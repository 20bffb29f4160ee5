"""Energy-minimal split of a journey's running time over its sections.

Given each section's convex energy-time front ``E_k(t)``, the split of a total running time ``T``
that minimises ``sum_k E_k(t_k)`` subject to ``sum_k t_k = T`` and ``t_k`` inside each front's
range is a convex resource allocation. Its optimality condition is equal marginal energy: one
price ``lambda`` (kWh saved per extra second) with ``-lambda`` inside the sub-gradient of every
``E_k`` at ``t_k``. On piecewise-linear convex fronts the optimum is found exactly, with no
iteration: start every section at its shortest time and hand out the budget segment by segment,
steepest energy decrease per second first (a bisection on the price would visit the same
segments in the same order). The price is minus the slope of the last segment used.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Callable, Sequence

import numpy as np
import pandas as pd

from pymoo_rail.journeys.fronts import FrontSource, convex_front, front_energy, front_slopes, strategy_front
from pymoo_rail.journeys.journey import Journey
from pymoo_rail.model import Case, CaseError, InfeasibleCaseError
from pymoo_rail.sim import Simulator

FRONT_SOURCES = ("simulated", "optimal")
DEFAULT_FRONT_SOURCE = "simulated"


def _time_grid(t_min: float, n_times: int, max_time_factor: float) -> np.ndarray:
    """Running times asked of a front source: just above the minimum up to ``max_time_factor`` times it."""
    return t_min * np.linspace(1.0 + _ABOVE_MIN, max_time_factor, n_times)


_ABOVE_MIN = 0.005  # the flat-out run itself is added from the simulator (it is the unique run at T_min)


def section_fronts(journey: Journey, fronts: FrontSource = DEFAULT_FRONT_SOURCE, *, n_times: int = 25,
                   max_time_factor: float = 1.5, dx_m: float | None = None,
                   running_times: Callable[[Case], np.ndarray] | None = None) -> list[pd.DataFrame]:
    """Convex energy-time fronts of a journey's sections.

    Parameters
    ----------
    fronts : str, callable or sequence of DataFrame
        ``"simulated"``: :func:`~pymoo_rail.journeys.fronts.strategy_front` (direct search over
        traction - hold - coast - brake runs). ``"optimal"``: the exact solver
        ``pymoo_rail.optimal.optimal_front``. A callable ``f(case, running_times) -> DataFrame``
        (the signature of ``optimal_front``). Or one precomputed DataFrame per section. Every front
        is replaced by its lower convex hull.
    n_times, max_time_factor : int, float
        Running times asked of a callable or of the exact solver: ``n_times`` from 0.5 % above the
        section's minimum running time to ``max_time_factor`` times it; the flat-out run (the only
        run at the minimum time) is added from the simulator. The simulated search keeps runs up
        to ``max_time_factor`` times the minimum.
    running_times : callable, optional
        ``case -> running times`` for a callable source, replacing that default grid.
    """
    if isinstance(fronts, str):
        if fronts == "simulated":
            return [strategy_front(c, dx_m=dx_m, max_time_factor=max_time_factor) for c in journey.sections]
        if fronts == "optimal":
            from pymoo_rail.optimal import optimal_front  # the exact solver (branch 'optimal')

            source: Callable = optimal_front
        else:
            raise CaseError("fronts", fronts, f"unknown front source (known: {', '.join(FRONT_SOURCES)}, "
                                              "a callable, or one DataFrame per section)")
    elif callable(fronts):
        source = fronts
    else:
        fronts = list(fronts)
        if len(fronts) != journey.n_sections:
            raise CaseError("fronts", len(fronts), f"needs one front per section ({journey.n_sections})")
        return [convex_front(f, f"fronts[{k}]") for k, f in enumerate(fronts)]
    out = []
    for k, case in enumerate(journey.sections):
        fastest = Simulator(case, dx_m).flat_out()
        times = running_times(case) if running_times is not None else \
            _time_grid(fastest.running_time_s, n_times, max_time_factor)
        front = source(case, np.asarray(times, dtype=float))
        flat_out = pd.DataFrame({"running_time_s": [fastest.running_time_s], "energy_kwh": [fastest.energy.net_kwh]})
        out.append(convex_front(pd.concat([flat_out, front], ignore_index=True), f"fronts[{k}]"))
    return out


def allocate_on_fronts(fronts: Sequence[pd.DataFrame], total_time_s: float) -> tuple[np.ndarray, np.ndarray, float]:
    """Exact energy-minimal split of ``total_time_s`` over convex piecewise-linear fronts.

    Returns ``(running_times_s, energies_kwh, price_kwh_per_s)``; the price is the marginal energy
    saved per extra second, equal across every section whose time is strictly inside a segment.
    """
    fronts = [convex_front(f, f"fronts[{k}]") for k, f in enumerate(fronts)]
    lo = np.array([f["running_time_s"].iloc[0] for f in fronts])
    hi = np.array([f["running_time_s"].iloc[-1] for f in fronts])
    total = float(total_time_s)
    tol = 1e-9 * max(1.0, hi.sum())
    if not np.isfinite(total):
        raise CaseError("total_time_s", total_time_s, "must be a finite number")
    if total < lo.sum() - tol:
        raise InfeasibleCaseError("total_time_s", total_time_s,
                                  f"is below the sum of the sections' minimum running times {lo.sum():.2f} s")
    if total > hi.sum() + tol:
        raise CaseError("total_time_s", total_time_s,
                        f"exceeds the longest running times the fronts cover ({hi.sum():.2f} s in total): "
                        "compute the fronts over a wider time range")
    segments = []  # (slope, section, duration); within a convex front slopes increase
    for k, f in enumerate(fronts):
        for j, (slope, dt) in enumerate(zip(front_slopes(f), np.diff(f["running_time_s"].to_numpy(float)))):
            segments.append((slope, k, j, dt))
    segments.sort(key=lambda s: (s[0], s[1], s[2]))
    times = lo.copy()
    budget = total - lo.sum()
    price_slope = segments[0][0] if segments else 0.0
    for slope, k, _, dt in segments:
        if budget <= tol:
            break
        take = min(dt, budget)
        times[k] += take
        budget -= take
        price_slope = slope
    times = np.clip(times, lo, hi)
    energies = np.array([float(front_energy(f, t)) for f, t in zip(fronts, times)])
    return times, energies, float(-price_slope)


def marginal_slopes(front: pd.DataFrame, running_time_s: float, rtol: float = 1e-9) -> tuple[float, float]:
    """Left and right derivative dE/dT of a convex front at a time (-inf / +inf at its ends)."""
    t = front["running_time_s"].to_numpy(dtype=float)
    slopes = front_slopes(front)
    tol = rtol * max(1.0, t[-1])
    j = int(np.searchsorted(t, running_time_s - tol, side="left"))  # first vertex at or after the time
    at_vertex = j < t.shape[0] and abs(t[j] - running_time_s) <= tol
    if at_vertex:
        left = slopes[j - 1] if j > 0 else -np.inf
        right = slopes[j] if j < slopes.shape[0] else np.inf
    else:
        left = right = slopes[j - 1]
    return float(left), float(right)


@dataclass(frozen=True, eq=False)
class Allocation:
    """A split of a journey's running time over its sections.

    ``table`` has one row per section: ``section``, ``label``, ``length_m``, ``min_time_s`` and
    ``max_time_s`` (the front's range), ``running_time_s``, ``supplement_s`` (over the minimum),
    ``energy_kwh`` (on the convex front), ``slope_left_kwh_per_s`` and ``slope_right_kwh_per_s``
    (the front's derivatives at the allocated time). ``price_kwh_per_s`` is the marginal energy per
    second of the energy-optimal split (``None`` for the rule-based splits).
    """

    rule: str
    table: pd.DataFrame
    total_time_s: float
    energy_kwh: float
    price_kwh_per_s: float | None
    trip_time_s: float

    @property
    def running_times_s(self) -> np.ndarray:
        return self.table["running_time_s"].to_numpy(dtype=float)

    @property
    def energies_kwh(self) -> np.ndarray:
        return self.table["energy_kwh"].to_numpy(dtype=float)

    def marginal_violation(self) -> float:
        """Largest breach (kWh/s) of ``slope_left <= -price <= slope_right`` over the sections.

        Zero for an exact energy-optimal split; meaningless (``None`` price) for rule-based splits.
        """
        if self.price_kwh_per_s is None:
            raise CaseError("price_kwh_per_s", None, f"the '{self.rule}' split has no marginal price")
        s = -self.price_kwh_per_s
        left = self.table["slope_left_kwh_per_s"].to_numpy(float)
        right = self.table["slope_right_kwh_per_s"].to_numpy(float)
        return float(max(0.0, np.max(left - s), np.max(s - right)))


def _allocation(journey: Journey, fronts: list[pd.DataFrame], times: np.ndarray, energies: np.ndarray,
                rule: str, price: float | None) -> Allocation:
    slopes = [marginal_slopes(f, t) for f, t in zip(fronts, times)]
    lo = np.array([f["running_time_s"].iloc[0] for f in fronts])
    table = pd.DataFrame({
        "section": np.arange(journey.n_sections),
        "label": [journey.section_label(k) for k in range(journey.n_sections)],
        "length_m": journey.section_lengths_m,
        "min_time_s": lo,
        "max_time_s": [f["running_time_s"].iloc[-1] for f in fronts],
        "running_time_s": times,
        "supplement_s": times - lo,
        "energy_kwh": energies,
        "slope_left_kwh_per_s": [s[0] for s in slopes],
        "slope_right_kwh_per_s": [s[1] for s in slopes],
    })
    total = float(times.sum())
    return Allocation(rule=rule, table=table, total_time_s=total, energy_kwh=float(energies.sum()),
                      price_kwh_per_s=price, trip_time_s=journey.trip_time_s(total))


def _fronts_for(journey: Journey, fronts: FrontSource | list[pd.DataFrame], **kwargs) -> list[pd.DataFrame]:
    return section_fronts(journey, fronts, **kwargs)


def allocate_running_time(journey: Journey, total_time_s: float,
                          fronts: FrontSource = DEFAULT_FRONT_SOURCE, **front_options) -> Allocation:
    """The energy-minimal split of a total running time over a journey's sections.

    Parameters
    ----------
    journey : Journey
    total_time_s : float
        Sum of the sections' running times (the trip time minus the dwells; see
        :meth:`Journey.running_time_s`).
    fronts : str, callable or sequence of DataFrame
        Section fronts or how to compute them (see :func:`section_fronts`). Pass precomputed
        fronts when splitting several totals on the same journey.
    **front_options
        Passed to :func:`section_fronts` when the fronts are computed here.

    Returns
    -------
    Allocation
        Exact on the convex (piecewise-linear) fronts: per-section times and energies, the line
        total and the common marginal price.
    """
    convex = _fronts_for(journey, fronts, **front_options)
    times, energies, price = allocate_on_fronts(convex, total_time_s)
    return _allocation(journey, convex, times, energies, "energy-optimal", price)


def supplement_split(journey: Journey, total_time_s: float, fronts: FrontSource = DEFAULT_FRONT_SOURCE,
                     rule: str = "equal", **front_options) -> Allocation:
    """A timetable rule of thumb: the same extra time on every section (``"equal"``) or the same
    percentage of each minimum running time (``"proportional"``), evaluated on the same fronts."""
    convex = _fronts_for(journey, fronts, **front_options)
    lo = np.array([f["running_time_s"].iloc[0] for f in convex])
    hi = np.array([f["running_time_s"].iloc[-1] for f in convex])
    extra = float(total_time_s) - lo.sum()
    if extra < -1e-9 * lo.sum():
        raise InfeasibleCaseError("total_time_s", total_time_s,
                                  f"is below the sum of the sections' minimum running times {lo.sum():.2f} s")
    if rule == "equal":
        times = lo + extra / lo.shape[0]
    elif rule == "proportional":
        times = lo * (float(total_time_s) / lo.sum())
    else:
        raise CaseError("rule", rule, "must be 'equal' or 'proportional'")
    over = np.argwhere(times > hi * (1 + 1e-12))
    if over.size:
        k = int(over[0, 0])
        raise CaseError("total_time_s", total_time_s, f"the {rule} split gives section {k} {times[k]:.2f} s, "
                                                      f"beyond its front ({hi[k]:.2f} s): widen the fronts")
    times = np.minimum(np.maximum(times, lo), hi)
    energies = np.array([float(front_energy(f, t)) for f, t in zip(convex, times)])
    return _allocation(journey, convex, times, energies, f"{rule} supplement", None)
