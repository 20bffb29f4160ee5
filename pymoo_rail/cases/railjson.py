"""OSRD railjson in the case-format registry: trains from rolling stocks, cases from an infrastructure,
a path and a rolling stock, and case files that name them.

>>> from pymoo_rail.cases import load_train, railjson_case
>>> train = load_train("tests/data/osrd/rolling_stocks/intercity-train.json", mode="25000V")  # doctest: +SKIP
>>> case = railjson_case("tests/data/osrd/infras/small_infra.json",
...                      "tests/data/osrd/rolling_stocks/intercity-train.json",
...                      from_point="Mid_West_station", to_point="Mid_East_station",
...                      planned_time_s=600.0)  # doctest: +SKIP

The formats, the mapping of every field and what is not represented: ``docs/railjson.md``.
"""

from __future__ import annotations

import json
import re
from collections.abc import Mapping, Sequence
from dataclasses import replace
from pathlib import Path
from typing import Union

from pymoo_rail.cases.railjson_infra import SPEED_DIGITS, PathStep, RailjsonInfra, is_infra, path_line, read_infra
from pymoo_rail.cases.railjson_rolling_stock import (
    RailjsonRollingStock,
    RailjsonWarning,
    is_rolling_stock,
    load_json,
    read_rolling_stock,
)
from pymoo_rail.cases.toml_case import parse_toml
from pymoo_rail.model import GRAVITY_MS2, Case, CaseError, ForceCurve, Line, Train

PathLike = Union[str, Path]


def read_train(path: PathLike, *, mode: str | None = None, comfort: str | None = None) -> Train:
    """The case-format registry's train reader: ``load_train(path, mode=..., comfort=...)``.

    Parameters
    ----------
    path : str or Path
        An OSRD railjson rolling stock (``.json``), or a railjson case file (its rolling stock in
        the mode and comfort class it names).
    mode : str, optional
        The traction mode (``"25000V"``, ``"1500V"``, ``"thermal"``, ...); default the file's
        ``default_mode``. An unknown mode is a :class:`CaseError` listing the available ones.
    comfort : str, optional
        The comfort class (``"STANDARD"``, ``"AIR_CONDITIONING"``, ``"HEATING"``); default the
        mode's ``default_curve``. An unknown class is a :class:`CaseError` listing the available ones.
    """
    path = Path(path)
    if path.suffix == ".toml":
        for field, value in (("mode", mode), ("comfort", comfort)):
            if value is not None:
                raise CaseError(field, value, "a railjson case file names its own mode and comfort", str(path))
        return read_railjson_file(path).train
    data, _ = load_json(path, "rolling stock")
    if is_infra(data):
        raise CaseError("<file>", str(path), "is an OSRD railjson infrastructure, not a train", str(path))
    return read_rolling_stock(path).train(mode, comfort)


def traction_voltages(stock: RailjsonRollingStock, mode: str | None = None,
                      comfort: str | None = None) -> tuple[str, ...] | None:
    """The electrifications the train can run on with the effort curve of ``mode``.

    OSRD runs a multi-mode train in whichever of its modes the track allows. The model has one
    traction curve, so the train draws power from every electrification whose mode has the same
    curve as the chosen one; ``None`` when one of these modes is thermal (traction everywhere).
    """
    curve = stock.effort_curve(mode, comfort)
    same = [name for name in stock.modes if _curve_or_none(stock, name, comfort) == curve]
    if any(not stock.is_electric(name) for name in same):
        return None
    return tuple(same)


def _curve_or_none(stock: RailjsonRollingStock, mode: str, comfort: str | None):
    try:
        return stock.effort_curve(mode, comfort)
    except CaseError:  # a mode without this comfort class: not the same curve
        return None


