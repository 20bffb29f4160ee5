"""Decision-vector encodings of a driving strategy, and their bounds.

An encoding turns a population of decision vectors into kernel programs. Two families:

- ``SpeedCodes``: one target speed (km/h) per section of a partition of the line (Liu (2019)
  4.3.3): ``"gradient_limit"`` cuts at every gradient, limit and neutral-section change (the
  non-equal partition of fig. 4-4), optionally splitting sections longer than ``max_section_m``;
  ``"equal"`` cuts ``n_sections`` equal pieces (fig. 4-3). Bounds run from a floor to the highest
  limit in the section; sections inside a neutral section are fixed at the floor (coasting).
  On long sparse lines (sections averaging more than 2 km, ``max_section_m`` not given) each
  section also gets a coasting point (m): the train heads for its code up to that point and coasts
  from there to the section's end, so one section holds the optimal structure of a long stretch
  (reach a speed, hold it, coast into the next limit or the stop) with two variables. There the
  codes start at the planned mean speed (:func:`sparse_code_floor_kmh`), not at ``floor_kmh``.
- ``SwitchingPoints``: positions (m) where a fixed regime sequence switches (Meng et al. (2017) and Tang et al. (2020)),
  by default ``traction, hold, coast`` per speed-limit zone and a final ``brake``.
- ``BrakingOnset``: the phases of Meng et al. (2017) (traction, cruise, coast) with the braking
  onset position and the braking deceleration as decisions. The train brakes at that
  deceleration and stops where the physics puts it, short of the platform or past it in an
  overrun zone, so the stop error is a consequence of the decision (with the other encodings the
  kernel lands every run exactly on the platform and the stop error is always 0).

Speed codes can be integers (``integer=True``: whole km/h, as the on-board codes of Liu (2019)),
for pymoo's integer operators.
"""

from __future__ import annotations

from dataclasses import dataclass, replace

import numpy as np

from pymoo_rail.constants import KMH_PER_MS
from pymoo_rail.model import Case, Line
from pymoo_rail.sim import (
    Simulator,
    Trajectory,
    braking_programs,
    equal_partition,
    gradient_limit_partition,
    speed_code_programs,
    switching_programs,
)
from pymoo_rail.sim import kernel as k
from pymoo_rail.sim.pacing import split_long_sections

