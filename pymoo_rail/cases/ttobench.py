"""TTOBench import: JSON tracks, trains and journeys to :class:`~pymoo_rail.model.Case` (export:
:mod:`pymoo_rail.cases.ttobench_writer`).

TTOBench (Kouzoupis, Pendharkar and Corman, Operations Research Forum 4, 67, 2023; BSD 2-Clause)
is the open benchmark library for train trajectory optimisation. A *track* file holds the stops,
the speed limits and the gradients of a whole line as change-point lists; a *train* file holds
scalar parameters, each as ``{"unit": ..., "value": ...}``. This module reads both into a
:class:`Case` for one run between two stops; :func:`read_case` is this format's entry in the
registry of :mod:`pymoo_rail.cases.formats` (``load_case(track, train=..., ...)``).

>>> from pymoo_rail.cases.ttobench import (BEIJING_SUBWAY_TRAIN, YIZHUANG_STOP_NAMES, YIZHUANG_TRACK,
...                                        from_ttobench)
>>> case = from_ttobench(YIZHUANG_TRACK, BEIJING_SUBWAY_TRAIN, "Tongjinan Rd", "Jinghai Rd", 150.0,
...                      stop_names=YIZHUANG_STOP_NAMES)
>>> case.line.length_m
2265.0

Mapping decisions (the full table is in ``docs/ttobench.md``):

- Units: every value is converted by its stated unit; a missing or unknown unit is a
  :class:`CaseError` naming the field. Efficiencies and ``rho`` in ``"%"`` are divided by 100
  (a value below 1 with unit ``"%"`` is refused as ambiguous: it is almost certainly a fraction).
- Davis resistance ``r0 + r1 v + r2 v^2`` is stored in kN with v in km/h, whatever the file's units.
- Traction is ``min(max traction force, max traction power / v)``.
- Braking: the model has one braking curve plus regen caps on its electric share. TTOBench's
  total braking is ``max pn braking force + min(max reg braking force, max reg braking power / v)``
  and the regen caps are the electric part. With no pneumatic force that is a force-plus-power
  curve, exactly; with a pneumatic force and a reg power cap that binds below the maximum speed it
  is a table with nodes 1 % apart in speed (linear interpolation of the hyperbola; relative error
  below 2e-5).
- Train length: TTOBench's benchmark formulations treat the train as a point mass and the train
  files have an optional ``length``. ``train_length_m=None`` uses that length when the file has one
  (limits hold over the whole train and gradients are averaged over it, Liu (2019) eq. 4-14), and a
  point mass otherwise; ``0`` forces a point mass. The model needs a positive length, so a point
  mass is a train of :data:`POINT_MASS_LENGTH_M` (1 mm) with ``gradient_model = "point_mass"``.
- Efficiencies absent (TTOBench allows omitting both) give traction efficiency 1 and no regen,
  so net energy is the traction work at the wheel.
- Curvatures become ``line.curves`` (clothoids cut into pieces of at most 5 m), with the curve
  resistance the caller picks (``curve_model``: ``"tang2020"`` 600 / R, or ``"roeckl"``);
  tunnels become ``line.tunnels`` (``tunnel_model``: Liu (2019) eq. 2-12, or ``"none"``).
- Read and checked but not modelled, each named in a :class:`TTOBenchWarning`: ``ETCS braking
  data`` (tracks and trains) and the trains' speed-dependent ``tunnel resistance``. ``num seats``
  and ``num coaches`` are kept on :class:`TTOBenchTrain`.
- An efficiency given as a table of losses over load and velocity (TTOBench's dynamic locomotive
  ``00_Loco_Dyn``) becomes an :class:`~pymoo_rail.model.EfficiencyMap` and the auxiliary power
  (:mod:`pymoo_rail.cases.ttobench_efficiency`).

The TTOBench files shipped in ``pymoo_rail/cases/data/`` (Yizhuang line and Beijing subway train)
are copies under the BSD 2-Clause license; the notice is in ``data/TTOBENCH_LICENSE``.
"""

from __future__ import annotations

import json
import math
import warnings
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, Union

import numpy as np

from pymoo_rail.cases.json_files import load_json_object
from pymoo_rail.cases.ttobench_efficiency import FIELDS, map_from_loss_table, no_load_loss_kw
from pymoo_rail.model import Case, CaseError, DavisResistance, ForceCurve, Line, Train
from pymoo_rail.constants import KMH_PER_MS
from pymoo_rail.model.line import CURVE_MODELS

DATA_DIR = Path(__file__).resolve().parent / "data"
YIZHUANG_TRACK = DATA_DIR / "CN_Songjiazhuang_Yizhuang.json"
BEIJING_SUBWAY_TRAIN = DATA_DIR / "CN_Beijing_Subway.json"
TTOBENCH_LICENSE = DATA_DIR / "TTOBENCH_LICENSE"
TTOBENCH_NOTICE = "TTOBench data, BSD 2-Clause License, Copyright (c) 2022, Dimitris Kouzoupis"

# TTOBench stores positions only. Station names of the Beijing Subway Yizhuang line in the order of
# the stops in CN_Songjiazhuang_Yizhuang.json (public line map, not part of TTOBench). Stops 9 -> 10
# are Liu's (2019) Tongjinan Rd -> Jinghai Rd run (2265 m in both sources).
YIZHUANG_STOP_NAMES = (
    "Songjiazhuang", "Xiaocun", "Xiaohongmen", "Jiugong", "Yizhuangqiao", "Yizhuang Culture Park",
    "Wanyuan St", "Rongjing East St", "Rongchang East St", "Tongjinan Rd", "Jinghai Rd", "Ciqu South",
    "Ciqu", "Yizhuang Railway Station",
)

POINT_MASS_LENGTH_M = 0.001
LIBRARY_VERSION = "TTOBench v1.3"
# Relative spacing of the speed nodes of a tabulated braking curve (pneumatic + power-capped regen).
_BRAKE_TABLE_RATIO = 1.01