def railjson_case(infra: RailjsonInfra | PathLike | Mapping, rolling_stock: RailjsonRollingStock | PathLike | Mapping,
                  *, planned_time_s: float, path: Sequence[tuple[str, str]] | None = None,
                  begin_m: float | None = None, end_m: float | None = None, from_point: str | None = None,
                  to_point: str | None = None, mode: str | None = None, comfort: str | None = None,
                  category: str | None = None, routes: Sequence[str] = (), power_recovery: bool = False,
                  name: str | None = None, allow_implausible: bool | Sequence[str] | None = None) -> Case:
    """A case: an OSRD rolling stock on a path of an OSRD infrastructure.

    Parameters
    ----------
    infra : RailjsonInfra, path or dict
        The infrastructure (:func:`~pymoo_rail.cases.railjson_infra.read_infra`).
    rolling_stock : RailjsonRollingStock, path or dict
        The train (:func:`~pymoo_rail.cases.railjson_rolling_stock.read_rolling_stock`).
    planned_time_s : float
        The planned running time of the case.
    path, begin_m, end_m : optional
        The path as ``(track, direction)`` pairs and the start / end on the first / last track
        (:meth:`RailjsonInfra.path`); or else
    from_point, to_point : str, optional
        Two operational points: the shortest path between them.
    mode, comfort : str, optional
        The traction mode and comfort class (:meth:`RailjsonRollingStock.train`).
    category : str, optional
        The speed-limit tag of the train (``speed_limit_by_tag``; default: the default limits).
    routes : sequence of str
        Routes of the path, for speed sections bound to routes.
    power_recovery : bool
        Lengthen the no-traction stretch after each neutral section by the rolling stock's
        ``raise_pantograph_time`` (pantograph lowered) or ``electrical_power_startup_time``
        at the speed limit (see :func:`~pymoo_rail.cases.railjson_infra.path_line`). Default off,
        as OSRD's simulator.
    name : str, optional
        The case's name (default from the infrastructure and the path).
    allow_implausible : bool or sequence of str, optional
        Handed to the :class:`Case` when given (the plausibility bounds of the case model).

    Returns
    -------
    Case
        Where no speed section applies the limit is the train's maximum speed (OSRD's rule). The
        braking force is raised so that the deceleration is ``const_gamma`` on the steepest
        descent of the line, as OSRD brakes.
    """
    infra = infra if isinstance(infra, RailjsonInfra) else read_infra(infra)
    stock = rolling_stock if isinstance(rolling_stock, RailjsonRollingStock) else read_rolling_stock(rolling_stock)
    if path is not None:
        if from_point is not None or to_point is not None:
            raise CaseError("path", path, "give either a path or two operational points, not both", infra.source)
        steps = infra.path(path, begin_m, end_m)
        where = f"{steps[0].track} -> {steps[-1].track}"
    elif from_point is not None and to_point is not None:
        steps = infra.shortest_path(from_point, to_point)
        where = f"{from_point} -> {to_point}"
    else:
        raise CaseError("path", None, "give a path ((track, direction) pairs) or from_point and to_point",
                        infra.source)
    train = stock.train(mode, comfort)
    voltages = traction_voltages(stock, mode, comfort)
    recovery = (stock.raise_pantograph_time_s or 0.0, stock.electrical_power_startup_time_s or 0.0) \
        if power_recovery and voltages is not None else (0.0, 0.0)
    line = path_line(infra, steps, category=category, voltages=voltages, neutral_sections=voltages is not None,
                     routes=routes, default_limit_kmh=round(train.max_speed_kmh, SPEED_DIGITS),
                     power_recovery_s=recovery)
    if line.neutral_sections and line.neutral_sections[0][0] == 0.0:
        powered = "any electrification" if voltages is None else f"electrification {', '.join(voltages)}"
        raise CaseError("mode", mode or stock.default_mode,
                        f"gives no traction where the path starts (no {powered} or a neutral section over "
                        f"[0, {line.neutral_sections[0][1]:g}] m): choose another traction mode of the rolling "
                        f"stock (modes: {', '.join(stock.modes)})", infra.source)
    train = replace(train, braking=ForceCurve(max_force_kn=braking_force_kn(stock, line)))
    label = Path(infra.source).stem if not infra.source.startswith("<") else "railjson"
    extra = {} if allow_implausible is None else {"allow_implausible": allow_implausible}
    return Case(name=name or f"{label}: {where}", train=train, line=line, planned_time_s=planned_time_s,
                source=f"OSRD railjson: infrastructure {infra.source}, rolling stock {stock.source}",
                description=f"{stock.name} from {where}; path {describe_path(steps)}", **extra)


