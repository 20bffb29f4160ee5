"""TTOBench export: a case's (or a journey's) line and train written as TTOBench JSON files.

The inverse of :mod:`pymoo_rail.cases.ttobench`: :func:`to_ttobench` writes a case as a track
file and a train file that :func:`~pymoo_rail.cases.ttobench.from_ttobench` reads back to the
same run (``docs/ttobench.md``).
"""

from __future__ import annotations

import json
import math
import re
from collections.abc import Mapping, Sequence
from pathlib import Path
from typing import Any

import numpy as np

from pymoo_rail.cases.ttobench import LIBRARY_VERSION, POINT_MASS_LENGTH_M, TTOBENCH_NOTICE
from pymoo_rail.cases.ttobench_efficiency import DIRECTIONS, FIELDS, loss_table_rows
from pymoo_rail.constants import KMH_PER_MS
from pymoo_rail.model import Case, CaseError, Line, Train

# Tolerance (relative to the largest braking force) of the export check on the braking curve.
_BRAKE_CHECK_RTOL = 1e-4


def _change_points_of(rows: Sequence[Sequence[float]]) -> list[list[float]]:
    """Rows back to change points, merging neighbours with the same value (TTOBench's rule)."""
    points: list[list[float]] = []
    for start, _end, value in rows:
        if not points or value != points[-1][1]:
            points.append([float(start), float(value)])
    return points


def _entry(unit: str, value: float) -> dict:
    return {"unit": unit, "value": float(value)}


def _ttobench_braking(train: Train) -> tuple[float, float, float]:
    """(reg force kN, reg power kW, pneumatic force kN) equal to the train's braking and regen split.

    Raises :class:`CaseError` when the model's braking curve or its electric share is not of the
    TTOBench form ``F_pn + min(F_reg, P_reg / v)`` with electric part ``min(F_reg, P_reg / v)``.
    """
    vmax = train.max_speed_kmh
    speeds = np.linspace(0.0, vmax, int(math.ceil(vmax / 0.25)) + 1)
    if train.braking.table is not None:
        speeds = np.union1d(speeds, [v for v, _ in train.braking.table if v <= vmax])
    total = train.braking.force_kn(speeds)
    electric = total.copy()
    if train.regen_max_force_kn is not None:
        electric = np.minimum(electric, train.regen_max_force_kn)
    if train.regen_max_power_kw is not None:
        with np.errstate(divide="ignore"):
            electric = np.minimum(electric, np.where(speeds > 0, train.regen_max_power_kw * KMH_PER_MS
                                                     / np.maximum(speeds, 1e-300), np.inf))
    reg_f = float(electric[0])
    # The power cap as given when there is one (exact round trip); else F v_max, which never binds.
    caps = [p for p in (train.braking.max_power_kw, train.regen_max_power_kw) if p is not None]
    reg_p = float(min(caps)) if caps else reg_f * vmax / KMH_PER_MS
    pn_f = float(total[0] - reg_f)
    if reg_f <= 0 or reg_p <= 0:
        raise CaseError("train.braking", train.braking, "TTOBench needs a positive regenerative braking force")
    with np.errstate(divide="ignore"):
        ttob_electric = np.minimum(reg_f, np.where(speeds > 0, reg_p * KMH_PER_MS / np.maximum(speeds, 1e-300),
                                                   np.inf))
    tol = _BRAKE_CHECK_RTOL * float(np.max(total))
    worst_total = float(np.max(np.abs(pn_f + ttob_electric - total)))
    worst_electric = float(np.max(np.abs(ttob_electric - electric)))
    if worst_total > tol:
        k = int(np.argmax(np.abs(pn_f + ttob_electric - total)))
        raise CaseError("train.braking", f"{total[k]:.3f} kN at {speeds[k]:.2f} km/h",
                        f"is not of the TTOBench form pneumatic + min(F_reg, P_reg / v) "
                        f"(off by {worst_total:.3f} kN with F_reg = {reg_f:g} kN, P_reg = {reg_p:g} kW, "
                        f"F_pn = {pn_f:g} kN)")
    if worst_electric > tol:
        raise CaseError("train.regen_max_force_kn|regen_max_power_kw",
                        (train.regen_max_force_kn, train.regen_max_power_kw),
                        f"the electric share of braking is not min(F_reg, P_reg / v) (off by {worst_electric:.3f} kN)")
    return reg_f, reg_p, max(pn_f, 0.0)


