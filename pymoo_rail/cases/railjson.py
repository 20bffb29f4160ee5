"""OSRD railjson: trains from any supported format, cases from an infrastructure, a path and a train.

>>> from pymoo_rail.cases.railjson import load_train, railjson_case
>>> train = load_train("tests/data/osrd/rolling_stocks/intercity-train.json", mode="25000V")  # doctest: +SKIP
>>> case = railjson_case("tests/data/osrd/infras/small_infra.json",
...                      "tests/data/osrd/rolling_stocks/intercity-train.json",
...                      from_point="Mid_West_station", to_point="Mid_East_station",
...                      planned_time_s=600.0)  # doctest: +SKIP

The formats, the mapping of every field and what is not represented: ``docs/railjson.md``.
"""

from __future__ import annotations

import json
from collections.abc import Mapping, Sequence
from dataclasses import replace
from pathlib import Path
from typing import Union

from pymoo_rail.cases.railjson_infra import PathStep, RailjsonInfra, is_infra, path_line, read_infra
from pymoo_rail.cases.railjson_rolling_stock import (
    RailjsonRollingStock,
    RailjsonWarning,
    is_rolling_stock,
    read_rolling_stock,
)
from pymoo_rail.model import GRAVITY_MS2, Case, CaseError, ForceCurve, Line, Train, read_case

PathLike = Union[str, Path]
TRAIN_FORMATS = ("a case file (.toml) or a built-in case name: its train", "a TTOBench train (.json)",
                 "an OSRD railjson rolling stock (.json)")


def _is_ttobench_train(data: Mapping) -> bool:
    # TTOBench gives every scalar as {"unit": ..., "value": ...} and names the train in metadata.id
    mass = data.get("mass")
    return isinstance(mass, Mapping) and "unit" in mass and "value" in mass


def _no_choice(source: str, what: str, mode: str | None, comfort: str | None) -> None:
    for field, value in (("mode", mode), ("comfort", comfort)):
        if value is not None:
            raise CaseError(field, value, f"{what} has one traction curve: traction modes and comfort classes "
                                          f"are railjson rolling stock options", source)


def load_train(path: PathLike, mode: str | None = None, comfort: str | None = None) -> Train:
    """Read a train from any supported format.

    Parameters
    ----------
    path : str or Path
        A case file (``.toml``: its ``[train]``), a built-in case name, a TTOBench train file or an
        OSRD railjson rolling stock (``.json``, told apart by their content).
    mode : str, optional
        railjson only: the traction mode (``"25000V"``, ``"1500V"``, ``"thermal"``, ...); default the
        file's ``default_mode``. An unknown mode is a :class:`CaseError` listing the available ones.
    comfort : str, optional
        railjson only: the comfort class (``"STANDARD"``, ``"AIR_CONDITIONING"``, ``"HEATING"``);
        default the mode's ``default_curve``. An unknown class is a :class:`CaseError` listing the
        available ones.

    Returns
    -------
    Train
    """
    # the case readers of pymoo_rail.cases (imported here: that package imports this module lazily)
    from pymoo_rail.cases import list_cases, load_case

    candidate = Path(path)
    if candidate.suffix == ".toml" or (not candidate.is_file() and str(path) in list_cases()):
        _no_choice(str(path), "a case file", mode, comfort)
        return (read_case(candidate) if candidate.is_file() else load_case(str(path))).train
    if not candidate.is_file():
        raise CaseError("path", str(path), "no such train file or built-in case (formats: "
                                           f"{'; '.join(TRAIN_FORMATS)})")
    try:
        data = json.loads(candidate.read_text(encoding="utf-8"))
    except (UnicodeDecodeError, json.JSONDecodeError) as err:
        raise CaseError("<file>", str(candidate), f"is neither TOML (.toml) nor valid JSON: {err}",
                        str(candidate)) from None
    if isinstance(data, dict) and is_rolling_stock(data):
        return read_rolling_stock(candidate).train(mode, comfort)
    if isinstance(data, dict) and _is_ttobench_train(data):
        # TTOBench support is read only when asked for (as pymoo_rail.cases does)
        from pymoo_rail.cases.ttobench import read_train

        _no_choice(str(candidate), "a TTOBench train", mode, comfort)
        return read_train(candidate).train
    raise CaseError("<file>", str(candidate), f"is not a train in a known format ({'; '.join(TRAIN_FORMATS)})",
                    str(candidate))


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
                  name: str | None = None) -> Case:
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
                     routes=routes, default_limit_kmh=train.max_speed_kmh, power_recovery_s=recovery)
    if line.neutral_sections and line.neutral_sections[0][0] == 0.0:
        powered = "any electrification" if voltages is None else f"electrification {', '.join(voltages)}"
        raise CaseError("mode", mode or stock.default_mode,
                        f"gives no traction where the path starts (no {powered} or a neutral section over "
                        f"[0, {line.neutral_sections[0][1]:g}] m): choose another traction mode of the rolling "
                        f"stock (modes: {', '.join(stock.modes)})", infra.source)
    train = replace(train, braking=ForceCurve(max_force_kn=braking_force_kn(stock, line)))
    label = Path(infra.source).stem if not infra.source.startswith("<") else "railjson"
    return Case(name=name or f"{label}: {where}", train=train, line=line, planned_time_s=planned_time_s,
                source=f"OSRD railjson: infrastructure {infra.source}, rolling stock {stock.source}",
                description=f"{stock.name} from {where}; path {describe_path(steps)}")


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


__all__ = ["load_train", "railjson_case", "traction_voltages", "braking_force_kn", "describe_path",
           "read_infra", "read_rolling_stock", "path_line", "is_infra", "is_rolling_stock", "RailjsonWarning",
           "TRAIN_FORMATS"]
