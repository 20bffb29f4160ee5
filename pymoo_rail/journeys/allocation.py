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
from pathlib import Path
from typing import Callable, Sequence

import numpy as np
import pandas as pd

from pymoo_rail.journeys.fronts import (
    FRONT_COLUMNS,
    FrontSource,
    convex_front,
    convex_fronts,
    front_energy,
    front_slopes,
    strategy_front,
)
from pymoo_rail.journeys.journey import Journey, as_journey
from pymoo_rail.model import Case, CaseError, InfeasibleCaseError
from pymoo_rail.optimal.reference import case_hash
from pymoo_rail.rowcache import RowCache
from pymoo_rail.sim import Simulator

FRONT_SOURCES = ("optimal", "simulated", "combined")
DEFAULT_FRONT_SOURCE = "optimal"


def _time_grid(t_min: float, n_times: int, max_time_factor: float) -> np.ndarray:
    """Running times asked of a front source, from just above the minimum to ``max_time_factor`` times it.

    Spaced quadratically: the front bends most near the minimum time, and a chord across a bend
    overestimates the energy of a convex front (with even spacing and 16 times, by up to 2 % just
    above the minimum on this project's metro sections).
    """
    u = np.linspace(0.0, 1.0, n_times)
    return t_min * (1.0 + _ABOVE_MIN + (max_time_factor - 1.0 - _ABOVE_MIN) * u * u)


_ABOVE_MIN = 0.005  # the flat-out run itself is added from the simulator (it is the unique run at T_min)
_GRID = "quadratic"  # recorded in front caches: a cache made with another spacing is not reused


def _named_source(fronts: str, n_times: int, max_time_factor: float, dx_m: float | None,
                  running_times) -> tuple[Callable[[int, Case], pd.DataFrame], str, str]:
    """``(compute(k, case), label, version)`` of a front source given by name (see :func:`section_fronts`)."""
    if fronts == "simulated":
        def compute(k: int, case: Case) -> pd.DataFrame:
            return strategy_front(case, dx_m=dx_m, max_time_factor=max_time_factor)
    elif fronts in ("optimal", "combined"):
        from pymoo_rail.optimal import optimal_front  # the exact solver

        exact = _sampled(lambda case, times: optimal_front(case, times, dx_m=dx_m), n_times,
                         max_time_factor, dx_m, running_times)
        if fronts == "optimal":
            compute = exact
        else:
            def compute(k: int, case: Case) -> pd.DataFrame:
                searched = strategy_front(case, dx_m=dx_m, max_time_factor=max_time_factor)
                return pd.concat([exact(k, case)[list(FRONT_COLUMNS)], searched[list(FRONT_COLUMNS)]],
                                 ignore_index=True)
    else:
        raise CaseError("fronts", fronts, f"unknown front source (known: {', '.join(FRONT_SOURCES)}, "
                                          "a callable, or one DataFrame per section)")
    from pymoo_rail.journeys.fronts import STRATEGY_VERSION  # read at the call (tests change them)
    from pymoo_rail.optimal.solver import SOLVER_VERSION

    version = {"simulated": f"strategy {STRATEGY_VERSION}", "optimal": f"solver {SOLVER_VERSION}",
               "combined": f"solver {SOLVER_VERSION} + strategy {STRATEGY_VERSION}"}[fronts]
    return compute, fronts, version


