"""OSRD railjson infrastructure: a path over the track graph to a :class:`~pymoo_rail.model.Line`.

A railjson *infra* (OSRD, OpenRail Association, LGPL-3.0) is a graph of *track sections* (each with
its length, slopes in m/km and curves by radius, in the track's own coordinate from its BEGIN to its
END) joined by *switches* (links, point switches, crossings, slip switches), with *speed sections*
(a default limit and one per train category tag, on directional track ranges), *electrifications*
(a voltage on track ranges), *neutral sections* (directional ranges without traction power) and
*operational points* (stations, each with parts on one or more tracks).

A path is a list of :class:`PathStep` (a track, the part of it used, the direction); it is given
track by track (:meth:`RailjsonInfra.path`) or found as the shortest route between two operational
points (:meth:`RailjsonInfra.shortest_path`, Dijkstra over the track graph, never reversing).
:func:`path_line` reads the properties along it into a ``Line``:

- gradients: the slopes (+ uphill in the track's direction, negated when the path runs STOP_TO_START),
  0 where a track has none (as OSRD);
- curves: ``|radius|`` (OSRD signs the radius by side; radius 0 is straight), resisted with OSRD's
  ``800 / R`` (``curve_model = "osrd"``);
- speed limits: at each point the lowest limit of the speed sections that apply in the path's
  direction, each section giving its limit for the train's category tag if it has one and its
  default ``speed_limit`` otherwise (OSRD's rule); sections bound to routes (``on_routes``) apply
  only when the path's routes are given; where no section applies the limit is
  ``default_limit_kmh`` (OSRD uses the train's maximum speed: :func:`~pymoo_rail.cases.railjson.railjson_case`
  passes it), else a :class:`CaseError` naming the track range;
- neutral sections (ranges in the path's direction) and, for an electric traction mode, every
  stretch not electrified at the mode's voltage become ``line.neutral_sections`` (no traction).
"""

from __future__ import annotations

import heapq
import math
from collections.abc import Iterable, Mapping, Sequence
from dataclasses import dataclass

from pymoo_rail.constants import KMH_PER_MS
from pymoo_rail.cases.railjson_rolling_stock import Source, load_json, number, warn_field
from pymoo_rail.model import CaseError, Line

START_TO_STOP = "START_TO_STOP"
STOP_TO_START = "STOP_TO_START"
DIRECTIONS = (START_TO_STOP, STOP_TO_START)

# OSRD's built-in switch types: ports and the port pairs each position connects
BUILTIN_SWITCH_TYPES: dict[str, tuple[tuple[str, str], ...]] = {
    "link": (("A", "B"),),
    "point_switch": (("A", "B1"), ("A", "B2")),
    "crossing": (("A1", "B1"), ("A2", "B2")),
    "single_slip_switch": (("A1", "B1"), ("A2", "B2"), ("A1", "B2")),
    "double_slip_switch": (("A1", "B1"), ("A1", "B2"), ("A2", "B1"), ("A2", "B2")),
}
# rounding of positions (m) and speeds (km/h) read from the file: sums of offsets carry float noise
POSITION_DIGITS = 6
SPEED_DIGITS = 6

Endpoint = tuple[str, str]  # (track id, "BEGIN" | "END")


@dataclass(frozen=True)
class TrackSection:
    """One track section: length, slopes ``(begin_m, end_m, permille)``, curves ``(begin_m, end_m, radius_m)``."""

    id: str
    length_m: float
    slopes: tuple[tuple[float, float, float], ...]
    curves: tuple[tuple[float, float, float], ...]


@dataclass(frozen=True)
class PathStep:
    """The part ``[begin_m, end_m]`` (track coordinates) of a track, run in ``direction``."""

    track: str
    begin_m: float
    end_m: float
    direction: str

    @property
    def length_m(self) -> float:
        """Length of the step (m)."""
        return self.end_m - self.begin_m


@dataclass(frozen=True)
class RangeValue:
    """A value on a track range, applying in some directions (``None``: both)."""

    track: str
    begin_m: float
    end_m: float
    direction: str | None
    value: object


