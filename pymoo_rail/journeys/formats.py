"""Journeys in files: one reader per format behind :func:`load_journey`, and the TTOBench export.

A journey needs the simulator (default planned times are the sections' minimum running times plus
a supplement) and the :class:`~pymoo_rail.journeys.Journey` type, both above :mod:`pymoo_rail.cases`
in the layers; so the journey readers live here, in the journeys room, and call the format modules
of :mod:`pymoo_rail.cases` (TTOBench tracks, trains and journey files, TOML) for the parsing. A new
journey format is one reader function here plus one line of :data:`JOURNEY_FORMATS`.
"""

from __future__ import annotations

import json
import math
from collections.abc import Callable
from dataclasses import dataclass, replace
from pathlib import Path
from typing import Sequence

import numpy as np

from pymoo_rail.cases import list_cases, load_case, ttobench
from pymoo_rail.cases.files import file_bytes
from pymoo_rail.cases.formats import HEAD_BYTES, call_reader
from pymoo_rail.cases.toml_case import read_toml
from pymoo_rail.cases.ttobench import POINT_MASS_LENGTH_M, TTOBENCH_NOTICE
from pymoo_rail.cases.ttobench_writer import track_to_json, train_to_json, ttobench_id, write_pair
from pymoo_rail.model import CaseError
from pymoo_rail.journeys.journey import Journey
from pymoo_rail.journeys.timing import TimedJourney, TimingPoint, window_end_s, window_start_s, with_speed_caps
from pymoo_rail.sim import Simulator


def read_timing_points(source: ttobench.Source) -> tuple[str, str | None, tuple[TimingPoint, ...], dict]:
    """Read a TTOBench journey file: ``(id, associated track id, timing points, metadata)``.

    Checks the rules of the TTOBench journey format (ordered positions, equal positions only for an
    arrival/departure pair of stopping points, first and last points stops, lower <= upper bounds).
    """
    journey_id, track_id, rows, meta, label = ttobench.read_journey(source)
    values = [list(r) for r in rows]
    points = []
    for k, row in enumerate(rows):
        field = f"timing points.values[{k}]"
        pos = row[0]
        point = TimingPoint(*row)
        for lo, hi, what in ((point.earliest_s, point.latest_s, "time"),
                             (point.min_speed_kmh, point.max_speed_kmh, "speed")):
            if lo is not None and hi is not None and lo > hi:
                raise CaseError(field, row, f"the lower {what} constraint exceeds the upper one", label)
        if (point.min_speed_kmh or 0.0) < 0 or (point.max_speed_kmh is not None and point.max_speed_kmh < 0):
            raise CaseError(field, row, "speed constraints must be >= 0", label)
        if points and pos < points[-1].position_m:
            raise CaseError(field, row, "timing points must be ordered by position", label)
        if points and pos == points[-1].position_m and not (point.is_stop and points[-1].is_stop):
            raise CaseError(field, row, "equal positions are only allowed for the arrival and departure "
                                        "stopping points of one station", label)
        points.append(point)
    if len(points) < 2:
        raise CaseError("timing points.values", values, "needs at least two timing points", label)
    for k in (0, len(points) - 1):
        if not points[k].is_stop:
            raise CaseError(f"timing points.values[{k}]", values[k], "the first and last timing points must be "
                                                                    "stops (both speed constraints 0)", label)
    return journey_id, track_id, tuple(points), meta


