"""Decision-vector encodings of a driving strategy, and their bounds.

An encoding turns a population of decision vectors into kernel programs. Two families:

- ``SpeedCodes``: one target speed (km/h) per section of a partition of the line (seed 000
  4.3.3): ``"gradient_limit"`` cuts at every gradient, limit and neutral-section change (the
  non-equal partition of fig. 4-4), optionally splitting sections longer than ``max_section_m``;
  ``"equal"`` cuts ``n_sections`` equal pieces (fig. 4-3). Bounds run from a floor to the highest
  limit in the section; sections inside a neutral section are fixed at the floor (coasting).
- ``SwitchingPoints``: positions (m) where a fixed regime sequence switches (seeds 002/003),
  by default ``traction, hold, coast`` per speed-limit zone and a final ``brake``.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from pymoo_rail.model import Case
from pymoo_rail.sim import equal_partition, gradient_limit_partition, speed_code_programs, switching_programs
from pymoo_rail.sim.pacing import split_long_sections

KMH_PER_MS = 3.6
PARTITIONS = ("gradient_limit", "equal")


@dataclass(frozen=True, eq=False)
class SpeedCodes:
    """Speed codes per section; decision variables in km/h."""

    boundaries_m: np.ndarray
    xl: np.ndarray
    xu: np.ndarray

    name = "speed_codes"

    @classmethod
    def build(cls, case: Case, partition: str = "gradient_limit", n_sections: int | None = None,
              max_section_m: float | None = None, floor_kmh: float = 10.0) -> SpeedCodes:
        line = case.line
        if partition == "gradient_limit":
            bounds = gradient_limit_partition(line)
            neutral_points = [p for row in line.neutral_sections for p in row]
            bounds = np.unique(np.concatenate([bounds, neutral_points]))
            bounds = split_long_sections(bounds, max_section_m)
        elif partition == "equal":
            bounds = equal_partition(line, n_sections if n_sections is not None else 10)
        else:
            raise ValueError(f"partition = {partition!r} is unknown (known: {', '.join(PARTITIONS)})")
        if not (np.isfinite(floor_kmh) and floor_kmh >= 0):
            raise ValueError(f"floor_kmh = {floor_kmh!r} must be a number >= 0")
        xu = np.empty(bounds.shape[0] - 1)
        for k, (a, b) in enumerate(zip(bounds[:-1], bounds[1:])):
            xu[k] = max(v for s, e, v in line.speed_limits if s < b and e > a)
        xu = np.minimum(xu, case.train.max_speed_kmh)
        xl = np.minimum(np.full_like(xu, floor_kmh), xu)
        for k, (a, b) in enumerate(zip(bounds[:-1], bounds[1:])):
            if any(s <= a and b <= e for s, e in line.neutral_sections):
                xu[k] = xl[k]  # no traction there: the gene cannot matter, so it is fixed
        return cls(boundaries_m=bounds, xl=xl, xu=xu)

    @property
    def n_var(self) -> int:
        return self.xl.shape[0]

    def programs(self, X: np.ndarray) -> np.ndarray:
        X = np.asarray(X, dtype=float)
        negative = np.argwhere(X < 0)
        if negative.size:  # reported in km/h, the unit it was given in
            idx = tuple(int(i) for i in negative[0])
            raise ValueError(f"speed_codes{list(idx)} = {float(X[idx])} km/h: speed codes must be >= 0 km/h")
        return speed_code_programs(self.boundaries_m, X / KMH_PER_MS)

    def fixed(self) -> np.ndarray:
        """Mask of genes that cannot change (inside neutral sections)."""
        return self.xl == self.xu


@dataclass(frozen=True, eq=False)
class SwitchingPoints:
    """Switching positions (m) of a regime sequence; sorted along each vector before use."""

    regimes: tuple[str, ...]
    length_m: float
    xl: np.ndarray
    xu: np.ndarray

    name = "switching_points"

    @classmethod
    def build(cls, case: Case, regimes: tuple[str, ...] | None = None) -> SwitchingPoints:
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
        return cls(regimes=regimes, length_m=length, xl=np.zeros(n), xu=np.full(n, length))

    @property
    def n_var(self) -> int:
        return self.xl.shape[0]

    def programs(self, X: np.ndarray) -> np.ndarray:
        return switching_programs(X, self.regimes, self.length_m)

    def fixed(self) -> np.ndarray:
        return np.zeros(self.n_var, dtype=bool)


ENCODINGS = ("speed_codes", "switching_points")