@dataclass(frozen=True)
class SpeedSection:
    """A speed section: its default limit (m/s, or ``None``), its limits by category tag, its routes."""

    id: str
    speed_limit_ms: float | None
    by_tag_ms: Mapping[str, float]
    ranges: tuple[RangeValue, ...]
    on_routes: tuple[str, ...]

    def limit_ms(self, category: str | None) -> float | None:
        """The limit for a train of ``category`` (OSRD: the tag's limit if listed, else the default)."""
        if category is not None and category in self.by_tag_ms:
            return self.by_tag_ms[category]
        return self.speed_limit_ms


@dataclass(frozen=True)
class RailjsonInfra:
    """A railjson infrastructure, checked: the track graph and what lies on it."""

    source: str
    tracks: Mapping[str, TrackSection]
    links: Mapping[Endpoint, tuple[Endpoint, ...]]
    speed_sections: tuple[SpeedSection, ...]
    electrifications: tuple[RangeValue, ...]
    neutral_sections: tuple[RangeValue, ...]
    operational_points: Mapping[str, tuple[tuple[str, float], ...]]

    def path(self, tracks: Sequence[tuple[str, str]], begin_m: float | None = None,
             end_m: float | None = None) -> tuple[PathStep, ...]:
        """A path along ``tracks`` (``(track id, direction)`` pairs, consecutive tracks connected).

        ``begin_m`` is the start on the first track and ``end_m`` the end on the last, in track
        coordinates (default: the whole tracks).
        """
        if not tracks:
            raise CaseError("path", [], "needs at least one (track, direction)", self.source)
        steps = []
        for k, entry in enumerate(tracks):
            if not (isinstance(entry, (tuple, list)) and len(entry) == 2):
                raise CaseError(f"path[{k}]", entry, "must be a (track id, direction) pair", self.source)
            track, direction = entry
            section = self.track(track, f"path[{k}]")
            if direction not in DIRECTIONS:
                raise CaseError(f"path[{k}].direction", direction, f"must be one of {DIRECTIONS}", self.source)
            if k > 0:
                previous, previous_dir = tracks[k - 1]
                exit_point = (previous, "END" if previous_dir == START_TO_STOP else "BEGIN")
                entry_point = (track, "BEGIN" if direction == START_TO_STOP else "END")
                if entry_point not in self.links.get(exit_point, ()):
                    raise CaseError(f"path[{k}]", list(entry), f"is not connected to the end of track '{previous}' "
                                                               f"run {previous_dir}", self.source)
            steps.append(PathStep(track, 0.0, section.length_m, direction))
        if begin_m is not None:
            steps[0] = self._cut(steps[0], begin_m, "begin_m", start=True)
        if end_m is not None:
            steps[-1] = self._cut(steps[-1], end_m, "end_m", start=False)
        for k, step in enumerate(steps):
            if step.length_m <= 0:
                raise CaseError(f"path[{k}]", step, "has no length: check begin_m / end_m and the directions",
                                self.source)
        return tuple(steps)

    def path_from_track_ranges(self, ranges: Sequence[Mapping]) -> tuple[PathStep, ...]:
        """A path from OSRD's directional track ranges (``{track, begin, end, direction}``, e.g. the
        ``track_sections`` of the route paths of an OSRD pathfinding result), consecutive ranges of a
        track merged; the tracks must be connected and the ranges contiguous."""
        merged: list[list] = []
        for k, rng in enumerate(ranges):
            where = f"track_ranges[{k}]"
            if not isinstance(rng, Mapping):
                raise CaseError(where, rng, "must be an object {track, begin, end, direction}", self.source)
            begin = number(rng, "begin", self.source, field=f"{where}.begin")
            end = number(rng, "end", self.source, field=f"{where}.end")
            track, direction = rng.get("track"), rng.get("direction")
            if merged and merged[-1][0] == track and merged[-1][3] == direction:
                joint = merged[-1][2] if direction == START_TO_STOP else merged[-1][1]
                if abs((begin if direction == START_TO_STOP else end) - joint) > 1e-6:
                    raise CaseError(where, [begin, end], f"does not continue the previous range of track '{track}'",
                                    self.source)
                merged[-1][1], merged[-1][2] = min(merged[-1][1], begin), max(merged[-1][2], end)
            else:
                merged.append([track, begin, end, direction])
        if not merged:
            raise CaseError("track_ranges", [], "needs at least one range", self.source)
        for m in merged[1:-1]:
            if m[0] in self.tracks and (m[1] > 1e-6 or m[2] < self.tracks[m[0]].length_m - 1e-6):
                raise CaseError(f"track_ranges (track '{m[0]}')", [m[1], m[2]],
                                "a track inside the path must be run over its whole length", self.source)
        first = merged[0][1] if merged[0][3] == START_TO_STOP else merged[0][2]
        last = merged[-1][2] if merged[-1][3] == START_TO_STOP else merged[-1][1]
        return self.path([(m[0], m[3]) for m in merged], first, last)

    def _cut(self, step: PathStep, position_m: float, field: str, *, start: bool) -> PathStep:
        number({field: position_m}, field, self.source)
        if not step.begin_m <= position_m <= step.end_m:
            raise CaseError(field, position_m, f"lies outside the track '{step.track}' [{step.begin_m}, "
                                               f"{step.end_m}] m", self.source)
        forward = step.direction == START_TO_STOP
        if start == forward:  # the start of a forward step or the end of a backward one moves its begin
            return PathStep(step.track, position_m, step.end_m, step.direction)
        return PathStep(step.track, step.begin_m, position_m, step.direction)

    def track(self, track: object, field: str = "track") -> TrackSection:
        """A track section by id, else a :class:`CaseError`."""
        if track not in self.tracks:
            raise CaseError(field, track, "no such track section in the infrastructure", self.source)
        return self.tracks[track]

    def operational_point(self, name: str) -> tuple[tuple[str, float], ...]:
        """The parts ``(track, position_m)`` of an operational point, else a :class:`CaseError`."""
        if name not in self.operational_points:
            known = ", ".join(sorted(self.operational_points)) or "none"
            raise CaseError("operational point", name, f"not in the infrastructure (known: {known})", self.source)
        return self.operational_points[name]

    def shortest_path(self, from_point: str, to_point: str) -> tuple[PathStep, ...]:
        """The shortest path from a part of one operational point to a part of another.

        Dijkstra over (track, direction) states; the train never reverses. Ties go to the first
        found in the file's order of parts and tracks, so the result is deterministic.
        """
        starts, goals = self.operational_point(from_point), self.operational_point(to_point)
        goal_on: dict[str, list[float]] = {}
        for track, position in goals:
            goal_on.setdefault(track, []).append(position)
        best: tuple[float, tuple[PathStep, ...]] | None = None
        queue: list[tuple[float, int, tuple[PathStep, ...]]] = []
        counter = 0
        for track, position in starts:
            length = self.tracks[track].length_m
            for direction in DIRECTIONS:
                forward = direction == START_TO_STOP
                step = PathStep(track, position, length, direction) if forward else \
                    PathStep(track, 0.0, position, direction)
                heapq.heappush(queue, (0.0, counter, (step,)))
                counter += 1
        settled: set[tuple[str, str]] = set()  # whole tracks entered at their entry end
        while queue:
            cost, _, steps = heapq.heappop(queue)
            if best is not None and cost >= best[0]:
                break
            step = steps[-1]
            if len(steps) > 1:
                if (step.track, step.direction) in settled:
                    continue
                settled.add((step.track, step.direction))
            forward = step.direction == START_TO_STOP
            entry = step.begin_m if forward else step.end_m
            for goal in goal_on.get(step.track, ()):
                ahead = goal - entry if forward else entry - goal
                if ahead < 0 or (ahead == 0 and len(steps) == 1) or (best is not None and cost + ahead >= best[0]):
                    continue
                if ahead == 0:  # the goal is where the previous track ends
                    best = (cost, steps[:-1])
                else:
                    cut = PathStep(step.track, step.begin_m, goal, step.direction) if forward else \
                        PathStep(step.track, goal, step.end_m, step.direction)
                    best = (cost + ahead, steps[:-1] + (cut,))
            exit_point = (step.track, "END" if forward else "BEGIN")
            for track, endpoint in self.links.get(exit_point, ()):
                direction = START_TO_STOP if endpoint == "BEGIN" else STOP_TO_START
                if (track, direction) not in settled:
                    heapq.heappush(queue, (cost + step.length_m, counter,
                                           steps + (PathStep(track, 0.0, self.tracks[track].length_m, direction),)))
                    counter += 1
        if best is None:
            raise CaseError("path", f"{from_point} -> {to_point}", "no path over the track graph joins the two "
                                                                  "operational points", self.source)
        return best[1]


