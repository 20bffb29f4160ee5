"""Unit factors that every room shares, defined once.

This module imports nothing, so a Numba kernel may use the factors as compile-time constants.
The objectives are a table of their own: :mod:`pymoo_rail.problems.objectives`.
"""

from __future__ import annotations

KMH_PER_MS = 3.6
"""Speed: km/h in one m/s (``speed_kmh = speed_ms * KMH_PER_MS``)."""

J_PER_KWH = 3.6e6
"""Energy: joules in one kWh (``energy_kwh = energy_j / J_PER_KWH``)."""