Source = Union[str, Path, Mapping]
StopRef = Union[int, float, str]

# Each accepted unit as (multiplier, divisor) to the unit used inside the case (t, km/h, kW, kN, m,
# fractions); a divisor keeps exact decimals exact (70 % -> 0.7, not 0.7000000000000001).
_LENGTH = {"m": (1.0, 1.0), "km": (1000.0, 1.0)}
_MASS_T = {"kg": (1.0, 1000.0), "t": (1.0, 1.0)}
_SPEED_KMH = {"km/h": (1.0, 1.0), "m/s": (KMH_PER_MS, 1.0)}
_POWER_KW = {"W": (1.0, 1000.0), "kW": (1.0, 1.0), "MW": (1000.0, 1.0)}
_FORCE_KN = {"N": (1.0, 1000.0), "kN": (1.0, 1.0)}
_ACCEL = {"m/s^2": (1.0, 1.0)}
_FRACTION = {"-": (1.0, 1.0), "%": (1.0, 100.0)}
_R1_KN_PER_KMH = {"N/(m/s)": (1.0, 1000.0 * KMH_PER_MS), "kN/(m/s)": (1.0, KMH_PER_MS), "kN/(km/h)": (1.0, 1.0)}
_R2_KN_PER_KMH2 = {"N/(m/s)^2": (1.0, 1000.0 * KMH_PER_MS**2), "kN/(m/s)^2": (1.0, KMH_PER_MS**2),
                   "kN/(km/h)^2": (1.0, 1.0)}
_SLOPE_PERMILLE = {"permil": (1.0, 1.0), "permille": (1.0, 1.0)}

_TRAIN_REQUIRED = ("metadata", "mass", "max speed", "max traction power", "max reg braking power",
                   "max traction force", "max reg braking force", "rolling resistance r0",
                   "rolling resistance r1", "rolling resistance r2")
_TRAIN_USED = {"rho", "length", "max pn braking force", "max acceleration", "max deceleration",
               "efficiency traction", "efficiency reg brake"}
_TRAIN_INFORMATIONAL = {"num seats", "num coaches", "tunnel resistance", "ETCS braking data"}
_TRACK_REQUIRED = ("metadata", "stops", "speed limits")
_TRACK_OPTIONAL = {"altitude", "gradients", "curvatures", "tunnels", "ETCS braking data"}
TUNNEL_MODELS = ("liu2019", "none")
# Clothoids (curvature linear in distance) become constant-radius pieces this long at most, each with
# the mean curvature of its stretch (exact for the 600 / R model, which is linear in curvature).
CLOTHOID_PIECE_M = 5.0


class TTOBenchWarning(UserWarning):
    """A TTOBench field that is read and checked but not modelled (the message names it)."""


def _warn(field: str, reason: str, source: str) -> None:
    warnings.warn(f"{source}: TTOBench field '{field}' {reason}", TTOBenchWarning, stacklevel=3)


# ----------------------------------------------------------------------------------------- reading


def _load(source: Source, what: str) -> tuple[dict, str]:
    """The parsed JSON object and a label for error messages."""
    return load_json_object(source, f"TTOBench {what}")


def _number(field: str, value: Any, source: str) -> float:
    if isinstance(value, bool) or not isinstance(value, (int, float)) or not math.isfinite(value):
        raise CaseError(field, value, "must be a finite number", source)
    return float(value)


def _unit_factor(field: str, unit: Any, units: Mapping[str, tuple[float, float]],
                 source: str) -> tuple[float, float]:
    if unit is None:
        raise CaseError(field, None, f"is required: TTOBench values carry their unit (one of {', '.join(units)})",
                        source)
    if unit not in units:
        raise CaseError(field, unit, f"unknown unit (known: {', '.join(units)})", source)
    return units[unit]


def _scalar(data: Mapping, key: str, units: Mapping[str, tuple[float, float]], source: str, *,
            default: float | None = None) -> float | None:
    """A ``{"unit", "value"}`` entry converted to the case's unit; ``default`` if absent."""
    if key not in data:
        return default
    entry = data[key]
    if not isinstance(entry, Mapping):
        raise CaseError(key, entry, 'must be an object {"unit": ..., "value": ...}', source)
    extra = sorted(set(entry) - {"unit", "value"})
    if extra:
        raise CaseError(f"{key}.{extra[0]}", entry[extra[0]], 'unknown key (expected "unit" and "value")', source)
    factor = _unit_factor(f"{key}.unit", entry.get("unit"), units, source)
    if "value" not in entry:
        raise CaseError(f"{key}.value", None, "is required", source)
    return _convert(_number(f"{key}.value", entry["value"], source), factor)


def _fraction(data: Mapping, key: str, source: str, *, default: float | None = None) -> float | None:
    """A dimensionless entry in ``"-"`` or ``"%"``; a percentage below 1 is ambiguous and refused."""
    value = _scalar(data, key, _FRACTION, source, default=default)
    if key in data and data[key].get("unit") == "%" and 0.0 < data[key]["value"] < 1.0 and key != "rho":
        raise CaseError(f"{key}.value", data[key]["value"],
                        "is below 1 % with unit '%': a fraction written as a percentage? "
                        "Write unit '-' for a fraction or the value in percent", source)
    return value


def _convert(value: float, factor: tuple[float, float]) -> float:
    mul, div = factor
    return value * mul / div


def _check_keys(data: Mapping, required: Sequence[str], allowed: set[str], what: str, source: str) -> None:
    for key in required:
        if key not in data:
            raise CaseError(key, None, f"is required in a TTOBench {what} file", source)
    unknown = sorted(set(data) - set(required) - allowed)
    if unknown:
        known = ", ".join(sorted(set(required) | allowed))
        raise CaseError(unknown[0], data[unknown[0]], f"unknown field of a TTOBench {what} file (known: {known})",
                        source)
    meta = data["metadata"]
    if not isinstance(meta, Mapping) or "id" not in meta:
        raise CaseError("metadata.id", None, "is required", source)
    if not isinstance(meta["id"], str) or not meta["id"]:
        raise CaseError("metadata.id", meta["id"], "must be a non-empty string", source)


