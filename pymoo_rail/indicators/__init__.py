"""Indicators pymoo lacks: Schott's spacing (divides by n - 1) and Deb's spread.

``energy_gap`` (gap of a rail front to the exact reference) lives in ``energy.py``.
"""

from pymoo_rail.indicators.spacing import Spacing
from pymoo_rail.indicators.spread import Spread

__all__ = ["Spacing", "Spread"]
