"""Unit factors and objective names that every room shares, defined once.

This module imports nothing, so the command line reads the objective names without loading Numba,
and a Numba kernel may use the factors as compile-time constants.
"""

from __future__ import annotations

KMH_PER_MS = 3.6
"""Speed: km/h in one m/s (``speed_kmh = speed_ms * KMH_PER_MS``)."""

J_PER_KWH = 3.6e6
"""Energy: joules in one kWh (``energy_kwh = energy_j / J_PER_KWH``)."""

OBJECTIVES = ("energy", "running_time", "time_error", "accel_variation", "jerk", "stop_error")
"""Objective names of :class:`pymoo_rail.problems.SpeedProfileProblem` (``"jerk"`` is an alias of
``"accel_variation"``)."""

TIME_OBJECTIVES = ("running_time", "time_error")
"""The objectives that measure the running time (absolute, or off the plan)."""

OBJECTIVE_COLUMNS = {"energy": "energy_kwh", "running_time": "running_time_s", "time_error": "time_error_s",
                     "accel_variation": "accel_variation_ms2", "stop_error": "stop_error_m"}
"""Column name, with its unit, under which a table of runs stores each objective."""