def section_fronts(journey: Journey | Case, fronts: FrontSource = DEFAULT_FRONT_SOURCE, *, n_times: int = 16,
                   max_time_factor: float = 1.5, dx_m: float | None = None,
                   running_times: Callable[[Case], np.ndarray] | None = None,
                   cache_path: str | Path | None = None,
                   on_front: Callable[[int, bool], None] | None = None) -> list[pd.DataFrame]:
    """Convex energy-time fronts of a journey's sections.

    Parameters
    ----------
    fronts : str, callable or sequence of DataFrame
        ``"optimal"`` (default): the exact solver ``pymoo_rail.optimal.optimal_front`` (about a
        second per running time on a 2 km section, so minutes for a whole line: pass
        ``cache_path``). ``"simulated"``: :func:`~pymoo_rail.journeys.fronts.strategy_front`, a
        direct search over traction - hold - coast - brake runs (seconds for a whole line; on the
        Yizhuang sections its mean gap to the exact front is below 1 %, locally a few %).
        ``"combined"``: the lower hull of both point sets; every point is a simulated run (the
        exact solver returns the simulator's replay of its controls), so the hull stays an upper
        estimate of the optimal front, at least as close as either. A callable
        ``f(case, running_times) -> DataFrame`` (the signature of ``optimal_front``). Or one
        precomputed DataFrame per section. Every front is replaced by its lower convex hull.
    n_times, max_time_factor : int, float
        Running times asked of a callable or of the exact solver: ``n_times`` from 0.5 % above the
        section's minimum running time to ``max_time_factor`` times it, spaced quadratically (denser
        near the minimum, where the front bends most); the flat-out run (the only run at the
        minimum time) is added from the simulator. The simulated search keeps runs up
        to ``max_time_factor`` times the minimum.
    running_times : callable, optional
        ``case -> running times`` for a callable source, replacing that default grid.
    cache_path : path, optional
        A CSV file of finished section fronts (:class:`pymoo_rail.rowcache.RowCache`). A section is
        read back only under the same key: its content (:func:`~pymoo_rail.optimal.reference.case_hash`,
        so a renamed section keeps its front and a changed one under the same name is computed
        anew), the version of the source (``pymoo_rail.optimal.solver.SOLVER_VERSION``,
        :data:`~pymoo_rail.journeys.fronts.STRATEGY_VERSION`, both for ``"combined"``; a callable is
        known by its qualified name only) and the settings above. Each new front is added as soon
        as it is computed, replacing the rows of its section index (an atomic rewrite under a file
        lock), so an interrupted run keeps every finished section and two runs on one file lose
        none. A corrupt file is moved aside with a warning and its sections computed again. The
        file keeps each convex front's ``running_time_s`` and ``energy_kwh``, ``section``,
        ``case`` (the name, for reading), then the key.
    on_front : callable, optional
        Called as ``on_front(k, computed)`` after section ``k``; ``computed`` is False when its
        front was read from ``cache_path``.
    """
    journey = as_journey(journey)
    if isinstance(fronts, str):
        compute, label, version = _named_source(fronts, n_times, max_time_factor, dx_m, running_times)
    elif callable(fronts):
        compute = _sampled(fronts, n_times, max_time_factor, dx_m, running_times)
        # a function's qualified name, or a callable object's class (its repr would hold its address)
        label = getattr(fronts, "__qualname__", None) or type(fronts).__qualname__
        version = ""
    else:
        fronts = list(fronts)
        if len(fronts) != journey.n_sections:
            raise CaseError("fronts", len(fronts), f"needs one front per section ({journey.n_sections})")
        return [convex_front(f, f"fronts[{k}]") for k, f in enumerate(fronts)]
    cache = None if cache_path is None else RowCache(cache_path, value_columns=(*FRONT_COLUMNS, "section"),
                                                     text_columns=("case", "case_hash", "version"))
    settings = {"source": label, "version": version, "grid": _GRID if running_times is None else "custom",
                "n_times": int(n_times), "max_time_factor": float(max_time_factor), "dx_m": float(dx_m or 0.0)}
    out: list[pd.DataFrame] = []
    for k, case in enumerate(journey.sections):
        key = {"case_hash": case_hash(case)[:16], **settings}
        rows = cache.rows(key) if cache is not None else None
        computed = rows is None or len(rows) == 0
        if computed:
            front = convex_front(compute(k, case), f"fronts[{k}]")
            if cache is not None:  # at once: an interrupted run keeps every finished section
                cache.add(front[list(FRONT_COLUMNS)].assign(section=k, case=case.name), key,
                          replace=lambda table, k=k: table["section"] == k)
        else:
            front = convex_front(rows[list(FRONT_COLUMNS)], f"fronts[{k}]")
        if on_front is not None:
            on_front(k, computed)
        out.append(front)
    return out


def _sampled(source: Callable, n_times: int, max_time_factor: float, dx_m: float | None,
             running_times: Callable[[Case], np.ndarray] | None) -> Callable[[int, Case], pd.DataFrame]:
    """A section-front function from a source evaluated at chosen running times, plus the flat-out run."""
    def compute(k: int, case: Case) -> pd.DataFrame:
        fastest = Simulator(case, dx_m).flat_out()
        times = running_times(case) if running_times is not None else \
            _time_grid(fastest.running_time_s, n_times, max_time_factor)
        front = source(case, np.asarray(times, dtype=float))
        flat_out = pd.DataFrame({"running_time_s": [fastest.running_time_s], "energy_kwh": [fastest.energy.net_kwh]})
        return pd.concat([flat_out, front], ignore_index=True)
    return compute


def allocate_on_fronts(fronts: Sequence[pd.DataFrame], total_time_s: float) -> tuple[np.ndarray, np.ndarray, float]:
    """Exact energy-minimal split of ``total_time_s`` over convex piecewise-linear fronts.

    Returns ``(running_times_s, energies_kwh, price_kwh_per_s)``; the price is the marginal energy
    saved per extra second, equal across every section whose time is strictly inside a segment.
    """
    fronts = convex_fronts(fronts)
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
        """Running time of each section (s)."""
        return self.table["running_time_s"].to_numpy(dtype=float)

    @property
    def energies_kwh(self) -> np.ndarray:
        """Net energy of each section (kWh)."""
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


def allocate_running_time(journey: Journey | Case, total_time_s: float,
                          fronts: FrontSource = DEFAULT_FRONT_SOURCE, **front_options) -> Allocation:
    """The energy-minimal split of a total running time over a journey's sections.

    Parameters
    ----------
    journey : Journey or Case
        A journey, or a case with legs (one section per leg).
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
    journey = as_journey(journey)
    convex = _fronts_for(journey, fronts, **front_options)
    times, energies, price = allocate_on_fronts(convex, total_time_s)
    return _allocation(journey, convex, times, energies, "energy-optimal", price)


def supplement_split(journey: Journey | Case, total_time_s: float, fronts: FrontSource = DEFAULT_FRONT_SOURCE,
                     rule: str = "equal", **front_options) -> Allocation:
    """A timetable rule of thumb: the same extra time on every section (``"equal"``) or the same
    percentage of each minimum running time (``"proportional"``), evaluated on the same fronts."""
    journey = as_journey(journey)
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