def braking_force_kn(stock: RailjsonRollingStock, line: Line) -> float:
    """The braking force that decelerates the train at ``const_gamma`` on the steepest descent.

    OSRD brakes at ``const_gamma`` whatever the gradient; the model brakes with a force capped at
    ``max_decel_ms2 = const_gamma``, so the force must cover the pull of the steepest descent.
    """
    steepest_permille = max([0.0] + [-permille for _, _, permille in line.gradients])
    pull_n = stock.mass_kg * GRAVITY_MS2 * steepest_permille / 1000.0
    return (stock.const_gamma_ms2 * stock.mass_kg * stock.inertia_coefficient + pull_n) / 1000.0


def describe_path(steps: Sequence[PathStep]) -> str:
    """The path as text: ``track [begin, end] +`` (START_TO_STOP) or ``-`` per step."""
    return ", ".join(f"{s.track} [{s.begin_m:g}, {s.end_m:g}] {'+' if s.direction == 'START_TO_STOP' else '-'}"
                     for s in steps)


# the keys of a railjson case file (docs/railjson.md): a case whose train and line come from OSRD files
RAILJSON_CASE_KEYS = {"": {"name", "source", "description", "run", "railjson"},
                      "run": {"planned_time_s", "dwell_s", "time_margin_s"},
                      "railjson": {"infra", "rolling_stock", "path", "begin_m", "end_m", "from_point", "to_point",
                                   "mode", "comfort", "category", "routes", "power_recovery"}}
_RAILJSON_TABLE = re.compile(r"^\s*(\[railjson\]|railjson\s*=)", re.MULTILINE)


_RAILJSON_JSON_KEY = re.compile(r'"(railjson_version|effort_curves|rolling_resistance|track_sections|'
                                r'extended_switch_types|speed_sections|neutral_sections)"\s*:')


def looks_like(head: bytes) -> bool:
    """Whether the first bytes of a file are OSRD railjson: a case file with a ``[railjson]`` table, or
    a rolling stock or an infrastructure (JSON keys only railjson has)."""
    text = head.decode("utf-8", errors="ignore")
    return bool(_RAILJSON_TABLE.search(text) or _RAILJSON_JSON_KEY.search(text))


def _keys(data: object, table: str, source: str, required: set[str]) -> dict:
    if not isinstance(data, dict):
        raise CaseError(table or "<file>", data, "must be a table", source)
    for key in data:
        if key not in RAILJSON_CASE_KEYS[table]:
            raise CaseError(f"{table}.{key}" if table else key, data[key],
                            f"unknown key (allowed: {', '.join(sorted(RAILJSON_CASE_KEYS[table]))})", source)
    for key in sorted(required - set(data)):
        raise CaseError(f"{table}.{key}" if table else key, None, "is required", source)
    return data


