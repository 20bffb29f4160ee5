"""A journey: one train calling at consecutive stops, a :class:`Case` with one leg per section."""

from __future__ import annotations

import math
from dataclasses import dataclass, replace
from functools import cached_property
from typing import Sequence

import numpy as np

from pymoo_rail.model import Case, CaseError, Leg, Line, Train
from pymoo_rail.sim import Simulator


def join_lines(lines: Sequence[Line]) -> Line:
    """Consecutive lines as one, each row moved by the length of the lines before it.

    Every line must have the same gradient and curve model (one train runs them all).
    """
    first = lines[0]
    offset, rows = 0.0, {name: [] for name in _LINE_ROWS}
    for k, line in enumerate(lines):
        for name in ("gradient_model", "curve_model"):
            if getattr(line, name) != getattr(first, name):
                raise CaseError(f"sections[{k}].line.{name}", getattr(line, name),
                                f"differs from the first section's {getattr(first, name)!r}")
        for name in _LINE_ROWS:
            rows[name].extend((a + offset, b + offset, *rest) for a, b, *rest in getattr(line, name))
        offset += line.length_m
    return replace(first, length_m=offset, **{name: tuple(r) for name, r in rows.items()})


_LINE_ROWS = ("gradients", "speed_limits", "curves", "tunnels", "neutral_sections")


