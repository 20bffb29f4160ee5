"""pymoo algorithms: artificial bee colonies and the golden-ratio NSGA-II.

These depend on pymoo only, never on rail code, so they work on any pymoo problem.
"""

from pymoo_rail.algorithms.abc import ABC
from pymoo_rail.algorithms.golden_ratio_nsga2 import GoldenRatioNSGA2
from pymoo_rail.algorithms.moabc import MOABC

__all__ = ["ABC", "MOABC", "GoldenRatioNSGA2"]
