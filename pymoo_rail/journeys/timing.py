"""Journeys with timing points: time windows and speed bounds along the track, stops with dwell.

A journey file (TTOBench JSON or TOML, read by :mod:`pymoo_rail.journeys.formats`) lists timing
points ``[position, earliest, latest, min speed, max speed]`` (times from the journey's start,
``null`` where unset). Two consecutive points at one position with
both speed bounds 0 are the arrival at and the departure from an intermediate stop; a point with
both speed bounds 0 is a stopping point, any other a passing point. The stopping points cut the
journey into stop-to-stop sections: a :class:`~pymoo_rail.journeys.Journey`, i.e. a
:class:`~pymoo_rail.model.Case` with one leg per section, with its timing points.

:func:`solve_timed_journey` finds the least-energy run meeting every window. Each section's run is
the exact solver's optimum for a running time: departures are as early as their windows allow
(a longer dwell never saves energy), the running time as long as the arrival window and the next
departure window allow (energy falls with running time). Passing points split a section into
stretches, each with its own price of time, and each missed window gets the ratio of the prices
around its point that puts the run on the window's bound. Minimum speeds are a speed floor of the
exact solver at their points. When no run meets a point, :class:`TimingError` names it.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, replace
from typing import Any, Sequence

import numpy as np

from pymoo_rail.constants import KMH_PER_MS
from pymoo_rail.model import CaseError, InfeasibleCaseError
from pymoo_rail.sim import Trajectory

TIME_TOL_S = 0.5  # the exact solver returns runs within 0.5 s of the request


class TimingError(CaseError):
    """No run of the journey meets a timing point (the message names it)."""


@dataclass(frozen=True)
class TimingPoint:
    """One timing point: a position on the track, a time window and speed bounds (``None`` = unset).

    Times are seconds from the journey's start; speeds in km/h; ``position_m`` on the track.
    """

    position_m: float
    earliest_s: float | None = None
    latest_s: float | None = None
    min_speed_kmh: float | None = None
    max_speed_kmh: float | None = None

    @property
    def is_stop(self) -> bool:
        """True when the point is a stop (speed window 0-0 km/h)."""
        return self.min_speed_kmh == 0.0 and self.max_speed_kmh == 0.0

    def time_ok(self, time_s: float, tol_s: float = 1e-6) -> bool:
        """True when ``time_s`` is inside the time window (within ``tol_s``)."""
        return (self.earliest_s is None or time_s >= self.earliest_s - tol_s) and \
            (self.latest_s is None or time_s <= self.latest_s + tol_s)

    def speed_ok(self, speed_kmh: float, tol_kmh: float = 1e-6) -> bool:
        """True when ``speed_kmh`` is inside the speed window (within ``tol_kmh``)."""
        return (self.min_speed_kmh is None or speed_kmh >= self.min_speed_kmh - tol_kmh) and \
            (self.max_speed_kmh is None or speed_kmh <= self.max_speed_kmh + tol_kmh)


@dataclass(frozen=True)
class TimedJourney:
    """A :class:`Journey` with the timing points of each section.

    ``windows[k]`` holds section ``k``'s departure point, its passing points and its arrival point
    (positions on the track); ``journey.stops_m`` are the section ends on the same track.
    """

    journey: Any  # a Journey (journey.py imports the simulator; this module stays below it)
    windows: tuple[tuple[TimingPoint, ...], ...]

    @property
    def timing_points(self) -> tuple[TimingPoint, ...]:
        """All timing points of the journey, section by section."""
        out: list[TimingPoint] = []
        for section in self.windows:
            out.extend(section)
        return tuple(out)


def window_start_s(point: TimingPoint) -> float:
    """The earliest time of a timing point, 0 when it has none."""
    return point.earliest_s if point.earliest_s is not None else 0.0


def window_end_s(point: TimingPoint) -> float:
    """The latest time of a timing point, infinity when it has none."""
    return point.latest_s if point.latest_s is not None else math.inf


_CAP_LENGTH_M = 1.0  # a passing point's maximum speed holds on this stretch of track after it


def with_speed_caps(line, group: Sequence[TimingPoint], start_m: float):
    """The section's line with each passing point's maximum speed as a short speed limit."""
    caps = [(p.position_m - start_m, p.max_speed_kmh) for p in group[1:-1] if p.max_speed_kmh is not None]
    if not caps:
        return line
    rows = []
    for s, e, v in line.speed_limits:
        cuts = sorted({s, e} | {x for x, _ in caps if s < x < e} | {x + _CAP_LENGTH_M for x, _ in caps
                                                                   if s < x + _CAP_LENGTH_M < e})
        for a, b in zip(cuts[:-1], cuts[1:]):
            limit = min([v] + [c for x, c in caps if x <= a < x + _CAP_LENGTH_M])
            if limit <= 0:
                raise CaseError("timing point", limit, "a passing point needs a maximum speed > 0")
            rows.append((a, b, limit))
    return replace(line, speed_limits=tuple(rows))


@dataclass(frozen=True)
class TimedRun:
    """The solved journey: one trajectory per section, departure times, and the check of every point."""

    trajectories: tuple[Trajectory, ...]
    departures_s: tuple[float, ...]
    checks: tuple[dict, ...]

    @property
    def energy_kwh(self) -> float:
        """Net energy of the whole journey (kWh)."""
        return float(sum(t.energy.net_kwh for t in self.trajectories))

    @property
    def all_met(self) -> bool:
        """True when every timing point's time and speed windows are met."""
        return all(c["time_ok"] and c["speed_ok"] for c in self.checks)


