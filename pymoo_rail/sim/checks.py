"""Checks of a finished run against the case itself, independent of the simulator's grid.

A study verifies every member of a final front with :func:`check_run`: no traction in a neutral
section, never above a limit over the whole train (computed from ``line.speed_limits`` alone, not
from the grid the run was simulated on), stopped at the platform.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from pymoo_rail.constants import KMH_PER_MS
from pymoo_rail.model import END_SPEED_TOL_MS, Case, Line, Train
from pymoo_rail.sim.trajectory import Trajectory


@dataclass(frozen=True)
class RunCheck:
    """What :func:`check_run` measured on one run.

    Attributes
    ----------
    neutral_traction_j : float
        Traction work inside neutral sections (the kernel's summary figure, J).
    neutral_max_force_n : float
        Largest force over the cells that touch a neutral section (N; traction > 0).
    limit_excess_ms : float
        Speed above the limit, largest over the run (the kernel's summary figure, m/s).
    independent_excess_ms : float
        Speed above the lowest line limit under the train, largest over the nodes (m/s).
    stop_error_m : float
        Distance between the stopping point and the platform mark (m).
    running_time_s, energy_kwh : float
        Running time (s) and net energy (kWh) of the run.
    end_speed_excess_ms : float
        How far the arrival speed lies outside the end speed the case asks for, beyond
        ``END_SPEED_TOL_MS`` (:func:`end_speed_violation_ms`; <= 0 when met).
    """

    neutral_traction_j: float
    neutral_max_force_n: float
    limit_excess_ms: float
    independent_excess_ms: float
    stop_error_m: float
    running_time_s: float
    energy_kwh: float
    end_speed_excess_ms: float = 0.0

    def passes(self, stop_tolerance_m: float = 0.25, speed_tolerance_ms: float = 1e-6) -> bool:
        """True when the run pulls nowhere in a neutral section, stays under every limit
        (within ``speed_tolerance_ms``), stops within ``stop_tolerance_m`` of the mark and arrives at
        the end speed asked for (within ``END_SPEED_TOL_MS``)."""
        return (self.neutral_traction_j == 0.0 and self.neutral_max_force_n <= 0.0
                and self.limit_excess_ms <= speed_tolerance_ms and self.independent_excess_ms <= speed_tolerance_ms
                and self.stop_error_m <= stop_tolerance_m and self.end_speed_excess_ms <= 0.0)


def end_speed_violation_ms(final_speed_ms, case: Case) -> np.ndarray:
    """How far arrival speeds lie outside the case's end speed, beyond ``END_SPEED_TOL_MS`` (m/s).

    The case asks for its final speed exactly (``run.final_speed_kmh``), or for any speed in its
    window (``run.final_speed_window_kmh``); a run meets it within ``END_SPEED_TOL_MS``. The one
    rule every encoding's runs are held to (``SpeedProfileProblem``'s end-speed constraint), and the
    one :func:`check_run` applies. Returns ``max(lo - v, v - hi) - END_SPEED_TOL_MS``: <= 0 when met.
    """
    lo, hi = case.end_speed_window_ms()
    v = np.asarray(final_speed_ms, dtype=float)
    return np.maximum(lo - v, v - hi) - END_SPEED_TOL_MS


def limit_under_train_ms(position_m: np.ndarray, line: Line, train: Train) -> np.ndarray:
    """Lowest line limit (m/s) over the train, head at each position, tail ``train.length_m`` behind.

    Computed from ``line.speed_limits`` and the train's maximum speed alone (not the simulator's
    grid): a limit applies from the moment the head reaches its start until the tail has passed
    its end.

    Parameters
    ----------
    position_m : array
        Head positions (m).
    line : Line
        The line and its speed limits.
    train : Train
        The train (its length and maximum speed).

    Returns
    -------
    numpy.ndarray
        The limit at each position (m/s).
    """
    limit = np.full(np.shape(position_m), train.max_speed_kmh)
    for start, end, value in line.speed_limits:
        under = (position_m >= start) & (position_m - train.length_m < end)
        limit[under] = np.minimum(limit[under], value)
    return limit / KMH_PER_MS


def check_run(trajectory: Trajectory, case: Case) -> RunCheck:
    """Measure a run against the case's neutral sections, limits and platform.

    Parameters
    ----------
    trajectory : Trajectory
        The run (e.g. ``problem.trajectory(x)``).
    case : Case
        The case it ran on.

    Returns
    -------
    RunCheck
        The measured figures; :meth:`RunCheck.passes` says whether they are within tolerance.
    """
    x_m = trajectory.position_m
    cells, cell_end = x_m[:-1], x_m[1:]
    force = trajectory.force_n[:-1]
    touch = np.zeros(cells.shape, dtype=bool)
    for start, end in case.line.neutral_sections:
        touch |= (cells < end) & (cell_end > start)
    excess = trajectory.speed_ms - limit_under_train_ms(x_m, case.line, case.train)
    return RunCheck(
        neutral_traction_j=float(trajectory.summary["neutral_traction_j"]),
        neutral_max_force_n=float(force[touch].max()) if touch.any() else 0.0,
        limit_excess_ms=float(trajectory.summary["limit_excess_ms"]),
        independent_excess_ms=float(excess.max()),
        stop_error_m=float(trajectory.stop_error_m),
        running_time_s=float(trajectory.running_time_s), energy_kwh=float(trajectory.energy.net_kwh),
        end_speed_excess_ms=float(end_speed_violation_ms(trajectory.speed_ms[-1], case)) if trajectory.reached else 0.0)


__all__ = ["RunCheck", "check_run", "limit_under_train_ms", "end_speed_violation_ms"]