def _ranges(entries: object, field: str, source: str, value: object, tracks: Mapping[str, TrackSection],
            direction_key: str) -> list[RangeValue]:
    if not isinstance(entries, list):
        raise CaseError(field, entries, "must be an array of track ranges", source)
    out = []
    for k, entry in enumerate(entries):
        where = f"{field}[{k}]"
        if not isinstance(entry, Mapping) or entry.get("track") not in tracks:
            raise CaseError(f"{where}.track", entry.get("track") if isinstance(entry, Mapping) else entry,
                            "must name a track section of the infrastructure", source)
        begin = number(entry, "begin", source, field=f"{where}.begin")
        end = number(entry, "end", source, field=f"{where}.end")
        if end < begin or end > tracks[entry["track"]].length_m + 1e-6:
            raise CaseError(where, [begin, end], f"must satisfy begin <= end <= the track's length "
                                                 f"{tracks[entry['track']].length_m} m", source)
        direction = entry.get(direction_key)
        if direction not in DIRECTIONS + ("BOTH",):
            raise CaseError(f"{where}.{direction_key}", direction, f"must be one of {DIRECTIONS + ('BOTH',)}", source)
        if end > begin:
            out.append(RangeValue(entry["track"], begin, end, None if direction == "BOTH" else direction, value))
    return out