def _time_and_speed_at(trajectory: Trajectory, x_m: float) -> tuple[float, float]:
    t = float(np.interp(x_m, trajectory.position_m, trajectory.time_s))
    v = float(np.interp(x_m, trajectory.position_m, trajectory.speed_ms)) * KMH_PER_MS
    return t, v


def check_run(timed: TimedJourney, trajectories: Sequence[Trajectory], departures_s: Sequence[float]) -> tuple[dict, ...]:
    """Time and speed of the run at every timing point, and whether its window and bounds hold."""
    out = []
    for k, group in enumerate(timed.windows):
        start = timed.journey.stops_m[k]
        traj = trajectories[k]
        for j, point in enumerate(group):
            if j == 0:
                t, v = departures_s[k], 0.0
            elif j == len(group) - 1:
                t, v = departures_s[k] + traj.running_time_s, float(traj.speed_ms[-1]) * KMH_PER_MS
            else:
                tau, v = _time_and_speed_at(traj, point.position_m - start)
                t = departures_s[k] + tau
            out.append({"section": k, "position_m": point.position_m, "time_s": t, "speed_kmh": v,
                        "earliest_s": point.earliest_s, "latest_s": point.latest_s,
                        "min_speed_kmh": point.min_speed_kmh, "max_speed_kmh": point.max_speed_kmh,
                        "time_ok": point.time_ok(t, TIME_TOL_S), "speed_ok": point.speed_ok(v, 1e-3)})
    return tuple(out)


def limit_time_bound_s(line, start_m: float, end_m: float) -> float:
    """Time to run from ``start_m`` to ``end_m`` of a line at its speed limits: a bound no train beats."""
    total = 0.0
    for s, e, v in line.speed_limits:
        a, b = max(s, start_m), min(e, end_m)
        if b > a:
            total += (b - a) / (v / KMH_PER_MS)
    return total


