"""Speed codes: one target speed (km/h) per section of a partition of the line (Liu (2019) 4.3.3).

``"gradient_limit"`` cuts at every gradient, limit and neutral-section change (the non-equal
partition of fig. 4-4), optionally splitting sections longer than ``max_section_m``; ``"equal"``
cuts ``n_sections`` equal pieces (fig. 4-3). Bounds run from a floor to the highest limit in the
section; sections inside a neutral section are fixed at the floor (coasting). On long sparse lines
(sections averaging more than 2 km, ``max_section_m`` not given) each section also gets a coasting
point (m): the train heads for its code up to that point and coasts from there to the section's
end, so one section holds the optimal structure of a long stretch (reach a speed, hold it, coast
into the next limit or the stop) with two variables. There the codes start at the planned mean
speed (:func:`sparse_code_floor_kmh`), not at ``floor_kmh``.

Speed codes can be integers (``integer_codes=True``: whole km/h, as the on-board codes of Liu (2019)),
for pymoo's integer operators.
"""

from __future__ import annotations

from dataclasses import dataclass, replace

import numpy as np

from pymoo_rail.constants import KMH_PER_MS
from pymoo_rail.model import Case
from pymoo_rail.problems.encodings.base import EncodingSetup, ProgramEncoding, bound_field
from pymoo_rail.sim import equal_partition, gradient_limit_partition, speed_code_programs
from pymoo_rail.sim import kernel as k
from pymoo_rail.sim.pacing import split_long_sections

PARTITIONS = ("gradient_limit", "equal")
# Long sparse lines: a gradient/limit partition whose sections average more than this keeps its
# sections and gives each a coasting point, unless max_section_m is given (the 48.5 km TTOBench
# reference: a code and a coasting point, where it had one variable: one cruise speed, no
# coasting). Cutting such sections into 1 km pieces instead (49 codes on the reference) left NSGA2
# up to 5 % above the optimum on the reference family: holding a speed over many pieces needs many
# equal codes (benchmarks/encodings.py --job sparse prints both).
SPARSE_MEAN_SECTION_M = 2000.0


def sparse_code_floor_kmh(case: Case, section_max_kmh: np.ndarray) -> np.ndarray:
    """Lowest speed code of each section of a long sparse line: the planned mean speed
    ``L / T_plan`` (km/h), or the section's highest code where that is lower.

    The energy-optimal run of a stretch reaches a speed, holds it and coasts: on level track it
    is nowhere faster than its hold speed (outside limits lower than that), so the hold speed is
    at least the run's mean speed. A code below it can only hold a run that is slower than
    planned, and on a long section a code below the entry speed coasts for kilometres without
    reaching it: a plateau where neither the code nor the coasting point changes the run. The
    coasting point expresses coasting, so the codes start at the mean speed, and random initial
    runs reach the planned time by coasting earlier (the high-cruise family of the optimum)
    rather than by holding slower.
    """
    mean_kmh = float(case.line.length_m) / float(case.planned_time_s) * KMH_PER_MS
    return np.minimum(section_max_kmh, mean_kmh)