def _track(entry: object, k: int, source: str) -> TrackSection:
    where = f"track_sections[{k}]"
    if not isinstance(entry, Mapping) or not isinstance(entry.get("id"), str):
        raise CaseError(f"{where}.id", entry, "a track section needs a string id", source)
    length = number(entry, "length", source, field=f"{where}.length", positive=True)
    rows = {}
    for key, value_key in (("slopes", "gradient"), ("curves", "radius")):
        items = entry.get(key, [])
        if not isinstance(items, list):
            raise CaseError(f"{where}.{key}", items, "must be an array", source)
        parsed = []
        for j, item in enumerate(items):
            if not isinstance(item, Mapping):
                raise CaseError(f"{where}.{key}[{j}]", item, "must be an object", source)
            begin = number(item, "begin", source, field=f"{where}.{key}[{j}].begin")
            end = number(item, "end", source, field=f"{where}.{key}[{j}].end")
            value = item.get(value_key)
            if isinstance(value, bool) or not isinstance(value, (int, float)) or not math.isfinite(value):
                raise CaseError(f"{where}.{key}[{j}].{value_key}", value, "must be a finite number", source)
            if not begin < end <= length + 1e-6:
                raise CaseError(f"{where}.{key}[{j}]", [begin, end], f"must satisfy begin < end <= length {length}",
                                source)
            parsed.append((begin, min(end, length), float(value)))
        parsed.sort()
        for j in range(1, len(parsed)):
            if parsed[j][0] < parsed[j - 1][1] - 1e-9:
                raise CaseError(f"{where}.{key}", [list(parsed[j - 1]), list(parsed[j])], "ranges overlap", source)
        rows[key] = tuple(parsed)
    return TrackSection(entry["id"], length, rows["slopes"], rows["curves"])


def is_infra(data: Mapping) -> bool:
    """Whether a parsed JSON object is a railjson infrastructure (it has track sections and switches)."""
    return isinstance(data, Mapping) and "track_sections" in data and "switches" in data


def _read_tracks(data: Mapping, label: str) -> dict[str, TrackSection]:
    raw_tracks = data["track_sections"]
    if not isinstance(raw_tracks, list) or not raw_tracks:
        raise CaseError("track_sections", raw_tracks, "must be a non-empty array", label)
    tracks: dict[str, TrackSection] = {}
    for k, entry in enumerate(raw_tracks):
        section = _track(entry, k, label)
        if section.id in tracks:
            raise CaseError(f"track_sections[{k}].id", section.id, "duplicate track section id", label)
        tracks[section.id] = section
    return tracks


