"""The running times a certified front covers and where its nodes lie.

A front covers running times from 0.5 % above the minimum to :data:`FRONT_SPAN` x the planned time
(:func:`default_window`, also a problem's default window). Its nodes (:func:`front_times`) are
spaced quadratically across it, with the planned time and both ends of the punctuality window
(:func:`punctual_tolerance_s`) among them.
"""

from __future__ import annotations

import numpy as np

from pymoo_rail.model import Case

PUNCTUAL_TOLERANCE_REL = 0.01
"""Default punctuality window: ``|T - T_plan| <= 1 %`` of the planned time (at least
:data:`PUNCTUAL_TOLERANCE_MIN_S`); fronts have nodes at both of its ends."""
PUNCTUAL_TOLERANCE_MIN_S = 1.0
FRONT_SPAN = 1.3
"""Fronts cover running times from the minimum to ``FRONT_SPAN`` x the planned time."""
DEFAULT_N_TIMES = 33
"""Nodes of a front. Each node's solve warm-starts the next one's: 33 nodes (not 17) keep the warm
start close enough that the yizhuang front no longer lies above members of the suite study by more
than its bound."""
LONG_LINE_M = 10_000.0
LONG_LINE_N_TIMES = DEFAULT_N_TIMES
"""Nodes of a front on lines longer than :data:`LONG_LINE_M`: as many as on short lines. It was 9
(each DP solve cost more) until the suite's baseline table scored runs on such fronts: between 9
nodes the chord lay above the convex front by up to 4.8 kWh on a 32.9 km high-speed line (median
3.1 kWh, 8 times the nodes' median certificate of 0.38 kWh), so the members of good runs lay below
the interpolated front and an energy gap to it meant little; with 33 nodes the chord's excess is at
most 0.27 kWh there, for 18.9 s of CPU instead of 6.8 s (``docs/suite.md``, "Families")."""


def default_window(min_time_s: float, planned_time_s: float) -> tuple[float, float]:
    """The running times a front covers and a problem's default window: planner's times around the plan.

    From 0.5 % above the minimum running time (the flat-out run is a single point, not a front) to
    ``FRONT_SPAN`` x the planned time (at least 1.2 x the minimum).
    """
    return min_time_s * 1.005, max(FRONT_SPAN * planned_time_s, 1.2 * min_time_s)


def punctual_tolerance_s(planned_time_s: float) -> float:
    """Half-width of the default punctuality window: 1 % of the planned time, at least 1 s."""
    return max(PUNCTUAL_TOLERANCE_MIN_S, PUNCTUAL_TOLERANCE_REL * float(planned_time_s))


def front_times(min_time_s: float, planned_time_s: float, n_times: int = DEFAULT_N_TIMES) -> np.ndarray:
    """Requested running times of the nodes: across :func:`default_window`, with the planned time
    and both ends of its punctuality window (:func:`punctual_tolerance_s`).

    Spaced quadratically (denser near the minimum time, where the front is steepest). The ends of
    the punctuality window are nodes because the optimum under ``|T - T_plan| <= tolerance`` lies on
    one of them (the slow end, energy falling with time): a node there is a solved run with its own
    bound, where a chord between nodes lies above the convex front (by 0.0045 kWh on the
    xiaohongmen-jiugong section, more than optimisers then end below it).
    """
    lo, hi = default_window(min_time_s, planned_time_s)
    u = np.linspace(0.0, 1.0, max(int(n_times) - 1, 2))
    times = lo + (hi - lo) * u ** 2
    tolerance = punctual_tolerance_s(planned_time_s)
    extra = [t for t in (planned_time_s - tolerance, planned_time_s, planned_time_s + tolerance) if lo < t < hi]
    return np.union1d(times, extra)


def n_times_for(case: Case) -> int:
    """Default number of front nodes of a case (:data:`DEFAULT_N_TIMES`, :data:`LONG_LINE_N_TIMES` beyond :data:`LONG_LINE_M`)."""
    return DEFAULT_N_TIMES if case.line.length_m <= LONG_LINE_M else LONG_LINE_N_TIMES