def _change_points(data: Mapping, key: str, value_key: str, value_units: Mapping[str, tuple[float, float]],
                   length_m: float, source: str) -> tuple[tuple[float, float], ...]:
    """``[[position, value], ...]`` in m and the case's unit; sorted, from 0, inside the track."""
    entry = data[key]
    if not isinstance(entry, Mapping):
        raise CaseError(key, entry, 'must be an object {"units": {...}, "values": [...]}', source)
    units = entry.get("units")
    if not isinstance(units, Mapping):
        raise CaseError(f"{key}.units", units, f'is required: an object with "position" and "{value_key}"', source)
    pos_factor = _unit_factor(f"{key}.units.position", units.get("position"), _LENGTH, source)
    val_factor = _unit_factor(f"{key}.units.{value_key}", units.get(value_key), value_units, source)
    values = entry.get("values")
    if not isinstance(values, list) or not values:
        raise CaseError(f"{key}.values", values, "must be a non-empty list of [position, value] pairs", source)
    points: list[tuple[float, float]] = []
    for k, pair in enumerate(values):
        field = f"{key}.values[{k}]"
        if not isinstance(pair, (list, tuple)) or len(pair) != 2:
            raise CaseError(field, pair, "must be a [position, value] pair", source)
        pos = _convert(_number(field, pair[0], source), pos_factor)
        val = _convert(_number(field, pair[1], source), val_factor)
        if k == 0 and pos != 0.0:
            raise CaseError(field, list(pair), "the first change point must be at position 0", source)
        if points and pos <= points[-1][0]:
            raise CaseError(field, list(pair), f"positions must be sorted and strictly increasing "
                                               f"(the previous change point is at {points[-1][0]} m)", source)
        if pos >= length_m:
            raise CaseError(field, list(pair), f"must start before the end of the track ({length_m} m)", source)
        points.append((pos, val))
    return tuple(points)


@dataclass(frozen=True)
class TTOBenchTrack:
    """A TTOBench track in the case's units: positions in m, limits in km/h, gradients in permille.

    ``speed_limits`` and ``gradients`` are change points ``(position_m, value)``: each value holds
    from its position to the next change point (the last one to the end of the track). ``curves``
    are rows ``(start_m, end_m, radius_m)`` of constant radius (clothoids already cut into pieces of
    at most :data:`CLOTHOID_PIECE_M`, straight track left out); ``tunnels`` rows
    ``(start_m, end_m, cross_section_m2)``.
    """

    id: str
    stops_m: tuple[float, ...]
    speed_limits: tuple[tuple[float, float], ...]
    gradients: tuple[tuple[float, float], ...]
    altitude_m: float = 0.0
    metadata: Mapping[str, Any] = field(default_factory=dict, compare=False)
    curves: tuple[tuple[float, float, float], ...] = ()
    tunnels: tuple[tuple[float, float, float], ...] = ()

    @property
    def length_m(self) -> float:
        """Length of the track (m): the position of the last stop."""
        return self.stops_m[-1]

    def line(self, gradient_model: str = "point_mass", *, curve_model: str = "tang2020",
             tunnel_model: str = "liu2019") -> Line:
        """The whole track as one :class:`Line` (stop 0 to the last stop).

        ``curve_model``: ``"tang2020"`` (600 / R) or ``"roeckl"``; ``tunnel_model``: ``"liu2019"``
        (0.00013 L_s N/kN, speed-independent) or ``"none"`` (tunnels add no resistance).
        """
        if curve_model not in CURVE_MODELS:
            raise CaseError("curve_model", curve_model, f"must be one of {CURVE_MODELS}")
        if tunnel_model not in TUNNEL_MODELS:
            raise CaseError("tunnel_model", tunnel_model, f"must be one of {TUNNEL_MODELS}")
        tunnels = tuple((s, e) for s, e, _ in self.tunnels) if tunnel_model == "liu2019" else ()
        return Line(length_m=self.length_m, gradients=_rows(self.gradients, self.length_m),
                    speed_limits=_rows(self.speed_limits, self.length_m), gradient_model=gradient_model,
                    curves=self.curves, tunnels=tunnels, curve_model=curve_model)

    def stop_index(self, stop: StopRef, stop_names: Sequence[str] | None = None) -> int:
        """Index of a stop given by index (int), name (str, needs ``stop_names``) or position (float, m).

        Negative indices count from the last stop. A position must match a stop within 0.5 m.
        """
        n = len(self.stops_m)
        if isinstance(stop, bool):
            raise CaseError("stop", stop, "give a stop index (int), name (str) or position in m (float)")
        if isinstance(stop, (int, np.integer)):
            index = int(stop) + n if stop < 0 else int(stop)
            if not 0 <= index < n:
                raise CaseError("stop", stop, f"index out of range: the track has {n} stops "
                                              "(pass a float to give a position in m)")
            return index
        if isinstance(stop, str):
            if stop_names is None:
                raise CaseError("stop", stop, "TTOBench stops have no names: pass stop_names=[...] "
                                              "(e.g. YIZHUANG_STOP_NAMES) or an index or position")
            if len(stop_names) != n:
                raise CaseError("stop_names", len(stop_names), f"needs one name per stop ({n})")
            matches = [k for k, name in enumerate(stop_names) if name.casefold() == stop.casefold()]
            if not matches:
                raise CaseError("stop", stop, f"no such stop (stops: {', '.join(stop_names)})")
            return matches[0]
        if isinstance(stop, (float, np.floating)):
            distances = np.abs(np.asarray(self.stops_m) - float(stop))
            index = int(np.argmin(distances))
            if distances[index] > 0.5:
                raise CaseError("stop", stop, f"no stop at this position (stops at {list(self.stops_m)} m)")
            return index
        raise CaseError("stop", stop, "give a stop index (int), name (str) or position in m (float)")