def _read_links(data: Mapping, label: str, tracks: Mapping[str, TrackSection]) -> dict[Endpoint, tuple[Endpoint, ...]]:
    """Which track ends the switches join (both ways), from the built-in and extended switch types."""
    switch_types = dict(BUILTIN_SWITCH_TYPES)
    for k, entry in enumerate(data.get("extended_switch_types", [])):
        groups = entry.get("groups", {}) if isinstance(entry, Mapping) else None
        if not isinstance(groups, Mapping):
            raise CaseError(f"extended_switch_types[{k}].groups", groups, "must be an object", label)
        switch_types[entry.get("id")] = tuple((c["src"], c["dst"]) for group in groups.values() for c in group)
    links: dict[Endpoint, list[Endpoint]] = {}
    for k, entry in enumerate(data["switches"]):
        kind = entry.get("switch_type") if isinstance(entry, Mapping) else None
        if kind not in switch_types:
            raise CaseError(f"switches[{k}].switch_type", kind, f"unknown switch type (known: "
                                                                f"{', '.join(sorted(switch_types))})", label)
        ports = entry.get("ports", {})
        for src, dst in switch_types[kind]:
            ends = []
            for port in (src, dst):
                end = ports.get(port) if isinstance(ports, Mapping) else None
                if not isinstance(end, Mapping) or end.get("track") not in tracks \
                        or end.get("endpoint") not in ("BEGIN", "END"):
                    raise CaseError(f"switches[{k}].ports.{port}", end, "must be {track, endpoint} of a track "
                                                                        "section of the infrastructure", label)
                ends.append((end["track"], end["endpoint"]))
            links.setdefault(ends[0], []).append(ends[1])
            links.setdefault(ends[1], []).append(ends[0])
    return {k: tuple(v) for k, v in links.items()}


def _read_speed_sections(data: Mapping, label: str, tracks: Mapping[str, TrackSection]) -> tuple[SpeedSection, ...]:
    speed_sections = []
    for k, entry in enumerate(data.get("speed_sections", [])):
        where = f"speed_sections[{k}]"
        default = number(entry, "speed_limit", label, field=f"{where}.speed_limit", positive=True, optional=True)
        tags = entry.get("speed_limit_by_tag") or {}
        if not isinstance(tags, Mapping):
            raise CaseError(f"{where}.speed_limit_by_tag", tags, "must be an object {tag: m/s}", label)
        by_tag = {tag: number(tags, tag, label, field=f"{where}.speed_limit_by_tag.{tag}", positive=True)
                  for tag in tags}
        routes = entry.get("on_routes") or []
        if not isinstance(routes, list) or not all(isinstance(r, str) for r in routes):
            raise CaseError(f"{where}.on_routes", routes, "must be an array of route ids", label)
        speed_sections.append(SpeedSection(
            id=str(entry.get("id", k)), speed_limit_ms=default, by_tag_ms=by_tag, on_routes=tuple(routes),
            ranges=tuple(_ranges(entry.get("track_ranges"), f"{where}.track_ranges", label, None, tracks,
                                 "applicable_directions"))))
    return tuple(speed_sections)


def _read_electric_ranges(data: Mapping, label: str, tracks: Mapping[str, TrackSection]) -> tuple[list, list]:
    """The electrified ranges (value: the voltage) and the neutral sections (value: lower pantograph)."""
    electrifications = []
    for k, entry in enumerate(data.get("electrifications", [])):
        voltage = entry.get("voltage")
        if not isinstance(voltage, str) or not voltage:
            raise CaseError(f"electrifications[{k}].voltage", voltage, "must be a voltage name", label)
        electrifications += _ranges(entry.get("track_ranges"), f"electrifications[{k}].track_ranges", label,
                                    voltage, tracks, "applicable_directions")
    neutral = []
    for k, entry in enumerate(data.get("neutral_sections", [])):
        lower = entry.get("lower_pantograph")
        if not isinstance(lower, bool):
            raise CaseError(f"neutral_sections[{k}].lower_pantograph", lower, "must be true or false", label)
        neutral += _ranges(entry.get("track_ranges"), f"neutral_sections[{k}].track_ranges", label, lower,
                           tracks, "direction")
    return electrifications, neutral


def _read_points(data: Mapping, label: str, tracks: Mapping[str, TrackSection]) -> dict[str, tuple[tuple[str, float], ...]]:
    points: dict[str, tuple[tuple[str, float], ...]] = {}
    for k, entry in enumerate(data.get("operational_points", [])):
        parts = []
        for j, part in enumerate(entry.get("parts", [])):
            if part.get("track") not in tracks:
                raise CaseError(f"operational_points[{k}].parts[{j}].track", part.get("track"),
                                "must name a track section of the infrastructure", label)
            position = number(part, "position", label, field=f"operational_points[{k}].parts[{j}].position")
            if position > tracks[part["track"]].length_m + 1e-6:
                raise CaseError(f"operational_points[{k}].parts[{j}].position", position,
                                f"is beyond the end of track '{part['track']}'", label)
            parts.append((part["track"], position))
        points[str(entry.get("id"))] = tuple(parts)
    return points