PARTITIONS = ("gradient_limit", "equal")
# Long sparse lines: a gradient/limit partition whose sections average more than this keeps its
# sections and gives each a coasting point, unless max_section_m is given (the 48.5 km TTOBench
# reference: a code and a coasting point, where it had one variable: one cruise speed, no
# coasting). Cutting such sections into 1 km pieces instead (49 codes on the reference) left NSGA2
# up to 5 % above the optimum on the reference family: holding a speed over many pieces needs many
# equal codes (benchmarks/sparse_encoding.py prints both).
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
class SpeedCodes:
    """Speed codes per section; decision variables in km/h.

    With ``coast_points`` the vector is the codes (km/h), then one coasting point (m) per section,
    bounded by the section: the train heads for the code up to it and coasts after it.
    """

    boundaries_m: np.ndarray
    xl: np.ndarray
    xu: np.ndarray
    integer: bool = False
    coast_points: bool = False

    name = "speed_codes"
    # every run lands on the platform through the braking envelope
    constant_objectives = ("stop_error",)

    @property
    def vtype(self) -> type:
        """pymoo's variable type: ``int`` for whole-km/h codes."""
        return int if self.integer else float

    @classmethod
    def build(cls, case: Case, partition: str = "gradient_limit", n_sections: int | None = None,
              max_section_m: float | None = None, floor_kmh: float = 10.0, integer: bool = False) -> SpeedCodes:
        """Partition the line and bound each code by the limits of its section.

        With ``integer=True`` the codes are whole km/h: the floor rounds up and each section's
        upper bound rounds down (never above its limit).
        """
        line = case.line
        if partition == "gradient_limit":
            bounds = gradient_limit_partition(line)
            neutral_points = [p for row in line.neutral_sections for p in row]
            bounds = np.unique(np.concatenate([bounds, neutral_points]))
            coast = max_section_m is None and (bounds[-1] - bounds[0]) / (bounds.shape[0] - 1) > SPARSE_MEAN_SECTION_M
            bounds = split_long_sections(bounds, max_section_m)
        elif partition == "equal":
            coast = False
            bounds = equal_partition(line, n_sections if n_sections is not None else 10)
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
        return cls(boundaries_m=bounds, xl=xl, xu=xu, integer=bool(integer), coast_points=bool(coast))

    @property
    def n_var(self) -> int:
        """Number of decision variables (one speed code per section)."""
        return self.xl.shape[0]

    @property
    def n_sections(self) -> int:
        """Number of sections of the partition (one speed code each)."""
        return self.boundaries_m.shape[0] - 1

    @property
    def units(self) -> list[str]:
        """Unit of each decision variable."""
        return ["km/h"] * self.n_sections + ["m"] * (self.n_var - self.n_sections)

    def programs(self, X: np.ndarray) -> np.ndarray:
        """Simulator programs of the speed codes ``X`` (km/h, one row per decision vector)."""
        X = np.atleast_2d(np.asarray(X, dtype=float))
        if self.coast_points:
            return self._coasting_programs(X)
        negative = np.argwhere(X < 0)
        if negative.size:  # reported in km/h, the unit it was given in
            idx = tuple(int(i) for i in negative[0])
            raise ValueError(f"speed_codes{list(idx)} = {float(X[idx])} km/h: speed codes must be >= 0 km/h")
        if self.integer and np.isfinite(X).all() and np.any(X != np.round(X)):
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


@dataclass(frozen=True, eq=False)
class SwitchingPoints:
    """Switching positions (m) of a regime sequence; sorted along each vector before use."""

    regimes: tuple[str, ...]
    length_m: float
    xl: np.ndarray
    xu: np.ndarray

    name = "switching_points"
    constant_objectives = ()
    vtype = float

    @classmethod
    def build(cls, case: Case, regimes: tuple[str, ...] | None = None) -> SwitchingPoints:
        """The switching-point encoding of ``case`` (default: a traction-hold-coast cycle per limit zone, then brake)."""
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
        """Number of decision variables (one switching point per regime change)."""
        return self.xl.shape[0]

    def programs(self, X: np.ndarray) -> np.ndarray:
        """Simulator programs of the switching points ``X`` (m, one row per decision vector)."""
        return switching_programs(X, self.regimes, self.length_m)

    def fixed(self) -> np.ndarray:
        """Mask of the genes an algorithm must not change (none)."""
        return np.zeros(self.n_var, dtype=bool)


def overrun_case(case: Case, overrun_m: float) -> Case:
    """The case with its line continued ``overrun_m`` past the platform (last gradient and limit).

    The simulated track of :class:`BrakingOnset`: a train that brakes too gently stops in it.
    """
    if not (np.isfinite(overrun_m) and overrun_m > 0):
        raise ValueError(f"overrun_m = {overrun_m!r} must be a positive number")
    line = case.line
    end = float(line.length_m) + float(overrun_m)

    def stretch(rows):
        rows = [list(r) for r in rows]
        rows[-1][1] = end
        return tuple(tuple(r) for r in rows)

    longer = Line(length_m=end, gradients=stretch(line.gradients), speed_limits=stretch(line.speed_limits),
                  curves=line.curves, tunnels=line.tunnels, neutral_sections=line.neutral_sections,
                  gradient_model=line.gradient_model)
    return replace(case, line=longer, legs=())