def timed_journey_from_ttobench(journey_path: ttobench.Source, track_path: ttobench.Source,
                                train_path: ttobench.Source, *, train_length_m: float | None = None,
                                curve_model: str = "tang2020", tunnel_model: str = "liu2019") -> TimedJourney:
    """A TTOBench journey file on its track with a train, as sections and their timing points."""
    journey_id, track_id, points, _ = read_timing_points(journey_path)
    track = ttobench.read_track(track_path)
    if track_id is not None and track_id != track.id:
        raise CaseError("metadata.associated track", track_id, f"the journey belongs to another track "
                                                               f"(this one is {track.id!r})", str(journey_path))
    groups: list[list[TimingPoint]] = [[points[0]]]
    for point in points[1:]:
        groups[-1].append(point)
        if point.is_stop and point is not points[-1]:
            groups.append([point])
    # An intermediate station is two stopping points at one position: arrival ends one section,
    # departure starts the next (the grouping above put the arrival at the head of a one-point group).
    merged: list[list[TimingPoint]] = []
    for group in groups:
        if merged and len(group) >= 2 and group[0].position_m == group[1].position_m:
            group = group[1:]
        if len(group) >= 2:
            merged.append(group)
    stops = [g[0].position_m for g in merged] + [merged[-1][-1].position_m]
    tt_train = ttobench.read_train(train_path, train_length_m=train_length_m)
    sections, dwell = [], []
    for k, group in enumerate(merged):
        planned = window_end_s(group[-1]) - window_start_s(group[0])
        if not math.isfinite(planned):
            planned = 1.0  # no window: the solver picks the time
        case = ttobench.case_between(track, tt_train, stops[k], stops[k + 1], max(planned, 1.0),
                                     name=f"{journey_id}[{k}]", curve_model=curve_model, tunnel_model=tunnel_model)
        case = replace(case, line=with_speed_caps(case.line, group, stops[k]))
        sections.append(case)
        if k > 0:
            arrival = merged[k - 1][-1]
            dwell.append(max(0.0, window_start_s(group[0]) - window_end_s(arrival)))
    journey = Journey.from_sections(journey_id, sections, dwell, stops, source=sections[0].source)
    return TimedJourney(journey=journey, windows=tuple(tuple(g) for g in merged))


_TOML_TOP = {"name", "track", "train", "curve_model", "tunnel_model", "train_length_m", "timing_points"}
_TOML_POINT = ("position_m", "earliest_s", "latest_s", "min_speed_kmh", "max_speed_kmh")


def timed_journey_from_toml(path: str | Path) -> TimedJourney:
    """A journey with timing points from a TOML file (TTOBench track and train files beside it).

    ``name``, ``track`` and ``train`` (paths relative to the file), optional ``curve_model``,
    ``tunnel_model``, ``train_length_m``, and one ``[[timing_points]]`` table per point with
    ``position_m`` and any of ``earliest_s``, ``latest_s``, ``min_speed_kmh``, ``max_speed_kmh``
    (a stop has both speeds 0). The rules are those of TTOBench journey files.
    """
    path = Path(path)
    data = read_toml(path)
    for key in sorted(set(data) - _TOML_TOP):
        raise CaseError(key, data[key], f"unknown key (allowed: {', '.join(sorted(_TOML_TOP))})", str(path))
    for key in ("name", "track", "train", "timing_points"):
        if key not in data:
            raise CaseError(key, None, "is required", str(path))
    rows = []
    for k, point in enumerate(data["timing_points"]):
        if not isinstance(point, dict) or "position_m" not in point:
            raise CaseError(f"timing_points[{k}].position_m", None, "is required", str(path))
        for key in sorted(set(point) - set(_TOML_POINT)):
            raise CaseError(f"timing_points[{k}].{key}", point[key],
                            f"unknown key (allowed: {', '.join(_TOML_POINT)})", str(path))
        rows.append([point.get(key) for key in _TOML_POINT])
    journey = {"metadata": {"id": data["name"]},
               "timing points": {"units": {"position": "m", "lower time constraint": "s",
                                           "upper time constraint": "s", "lower speed constraint": "km/h",
                                           "upper speed constraint": "km/h"}, "values": rows}}
    return timed_journey_from_ttobench(journey, path.parent / data["track"], path.parent / data["train"],
                                       train_length_m=data.get("train_length_m"),
                                       curve_model=data.get("curve_model", "tang2020"),
                                       tunnel_model=data.get("tunnel_model", "liu2019"))


