"""A journey: one train calling at consecutive stops, each section a :class:`Case`."""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from pathlib import Path
from typing import Sequence

import numpy as np

from pymoo_rail.cases import ttobench
from pymoo_rail.model import Case, CaseError, Train
from pymoo_rail.sim import Simulator


@dataclass(frozen=True)
class Journey:
    """Consecutive stop-to-stop sections run by one train, with dwell times at the stops between.

    Parameters
    ----------
    name : str
    sections : tuple of Case
        Section k runs from stop k to stop k + 1; every section has the same train.
    dwell_s : tuple of float
        Dwell at each intermediate stop (``len(sections) - 1`` values).
    stops_m : tuple of float, optional
        Positions of the stops on the original track (default: cumulative section lengths from 0).
    stop_names : tuple of str, optional
        One name per stop (``len(sections) + 1``), or empty.
    altitude_m : float
        Altitude of the first stop (kept for TTOBench export; no effect on the physics).
    source : str
        Where the data come from (carried into exports).
    """

    name: str
    sections: tuple[Case, ...]
    dwell_s: tuple[float, ...] = ()
    stops_m: tuple[float, ...] = ()
    stop_names: tuple[str, ...] = ()
    altitude_m: float = 0.0
    source: str = field(default="", compare=False)

    def __post_init__(self) -> None:
        object.__setattr__(self, "sections", tuple(self.sections))
        object.__setattr__(self, "dwell_s", tuple(float(d) for d in self.dwell_s))
        object.__setattr__(self, "stop_names", tuple(self.stop_names))
        if not self.sections:
            raise CaseError("sections", (), "a journey needs at least one section")
        for k, case in enumerate(self.sections):
            if not isinstance(case, Case):
                raise CaseError(f"sections[{k}]", type(case).__name__, "must be a Case")
            if case.legs:
                raise CaseError(f"sections[{k}].legs", len(case.legs), "a section is one stop-to-stop run")
            if case.train != self.sections[0].train:
                raise CaseError(f"sections[{k}].train", case.train.name, "every section must have the same train")
        n = len(self.sections)
        if not self.dwell_s and n > 1:
            object.__setattr__(self, "dwell_s", (0.0,) * (n - 1))
        if len(self.dwell_s) != n - 1:
            raise CaseError("dwell_s", self.dwell_s, f"needs one dwell per intermediate stop ({n - 1})")
        for k, d in enumerate(self.dwell_s):
            if not (math.isfinite(d) and d >= 0):
                raise CaseError(f"dwell_s[{k}]", d, "must be a finite number >= 0")
        cumulative = tuple(float(x) for x in np.concatenate([[0.0], np.cumsum(self.section_lengths_m)]))
        if not self.stops_m:
            object.__setattr__(self, "stops_m", cumulative)
        object.__setattr__(self, "stops_m", tuple(float(x) for x in self.stops_m))
        if len(self.stops_m) != n + 1:
            raise CaseError("stops_m", self.stops_m, f"needs one position per stop ({n + 1})")
        for k in range(n):
            gap = self.stops_m[k + 1] - self.stops_m[k]
            if abs(gap - self.sections[k].line.length_m) > 1e-6:
                raise CaseError(f"stops_m[{k + 1}]", self.stops_m[k + 1],
                                f"is {gap} m after the previous stop, but section {k} is "
                                f"{self.sections[k].line.length_m} m long")
        if self.stop_names and len(self.stop_names) != n + 1:
            raise CaseError("stop_names", self.stop_names, f"needs one name per stop ({n + 1})")

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

    # --------------------------------------------------------------------------------- TTOBench

    @classmethod
    def from_ttobench(cls, track_path: ttobench.Source, train_path: ttobench.Source,
                      stops: Sequence[ttobench.StopRef] | None = None, *,
                      stop_names: Sequence[str] | None = None,
                      planned_times_s: Sequence[float] | float | None = None, supplement: float = 0.10,
                      dwell_s: Sequence[float] | float = 30.0, train_length_m: float | None = None,
                      name: str | None = None, dx_m: float | None = None) -> Journey:
        """A journey on a TTOBench track calling at ``stops`` (default: every stop).

        Parameters
        ----------
        stops : sequence of int, str or float, optional
            Stops called at, in order, by index, name (with ``stop_names``) or position (m); see
            :func:`pymoo_rail.cases.ttobench.from_ttobench`. Stops left out are passed.
        planned_times_s : float or sequence of float, optional
            Planned running time of each section (TTOBench has none). Default: each section's
            minimum running time plus ``supplement`` (10 %), a usual timetable running-time supplement.
        dwell_s : float or sequence of float
            Dwell at each intermediate stop (default 30 s, Liu (2019) 5.1.1 for this line).
        train_length_m : float, optional
            As in :func:`~pymoo_rail.cases.ttobench.from_ttobench` (default: point mass).
        """
        track = ttobench.read_track(track_path)
        indices = list(range(len(track.stops_m))) if stops is None else \
            [track.stop_index(s, stop_names) for s in stops]
        if len(indices) < 2:
            raise CaseError("stops", stops, "a journey calls at two stops at least")
        for a, b in zip(indices, indices[1:]):
            if b <= a:
                raise CaseError("stops", stops, f"stop {b} does not follow stop {a} in the track's direction")
        n = len(indices) - 1
        dwell = [float(dwell_s)] * (n - 1) if np.isscalar(dwell_s) else [float(d) for d in dwell_s]
        plans = [None] * n if planned_times_s is None else \
            ([float(planned_times_s)] * n if np.isscalar(planned_times_s) else list(planned_times_s))
        if len(plans) != n:
            raise CaseError("planned_times_s", planned_times_s, f"needs one time per section ({n})")
        sections = []
        for k, (a, b) in enumerate(zip(indices, indices[1:])):
            case = ttobench.from_ttobench(track_path, train_path, a, b, plans[k] or 1.0,
                                          dwell_s=dwell[k] if k < n - 1 else 0.0, stop_names=stop_names,
                                          train_length_m=train_length_m)
            if plans[k] is None:
                case = case.with_planned_time(Simulator(case, dx_m).min_running_time_s() * (1.0 + supplement))
            sections.append(case)
        names = tuple(stop_names[i] for i in indices) if stop_names else ()
        altitude = track.altitude_m + float(track.line().altitude_m(track.stops_m[indices[0]]))
        return cls(name=name or f"{track.id}[{indices[0]}-{indices[-1]}]", sections=tuple(sections),
                   dwell_s=tuple(dwell), stops_m=tuple(track.stops_m[i] for i in indices), stop_names=names,
                   altitude_m=altitude, source=sections[0].source)

    def to_ttobench(self, out_dir: str | Path, *, track_id: str | None = None,
                    train_id: str | None = None) -> tuple[Path, Path]:
        """Write the journey's line (its stops only) and train as TTOBench files.

        Positions restart at 0 at the first stop. Returns ``(track_path, train_path)``.
        """
        first = self.sections[0]
        if self.train.length_m > ttobench.POINT_MASS_LENGTH_M and first.line.gradient_model != "train_length":
            raise CaseError("line.gradient_model", first.line.gradient_model,
                            "a train with a length is written with gradients averaged over it")
        license_text = ttobench.TTOBENCH_NOTICE if "TTOBench" in self.source else None
        meta = {"description": self.name}
        if license_text:
            meta["license"] = license_text
        track_id = track_id or ttobench.ttobench_id(self.name)
        train_id = train_id or ttobench.ttobench_id(self.train.name or f"{self.name}_train")
        track = ttobench.track_to_json([c.line for c in self.sections], track_id, altitude_m=self.altitude_m,
                                       metadata=meta)
        train = ttobench.train_to_json(self.train, train_id,
                                       metadata={"license": license_text} if license_text else None)
        return ttobench.write_pair(out_dir, track, train)