@dataclass(frozen=True, eq=False)
class BrakingOnset:
    """Phases before braking, the braking onset (m) and the braking deceleration (m/s^2).

    Decision vector: ``len(regimes) - 1`` switching positions between the regimes run before
    braking, then the braking onset (all sorted together, so the onset is the largest), then the
    service deceleration. The train is simulated on the line continued ``overrun_m`` past the
    platform (:func:`overrun_case`): from the onset it brakes at that deceleration and stops where
    it stops; the stop error is its distance to the platform, either way. The braking envelope of
    every speed limit still holds over the whole train (a limit ahead brakes the train harder than
    asked); a train that would run beyond the overrun zone is stopped at its end by the envelope
    (stop error ``overrun_m``).
    """

    regimes: tuple[str, ...]
    platform_m: float
    overrun_m: float
    simulator: Simulator
    xl: np.ndarray
    xu: np.ndarray

    name = "braking_onset"
    constant_objectives = ()
    vtype = float

    @classmethod
    def build(cls, case: Case, regimes: tuple[str, ...] | None = None,
              decel_range_ms2: tuple[float, float] | None = None, overrun_m: float = 20.0,
              dx_m: float | None = None) -> BrakingOnset:
        """Bounds: positions in [0, platform]; deceleration in ``decel_range_ms2``.

        The default deceleration range is [0.5, d_max] m/s^2 with d_max the train's service
        deceleration cap (``max_decel_ms2``, 1.0 when the case gives none).
        """
        regimes = ("traction", "hold", "coast") if regimes is None else tuple(regimes)
        if not regimes:
            raise ValueError("regimes = (): at least one regime must run before braking")
        if decel_range_ms2 is None:
            d_max = case.train.max_decel_ms2 if case.train.max_decel_ms2 is not None else 1.0
            decel_range_ms2 = (min(0.5, d_max), d_max)
        lo, hi = (float(v) for v in decel_range_ms2)
        if not (np.isfinite(lo) and np.isfinite(hi) and 0 < lo <= hi):
            raise ValueError(f"decel_range_ms2 = {decel_range_ms2!r}: need 0 < low <= high")
        platform = float(case.line.length_m)
        simulator = Simulator(overrun_case(case, overrun_m), dx_m)
        n_pos = len(regimes)
        xl = np.concatenate([np.zeros(n_pos), [lo]])
        xu = np.concatenate([np.full(n_pos, platform), [hi]])
        return cls(regimes=regimes, platform_m=platform, overrun_m=float(overrun_m), simulator=simulator,
                   xl=xl, xu=xu)

    @property
    def n_var(self) -> int:
        """Number of decision variables (switching points, braking onset, deceleration)."""
        return self.xl.shape[0]

    def programs(self, X: np.ndarray) -> np.ndarray:
        """Simulator programs of ``X`` (switching points and braking onset in m, deceleration last)."""
        X = np.atleast_2d(np.asarray(X, dtype=float))
        return braking_programs(X[:, :-1], self.regimes, X[:, -1], self.simulator.length_m)

    def fixed(self) -> np.ndarray:
        """Mask of the genes an algorithm must not change (none)."""
        return np.zeros(self.n_var, dtype=bool)

    def run_batch(self, programs: np.ndarray) -> np.ndarray:
        """Summaries with the stop error measured from the platform (short or past it)."""
        s = self.simulator.run_batch(programs)
        s[:, k.OUT_STOP_ERROR_M] = np.abs(s[:, k.OUT_STOP_POSITION_M] - self.platform_m)
        return s

    def run(self, program: np.ndarray) -> Trajectory:
        """The trajectory of one program, stop error measured from the platform."""
        tr = self.simulator.run(program)
        stop = tr.summary["stop_position_m"]
        error = abs(stop - self.platform_m)
        return replace(tr, stop_error_m=error, summary={**tr.summary, "stop_error_m": error})


ENCODINGS = ("speed_codes", "switching_points", "braking_onset", "paced_speed_codes")
"""Encoding names of ``SpeedProfileProblem`` (``paced_speed_codes``: :mod:`pymoo_rail.problems.paced_codes`)."""