@dataclass(frozen=True)
class Journey:
    """One train calling at consecutive stops: a view of a :class:`Case` whose legs are the sections.

    The run itself is the case (one line from the first stop to the last, one leg per stop-to-stop
    section with its planned time and the dwell at its end): a journey is a case with legs, and
    every function of :mod:`pymoo_rail.journeys` accepts either (:func:`as_journey`). The journey
    adds only what names the stops.

    Parameters
    ----------
    case : Case
        The whole run; a case without legs is a journey of one section.
    stop_names : tuple of str, optional
        One name per stop (``n_sections + 1``), or empty.
    origin_m : float
        Position of the first stop on the original track (``stops_m`` are track positions).
    altitude_m : float
        Altitude of the first stop (kept for TTOBench export; no effect on the physics).
    """

    case: Case
    stop_names: tuple[str, ...] = ()
    origin_m: float = 0.0
    altitude_m: float = 0.0

    def __post_init__(self) -> None:
        if not isinstance(self.case, Case):
            raise CaseError("case", type(self.case).__name__, "must be a Case")
        object.__setattr__(self, "stop_names", tuple(self.stop_names))
        if self.stop_names and len(self.stop_names) != self.n_sections + 1:
            raise CaseError("stop_names", self.stop_names, f"needs one name per stop ({self.n_sections + 1})")

    @classmethod
    def from_sections(cls, name: str, sections: Sequence[Case], dwell_s: Sequence[float] = (),
                      stops_m: Sequence[float] = (), stop_names: Sequence[str] = (), altitude_m: float = 0.0,
                      source: str = "") -> Journey:
        """The journey of consecutive stop-to-stop cases (one train), ``dwell_s`` at the stops between.

        ``stops_m`` are the stops' track positions (default: cumulative section lengths from 0).
        """
        sections = tuple(sections)
        if not sections:
            raise CaseError("sections", (), "a journey needs at least one section")
        for k, case in enumerate(sections):
            if not isinstance(case, Case):
                raise CaseError(f"sections[{k}]", type(case).__name__, "must be a Case")
            if case.legs:
                raise CaseError(f"sections[{k}].legs", len(case.legs), "a section is one stop-to-stop run")
            if case.train != sections[0].train:
                raise CaseError(f"sections[{k}].train", case.train.name, "every section must have the same train")
        n = len(sections)
        dwell = tuple(float(d) for d in dwell_s) if len(dwell_s) or n == 1 else (0.0,) * (n - 1)
        if len(dwell) != n - 1:
            raise CaseError("dwell_s", tuple(dwell_s), f"needs one dwell per intermediate stop ({n - 1})")
        for k, d in enumerate(dwell):
            if not (math.isfinite(d) and d >= 0):
                raise CaseError(f"dwell_s[{k}]", d, "must be a finite number >= 0")
        ends = np.concatenate([[0.0], np.cumsum([c.line.length_m for c in sections])])
        stops = tuple(float(x) for x in stops_m) if len(stops_m) else tuple(float(x) for x in ends)
        if len(stops) != n + 1:
            raise CaseError("stops_m", stops, f"needs one position per stop ({n + 1})")
        for k in range(n):
            gap = stops[k + 1] - stops[k]
            if abs(gap - sections[k].line.length_m) > 1e-6:
                raise CaseError(f"stops_m[{k + 1}]", stops[k + 1], f"is {gap} m after the previous stop, but "
                                                                   f"section {k} is {sections[k].line.length_m} m long")
        legs = tuple(Leg(start_m=float(ends[k]), end_m=float(ends[k + 1]), planned_time_s=c.planned_time_s,
                         dwell_s=dwell[k] if k < n - 1 else 0.0) for k, c in enumerate(sections))
        case = replace(sections[0], name=name, line=join_lines([c.line for c in sections]),
                       planned_time_s=float(sum(c.planned_time_s for c in sections)),
                       dwell_s=0.0, source=source or sections[0].source, legs=legs)
        return cls(case=case, stop_names=tuple(stop_names), origin_m=stops[0], altitude_m=altitude_m)

    @cached_property
    def sections(self) -> tuple[Case, ...]:
        """Each stop-to-stop leg as a case of its own (:meth:`Case.leg`)."""
        if not self.case.legs:
            return (self.case,)
        return tuple(self.case.leg(k) for k in range(len(self.case.legs)))

    @property
    def name(self) -> str:
        """The journey's name (its case's)."""
        return self.case.name

    @property
    def source(self) -> str:
        """Where the journey's data come from (its case's source)."""
        return self.case.source

    @property
    def dwell_s(self) -> tuple[float, ...]:
        """Dwell at each intermediate stop (``n_sections - 1`` values)."""
        return tuple(float(leg.dwell_s) for leg in self.case.legs[:-1])

    @property
    def stops_m(self) -> tuple[float, ...]:
        """Track positions of the stops."""
        ends = [0.0] + [leg.end_m for leg in self.case.legs] if self.case.legs else [0.0, self.case.line.length_m]
        return tuple(self.origin_m + float(x) for x in ends)

    # --------------------------------------------------------------------------------- properties

    @property
    def train(self) -> Train:
        """The train (the same in every section)."""
        return self.sections[0].train

    @property
    def n_sections(self) -> int:
        """Number of sections (stop to stop)."""
        return len(self.sections)

    @property
    def section_lengths_m(self) -> np.ndarray:
        """Length of each section (m)."""
        return np.array([c.line.length_m for c in self.sections])

    @property
    def length_m(self) -> float:
        """Length of the whole journey (m)."""
        return float(self.section_lengths_m.sum())

    @property
    def total_dwell_s(self) -> float:
        """Sum of the dwell times at the intermediate stops (s)."""
        return float(sum(self.dwell_s))

    @property
    def planned_running_times_s(self) -> np.ndarray:
        """Planned running time of each section (s)."""
        return np.array([c.planned_time_s for c in self.sections])

    def section_label(self, k: int) -> str:
        """``"A -> B"`` with stop names, else the stop positions."""
        if self.stop_names:
            return f"{self.stop_names[k]} -> {self.stop_names[k + 1]}"
        return f"{self.stops_m[k]:g} -> {self.stops_m[k + 1]:g} m"

    def trip_time_s(self, running_time_s: float) -> float:
        """Trip time from departure at the first stop to arrival at the last: running + dwells."""
        return float(running_time_s) + self.total_dwell_s

    def running_time_s(self, trip_time_s: float) -> float:
        """Running-time budget of a trip time (the inverse of :meth:`trip_time_s`)."""
        return float(trip_time_s) - self.total_dwell_s

    def min_running_times_s(self, dx_m: float | None = None) -> np.ndarray:
        """Flat-out running time of each section on the simulator grid."""
        return np.array([Simulator(c, dx_m).min_running_time_s() for c in self.sections])


def as_journey(run: Journey | Case) -> Journey:
    """A journey as it is, or a case as the journey of its legs (one section without legs)."""
    if isinstance(run, Journey):
        return run
    if isinstance(run, Case):
        return Journey(case=run)
    raise CaseError("journey", type(run).__name__, "must be a Journey or a Case (with legs for several stops)")