def check_windows_reachable(timed: TimedJourney) -> None:
    """Raise :class:`TimingError` when two timing points' windows leave less time than the speed
    limits allow between them (a bound independent of the train), or a minimum speed is above the
    speed limit (or the train's top speed) at its point."""
    for k, group in enumerate(timed.windows):
        start = timed.journey.stops_m[k]
        case = timed.journey.sections[k]
        line = case.line
        for p in group[1:-1]:
            if p.min_speed_kmh:
                cap = min(case.train.max_speed_kmh, min(v for s, e, v in line.speed_limits
                                                        if s <= p.position_m - start <= e))
                if p.min_speed_kmh > cap:
                    raise TimingError(f"timing point at {p.position_m:g} m", p.min_speed_kmh,
                                      f"cannot be met: the minimum speed {p.min_speed_kmh:g} km/h is above the "
                                      f"limit of {cap:g} km/h there")
        for i, p in enumerate(group):
            for q in group[i + 1:]:
                if p.earliest_s is None or q.latest_s is None:
                    continue
                need = limit_time_bound_s(line, p.position_m - start, q.position_m - start)
                if q.latest_s - p.earliest_s < need:
                    raise TimingError(f"timing point at {q.position_m} m", q.latest_s,
                                      f"cannot be met: after the earliest time {p.earliest_s:g} s at "
                                      f"{p.position_m} m, {q.position_m - p.position_m:.1f} m take at least "
                                      f"{need:.1f} s at the speed limits, but the windows leave "
                                      f"{q.latest_s - p.earliest_s:.1f} s: no train passes {q.position_m} m "
                                      f"before {p.earliest_s + need:.1f} s (latest allowed {q.latest_s:g} s)")


def speed_floor_ms(nodes_m: np.ndarray, passing: Sequence[TimingPoint], start_m: float) -> np.ndarray | None:
    """The passing points' minimum speeds (m/s) at the grid nodes on either side of each point.

    A run is checked at a point by linear interpolation between those two nodes, so a floor on
    both makes the interpolated speed hold it. None when no point has a minimum speed.
    """
    floor = np.zeros(nodes_m.shape[0])
    for p in passing:
        if p.min_speed_kmh:
            i = int(np.clip(np.searchsorted(nodes_m, p.position_m - start_m), 1, nodes_m.shape[0] - 1))
            floor[i - 1:i + 1] = np.maximum(floor[i - 1:i + 1], p.min_speed_kmh / KMH_PER_MS)
    return floor if np.any(floor > 0) else None


def _passing_times(traj: Trajectory, passing: Sequence[TimingPoint], start_m: float, depart_s: float) -> list[float]:
    return [depart_s + _time_and_speed_at(traj, p.position_m - start_m)[0] for p in passing]


def _violation(times: Sequence[float], passing: Sequence[TimingPoint]) -> tuple[int, float] | None:
    """The first passing point missed: (index, signed miss in s, + late / - early)."""
    for j, (t, p) in enumerate(zip(times, passing)):
        if p.latest_s is not None and t > p.latest_s + TIME_TOL_S:
            return j, t - p.latest_s
        if p.earliest_s is not None and t < p.earliest_s - TIME_TOL_S:
            return j, t - p.earliest_s
    return None


def _meet_passing_windows(solver, case, passing: Sequence[TimingPoint], start_m: float, depart_s: float,
                          running_time_s: float, n_bisect: int) -> Trajectory:
    """The least-energy run of one section taking ``running_time_s`` and meeting its passing windows.

    One price of time per stretch between passing points (the Lagrange structure of the windows: a
    binding latest time raises the price of every stretch before the point, a binding earliest time
    lowers it). Starting from one price everywhere, each missed window in turn gets the ratio of
    the prices before and after its point that puts the run on the window's bound (bisection on
    the log of the ratio; the ``lambda`` search keeps the running time); two sweeps over the points.
    """
    cells_mid = 0.5 * (solver.simulator.grid.position_m[:-1] + solver.simulator.grid.position_m[1:])
    point_x = np.array([p.position_m - start_m for p in passing])
    solver.set_speed_floor(speed_floor_ms(solver.simulator.grid.position_m, passing, start_m))
    log_ratio = np.zeros(len(passing))

    def run(ratios):
        # stretch before point j is priced exp(sum of log ratios of the points at or after it)
        after = np.searchsorted(point_x, cells_mid)  # index of the first point after each cell
        cum = np.concatenate([np.cumsum(ratios[::-1])[::-1], [0.0]])
        solver.set_price_shape(np.exp(cum[after]))
        traj = solver.profile(running_time_s)
        return traj, _passing_times(traj, passing, start_m, depart_s)

    best, times = run(log_ratio)
    for _ in range(2 * len(passing)):
        missed = _violation(times, passing)
        if missed is None:
            return best
        j, miss = missed
        # late (miss > 0): a higher price before point j; early: a lower one
        lo, hi = (log_ratio[j], log_ratio[j] + 8.0) if miss > 0 else (log_ratio[j] - 8.0, log_ratio[j])
        bound = passing[j].latest_s if miss > 0 else passing[j].earliest_s
        found = None
        for _ in range(n_bisect):  # keep the feasible ratio closest to the window's bound
            mid = 0.5 * (lo + hi)
            trial = log_ratio.copy()
            trial[j] = mid
            traj, t = run(trial)
            still_late, still_early = t[j] > bound + TIME_TOL_S, t[j] < bound - TIME_TOL_S
            if miss > 0:
                if still_late:
                    lo = mid
                else:
                    found, hi = (trial, traj, t), mid
            else:
                if still_early:
                    hi = mid
                else:
                    found, lo = (trial, traj, t), mid
            if found is not None and abs(found[2][j] - bound) <= TIME_TOL_S:
                break
        if found is None:
            raise TimingError(f"timing point at {passing[j].position_m} m", bound,
                              "no price of time before it meets the window at this section's running time")
        log_ratio, best, times = found
    if _violation(times, passing) is not None:
        j, _ = _violation(times, passing)
        raise TimingError(f"timing point at {passing[j].position_m} m", times[j], "missed after the price search")
    return best