def _rows(points: Sequence[tuple[float, float]], length_m: float) -> tuple[tuple[float, float, float], ...]:
    """Change points to ``(start_m, end_m, value)`` rows covering [0, length]."""
    ends = [p for p, _ in points[1:]] + [length_m]
    return tuple((p, e, v) for (p, v), e in zip(points, ends))


def read_track(source: Source) -> TTOBenchTrack:
    """Read a TTOBench track file (or its parsed JSON object)."""
    data, label = _load(source, "track")
    _check_keys(data, _TRACK_REQUIRED, _TRACK_OPTIONAL, "track", label)
    stops = data["stops"]
    if not isinstance(stops, Mapping):
        raise CaseError("stops", stops, 'must be an object {"unit": ..., "values": [...]}', label)
    factor = _unit_factor("stops.unit", stops.get("unit"), _LENGTH, label)
    values = stops.get("values")
    if not isinstance(values, list) or len(values) < 2:
        raise CaseError("stops.values", values, "needs at least two stop positions", label)
    stops_m = []
    for k, v in enumerate(values):
        x = _convert(_number(f"stops.values[{k}]", v, label), factor)
        if k == 0 and x != 0.0:
            raise CaseError("stops.values[0]", v, "the first stop must be at position 0", label)
        if stops_m and x <= stops_m[-1]:
            raise CaseError(f"stops.values[{k}]", v, f"stops must be sorted and strictly increasing "
                                                     f"(the previous stop is at {stops_m[-1]} m)", label)
        stops_m.append(x)
    length = stops_m[-1]
    limits = _change_points(data, "speed limits", "velocity", _SPEED_KMH, length, label)
    for k, (_, v) in enumerate(limits):
        if v <= 0:
            raise CaseError(f"speed limits.values[{k}]", v, "a speed limit must be > 0", label)
    if "gradients" in data:
        gradients = _change_points(data, "gradients", "slope", _SLOPE_PERMILLE, length, label)
    else:  # TTOBench: the field may be omitted for level tracks
        gradients = ((0.0, 0.0),)
    curves = _curvatures(data["curvatures"], length, label) if "curvatures" in data else ()
    tunnels = _tunnels(data["tunnels"], length, label) if "tunnels" in data else ()
    if "ETCS braking data" in data:
        _etcs(data["ETCS braking data"], _TRACK_ETCS, label)
    altitude = _scalar(data, "altitude", _LENGTH, label, default=0.0)
    return TTOBenchTrack(id=data["metadata"]["id"], stops_m=tuple(stops_m), speed_limits=limits,
                         gradients=gradients, altitude_m=altitude, metadata=dict(data["metadata"]),
                         curves=curves, tunnels=tunnels)


def _table_entry(entry: Any, key: str, columns: Sequence[tuple[str, Mapping[str, tuple[float, float]]]],
                 source: str) -> tuple[list[tuple[float, float]], list]:
    """The unit factors and the rows of a ``{"units": {...}, "values": [[...], ...]}`` entry."""
    if not isinstance(entry, Mapping) or set(entry) != {"units", "values"}:
        raise CaseError(key, entry, 'must be an object {"units": {...}, "values": [...]}', source)
    units = entry["units"]
    names = [c for c, _ in columns]
    if not isinstance(units, Mapping) or set(units) != set(names):
        raise CaseError(f"{key}.units", units, f"must give exactly the units of {', '.join(names)}", source)
    factors = [_unit_factor(f"{key}.units.{c}", units[c], table, source) for c, table in columns]
    values = entry["values"]
    if not isinstance(values, list):
        raise CaseError(f"{key}.values", values, "must be a list of rows", source)
    for k, row in enumerate(values):
        if not isinstance(row, (list, tuple)) or len(row) != len(columns):
            raise CaseError(f"{key}.values[{k}]", row, f"must be a row [{', '.join(names)}]", source)
    return factors, values


def _radius(field: str, value: Any, factor: tuple[float, float], source: str) -> float:
    """A signed radius in m; ``"infinity"`` (straight track) gives ``inf``."""
    if isinstance(value, str) and value.strip().lower() in ("infinity", "inf", "+infinity", "-infinity"):
        return math.inf
    if isinstance(value, bool) or not isinstance(value, (int, float)) or math.isnan(value):
        raise CaseError(field, value, 'must be a number or "infinity"', source)
    if value == 0:
        raise CaseError(field, value, "a radius of 0 is not a curve", source)
    return _convert(float(value), factor) if math.isfinite(value) else math.inf


def _mean_abs_curvature(k_a: float, k_b: float) -> float:
    """Mean of |k| over a stretch where the curvature k runs linearly from k_a to k_b."""
    if k_a * k_b >= 0.0:
        return 0.5 * abs(k_a + k_b)
    return 0.5 * (k_a * k_a + k_b * k_b) / abs(k_b - k_a)


