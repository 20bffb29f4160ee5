from pymoo_rail.algorithms.abc import ABC
from pymoo_rail.algorithms.moabc import MOABC

__all__ = ["ABC", "MOABC"]