def solve_timed_journey(timed: TimedJourney, *, n_bisect: int = 12, **settings) -> TimedRun:
    """The least-energy run of the journey that meets every timing point (exact solver per section).

    ``settings`` go to :class:`pymoo_rail.optimal.OptimalSolver` (``dx_m``, ``n_speeds`` ...;
    ``certify`` is off unless asked for: the window search solves many running times).
    Raises :class:`TimingError` naming the first point no run with one price per section can meet.
    """
    from pymoo_rail.optimal.solver import OptimalSolver

    check_windows_reachable(timed)
    settings.setdefault("certify", False)
    trajectories, departures = [], []
    arrival_prev = 0.0
    for k, group in enumerate(timed.windows):
        case = timed.journey.sections[k]
        dep_point, arr_point, passing = group[0], group[-1], group[1:-1]
        depart = max(window_start_s(dep_point), arrival_prev)
        if depart > window_end_s(dep_point) + 1e-9:
            raise TimingError(f"section {k} departure", depart, f"the train arrives at {arrival_prev:.1f} s, "
                                                                f"after the departure window ends ({dep_point.latest_s} s)")
        solver = OptimalSolver(case, **settings)
        t_min = solver.min_running_time_s()
        t_hi = window_end_s(arr_point) - depart
        if k + 1 < len(timed.windows):  # arriving after the next departure window closes is useless
            t_hi = min(t_hi, window_end_s(timed.windows[k + 1][0]) - depart)
        t_lo = max(window_start_s(arr_point) - depart, t_min)
        if not math.isfinite(t_hi):
            t_hi = 1.5 * t_min
        if t_hi < t_lo:
            raise TimingError(f"section {k} arrival", arr_point, f"needs a running time <= {t_hi:.1f} s; the "
                                                                 f"minimum is {t_min:.1f} s")
        try:
            best = _meet_passing_windows(solver, case, passing, timed.journey.stops_m[k], depart, t_hi, n_bisect)
        except InfeasibleCaseError as err:
            floors = [p for p in passing if p.min_speed_kmh]
            if not floors:
                raise
            raise TimingError(f"timing point at {floors[0].position_m:g} m", floors[0].min_speed_kmh,
                              f"no run of section {k} holds the minimum speeds "
                              f"({', '.join(f'{p.min_speed_kmh:g} km/h at {p.position_m:g} m' for p in floors)}) "
                              f"and reaches the platform: {err}") from None
        trajectories.append(best)
        departures.append(depart)
        arrival_prev = depart + best.running_time_s
    checks = check_run(timed, trajectories, departures)
    for c in checks:
        if not c["time_ok"] or not c["speed_ok"]:
            raise TimingError(f"timing point at {c['position_m']} m", c,
                              "no run with one price of time per section meets it")
    return TimedRun(trajectories=tuple(trajectories), departures_s=tuple(departures), checks=checks)
