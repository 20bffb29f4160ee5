"""A case: one train on one line with a planned running time."""

from __future__ import annotations

import math
from dataclasses import dataclass, replace

from pymoo_rail.model.errors import CaseError
from pymoo_rail.model.line import Line
from pymoo_rail.model.train import Train


@dataclass(frozen=True)
class Leg:
    """One stop-to-stop run of a multi-section case."""

    start_m: float
    end_m: float
    planned_time_s: float
    dwell_s: float = 0.0


@dataclass(frozen=True)
class Case:
    """Everything an optimisation needs: the train, the line, the planned running time.

    ``legs`` is empty for a single stop-to-stop run; multi-section cases (e.g. the cooperative
    pair of Chen et al. (2017)) list consecutive legs, and ``leg(k)`` returns each as a case of its own.
    """

    name: str
    train: Train
    line: Line
    planned_time_s: float
    dwell_s: float = 0.0
    source: str = ""
    description: str = ""
    time_margin_s: float = 0.0
    legs: tuple[Leg, ...] = ()

    def __post_init__(self) -> None:
        if not isinstance(self.name, str) or not self.name:
            raise CaseError("name", self.name, "must be a non-empty string")
        for field in ("planned_time_s", "dwell_s", "time_margin_s"):
            value = getattr(self, field)
            if isinstance(value, bool) or not isinstance(value, (int, float)) or not math.isfinite(value):
                raise CaseError(f"run.{field}", value, "must be a finite number")
            if value < 0 or (field == "planned_time_s" and value <= 0):
                raise CaseError(f"run.{field}", value, "must be positive" if field == "planned_time_s" else "must be >= 0")
        previous_end = 0.0
        for k, leg in enumerate(self.legs):
            if abs(leg.start_m - previous_end) > 1e-9 or leg.end_m <= leg.start_m:
                raise CaseError(f"run.legs[{k}]", leg, "legs must be consecutive, positive-length and start at 0")
            if leg.planned_time_s <= 0:
                raise CaseError(f"run.legs[{k}].planned_time_s", leg.planned_time_s, "must be positive")
            previous_end = leg.end_m
        if self.legs and abs(previous_end - self.line.length_m) > 1e-9:
            raise CaseError("run.legs", f"end at {previous_end} m", f"must end at line.length_m = {self.line.length_m}")

    def leg(self, index: int) -> Case:
        """Leg ``index`` of a multi-section case as a single-run case."""
        if not self.legs:
            raise CaseError("legs", (), f"case '{self.name}' has no legs")
        if not 0 <= index < len(self.legs):
            raise CaseError("leg index", index, f"case '{self.name}' has {len(self.legs)} legs")
        leg = self.legs[index]
        return replace(self, name=f"{self.name}[{index}]", line=self.line.slice(leg.start_m, leg.end_m),
                       planned_time_s=leg.planned_time_s, dwell_s=leg.dwell_s, legs=())

    def with_planned_time(self, planned_time_s: float) -> Case:
        """The same case with another planned running time."""
        return replace(self, planned_time_s=planned_time_s)