def _curvatures(entry: Any, length_m: float, source: str) -> tuple[tuple[float, float, float], ...]:
    """TTOBench ``curvatures`` as constant-radius rows ``(start_m, end_m, |radius| m)``.

    The sign (turn direction) does not change the resistance. A clothoid (different radii at the
    start and the end: curvature linear in distance) is cut into pieces of at most
    :data:`CLOTHOID_PIECE_M`, each with its mean absolute curvature.
    """
    factors, values = _table_entry(entry, "curvatures", (("position", _LENGTH), ("radius at start", _LENGTH),
                                                         ("radius at end", _LENGTH)), source)
    rows: list[tuple[float, float, float]] = []
    starts = []
    for k, row in enumerate(values):
        pos = _convert(_number(f"curvatures.values[{k}]", row[0], source), factors[0])
        if k == 0 and pos != 0.0:
            raise CaseError(f"curvatures.values[{k}]", row, "the first change point must be at position 0", source)
        if starts and pos <= starts[-1]:
            raise CaseError(f"curvatures.values[{k}]", row, "positions must be strictly increasing", source)
        if pos >= length_m:
            raise CaseError(f"curvatures.values[{k}]", row, f"must start before the end of the track ({length_m} m)",
                            source)
        starts.append(pos)
    for k, row in enumerate(values):
        start, end = starts[k], (starts[k + 1] if k + 1 < len(starts) else length_m)
        k_a = 1.0 / _radius(f"curvatures.values[{k}][1]", row[1], factors[1], source)
        k_b = 1.0 / _radius(f"curvatures.values[{k}][2]", row[2], factors[2], source)
        n_pieces = 1 if k_a == k_b else max(1, math.ceil((end - start) / CLOTHOID_PIECE_M))
        edges = np.linspace(start, end, n_pieces + 1)
        for a, b in zip(edges[:-1], edges[1:]):
            kappa = _mean_abs_curvature(k_a + (k_b - k_a) * (a - start) / (end - start),
                                        k_a + (k_b - k_a) * (b - start) / (end - start))
            if kappa > 0.0:
                rows.append((float(a), float(b), 1.0 / kappa))
    return tuple(rows)


_AREA_M2 = {"m^2": (1.0, 1.0)}


def _tunnels(entry: Any, length_m: float, source: str) -> tuple[tuple[float, float, float], ...]:
    """TTOBench ``tunnels`` ``[position, length, cross section]`` as rows ``(start_m, end_m, area_m2)``."""
    factors, values = _table_entry(entry, "tunnels", (("position", _LENGTH), ("length", _LENGTH),
                                                      ("cross section", _AREA_M2)), source)
    rows: list[tuple[float, float, float]] = []
    for k, row in enumerate(values):
        field = f"tunnels.values[{k}]"
        start = _convert(_number(field, row[0], source), factors[0])
        tunnel_length = _convert(_number(field, row[1], source), factors[1])
        area = _number(field, row[2], source)
        if start < 0 or tunnel_length < 0 or area < 0:
            raise CaseError(field, row, "position, length and cross section must be >= 0", source)
        if start + tunnel_length > length_m:
            raise CaseError(field, row, f"ends beyond the end of the track ({length_m} m)", source)
        if rows and start < rows[-1][1]:
            raise CaseError(field, row, f"overlaps the previous tunnel ending at {rows[-1][1]} m", source)
        if tunnel_length > 0:  # a tunnel of length 0 adds nothing
            rows.append((start, start + tunnel_length, area))
    return tuple(rows)


def _etcs(entry: Any, required: Sequence[str], source: str) -> None:
    """Check the fields of ``ETCS braking data`` and warn that ETCS supervision is not modelled."""
    if not isinstance(entry, Mapping):
        raise CaseError("ETCS braking data", entry, "must be an object", source)
    missing = sorted(set(required) - set(entry))
    unknown = sorted(set(entry) - set(required))
    if missing or unknown:
        bad = (missing or unknown)[0]
        raise CaseError(f"ETCS braking data.{bad}", entry.get(bad),
                        f"TTOBench's ETCS braking data holds exactly {', '.join(required)}", source)
    _warn("ETCS braking data", "is not modelled: runs are bounded by the speed limits and the train's "
                               "braking forces and deceleration cap, not by ETCS braking curves", source)


_TIME_S = {"s": (1.0, 1.0), "min": (60.0, 1.0)}
_JOURNEY_COLUMNS = (("position", _LENGTH), ("lower time constraint", _TIME_S), ("upper time constraint", _TIME_S),
                    ("lower speed constraint", _SPEED_KMH), ("upper speed constraint", _SPEED_KMH))


_TRACK_ETCS = ("M_NVAVADH", "Kt_int")
_TRAIN_ETCS = ("A_brake_emergency", "A_brake_service", "K_dry_rst", "K_wet_rst", "T_traction", "T_be", "T_bs",
               "v_uncertainty")


def known_fields() -> dict[str, tuple[str, ...]]:
    """Every field the importer accepts, by file kind (``track``, ``train``, ``journey``) and for the
    ETCS sub-objects and the columns of a journey's timing points; anything else is refused."""
    return {"track": tuple(_TRACK_REQUIRED) + tuple(sorted(_TRACK_OPTIONAL)),
            "train": tuple(_TRAIN_REQUIRED) + tuple(sorted(_TRAIN_USED | _TRAIN_INFORMATIONAL)),
            "journey": ("metadata", "timing points"),
            "track.ETCS braking data": _TRACK_ETCS, "train.ETCS braking data": _TRAIN_ETCS,
            "journey.timing points": tuple(name for name, _ in _JOURNEY_COLUMNS)}


def read_journey(source: Source) -> tuple[str, str | None, list[tuple[float | None, ...]], dict, str]:
    """Read a TTOBench journey file: ``(id, associated track id, rows, metadata, label)``.

    Each row is ``(position_m, earliest_s, latest_s, min_kmh, max_kmh)`` in these units, ``None``
    where the file has ``null``. The timing-point rules are checked by
    :func:`pymoo_rail.journeys.read_timing_points`.
    """
    data, label = _load(source, "journey")
    _check_keys(data, ("metadata", "timing points"), set(), "journey", label)
    factors, values = _table_entry(data["timing points"], "timing points", _JOURNEY_COLUMNS, label)
    rows = []
    for k, row in enumerate(values):
        field = f"timing points.values[{k}]"
        if row[0] is None:
            raise CaseError(field, row, "a timing point needs a position", label)
        rows.append(tuple(None if v is None else _convert(_number(field, v, label), f) for v, f in zip(row, factors)))
    meta = dict(data["metadata"])
    return meta["id"], meta.get("associated track"), rows, meta, label


@dataclass(frozen=True)
class TTOBenchTrain:
    """A TTOBench train file converted to a :class:`Train`, with what the model does not store."""

    id: str
    train: Train
    length_m: float | None
    metadata: Mapping[str, Any] = field(default_factory=dict, compare=False)
    n_seats: int | None = None
    n_coaches: int | None = None
    tunnel_resistance: tuple[tuple[float, float], ...] = ()  # (cross section m^2, kN/(km/h)^2)