def train_to_json(train: Train, train_id: str, *, metadata: Mapping[str, Any] | None = None) -> dict:
    """A TTOBench train object (units: kg, %, km/h, kW, kN, m/s^2, kN/(km/h)^k) for a :class:`Train`."""
    if train.traction.max_force_kn is None:
        form = "segments" if train.traction.segments is not None else "table"
        raise CaseError(f"train.traction.{form}", getattr(train.traction, form),
                        "TTOBench trains give traction as a force cap and a power cap only")
    if train.regen_min_speed_kmh > 0:
        raise CaseError("train.regen_min_speed_kmh", train.regen_min_speed_kmh, "TTOBench has no regen cut-off speed")
    maps = {d: getattr(train, f"{d}_efficiency_map") for d in DIRECTIONS}
    if train.aux_power_kw > 0 and not any(maps.values()):
        raise CaseError("train.aux_power_kw", train.aux_power_kw,
                        "TTOBench carries auxiliary power only inside a loss table (a train with an efficiency map)")
    trac_f = train.traction.max_force_kn
    # No power cap: F <= F_max equals min(F_max, F_max v_max / v) at every speed the train can run.
    trac_p = train.traction.max_power_kw if train.traction.max_power_kw is not None else \
        trac_f * train.max_speed_kmh / KMH_PER_MS
    reg_f, reg_p, pn_f = _ttobench_braking(train)
    r = train.resistance
    a, b, c = r.a, r.b, r.c
    if r.unit == "N/kN":
        a, b, c = (x * train.weight_kn / 1000.0 for x in (a, b, c))
    if r.speed_unit == "ms":
        b, c = b / KMH_PER_MS, c / KMH_PER_MS**2
    meta = {"id": train_id, "library version": LIBRARY_VERSION, "created by": "pymoo-rail (to_ttobench)"}
    meta.update(metadata or {})
    out: dict[str, Any] = {"metadata": meta}
    if train.length_m > POINT_MASS_LENGTH_M:
        out["length"] = _entry("m", train.length_m)
    out.update({
        "mass": _entry("kg", train.mass_t * 1000.0),
        "rho": _entry("%", train.rotary_factor * 100.0),
        "max traction power": _entry("kW", trac_p),
        "max reg braking power": _entry("kW", reg_p),
        "max traction force": _entry("kN", trac_f),
        "max reg braking force": _entry("kN", reg_f),
        "max pn braking force": _entry("kN", pn_f),
    })
    if train.max_accel_ms2 is not None:
        out["max acceleration"] = _entry("m/s^2", train.max_accel_ms2)
    if train.max_decel_ms2 is not None:
        out["max deceleration"] = _entry("m/s^2", train.max_decel_ms2)
    out.update({
        "max speed": _entry("km/h", train.max_speed_kmh),
        "rolling resistance r0": _entry("kN", a),
        "rolling resistance r1": _entry("kN/(km/h)", b),
        "rolling resistance r2": _entry("kN/(km/h)^2", c),
    })
    scalars = {"traction": train.traction_efficiency, "regen": train.regen_efficiency}
    if any(maps.values()) or scalars != {"traction": 1.0, "regen": 0.0}:  # absent = (1, 0) on import
        caps = {"traction": (trac_f, trac_p), "regen": (reg_f, reg_p)}
        for direction, field in FIELDS.items():
            if maps[direction] is None:
                out[field] = _entry("%", scalars[direction] * 100.0)
            else:
                out[field] = {"units": {"load": "%", "velocity": "km/h", "losses": "kW"},
                              "values": loss_table_rows(maps[direction], direction, *caps[direction],
                                                        train.aux_power_kw)}
    return out


