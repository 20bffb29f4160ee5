"""Indicators pymoo lacks: Schott's spacing (divides by n - 1), Deb's spread, and the energy gap
of a rail front to the exact minimum-energy front (``pymoo_rail.optimal``).
"""

from pymoo_rail.indicators.energy import energy_gap
from pymoo_rail.indicators.spacing import Spacing
from pymoo_rail.indicators.spread import Spread

__all__ = ["Spacing", "Spread", "energy_gap"]
