"""One section of a journey with timing points as a pymoo problem, for metaheuristics."""

from __future__ import annotations

import numpy as np

from pymoo_rail.constants import KMH_PER_MS
from pymoo_rail.journeys.timing import TimedJourney, window_start_s, window_end_s
from pymoo_rail.model import CaseError
from pymoo_rail.problems import SpeedProfileProblem


class TimedSectionProblem(SpeedProfileProblem):
    """Section ``k`` of a timed journey: a :class:`SpeedProfileProblem` plus one constraint per bound.

    Objectives as in :class:`SpeedProfileProblem` (default: net energy alone). Besides its
    constraints, each time bound of a passing point (``t - latest <= 0``, ``earliest - t <= 0``,
    seconds from the journey's start with the section departing at ``departure_s``), each minimum
    speed at a passing point (km/h) and the arrival window on the running time are inequality
    constraints; maximum speeds are already speed limits of the section's line. The times at passing
    points come from each member's trajectory (one simulator trace per member).

    Parameters
    ----------
    timed : TimedJourney
    k : int
        The section.
    departure_s : float, optional
        Departure time (default: the earliest of the section's departure window).
    """

    def __init__(self, timed: TimedJourney, k: int, departure_s: float | None = None,
                 objectives=("energy",), **kwargs):
        if not 0 <= k < len(timed.windows):
            raise CaseError("k", k, f"the journey has {len(timed.windows)} sections")
        group = timed.windows[k]
        self.departure_s = window_start_s(group[0]) if departure_s is None else float(departure_s)
        self.start_m = timed.journey.stops_m[k]
        self.passing = group[1:-1]
        self.arrival = group[-1]
        super().__init__(timed.journey.sections[k], objectives=objectives, **kwargs)
        self._bounds = []  # (kind, point index or -1, bound): kind in latest / earliest / min_speed
        for j, p in enumerate(self.passing):
            if p.latest_s is not None:
                self._bounds.append(("latest", j, p.latest_s))
            if p.earliest_s is not None:
                self._bounds.append(("earliest", j, p.earliest_s))
            if p.min_speed_kmh:
                self._bounds.append(("min_speed", j, p.min_speed_kmh))
        if np.isfinite(window_end_s(self.arrival)):
            self._bounds.append(("latest", -1, window_end_s(self.arrival)))
        if self.arrival.earliest_s is not None:
            self._bounds.append(("earliest", -1, self.arrival.earliest_s))
        self.n_ieq_constr += len(self._bounds)

    def _evaluate(self, x, out, *args, **kwargs):
        super()._evaluate(x, out, *args, **kwargs)
        extra = np.empty((x.shape[0], len(self._bounds)))
        for i, row in enumerate(np.asarray(x)):
            traj = self.trajectory(row)
            for c, (kind, j, bound) in enumerate(self._bounds):
                if j < 0:
                    t, v = self.departure_s + traj.running_time_s, 0.0
                else:
                    x_m = self.passing[j].position_m - self.start_m
                    t = self.departure_s + float(np.interp(x_m, traj.position_m, traj.time_s))
                    v = float(np.interp(x_m, traj.position_m, traj.speed_ms)) * KMH_PER_MS
                extra[i, c] = {"latest": t - bound, "earliest": bound - t, "min_speed": bound - v}[kind]
        out["G"] = np.column_stack([out["G"], extra])