def braking_curve(reg_force_kn: float, reg_power_kw: float, pn_force_kn: float, max_speed_kmh: float) -> ForceCurve:
    """The total braking limit ``F_pn + min(F_reg, P_reg / v)`` as a :class:`ForceCurve`.

    Exact (a force and a power cap) when there is no pneumatic part, or when the regen power cap
    does not bind below ``max_speed_kmh``; otherwise a table with speed nodes 1 % apart from the
    corner speed up, whose linear interpolation of the hyperbola is within 2e-5 relative.
    """
    corner_kmh = reg_power_kw / reg_force_kn * KMH_PER_MS
    if pn_force_kn == 0.0:
        return ForceCurve(max_force_kn=reg_force_kn, max_power_kw=reg_power_kw)
    if corner_kmh >= max_speed_kmh:
        return ForceCurve(max_force_kn=reg_force_kn + pn_force_kn)
    speeds = [0.0, corner_kmh]
    while speeds[-1] < max_speed_kmh:
        speeds.append(min(speeds[-1] * _BRAKE_TABLE_RATIO, max_speed_kmh))
    table = [(v, pn_force_kn + min(reg_force_kn, reg_power_kw * KMH_PER_MS / v) if v > 0 else
              pn_force_kn + reg_force_kn) for v in speeds]
    return ForceCurve(table=tuple(table))


def read_train(source: Source, *, train_length_m: float | None = None) -> TTOBenchTrain:
    """Read a TTOBench train file (or its parsed JSON object).

    ``train_length_m``: ``None`` takes the file's ``length`` if any, else a point mass; ``0`` forces
    a point mass; a positive value sets the length (limits over the whole train, averaged gradients).
    """
    data, label = _load(source, "train")
    _check_keys(data, _TRAIN_REQUIRED, _TRAIN_USED | _TRAIN_INFORMATIONAL, "train", label)
    counts = {key: _count(data, key, label) for key in ("num seats", "num coaches")}
    tunnel_resistance = _tunnel_resistance(data["tunnel resistance"], label) if "tunnel resistance" in data else ()
    if "ETCS braking data" in data:
        _etcs(data["ETCS braking data"], _TRAIN_ETCS, label)
    mass_t = _scalar(data, "mass", _MASS_T, label)
    rho = _fraction(data, "rho", label, default=0.0)
    vmax = _scalar(data, "max speed", _SPEED_KMH, label)
    trac_p = _scalar(data, "max traction power", _POWER_KW, label)
    trac_f = _scalar(data, "max traction force", _FORCE_KN, label)
    reg_p = _scalar(data, "max reg braking power", _POWER_KW, label)
    reg_f = _scalar(data, "max reg braking force", _FORCE_KN, label)
    pn_f = _scalar(data, "max pn braking force", _FORCE_KN, label, default=0.0)
    accel = _scalar(data, "max acceleration", _ACCEL, label)
    decel = _scalar(data, "max deceleration", _ACCEL, label)
    r0 = _scalar(data, "rolling resistance r0", _FORCE_KN, label)
    r1 = _scalar(data, "rolling resistance r1", _R1_KN_PER_KMH, label)
    r2 = _scalar(data, "rolling resistance r2", _R2_KN_PER_KMH2, label)
    has_eta = ("efficiency traction" in data, "efficiency reg brake" in data)
    if any(has_eta) and not all(has_eta):
        missing = "efficiency reg brake" if has_eta[0] else "efficiency traction"
        raise CaseError(missing, None, "TTOBench gives both efficiencies or neither", label)
    tables = {d: _loss_table(data[f], f, label) for d, f in FIELDS.items() if _is_table(data.get(f))}
    aux_kw = no_load_loss_kw(tables)
    caps = {"traction": (trac_f, trac_p), "regen": (reg_f, reg_p)}
    maps = {d: map_from_loss_table(d, rows, *caps[d], aux_kw, label) for d, rows in tables.items()}
    eta_t = maps["traction"].peak if "traction" in maps else _fraction(data, "efficiency traction", label, default=1.0)
    eta_r = maps["regen"].peak if "regen" in maps else _fraction(data, "efficiency reg brake", label, default=0.0)
    for key, value in (("mass", mass_t), ("max speed", vmax), ("max traction power", trac_p),
                       ("max traction force", trac_f), ("max reg braking power", reg_p),
                       ("max reg braking force", reg_f)):
        if value <= 0:
            raise CaseError(f"{key}.value", data[key]["value"], "must be > 0", label)
    if pn_f < 0:
        raise CaseError("max pn braking force.value", data["max pn braking force"]["value"], "must be >= 0", label)
    file_length = _scalar(data, "length", _LENGTH, label)
    if train_length_m is None:
        length = file_length
    else:
        length = _number("train_length_m", train_length_m, "from_ttobench")
        if length < 0:
            raise CaseError("train_length_m", train_length_m, "must be >= 0 (0 = point mass)", "from_ttobench")
        length = length or None
    try:
        train = Train(
            name=data["metadata"]["id"], mass_t=mass_t, rotary_factor=rho,
            length_m=length if length else POINT_MASS_LENGTH_M, max_speed_kmh=vmax,
            max_accel_ms2=accel, max_decel_ms2=decel, traction_efficiency=eta_t, regen_efficiency=eta_r,
            resistance=DavisResistance(r0, r1, r2, unit="kN", speed_unit="kmh"),
            traction=ForceCurve(max_force_kn=trac_f, max_power_kw=trac_p),
            braking=braking_curve(reg_f, reg_p, pn_f, vmax),
            regen_max_force_kn=reg_f, regen_max_power_kw=reg_p, aux_power_kw=aux_kw,
            traction_efficiency_map=maps.get("traction"), regen_efficiency_map=maps.get("regen"),
        )
    except CaseError as err:  # name the TTOBench field behind the model's field
        raise CaseError(_TTOBENCH_FIELD.get(err.field, err.field), err.value, err.reason, label) from None
    return TTOBenchTrain(id=data["metadata"]["id"], train=train, length_m=length, metadata=dict(data["metadata"]),
                         n_seats=counts["num seats"], n_coaches=counts["num coaches"],
                         tunnel_resistance=tunnel_resistance)


