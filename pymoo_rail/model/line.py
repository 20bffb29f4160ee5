"""The line between two stops: gradients, curves, tunnels, speed limits, neutral sections."""

from __future__ import annotations

import math
from dataclasses import dataclass, replace
from itertools import chain

import numpy as np

from pymoo_rail.model.errors import CaseError, check_number

Interval = tuple[float, float]
Valued = tuple[float, float, float]

GRADIENT_MODELS = ("train_length", "point_mass")
# Curve resistance per unit weight (N/kN) from the radius R (m), see ``model/grid.py`` and docs/ttobench.md:
# "tang2020": 600 / R (Tang et al. (2020) eq. 2; with the train-length average it is their 10.5 alpha / L_c
# branch for curves shorter than the train); "roeckl": Roeckl's standard-gauge formula; "osrd": 800 / R,
# OSRD's equivalent gradient of a curve (railjson lines, ``cases/railjson_infra.py``).
CURVE_MODELS = ("tang2020", "roeckl", "osrd")


def _intervals_hold(rows: np.ndarray, length_m: float, *, tile: bool) -> bool:
    """True when the rows (an (n, width) array of finite numbers) pass :func:`_check_intervals`.

    The same conditions on whole arrays, so a line of a million rows is checked in milliseconds;
    only a line that fails them is walked row by row, to name the first bad row.
    """
    if rows.shape[0] == 0:
        return not tile or abs(length_m) <= 1e-9
    start, end = rows[:, 0], rows[:, 1]
    ok = bool(np.all(end > start) and np.all(start >= 0) and np.all(end <= length_m + 1e-9))
    if tile:
        previous_end = np.concatenate([[0.0], end[:-1]])
        return ok and bool(np.all(np.abs(start - previous_end) <= 1e-9)) and abs(end[-1] - length_m) <= 1e-9
    return ok and bool(np.all(start[1:] >= end[:-1] - 1e-9))


def _float_rows(rows: object, width: int) -> tuple[np.ndarray, bool] | None:
    """``rows`` as an (n, width) float array when every row is a list or tuple of ``width`` Python
    floats or ints, all finite, and whether ``rows`` already is a tuple of tuples of floats (kept
    as it is then); else None (the caller then checks entry by entry and names the bad one)."""
    if not isinstance(rows, (list, tuple)):
        return None
    row_types = set(map(type, rows))
    if not row_types <= {list, tuple} or not set(map(len, rows)) <= {width}:
        return None
    flat = list(chain.from_iterable(rows))
    types = set(map(type, flat))
    if not types <= {float, int}:
        return None
    array = np.array(flat, dtype=float).reshape(-1, width)
    if not np.isfinite(array).all():
        return None
    return array, isinstance(rows, tuple) and row_types <= {tuple} and types <= {float}


def _check_intervals(field: str, rows: tuple, length_m: float, *, tile: bool, width: int,
                     array: np.ndarray | None = None) -> None:
    """Rows ``[start_m, end_m, ...]`` inside [0, length]; ``tile`` demands they cover it exactly."""
    if array is not None and _intervals_hold(array, length_m, tile=tile):
        return
    previous_end = 0.0
    for k, row in enumerate(rows):
        if len(row) != width:
            raise CaseError(f"{field}[{k}]", list(row), f"needs {width} numbers")
        if not all(isinstance(v, (int, float)) and not isinstance(v, bool) and math.isfinite(v) for v in row):
            raise CaseError(f"{field}[{k}]", list(row), "needs finite numbers")
        start, end = row[0], row[1]
        if end <= start:
            raise CaseError(f"{field}[{k}]", list(row), "end_m must be greater than start_m (negative or zero length)")
        if start < 0 or end > length_m + 1e-9:
            raise CaseError(f"{field}[{k}]", list(row), f"lies outside the line [0, {length_m}] m")
        if tile and abs(start - previous_end) > 1e-9:
            kind = "gap" if start > previous_end else "overlap"
            raise CaseError(f"{field}[{k}]", list(row), f"{kind} at {previous_end} m: segments must tile the line")
        if not tile and start < previous_end - 1e-9:
            raise CaseError(f"{field}[{k}]", list(row), f"overlaps the previous entry ending at {previous_end} m")
        previous_end = end
    if tile and abs(previous_end - length_m) > 1e-9:
        raise CaseError(field, f"ends at {previous_end} m", f"must cover the line up to length_m = {length_m}")