def read_infra(source: Source) -> RailjsonInfra:
    """Read and check a railjson infrastructure file (or its parsed JSON object).

    Signalling objects (routes, signals, detectors, buffer stops) are not read: a run between two
    stops does not need them.
    """
    data, label = load_json(source, "infrastructure")
    if not is_infra(data):
        raise CaseError("track_sections", None, "is required: not a railjson infrastructure "
                                                "(needs track_sections and switches)", label)
    tracks = _read_tracks(data, label)
    electrifications, neutral = _read_electric_ranges(data, label, tracks)
    if data.get("version") is None:
        warn_field("version", "is missing: read as railjson infrastructure 3.4", label)
    return RailjsonInfra(source=label, tracks=tracks, links=_read_links(data, label, tracks),
                         speed_sections=_read_speed_sections(data, label, tracks),
                         electrifications=tuple(electrifications), neutral_sections=tuple(neutral),
                         operational_points=_read_points(data, label, tracks))


# ------------------------------------------------------------------------------------- along the path


def _offsets(steps: Sequence[PathStep]) -> list[float]:
    out, total = [], 0.0
    for step in steps:
        out.append(total)
        total += step.length_m
    return out + [total]


def _on_path(steps: Sequence[PathStep], offsets: Sequence[float], track: str, begin: float, end: float,
             direction: str | None) -> Iterable[tuple[float, float, bool]]:
    """Path intervals ``(start_m, end_m, reversed)`` of a track range (in the given directions)."""
    for step, s0 in zip(steps, offsets):
        if step.track != track or (direction is not None and direction != step.direction):
            continue
        a, b = max(begin, step.begin_m), min(end, step.end_m)
        if b <= a:
            continue
        if step.direction == START_TO_STOP:
            yield s0 + a - step.begin_m, s0 + b - step.begin_m, False
        else:
            yield s0 + step.end_m - b, s0 + step.end_m - a, True


def _round(x: float) -> float:
    return round(x, POSITION_DIGITS) + 0.0


def _tiles(length_m: float, intervals: Iterable[tuple[float, float, float]], fill: float | None,
           combine, field: str, source: str) -> tuple[tuple[float, float, float], ...]:
    """Rows tiling [0, length]: ``combine`` of the values of the intervals over each piece, ``fill``
    where none lies (``None``: a :class:`CaseError`), adjacent equal rows merged."""
    intervals = [(_round(a), _round(b), v) for a, b, v in intervals]
    cuts = sorted({0.0, _round(length_m)} | {x for a, b, _ in intervals for x in (a, b)})
    rows: list[list[float]] = []
    for a, b in zip(cuts[:-1], cuts[1:]):
        if b <= a:
            continue
        values = [v for s, e, v in intervals if s <= a and e >= b]
        if values:
            value = combine(values)
        elif fill is not None:
            value = fill
        else:
            raise CaseError(field, f"path [{a}, {b}] m", "no value applies here", source)
        if rows and rows[-1][2] == value and rows[-1][1] == a:
            rows[-1][1] = b
        else:
            rows.append([a, b, value])
    return tuple((a, b, v) for a, b, v in rows)


def _value_at(rows: Sequence[tuple[float, float, float]], position_m: float) -> float:
    """The value of tiling rows at a position (the row starting there at a boundary)."""
    for start, end, value in rows:
        if start <= position_m < end:
            return value
    return rows[-1][2]


def _union(intervals: Iterable[tuple[float, float]]) -> tuple[tuple[float, float], ...]:
    out: list[list[float]] = []
    for a, b in sorted((_round(a), _round(b)) for a, b in intervals):
        if out and a <= out[-1][1]:
            out[-1][1] = max(out[-1][1], b)
        else:
            out.append([a, b])
    return tuple((a, b) for a, b in out if b > a)