def journey_from_ttobench(track_path: ttobench.Source, train_path: ttobench.Source,
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
    return Journey.from_sections(name or f"{track.id}[{indices[0]}-{indices[-1]}]", sections, dwell,
                             tuple(track.stops_m[i] for i in indices), names, altitude, sections[0].source)

def journey_to_ttobench(journey: Journey, out_dir: str | Path, *, track_id: str | None = None,
                    train_id: str | None = None) -> tuple[Path, Path]:
    """Write the journey's line (its stops only) and train as TTOBench files.

    Positions restart at 0 at the first stop. Returns ``(track_path, train_path)``.
    """
    first = journey.sections[0]
    if journey.train.length_m > POINT_MASS_LENGTH_M and first.line.gradient_model != "train_length":
        raise CaseError("line.gradient_model", first.line.gradient_model,
                        "a train with a length is written with gradients averaged over it")
    license_text = TTOBENCH_NOTICE if "TTOBench" in journey.source else None
    meta = {"description": journey.name}
    if license_text:
        meta["license"] = license_text
    track_id = track_id or ttobench_id(journey.name)
    train_id = train_id or ttobench_id(journey.train.name or f"{journey.name}_train")
    track = track_to_json([c.line for c in journey.sections], track_id, altitude_m=journey.altitude_m,
                                   metadata=meta)
    train = train_to_json(journey.train, train_id,
                                   metadata={"license": license_text} if license_text else None)
    return write_pair(out_dir, track, train)


# ----------------------------------------------------------------------------------- load_journey


def _json_keys(path: Path) -> set[str]:
    """The top-level keys of a JSON object file (empty when it is not one)."""
    try:
        data = json.loads(path.read_text(encoding="utf-8"))
    except (OSError, UnicodeDecodeError, json.JSONDecodeError):
        return set()
    return set(data) if isinstance(data, dict) else set()


def _read_case_journey(path: Path, **options) -> Journey:
    """A case file (or built-in name) as the journey of its legs."""
    return Journey(case=load_case(path, **options))


def _read_ttobench_journey(path: Path, *, track: str | Path, train: str | Path, **options) -> TimedJourney:
    return timed_journey_from_ttobench(path, track, train, **options)


def _read_ttobench_track(path: Path, *, train: str | Path, **options) -> Journey:
    return journey_from_ttobench(path, train, **options)


def _read_toml_journey(path: Path, **options) -> TimedJourney:
    if options:
        raise CaseError("options", sorted(options), "a TOML journey file names its own track and train")
    return timed_journey_from_toml(path)


@dataclass(frozen=True)
class JourneyFormat:
    """One journey file format: a name, its suffix, a test of the file and its reader."""

    name: str
    suffix: str
    matches: Callable[[Path], bool]
    read: Callable[..., Journey | TimedJourney]


JOURNEY_FORMATS: tuple[JourneyFormat, ...] = (
    JourneyFormat("toml journey", ".toml", lambda p: b"timing_points" in file_bytes(p, HEAD_BYTES), _read_toml_journey),
    JourneyFormat("toml case", ".toml", lambda p: True, _read_case_journey),
    JourneyFormat("ttobench journey", ".json", lambda p: "timing points" in _json_keys(p), _read_ttobench_journey),
    JourneyFormat("ttobench track", ".json", lambda p: "stops" in _json_keys(p), _read_ttobench_track),
)


def load_journey(source: str | Path, **options) -> Journey | TimedJourney:
    """Load a journey from a file of any format of :data:`JOURNEY_FORMATS`, or a built-in case name.

    - a TOML journey file (``[[timing_points]]``, track and train named inside) or a TTOBench
      journey file (with ``track=`` and ``train=``): a :class:`TimedJourney`;
    - a TTOBench track (with ``train=`` and the keywords of :func:`journey_from_ttobench`): a
      :class:`Journey` calling at its stops;
    - a case file or a built-in case name (``"cooperative-pair"``): the :class:`Journey` of its legs.
    """
    path = Path(source)
    if not path.is_file():
        if str(source) in list_cases():
            return Journey(case=load_case(str(source), **options))
        raise CaseError("path", str(source), "no such journey file or built-in case")
    for fmt in JOURNEY_FORMATS:
        if path.suffix.lower() == fmt.suffix and fmt.matches(path):
            return call_reader(fmt.read, fmt.name, path, **options)
    known = ", ".join(f"{f.name} ({f.suffix})" for f in JOURNEY_FORMATS)
    raise CaseError("path", str(path), f"is in no known journey format (known: {known})", str(path))