@dataclass(frozen=True)
class Line:
    """A section of track from one stop (x = 0) to the next (x = ``length_m``).

    ``gradients`` rows are ``(start_m, end_m, permille)`` with + uphill; ``speed_limits`` rows are
    ``(start_m, end_m, kmh)``; both must tile [0, length]. ``curves`` rows are
    ``(start_m, end_m, radius_m)``; ``tunnels`` and ``neutral_sections`` rows ``(start_m, end_m)``.
    ``gradient_model`` is ``"train_length"`` (line resistance averaged over the train, Liu (2019)
    eq. 4-14) or ``"point_mass"``. ``curve_model`` picks the curve resistance: ``"tang2020"``
    (``600 / R`` N/kN) or ``"roeckl"`` (``650 / (R - 55)`` for R >= 300 m, ``500 / (R - 30)`` below;
    needs R > 30 m) or ``"osrd"`` (``800 / R``, as OSRD).
    """

    length_m: float
    gradients: tuple[Valued, ...]
    speed_limits: tuple[Valued, ...]
    curves: tuple[Valued, ...] = ()
    tunnels: tuple[Interval, ...] = ()
    neutral_sections: tuple[Interval, ...] = ()
    gradient_model: str = "train_length"
    curve_model: str = "tang2020"

    # (field, whether its rows tile the line, numbers per row)
    _ROWS = (("gradients", True, 3), ("speed_limits", True, 3), ("curves", False, 3), ("tunnels", False, 2),
             ("neutral_sections", False, 2))

    def __post_init__(self) -> None:
        check_number("line.length_m", self.length_m, positive=True)
        arrays = {}
        for name, _, width in self._ROWS:
            checked = _float_rows(getattr(self, name), width)
            arrays[name] = None if checked is None else checked[0]
            if checked is not None:  # all plain numbers: converted at once (linear in the rows)
                if not checked[1]:
                    object.__setattr__(self, name, tuple(map(tuple, checked[0].tolist())))
            else:
                rows = []
                for k, row in enumerate(getattr(self, name)):
                    if isinstance(row, (str, bytes)) or not hasattr(row, "__len__"):
                        raise CaseError(f"line.{name}[{k}]", row, "must be an array of numbers")
                    # type-checked before converting: true or "80" is not a number
                    rows.append(tuple(check_number(f"line.{name}[{k}][{j}]", v) for j, v in enumerate(row)))
                object.__setattr__(self, name, tuple(rows))
        for name, tile, width in self._ROWS:
            _check_intervals(f"line.{name}", getattr(self, name), self.length_m, tile=tile, width=width,
                             array=arrays[name])
        for k, row in enumerate(self.speed_limits):
            if row[2] <= 0:
                raise CaseError(f"line.speed_limits[{k}]", list(row), "the limit must be > 0 km/h")
        for k, row in enumerate(self.curves):
            if row[2] <= 0:
                raise CaseError(f"line.curves[{k}]", list(row), "the radius must be > 0 m")
        if self.curve_model not in CURVE_MODELS:
            raise CaseError("line.curve_model", self.curve_model, f"must be one of {CURVE_MODELS}")
        if self.curve_model == "roeckl":
            for k, row in enumerate(self.curves):
                if row[2] <= 30.0:
                    raise CaseError(f"line.curves[{k}]", list(row), "Roeckl's formula needs a radius > 30 m")
        if self.gradient_model not in GRADIENT_MODELS:
            raise CaseError("line.gradient_model", self.gradient_model, f"must be one of {GRADIENT_MODELS}")

    def breakpoints_m(self) -> list[float]:
        """Every position where the gradient or the speed limit changes, with 0 and the length."""
        points = {0.0, float(self.length_m)}
        for rows in (self.gradients, self.speed_limits):
            for row in rows:
                points.update((row[0], row[1]))
        return sorted(points)

    def limit_kmh_at(self, position_m: float) -> float:
        """The speed limit at one point of the track."""
        for start, end, limit in self.speed_limits:
            if start <= position_m < end:
                return limit
        return self.speed_limits[-1][2]

    def altitude_m(self, position_m: float | np.ndarray) -> np.ndarray:
        """Altitude relative to the start, integrating the gradients (point values, not averaged)."""
        x = np.asarray(position_m, dtype=float)
        knots = [0.0] + [row[1] for row in self.gradients]
        heights = [0.0]
        for start, end, permille in self.gradients:
            heights.append(heights[-1] + (end - start) * permille / 1000.0)
        return np.interp(x, knots, heights)

    def slice(self, start_m: float, end_m: float) -> Line:
        """The part of the line between two positions, re-based to start at 0."""
        if not (0 <= start_m < end_m <= self.length_m + 1e-9):
            raise CaseError("slice", (start_m, end_m), f"must satisfy 0 <= start < end <= {self.length_m}")

        def cut(rows):
            out = []
            for row in rows:
                a, b = max(row[0], start_m), min(row[1], end_m)
                if b > a:
                    out.append((a - start_m, b - start_m, *row[2:]))
            return tuple(out)

        return replace(self, length_m=end_m - start_m, gradients=cut(self.gradients),
                       speed_limits=cut(self.speed_limits), curves=cut(self.curves),
                       tunnels=cut(self.tunnels), neutral_sections=cut(self.neutral_sections))