def path_line(infra: RailjsonInfra, steps: Sequence[PathStep], *, category: str | None = None,
              voltages: Sequence[str] | None = None, neutral_sections: bool = True, routes: Sequence[str] = (),
              default_limit_kmh: float | None = None, curve_model: str = "osrd",
              power_recovery_s: tuple[float, float] = (0.0, 0.0)) -> Line:
    """The :class:`Line` along a path (see the module docstring for each property).

    Parameters
    ----------
    infra : RailjsonInfra
    steps : sequence of PathStep
        From :meth:`RailjsonInfra.path` or :meth:`RailjsonInfra.shortest_path`.
    category : str, optional
        The train's speed-limit tag (``speed_limit_by_tag``); ``None``: the default limits.
    voltages : sequence of str, optional
        The electrifications the train can draw from (its electric traction modes, e.g.
        ``("25000V",)``): stretches electrified at none of them have no traction. ``None``:
        electrification is not looked at (a thermal mode).
    neutral_sections : bool
        Whether the infrastructure's neutral sections cut the traction (an electric mode).
    power_recovery_s : (float, float)
        Time without traction after a neutral section where the pantograph is lowered, and after
        one where it is not (the rolling stock's ``raise_pantograph_time`` and
        ``electrical_power_startup_time``). The no-traction stretch is lengthened by the distance
        covered in that time at the speed limit, an upper bound of the true distance. Default
        ``(0, 0)``: as OSRD's simulator, which does not apply these times.
    routes : sequence of str
        Routes of the path, for speed sections bound to routes (default: none apply).
    default_limit_kmh : float, optional
        The limit where no speed section applies (OSRD: the train's maximum speed).
    curve_model : str
        ``line.curve_model`` (default ``"osrd"``: OSRD's ``800 / R``).
    """
    steps = tuple(steps)
    offsets = _offsets(steps)
    length = offsets[-1]
    slopes, curves, limits, powered, cut = [], [], [], [], []
    for track in dict.fromkeys(step.track for step in steps):  # each track once: _on_path finds every pass
        section = infra.tracks[track]
        for begin, end, gradient in section.slopes:
            for a, b, backward in _on_path(steps, offsets, track, begin, end, None):
                slopes.append((a, b, -gradient if backward else gradient))
        for begin, end, radius in section.curves:
            if radius != 0.0:
                curves += [(a, b, abs(radius)) for a, b, _ in _on_path(steps, offsets, track, begin, end, None)]
    for section in infra.speed_sections:
        if section.on_routes and not set(section.on_routes) & set(routes):
            continue
        limit = section.limit_ms(category)
        if limit is None:
            continue
        kmh = round(limit * KMH_PER_MS, SPEED_DIGITS)
        for rng in section.ranges:
            limits += [(a, b, kmh) for a, b, _ in _on_path(steps, offsets, rng.track, rng.begin_m, rng.end_m,
                                                             rng.direction)]
    if voltages is not None:
        for rng in infra.electrifications:
            if rng.value in voltages:
                powered += [(a, b, 1.0) for a, b, _ in _on_path(steps, offsets, rng.track, rng.begin_m, rng.end_m,
                                                                  rng.direction)]
        for a, b, value in _tiles(length, powered, 0.0, max, "electrifications", infra.source):
            if value == 0.0:
                cut.append((a, b))
    if default_limit_kmh is not None:
        number({"default_limit_kmh": default_limit_kmh}, "default_limit_kmh", infra.source, positive=True)
    try:
        speed_rows = _tiles(length, limits, default_limit_kmh, min, "speed_sections", infra.source)
    except CaseError as err:
        raise CaseError("speed_sections", err.value, f"no speed section applies here"
                        f"{' for category ' + repr(category) if category else ''}: give default_limit_kmh "
                        f"(OSRD then limits the train to its maximum speed)", infra.source) from None
    if neutral_sections:
        for rng in infra.neutral_sections:
            recovery_s = power_recovery_s[0] if rng.value else power_recovery_s[1]
            for a, b, _ in _on_path(steps, offsets, rng.track, rng.begin_m, rng.end_m, rng.direction):
                cut.append((a, min(length, b + recovery_s * _value_at(speed_rows, b) / KMH_PER_MS)))
    curve_rows = tuple((a, b, r) for a, b, r in _tiles(length, curves, 0.0, max, "curves", infra.source) if r > 0)
    return Line(length_m=_round(length), gradients=_tiles(length, slopes, 0.0, sum, "slopes", infra.source),
                speed_limits=speed_rows, curves=curve_rows, neutral_sections=_union(cut),
                gradient_model="train_length", curve_model=curve_model)


__all__ = ["RailjsonInfra", "TrackSection", "PathStep", "SpeedSection", "RangeValue", "read_infra", "path_line",
           "is_infra", "START_TO_STOP", "STOP_TO_START"]
