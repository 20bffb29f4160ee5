"""A case: one train on one line with a planned running time."""

from __future__ import annotations

import math
from dataclasses import dataclass, replace

from pymoo_rail.constants import KMH_PER_MS
from pymoo_rail.model.errors import CaseError, check_number
from pymoo_rail.model.line import Line
from pymoo_rail.model.plausibility import allowed_kinds, check_plausible
from pymoo_rail.model.train import Train

END_SPEED_TOL_MS = 0.01
"""A simulated run meets the end speed asked for when it arrives within this of it (m/s), or of its
window (``Case.end_speed_window_ms``); the exact solver lands on it exactly (docs/case-format.md)."""


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

    ``initial_speed_ms`` and ``final_speed_ms`` are the speeds at the start and at the end of the
    line (default 0: from standstill to a stop at the platform); a run may start and end moving,
    e.g. at a timing point of a journey or in a benchmark that fixes boundary speeds. Case files
    give them in km/h (``run.initial_speed_kmh``, ``run.final_speed_kmh``).

    The final speed is the speed asked for at the end, not a ceiling: a run arriving slower does not
    meet the case. ``final_speed_window_ms`` = ``(lo, hi)`` allows any arrival speed in between instead
    (``run.final_speed_window_kmh``); its upper end is then ``final_speed_ms`` (where the braking
    envelope ends). See :meth:`end_speed_window_ms` and :data:`END_SPEED_TOL_MS`.

    Values no train or line has (a 120 permille gradient, a force in N where kN is meant; the
    bounds of :mod:`pymoo_rail.model.plausibility`) raise :class:`CaseError`;
    ``allow_implausible`` waives them for a research case: ``True`` for all, or a tuple of kinds
    of bound (``("gradient", "speed")``, :data:`~pymoo_rail.model.plausibility.IMPLAUSIBLE_KINDS`).
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
    initial_speed_ms: float = 0.0
    final_speed_ms: float = 0.0
    final_speed_window_ms: tuple[float, float] | None = None
    allow_implausible: bool | tuple[str, ...] = False

    def __post_init__(self) -> None:
        if not isinstance(self.name, str) or not self.name:
            raise CaseError("name", self.name, "must be a non-empty string")
        for field in ("source", "description"):
            if not isinstance(getattr(self, field), str):
                raise CaseError(field, getattr(self, field), f"must be a string, not {type(getattr(self, field)).__name__}")
        if not isinstance(self.train, Train):
            raise CaseError("train", type(self.train).__name__, "must be a Train")
        if not isinstance(self.line, Line):
            raise CaseError("line", type(self.line).__name__, "must be a Line")
        if not isinstance(self.allow_implausible, bool):
            object.__setattr__(self, "allow_implausible", tuple(sorted(allowed_kinds(self.allow_implausible))))
        for field in ("planned_time_s", "dwell_s", "time_margin_s"):
            value = getattr(self, field)
            check_number(f"run.{field}", value, positive=field == "planned_time_s", nonneg=True)
        self._check_boundary_speeds()
        previous_end = 0.0
        for k, leg in enumerate(self.legs):
            check_number(f"run.legs[{k}].start_m", leg.start_m, nonneg=True)
            check_number(f"run.legs[{k}].end_m", leg.end_m, positive=True)
            check_number(f"run.legs[{k}].planned_time_s", leg.planned_time_s, positive=True)
            check_number(f"run.legs[{k}].dwell_s", leg.dwell_s, nonneg=True)
            if abs(leg.start_m - previous_end) > 1e-9 or leg.end_m <= leg.start_m:
                raise CaseError(f"run.legs[{k}]", leg, "legs must be consecutive, positive-length and start at 0")
            if leg.planned_time_s <= 0:
                raise CaseError(f"run.legs[{k}].planned_time_s", leg.planned_time_s, "must be positive")
            previous_end = leg.end_m
        if self.legs and abs(previous_end - self.line.length_m) > 1e-9:
            raise CaseError("run.legs", f"end at {previous_end} m", f"must end at line.length_m = {self.line.length_m}")
        check_plausible(self, self.allow_implausible)

    def _check_boundary_speeds(self) -> None:
        limits = self.line.speed_limits
        ends = (("initial_speed", self.initial_speed_ms, limits[0][2] if limits else math.inf),
                ("final_speed", self.final_speed_ms, limits[-1][2] if limits else math.inf))
        for field, speed_ms, limit_kmh in ends:
            name = f"run.{field}_kmh"
            if isinstance(speed_ms, bool) or not isinstance(speed_ms, (int, float)) or not math.isfinite(speed_ms):
                raise CaseError(name, speed_ms, "must be a finite number")
            kmh = speed_ms * KMH_PER_MS
            if speed_ms < 0.0:
                raise CaseError(name, kmh, "must be >= 0")
            cap = min(limit_kmh, self.train.max_speed_kmh)
            if kmh > cap + 1e-9:
                raise CaseError(name, kmh, f"is above the speed limit there ({cap:g} km/h)")
        window = self.final_speed_window_ms
        if window is not None:
            name = "run.final_speed_window_kmh"
            if (isinstance(window, (str, bytes)) or not hasattr(window, "__len__") or len(window) != 2
                    or not all(isinstance(v, (int, float)) and not isinstance(v, bool) and math.isfinite(v)
                               for v in window)):
                raise CaseError(name, window, "must be two finite speeds [lo, hi]")
            lo, hi = float(window[0]), float(window[1])
            if not 0.0 <= lo <= hi:
                raise CaseError(name, [lo * KMH_PER_MS, hi * KMH_PER_MS], "needs 0 <= lo <= hi")
            if abs(hi - self.final_speed_ms) > 1e-9:
                raise CaseError(name, [lo * KMH_PER_MS, hi * KMH_PER_MS],
                                f"its upper end must be run.final_speed_kmh = {self.final_speed_ms * KMH_PER_MS:g} "
                                "(the braking envelope ends there)")
            object.__setattr__(self, "final_speed_window_ms", (lo, hi))
        if self.legs and (self.initial_speed_ms or self.final_speed_ms):
            raise CaseError("run.legs", len(self.legs), "a case with legs starts and ends each leg at rest: "
                                                        "boundary speeds are not supported with legs")

    @property
    def final_speed_window_kmh(self) -> tuple[float, float] | None:
        """``final_speed_window_ms`` in km/h, as in the case file (None without a window)."""
        w = self.final_speed_window_ms
        return None if w is None else (w[0] * KMH_PER_MS, w[1] * KMH_PER_MS)

    def end_speed_window_ms(self) -> tuple[float, float]:
        """The arrival speeds the case asks for (m/s): its window, or the final speed itself (lo = hi)."""
        if self.final_speed_window_ms is not None:
            return self.final_speed_window_ms
        return self.final_speed_ms, self.final_speed_ms

    def require_single_run(self, user: str) -> Case:
        """This case when it is one stop-to-stop run; a :class:`CaseError` naming the leg API when
        it has legs (a single-run problem would run through the intermediate stops without a word).

        Parameters
        ----------
        user : str
            What refuses the legs (``"SpeedProfileProblem"``), named in the message.
        """
        if not self.legs:
            return self
        stops = ", ".join(f"{leg.end_m:g}" for leg in self.legs[:-1])
        raise CaseError("run.legs", len(self.legs),
                        f"case '{self.name}' has {len(self.legs)} legs (intermediate stops at {stops} m): "
                        f"{user} optimises one stop-to-stop run and would run through them. Use "
                        f"case.leg(k) for one leg, pymoo_rail.journeys.Journey(case) with allocate_running_time "
                        "for the whole journey, or CooperativeTrainsProblem / TimetableProblem (pymoo_rail.problems) "
                        "for the legs together")

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