_LOSS_COLUMNS = (("load", _FRACTION), ("velocity", _SPEED_KMH), ("losses", _POWER_KW))


def _is_table(entry: Any) -> bool:
    """An efficiency given as a loss table (``units``/``values``) rather than one ``{unit, value}``."""
    return isinstance(entry, Mapping) and ("units" in entry or "values" in entry)


def _loss_table(entry: Any, key: str, source: str) -> tuple[tuple[float, float, float], ...]:
    """An efficiency's loss table ``[[load, velocity, losses], ...]`` as rows ``(load fraction, km/h,
    kW)``, each number finite and >= 0 (:mod:`pymoo_rail.cases.ttobench_efficiency` reads them)."""
    factors, values = _table_entry(entry, key, _LOSS_COLUMNS, source)
    if not values:
        raise CaseError(f"{key}.values", values, "needs at least one row [load, velocity, losses]", source)
    rows = []
    for k, row in enumerate(values):
        converted = tuple(_convert(_number(f"{key}.values[{k}]", x, source), f) for x, f in zip(row, factors))
        if min(converted) < 0.0:
            raise CaseError(f"{key}.values[{k}]", row, "load, velocity and losses must be >= 0", source)
        rows.append(converted)
    return tuple(rows)


def _count(data: Mapping, key: str, source: str) -> int | None:
    """``num seats`` / ``num coaches``: kept with the train (they do not change the physics)."""
    if key not in data:
        return None
    value = _scalar(data, key, {"-": (1.0, 1.0)}, source)
    if value != int(value) or value < 0:
        raise CaseError(f"{key}.value", data[key]["value"], "must be a whole number >= 0", source)
    return int(value)


_TUNNEL_COEF_KN_PER_KMH2 = {"kN/(km/h)^2": (1.0, 1.0), "N/(m/s)^2": (1.0, 1000.0 * KMH_PER_MS**2),
                            "kg/m": (1.0, 1000.0 * KMH_PER_MS**2)}


def _tunnel_resistance(entry: Any, source: str) -> tuple[tuple[float, float], ...]:
    """``tunnel resistance`` rows ``(cross section m^2, extra v^2 coefficient in kN/(km/h)^2)``.

    Read and checked, then a :class:`TTOBenchWarning`: the kernels' resistance depends on speed only
    through the train's Davis terms, so an extra ``c v^2`` inside tunnels is not modelled.
    """
    factors, values = _table_entry(entry, "tunnel resistance", (("cross section", _AREA_M2),
                                                                ("coefficient", _TUNNEL_COEF_KN_PER_KMH2)), source)
    rows = []
    for k, row in enumerate(values):
        area = _number(f"tunnel resistance.values[{k}]", row[0], source)
        coef = _convert(_number(f"tunnel resistance.values[{k}]", row[1], source), factors[1])
        if area <= 0 or coef < 0:
            raise CaseError(f"tunnel resistance.values[{k}]", row, "needs a cross section > 0 and a coefficient >= 0",
                            source)
        rows.append((area, coef))
    _warn("tunnel resistance", "is not modelled: the extra aerodynamic drag c v^2 in tunnels is speed-dependent "
                               "and the kernels' line resistance is not; tunnels on the track get the "
                               "speed-independent 0.00013 L_s N/kN of Liu (2019) eq. 2-12 (tunnel_model='liu2019') "
                               "or nothing (tunnel_model='none')", source)
    return tuple(rows)


_TTOBENCH_FIELD = {
    "train.rotary_factor": "rho", "train.traction_efficiency": "efficiency traction",
    "train.regen_efficiency": "efficiency reg brake", "resistance.a": "rolling resistance r0",
    "resistance.b": "rolling resistance r1", "resistance.c": "rolling resistance r2",
    "train.max_accel_ms2": "max acceleration", "train.max_decel_ms2": "max deceleration",
}


def _boundary_speed_ms(field: str, kmh: float) -> float:
    if isinstance(kmh, bool) or not isinstance(kmh, (int, float)) or not math.isfinite(kmh) or kmh < 0.0:
        raise CaseError(field, kmh, "must be a finite number of km/h >= 0")
    return kmh / KMH_PER_MS