@dataclass(frozen=True, eq=False)
class SpeedCodes(ProgramEncoding):
    """Speed codes per section; decision variables in km/h.

    With coasting points (long sparse lines) the vector is the codes (km/h), then one coasting
    point (m) per section, bounded by the section: the train heads for the code up to it and
    coasts after it.

    Parameters
    ----------
    partition : {"gradient_limit", "equal"}
        Sections: cut at every gradient, limit and neutral-section change (Liu (2019) fig. 4-4), or
        ``n_sections`` equal pieces (fig. 4-3).
    n_sections : int, optional
        Number of equal sections (``partition="equal"``, default 10). Once bound: the number of
        sections of the partition (one speed code each).
    max_section_m : float, optional
        Split ``gradient_limit`` sections longer than this (and give no coasting points).
    floor_kmh : float
        Lowest speed code (default 10 km/h): a code below the current speed means coasting.
    integer_codes : bool
        Whole-km/h codes (``vtype=int``), for pymoo's integer operators.

    Attributes
    ----------
    boundaries_m, xl, xu : numpy.ndarray
        Set by :meth:`bind`: section boundaries (m) and the bounds of the decision variables.
    coast_points : bool
        Set by :meth:`bind`: each section also has a coasting point.
    """

    partition: str = "gradient_limit"
    n_sections: int | None = None
    max_section_m: float | None = None
    floor_kmh: float = 10.0
    integer_codes: bool = False
    boundaries_m: np.ndarray | None = bound_field()
    xl: np.ndarray | None = bound_field()
    xu: np.ndarray | None = bound_field()
    coast_points: bool = bound_field(False)

    name = "speed_codes"
    # every run lands on the platform through the braking envelope
    constant_objectives = ("stop_error",)

    @property
    def vtype(self) -> type:
        """pymoo's variable type: ``int`` for whole-km/h codes."""
        return int if self.integer_codes else float

    @classmethod
    def build(cls, case: Case, partition: str = "gradient_limit", n_sections: int | None = None,
              max_section_m: float | None = None, floor_kmh: float = 10.0, integer: bool = False) -> SpeedCodes:
        """``SpeedCodes(...)`` bound to ``case`` (see :meth:`bind`)."""
        return cls(partition, n_sections, max_section_m, floor_kmh, integer).bind(EncodingSetup(case, None))

    def bind(self, setup: EncodingSetup) -> SpeedCodes:
        """Partition the line and bound each code by the limits of its section.

        With ``integer_codes=True`` the codes are whole km/h: the floor rounds up and each section's
        upper bound rounds down (never above its limit).
        """
        case, partition, floor_kmh, integer = setup.case, self.partition, self.floor_kmh, self.integer_codes
        max_section_m = self.max_section_m
        line = case.line
        if partition == "gradient_limit":
            bounds = gradient_limit_partition(line)
            neutral_points = [p for row in line.neutral_sections for p in row]
            bounds = np.unique(np.concatenate([bounds, neutral_points]))
            coast = max_section_m is None and (bounds[-1] - bounds[0]) / (bounds.shape[0] - 1) > SPARSE_MEAN_SECTION_M
            bounds = split_long_sections(bounds, max_section_m)
        elif partition == "equal":
            coast = False
            bounds = equal_partition(line, self.n_sections if self.n_sections is not None else 10)
        else:
            raise ValueError(f"partition = {partition!r} is unknown (known: {', '.join(PARTITIONS)})")
        if not (np.isfinite(floor_kmh) and floor_kmh >= 0):
            raise ValueError(f"floor_kmh = {floor_kmh!r} must be a number >= 0")
        xu = np.empty(bounds.shape[0] - 1)
        for j, (a, b) in enumerate(zip(bounds[:-1], bounds[1:])):
            xu[j] = max(v for s, e, v in line.speed_limits if s < b and e > a)
        xu = np.minimum(xu, case.train.max_speed_kmh)
        xl = np.minimum(np.full_like(xu, floor_kmh), xu)
        if coast:
            sparse_floor = sparse_code_floor_kmh(case, xu)
            xl = np.maximum(xl, np.floor(sparse_floor + 1e-9) if integer else sparse_floor)
        neutral = np.zeros(xu.shape[0], dtype=bool)
        for j, (a, b) in enumerate(zip(bounds[:-1], bounds[1:])):
            if any(s <= a and b <= e for s, e in line.neutral_sections):
                xu[j] = xl[j]  # no traction there: the gene cannot matter, so it is fixed
                neutral[j] = True
        if integer:
            xl, xu = np.ceil(xl - 1e-9), np.floor(xu + 1e-9)
            if np.any(xl > xu):
                j = int(np.argmax(xl > xu))
                raise ValueError(f"floor_kmh = {floor_kmh!r}: section {j} has no whole km/h code "
                                 f"between {xl[j]} and {xu[j]}")
        if coast:  # coasting point of each section, inside it (fixed at its end in neutral sections)
            xl = np.concatenate([xl, np.where(neutral, bounds[1:], bounds[:-1])])
            xu = np.concatenate([xu, bounds[1:]])
            if integer:
                xl, xu = np.ceil(xl - 1e-9), np.floor(xu + 1e-9)
        return replace(self, n_sections=bounds.shape[0] - 1, integer_codes=bool(integer), boundaries_m=bounds, xl=xl, xu=xu,
                       coast_points=bool(coast))

    @property
    def units(self) -> list[str]:
        """Unit of each decision variable."""
        return ["km/h"] * self.n_sections + ["m"] * (self.n_var - self.n_sections)

    def programs(self, X: np.ndarray) -> np.ndarray:
        """Simulator programs of the speed codes ``X`` (km/h, one row per decision vector)."""
        self.bound()
        X = np.atleast_2d(np.asarray(X, dtype=float))
        if self.coast_points:
            return self._coasting_programs(X)
        negative = np.argwhere(X < 0)
        if negative.size:  # reported in km/h, the unit it was given in
            idx = tuple(int(i) for i in negative[0])
            raise ValueError(f"speed_codes{list(idx)} = {float(X[idx])} km/h: speed codes must be >= 0 km/h")
        if self.integer_codes and np.isfinite(X).all() and np.any(X != np.round(X)):
            idx = tuple(int(i) for i in np.argwhere(X != np.round(X))[0])
            raise ValueError(f"speed_codes{list(idx)} = {float(X[idx])}: integer codes must be whole km/h "
                             "(use pymoo's integer operators or RoundingRepair)")
        return speed_code_programs(self.boundaries_m, X / KMH_PER_MS)

    def _coasting_programs(self, X: np.ndarray) -> np.ndarray:
        """Two rows per section: head for the code up to the coasting point, then coast."""
        n = self.n_sections
        if X.shape[1] != self.n_var:
            raise ValueError(f"speed codes with coasting points need {self.n_var} values per run, got {X.shape[1]}")
        codes = speed_code_programs(self.boundaries_m, X[:, :n] / KMH_PER_MS)
        coast_m = np.clip(X[:, n:], self.boundaries_m[:-1], self.boundaries_m[1:])
        programs = np.empty((X.shape[0], 2 * n, 3))
        programs[:, 0::2, 0] = coast_m
        programs[:, 0::2, 1:] = codes[:, :, 1:]
        programs[:, 1::2, 0] = self.boundaries_m[1:]
        programs[:, 1::2, 1] = k.MODE_COAST
        programs[:, 1::2, 2] = 0.0
        return programs

    def fixed(self) -> np.ndarray:
        """Mask of genes that cannot change (inside neutral sections)."""
        return self.xl == self.xu