def track_to_json(lines: Sequence[Line], track_id: str, *, altitude_m: float = 0.0,
                  metadata: Mapping[str, Any] | None = None) -> dict:
    """A TTOBench track object for consecutive stop-to-stop lines (one stop between each pair)."""
    gradients: list[list[float]] = []
    limits: list[list[float]] = []
    stops = [0.0]
    for k, line in enumerate(lines):
        for name in ("curves", "tunnels", "neutral_sections"):
            if getattr(line, name):
                raise CaseError(f"line.{name}", getattr(line, name), "is not represented in TTOBench tracks")
        offset = stops[-1]
        gradients += [[s + offset, e + offset, v] for s, e, v in line.gradients]
        limits += [[s + offset, e + offset, v] for s, e, v in line.speed_limits]
        stops.append(offset + line.length_m)
    meta = {"id": track_id, "library version": LIBRARY_VERSION, "created by": "pymoo-rail (to_ttobench)"}
    meta.update(metadata or {})
    return {
        "metadata": meta,
        "altitude": _entry("m", altitude_m),
        "stops": {"unit": "m", "values": stops},
        "speed limits": {"units": {"position": "m", "velocity": "km/h"}, "values": _change_points_of(limits)},
        "gradients": {"units": {"position": "m", "slope": "permil"}, "values": _change_points_of(gradients)},
    }


def ttobench_id(text: str) -> str:
    """A TTOBench id from any text (ids hold letters, numbers and underscores only)."""
    return re.sub(r"[^A-Za-z0-9_]+", "_", text).strip("_") or "track"


def to_ttobench(case: Case, out_dir: str | Path, *, track_id: str | None = None, train_id: str | None = None,
                altitude_m: float = 0.0, license_text: str | None = None) -> tuple[Path, Path]:
    """Write a case as a TTOBench track (two stops, or one per leg) and a TTOBench train.

    Returns ``(track_path, train_path)``, files named ``<id>.json``. Raises :class:`CaseError`
    naming the field for what TTOBench cannot hold: traction as polynomials or tables, a braking
    curve not of the form ``pneumatic + min(F_reg, P_reg / v)``, a regen cut-off speed, auxiliary
    power without an efficiency map (a map is written as TTOBench's loss table, which carries it), an
    efficiency map whose row at 0 km/h or column at 0 kN is not its neighbour's, curves, tunnels, neutral sections, or averaged gradients on a point-mass train.

    ``altitude_m`` is the altitude of the first stop (the case does not store it). ``license_text``
    goes into the metadata; by default the TTOBench notice is carried when the case came from
    TTOBench data (its ``source`` says so).
    """
    train = case.train
    whole_train = train.length_m > POINT_MASS_LENGTH_M
    if whole_train and case.line.gradient_model != "train_length":
        raise CaseError("line.gradient_model", case.line.gradient_model,
                        "TTOBench has no flag for it: a train with a length is written with gradients averaged "
                        "over it ('train_length'); use a point mass (train length 0.001 m) for 'point_mass'")
    lines = [case.leg(k).line for k in range(len(case.legs))] if case.legs else [case.line]
    if license_text is None and "TTOBench" in case.source:
        license_text = TTOBENCH_NOTICE
    meta = {"description": case.description or case.name}
    if license_text:
        meta["license"] = license_text
    track_id = track_id or ttobench_id(case.name)
    train_id = train_id or ttobench_id(train.name or f"{case.name}_train")
    track = track_to_json(lines, track_id, altitude_m=altitude_m, metadata=meta)
    train_json = train_to_json(train, train_id, metadata={"license": license_text} if license_text else None)
    return write_pair(out_dir, track, train_json)


def write_pair(out_dir: str | Path, track: Mapping, train: Mapping) -> tuple[Path, Path]:
    """Write a track and a train object as ``<id>.json`` files in ``out_dir``."""
    out = Path(out_dir)
    out.mkdir(parents=True, exist_ok=True)
    paths = []
    for obj in (track, train):
        path = out / f"{obj['metadata']['id']}.json"
        path.write_text(json.dumps(obj, indent=2) + "\n", encoding="utf-8")
        paths.append(path)
    return paths[0], paths[1]


__all__ = ["to_ttobench", "track_to_json", "train_to_json", "write_pair", "ttobench_id"]