def from_ttobench(track_path: Source, train_path: Source, from_stop: StopRef, to_stop: StopRef,
                  planned_time_s: float, *, dwell_s: float = 0.0, stop_names: Sequence[str] | None = None,
                  train_length_m: float | None = None, name: str | None = None,
                  initial_speed_kmh: float = 0.0, final_speed_kmh: float = 0.0,
                  curve_model: str = "tang2020", tunnel_model: str = "liu2019",
                  allow_implausible: bool | Sequence[str] = False) -> Case:
    """The run of a TTOBench train between two stops of a TTOBench track, as a :class:`Case`.

    Parameters
    ----------
    track_path, train_path : str, Path or dict
        TTOBench JSON files (or their parsed objects).
    from_stop, to_stop : int, str or float
        Departure and arrival stop: an index into the track's stops (int, negative counts from the
        end), a name (str, with ``stop_names``), or a position in m (float, within 0.5 m of a stop).
        Stops in between are passed without stopping.
    planned_time_s : float
        Planned running time (TTOBench tracks carry none).
    dwell_s : float
        Dwell at the arrival stop.
    stop_names : sequence of str, optional
        One name per stop of the track (e.g. :data:`YIZHUANG_STOP_NAMES`).
    train_length_m : float, optional
        ``None``: the train file's ``length`` if it has one, else a point mass (TTOBench's own
        convention). ``0``: a point mass. ``> 0``: this length, with limits over the whole train and
        gradients averaged over it.
    name : str, optional
        Case name (default ``"<track id>[<i>-<j>]"``).
    initial_speed_kmh, final_speed_kmh : float
        Speeds at ``from_stop`` and ``to_stop`` (default 0: a stop at both); TTOBench benchmark
        formulations such as the ms-eetc one start and end at a small speed (e.g. 1 m/s).
    curve_model : {"tang2020", "roeckl"}
        Curve resistance from the track's ``curvatures``: ``600 / R`` N/kN (Tang et al. (2020)) or
        Roeckl's standard-gauge formula (``docs/ttobench.md`` compares them).
    tunnel_model : {"liu2019", "none"}
        Resistance of the track's ``tunnels``: Liu (2019) eq. 2-12, ``0.00013 L_s`` N/kN, or none.
    allow_implausible : bool or sequence of str
        Waive the plausibility bounds, as in :class:`~pymoo_rail.model.Case`.
    """
    track = read_track(track_path)
    tt_train = read_train(train_path, train_length_m=train_length_m)
    i = track.stop_index(from_stop, stop_names)
    j = track.stop_index(to_stop, stop_names)
    if j <= i:
        raise CaseError("to_stop", to_stop, f"must lie after from_stop {from_stop!r} (stop {i} at "
                                            f"{track.stops_m[i]} m) in the track's direction")
    stop_label = (lambda k: f"{stop_names[k]} (stop {k}, {track.stops_m[k]:g} m)") if stop_names else \
        (lambda k: f"stop {k} at {track.stops_m[k]:g} m")
    return case_between(track, tt_train, track.stops_m[i], track.stops_m[j], planned_time_s, dwell_s=dwell_s,
                        name=name or f"{track.id}[{i}-{j}]", labels=(stop_label(i), stop_label(j)),
                        curve_model=curve_model, tunnel_model=tunnel_model, initial_speed_kmh=initial_speed_kmh,
                        final_speed_kmh=final_speed_kmh, allow_implausible=allow_implausible)


def looks_like(head: bytes) -> bool:
    """True when the start of a file reads as a TTOBench JSON object (a track, train or journey)."""
    text = head.lstrip(b"\xef\xbb\xbf").lstrip()
    return text.startswith(b"{") and b'"metadata"' in text


def read_train_file(path: Source, *, train_length_m: float | None = None) -> Train:
    """The format registry's train reader: the :class:`Train` of a TTOBench train file."""
    return read_train(path, train_length_m=train_length_m).train


def read_case(track_path: Source, *, train: Source, from_stop: StopRef = 0, to_stop: StopRef = -1,
              planned_time_s: float, allow_implausible: bool | Sequence[str] | None = None, **options) -> Case:
    """The format registry's reader: ``load_case(track.json, train=..., planned_time_s=...)``.

    The run of ``train`` from ``from_stop`` (default the first stop) to ``to_stop`` (default the
    last) of the track; further keywords as in :func:`from_ttobench`.
    """
    return from_ttobench(track_path, train, from_stop, to_stop, planned_time_s,
                         allow_implausible=False if allow_implausible is None else allow_implausible, **options)


def case_between(track: TTOBenchTrack, tt_train: TTOBenchTrain, start_m: float, end_m: float,
                 planned_time_s: float, *, dwell_s: float = 0.0, name: str | None = None,
                 labels: tuple[str, str] | None = None, curve_model: str = "tang2020",
                 tunnel_model: str = "liu2019", initial_speed_kmh: float = 0.0,
                 final_speed_kmh: float = 0.0, allow_implausible: bool | Sequence[str] = False) -> Case:
    """The run from ``start_m`` to ``end_m`` on a read track (any positions, e.g. a journey's stops).

    Arguments as in :func:`from_ttobench`; ``labels`` name the two ends in the case's source.
    """
    if not 0.0 <= start_m < end_m <= track.length_m:
        raise CaseError("start_m, end_m", (start_m, end_m), f"must satisfy 0 <= start < end <= {track.length_m}")
    point_mass = tt_train.length_m is None
    line = track.line("point_mass" if point_mass else "train_length", curve_model=curve_model,
                      tunnel_model=tunnel_model).slice(start_m, end_m)
    a, b = labels or (f"{start_m:g} m", f"{end_m:g} m")
    model = "point mass" if point_mass else f"train of {tt_train.length_m:g} m (limits over its length)"
    source = (f"TTOBench track {track.id} ({track.metadata.get('library version', '?')}), "
              f"{a} -> {b}; TTOBench train {tt_train.id} "
              f"({tt_train.metadata.get('library version', '?')}); {model}; curves {curve_model}, tunnels "
              f"{tunnel_model}; converted by pymoo_rail.cases.ttobench. {TTOBENCH_NOTICE}.")
    return Case(name=name or f"{track.id}[{start_m:g}-{end_m:g}]", train=tt_train.train, line=line,
                planned_time_s=planned_time_s, dwell_s=dwell_s, source=source,
                initial_speed_ms=_boundary_speed_ms("initial_speed_kmh", initial_speed_kmh),
                final_speed_ms=_boundary_speed_ms("final_speed_kmh", final_speed_kmh),
                description=f"{track.id} {a} -> {b}, {line.length_m:g} m, train {tt_train.id}",
                allow_implausible=allow_implausible)


__all__ = ["from_ttobench", "case_between", "read_case", "read_train_file", "looks_like", "read_journey", "TTOBenchWarning",
           "TUNNEL_MODELS", "CLOTHOID_PIECE_M", "read_track", "read_train", "TTOBenchTrack", "TTOBenchTrain",
           "braking_curve", "YIZHUANG_TRACK", "BEIJING_SUBWAY_TRAIN", "YIZHUANG_STOP_NAMES", "POINT_MASS_LENGTH_M",
           "TTOBENCH_LICENSE", "TTOBENCH_NOTICE", "LIBRARY_VERSION", "DATA_DIR", "Source", "StopRef"]