def read_railjson_file(path: PathLike, *, allow_implausible: bool | Sequence[str] | None = None) -> Case:
    """The case of a railjson case file (TOML): a ``[run]`` and a ``[railjson]`` table naming the
    infrastructure, the rolling stock (paths relative to the file), the path and the options of
    :func:`railjson_case`. A railjson infrastructure or rolling stock alone is not a case: a
    :class:`CaseError` says what to give with it."""
    path = Path(path)
    if path.suffix == ".json":
        data = json.loads(path.read_text(encoding="utf-8"))
        what = "infrastructure" if is_infra(data) else "rolling stock"
        raise CaseError("<file>", str(path), f"is an OSRD railjson {what}, not a case: a case file names the "
                                             f"infrastructure, the rolling stock, the path and the planned time "
                                             f"([railjson] table, docs/railjson.md); load_train reads a rolling "
                                             f"stock", str(path))
    source = str(path)
    try:
        raw = path.read_bytes()
    except OSError as err:
        raise CaseError("path", source, f"cannot be read: {err.strerror or err}", source) from None
    data = _keys(parse_toml(raw, source), "", source, {"run", "railjson"})
    run = _keys(data["run"], "run", source, {"planned_time_s"})
    spec = _keys(data["railjson"], "railjson", source, {"infra", "rolling_stock"})
    files = {key: path.parent / spec[key] if isinstance(spec[key], str) else spec[key]
             for key in ("infra", "rolling_stock")}
    for key, value in files.items():
        if not isinstance(value, Path) or not value.is_file():
            raise CaseError(f"railjson.{key}", spec[key], "must be the path of a file (relative to the case file)",
                            source)
    options = {key: spec[key] for key in ("path", "begin_m", "end_m", "from_point", "to_point", "mode", "comfort",
                                          "category", "routes", "power_recovery") if key in spec}
    if "path" in options:
        options["path"] = [tuple(step) if isinstance(step, list) else step for step in options["path"]]
    try:
        case = railjson_case(files["infra"], files["rolling_stock"], planned_time_s=run["planned_time_s"],
                             name=data.get("name"), allow_implausible=allow_implausible, **options)
        return replace(case, dwell_s=run.get("dwell_s", 0.0), time_margin_s=run.get("time_margin_s", 0.0),
                       source=data.get("source", case.source), description=data.get("description", case.description))
    except CaseError as err:
        if err.source is None:  # a run value: the case file's (errors in the OSRD files name those files)
            raise CaseError(err.field, err.value, err.reason, source) from None
        raise
    except TypeError as err:  # a value of the wrong kind that no check above named
        raise CaseError("railjson", type(err).__name__, f"malformed value: {err}", source) from None


def read_case(path: PathLike, *, allow_implausible: bool | Sequence[str] | None = None, **options) -> Case:
    """The case-format registry's reader of OSRD railjson files.

    A railjson case file (TOML with a ``[railjson]`` table) takes no options. An infrastructure
    takes those of :func:`railjson_case`:
    ``load_case("small_infra.json", rolling_stock=..., from_point=..., to_point=..., planned_time_s=...)``.
    A rolling stock alone is not a case (a :class:`CaseError` says so).
    """
    path = Path(path)
    if path.suffix == ".json" and options:
        try:
            data = json.loads(path.read_text(encoding="utf-8"))
        except (OSError, UnicodeDecodeError, json.JSONDecodeError):
            data = None
        if isinstance(data, dict) and is_infra(data):
            if "rolling_stock" not in options or "planned_time_s" not in options:
                missing = "rolling_stock" if "rolling_stock" not in options else "planned_time_s"
                raise CaseError(missing, None, "is required to make a case of an OSRD infrastructure "
                                               "(with from_point/to_point or path)", str(path))
            return railjson_case(path, options.pop("rolling_stock"),
                                 allow_implausible=allow_implausible, **options)
    if options:
        raise CaseError(next(iter(options)), options[next(iter(options))],
                        "options are for an OSRD infrastructure; a railjson case file names its own", str(path))
    return read_railjson_file(path, allow_implausible=allow_implausible)


__all__ = ["read_train", "railjson_case", "looks_like", "read_case", "read_railjson_file", "RAILJSON_CASE_KEYS",
           "traction_voltages", "braking_force_kn", "describe_path", "read_infra", "read_rolling_stock", "path_line",
           "is_infra", "is_rolling_stock", "RailjsonWarning"]
