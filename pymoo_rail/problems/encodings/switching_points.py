"""Switching points: the positions (m) where a fixed regime sequence switches (Meng et al. (2017), Tang et al. (2020))."""

from __future__ import annotations

from dataclasses import dataclass, replace

import numpy as np

from pymoo_rail.problems.encodings.base import EncodingSetup, ProgramEncoding, bound_field
from pymoo_rail.sim import switching_programs


@dataclass(frozen=True, eq=False)
class SwitchingPoints(ProgramEncoding):
    """Switching positions (m) of a regime sequence; sorted along each vector before use.

    Parameters
    ----------
    regimes : tuple of str, optional
        The regime sequence, from ``traction``, ``hold`` (alias ``cruise``), ``coast``, ``brake``
        and ``hold_brake``; by default a traction-hold-coast cycle per speed-limit zone, then brake.

    Attributes
    ----------
    length_m : float
        Set by :meth:`bind`: the line length (m), the last program row's end.
    xl, xu : numpy.ndarray
        Set by :meth:`bind`: 0 and the line length for every switching point.
    """

    regimes: tuple[str, ...] | None = None
    length_m: float | None = bound_field()
    xl: np.ndarray | None = bound_field()
    xu: np.ndarray | None = bound_field()

    name = "switching_points"

    @classmethod
    def build(cls, case, regimes: tuple[str, ...] | None = None) -> SwitchingPoints:
        """``SwitchingPoints(regimes)`` bound to ``case`` (see :meth:`bind`)."""
        return cls(regimes).bind(EncodingSetup(case))

    def bind(self, setup: EncodingSetup) -> SwitchingPoints:
        """The switching points of the case's line (default regimes: a traction-hold-coast cycle per limit zone, then brake)."""
        case, regimes = setup.case, self.regimes
        if regimes is None:
            zones = 1
            limits = [row[2] for row in case.line.speed_limits]
            for prev, cur in zip(limits[:-1], limits[1:]):
                zones += cur != prev
            # one traction-hold-coast cycle per limit zone is enough to follow every limit
            regimes = ("traction", "hold", "coast") * max(1, zones - 2) + ("brake",)
        regimes = tuple(regimes)
        n = len(regimes) - 1
        if n < 1:
            raise ValueError(f"regimes = {regimes!r}: at least two regimes are needed")
        length = float(case.line.length_m)
        return replace(self, regimes=regimes, length_m=length, xl=np.zeros(n), xu=np.full(n, length))

    @property
    def units(self) -> list[str]:
        """Unit of each decision variable (m)."""
        return ["m"] * self.n_var

    def programs(self, X: np.ndarray) -> np.ndarray:
        """Simulator programs of the switching points ``X`` (m, one row per decision vector)."""
        self.bound()
        return switching_programs(X, self.regimes, self.length_m)
