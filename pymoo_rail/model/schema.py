"""The case as plain data: the nested tables of ``docs/case-format.md``, to and from a :class:`Case`.

Every file format reads into this structure (:mod:`pymoo_rail.cases.toml_case` parses TOML into
it) and the fingerprints of runs hash it; the checks name fields by their paths in it.
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import Any

from pymoo_rail.model.case import Case, Leg
from pymoo_rail.constants import KMH_PER_MS
from pymoo_rail.model.curves import DavisResistance, ForceCurve
from pymoo_rail.model.efficiency import EfficiencyMap
from pymoo_rail.model.errors import CaseError, check_number
from pymoo_rail.model.line import Line
from pymoo_rail.model.train import Train

_TOP = {"name", "source", "description", "allow_implausible", "run", "train", "line"}
_RUN = {"planned_time_s", "dwell_s", "time_margin_s", "legs", "initial_speed_kmh", "final_speed_kmh",
        "final_speed_window_kmh"}
_LEG = {"start_m", "end_m", "planned_time_s", "dwell_s"}
_TRAIN = {"name", "mass_t", "rotary_factor", "length_m", "max_speed_kmh", "max_accel_ms2", "max_decel_ms2",
          "traction_efficiency", "regen_efficiency", "regen_min_speed_kmh", "aux_power_kw",
          "resistance", "traction", "braking", "traction_efficiency_map", "regen_efficiency_map"}
_EFFICIENCY_MAP = {"speeds_kmh", "forces_kn", "values", "gear", "converter"}
_RESISTANCE = {"a", "b", "c", "unit", "speed_unit"}
_CURVE = {"segments", "table", "max_force_kn", "max_power_kw"}
_BRAKING = _CURVE | {"regen_max_force_kn", "regen_max_power_kw"}
_SEGMENT = {"v_max_kmh", "poly"}
_LINE = {"length_m", "gradients", "speed_limits", "curves", "tunnels", "neutral_sections", "gradient_model",
         "curve_model"}


# every table of the format and the keys it may hold ("[]": each table of an array of tables)
CASE_TABLES = {"": _TOP, "run": _RUN, "run.legs[]": _LEG, "train": _TRAIN, "train.resistance": _RESISTANCE,
               "train.traction": _CURVE, "train.traction.segments[]": _SEGMENT, "train.braking": _BRAKING,
               "train.braking.segments[]": _SEGMENT, "train.traction_efficiency_map": _EFFICIENCY_MAP,
               "train.regen_efficiency_map": _EFFICIENCY_MAP, "line": _LINE}


def case_keys() -> list[str]:
    """Every key a case file may hold, as dotted paths (``train.resistance.unit``, ``run.legs[].end_m``).

    ``docs/case-format.md`` documents each of them; a test keeps the two in step.
    """
    return sorted(f"{table}.{key}" if table else key for table, keys in CASE_TABLES.items() for key in keys)


def _table(data: Any, field: str, allowed: set[str], required: set[str], source: str) -> dict:
    if not isinstance(data, dict):
        raise CaseError(field, data, "must be a table", source)
    unknown = sorted(set(data) - allowed)
    if unknown:
        raise CaseError(f"{field}.{unknown[0]}" if field else unknown[0], data[unknown[0]],
                        f"unknown key (allowed: {', '.join(sorted(allowed))})", source)
    missing = sorted(required - set(data))
    if missing:
        raise CaseError(f"{field}.{missing[0]}" if field else missing[0], None, "is required", source)
    return data


def _list(value: Any, field: str, source: str) -> list:
    if not isinstance(value, list):
        raise CaseError(field, value, f"must be an array, not {type(value).__name__}", source)
    return value


def _rows(value: Any, field: str, source: str) -> tuple[tuple, ...]:
    """An array of arrays (e.g. ``[[start_m, end_m, permille], ...]``), each checked to be an array."""
    if isinstance(value, list) and all(type(row) is list for row in value):
        return tuple(map(tuple, value))  # the usual case, at C speed for a line of a million rows
    return tuple(tuple(_list(row, f"{field}[{k}]", source)) for k, row in enumerate(_list(value, field, source)))


def _curve(data: Any, field: str, allowed: set[str], source: str) -> ForceCurve:
    data = _table(data, field, allowed, set(), source)
    segments = None
    if "segments" in data:
        rows = []
        for k, seg in enumerate(_list(data["segments"], f"{field}.segments", source)):
            seg = _table(seg, f"{field}.segments[{k}]", _SEGMENT, _SEGMENT, source)
            rows.append((seg["v_max_kmh"], tuple(_list(seg["poly"], f"{field}.segments[{k}].poly", source))))
        segments = tuple(rows)
    table = _rows(data["table"], f"{field}.table", source) if "table" in data else None
    try:
        return ForceCurve(segments=segments, table=table, max_force_kn=data.get("max_force_kn"),
                          max_power_kw=data.get("max_power_kw"))
    except CaseError as err:
        raise CaseError(f"{field}.{err.field}", err.value, err.reason, source) from None


def _speed_ms(run: dict, key: str) -> float:
    """A boundary speed of ``[run]`` (km/h in the file) in m/s; a bad value names the field."""
    return check_number(f"run.{key}", run.get(key, 0.0), nonneg=True) / KMH_PER_MS


def _end_window_ms(run: dict) -> tuple[float, float] | None:
    """``run.final_speed_window_kmh`` in m/s (None when absent); a bad value names the field."""
    if "final_speed_window_kmh" not in run:
        return None
    window = run["final_speed_window_kmh"]
    if not isinstance(window, list) or len(window) != 2:
        raise CaseError("run.final_speed_window_kmh", window, "must be two speeds [lo, hi] in km/h")
    return tuple(check_number(f"run.final_speed_window_kmh[{k}]", v, nonneg=True) / KMH_PER_MS
                 for k, v in enumerate(window))


def _final_speed_ms(run: dict) -> float:
    """``run.final_speed_kmh`` in m/s; with a window and no final speed, the window's upper end."""
    window = _end_window_ms(run)
    if window is not None and "final_speed_kmh" not in run:
        return window[1]
    return _speed_ms(run, "final_speed_kmh")


def case_from_dict(data: dict, source: str = "<dict>", *, allow_implausible: bool | Sequence[str] | None = None) -> Case:
    """Build a :class:`Case` from the parsed TOML structure; every error names the field.

    ``allow_implausible`` (``True``, or kinds of bound) replaces the file's own key when given:
    see :class:`Case`.
    """
    data = _table(data, "", _TOP, {"name", "run", "train", "line"}, source)
    allow = data.get("allow_implausible", False) if allow_implausible is None else allow_implausible
    if not isinstance(allow, (bool, list, tuple)):
        raise CaseError("allow_implausible", allow, "must be true, false or an array of kinds of bound", source)
    run = _table(data["run"], "run", _RUN, {"planned_time_s"}, source)
    train = train_from_dict(data["train"], source)
    line = _table(data["line"], "line", _LINE, {"length_m", "gradients", "speed_limits"}, source)

    def build() -> Case:
        legs = tuple(Leg(**_table(leg, f"run.legs[{k}]", _LEG, {"start_m", "end_m", "planned_time_s"}, source))
                     for k, leg in enumerate(_list(run.get("legs", []), "run.legs", source)))
        line_obj = Line(
            length_m=line["length_m"], gradients=_rows(line["gradients"], "line.gradients", source),
            speed_limits=_rows(line["speed_limits"], "line.speed_limits", source),
            curves=_rows(line.get("curves", []), "line.curves", source),
            tunnels=_rows(line.get("tunnels", []), "line.tunnels", source),
            neutral_sections=_rows(line.get("neutral_sections", []), "line.neutral_sections", source),
            gradient_model=line.get("gradient_model", "train_length"),
            curve_model=line.get("curve_model", "tang2020"),
        )
        return Case(name=data["name"], source=data.get("source", ""), description=data.get("description", ""),
                    train=train, line=line_obj, planned_time_s=run["planned_time_s"],
                    dwell_s=run.get("dwell_s", 0.0), time_margin_s=run.get("time_margin_s", 0.0), legs=legs,
                    initial_speed_ms=_speed_ms(run, "initial_speed_kmh"),
                    final_speed_ms=_final_speed_ms(run), final_speed_window_ms=_end_window_ms(run),
                    allow_implausible=allow)

    return _named(build, "case", source)


def _named(build, what: str, source: str):
    """``build()`` with every error a :class:`CaseError` that names ``source``."""
    try:
        return build()
    except CaseError as err:
        if err.source is None:
            raise CaseError(err.field, err.value, err.reason, source) from None
        raise
    except (TypeError, ValueError) as err:  # a last resort: every field is checked by name
        raise CaseError(what, type(err).__name__, f"malformed value: {err}", source) from None


def train_from_dict(data: Any, source: str = "<dict>") -> Train:
    """Build a :class:`Train` from a case's ``[train]`` table; every error names the field
    (``train.mass_t``). A train alone meets the plausibility bounds when it joins a case."""
    tr = _table(data, "train", _TRAIN,
                {"mass_t", "length_m", "max_speed_kmh", "resistance", "traction", "braking"}, source)
    res = _table(tr["resistance"], "train.resistance", _RESISTANCE, _RESISTANCE, source)
    braking = tr["braking"]

    def build() -> Train:
        maps = {d: _efficiency_map(tr.get(f"{d}_efficiency_map"), f"train.{d}_efficiency_map", source)
                for d in ("traction", "regen")}
        # with a map, the constant defaults to its peak (Train checks a given one against it)
        constant = {d: tr.get(f"{d}_efficiency", maps[d].peak if maps[d] is not None else default)
                    for d, default in (("traction", 1.0), ("regen", 0.0))}
        return Train(
            name=tr.get("name", ""),
            mass_t=tr["mass_t"], length_m=tr["length_m"], max_speed_kmh=tr["max_speed_kmh"],
            rotary_factor=tr.get("rotary_factor", 0.0),
            max_accel_ms2=tr.get("max_accel_ms2"), max_decel_ms2=tr.get("max_decel_ms2"),
            traction_efficiency=constant["traction"], regen_efficiency=constant["regen"],
            traction_efficiency_map=maps["traction"], regen_efficiency_map=maps["regen"],
            regen_min_speed_kmh=tr.get("regen_min_speed_kmh", 0.0),
            aux_power_kw=tr.get("aux_power_kw", 0.0),
            resistance=DavisResistance(res["a"], res["b"], res["c"], res["unit"], res["speed_unit"]),
            traction=_curve(tr["traction"], "train.traction", _CURVE, source),
            braking=_curve(braking, "train.braking", _BRAKING, source),
            regen_max_force_kn=braking.get("regen_max_force_kn"),
            regen_max_power_kw=braking.get("regen_max_power_kw"),
        )

    return _named(build, "train", source)


def _efficiency_map(data: Any, field: str, source: str) -> EfficiencyMap | None:
    """An efficiency map table: the table (the motor's, where parts are given) times ``gear`` and
    ``converter`` efficiencies when present (the chain motor x gear x converter)."""
    if data is None:
        return None
    tab = _table(data, field, _EFFICIENCY_MAP, {"speeds_kmh", "forces_kn", "values"}, source)
    for key in ("speeds_kmh", "forces_kn", "values"):
        if not isinstance(tab[key], (list, tuple)):
            raise CaseError(f"{field}.{key}", tab[key], "must be an array", source)
    for i, row in enumerate(tab["values"]):
        if not isinstance(row, (list, tuple)):
            raise CaseError(f"{field}.values[{i}]", row, "must be an array (one row per speed)", source)
    table = EfficiencyMap(tuple(tab["speeds_kmh"]), tuple(tab["forces_kn"]),
                          tuple(tuple(row) for row in tab["values"]), field)
    parts = [check_number(f"{field}.{k}", tab[k], positive=True, upper=1.0, source=source)
             for k in ("gear", "converter") if k in tab]
    return EfficiencyMap.chain((table, *parts), field) if parts else table


def _map_to_dict(efficiency_map: EfficiencyMap) -> dict:
    return {"speeds_kmh": list(efficiency_map.speeds_kmh), "forces_kn": list(efficiency_map.forces_kn),
            "values": [list(row) for row in efficiency_map.values]}


def case_to_dict(case: Case) -> dict:
    """The TOML structure of a case (inverse of :func:`case_from_dict`)."""
    t = case.train

    def curve(c: ForceCurve) -> dict:
        out: dict[str, Any] = {}
        if c.segments is not None:
            out["segments"] = [{"v_max_kmh": v, "poly": list(p)} for v, p in c.segments]
        if c.table is not None:
            out["table"] = [list(r) for r in c.table]
        if c.max_force_kn is not None:
            out["max_force_kn"] = c.max_force_kn
        if c.max_power_kw is not None:
            out["max_power_kw"] = c.max_power_kw
        return out

    braking = curve(t.braking)
    if t.regen_max_force_kn is not None:
        braking["regen_max_force_kn"] = t.regen_max_force_kn
    if t.regen_max_power_kw is not None:
        braking["regen_max_power_kw"] = t.regen_max_power_kw
    train = {"name": t.name, "mass_t": t.mass_t, "rotary_factor": t.rotary_factor, "length_m": t.length_m,
             "max_speed_kmh": t.max_speed_kmh, "traction_efficiency": t.traction_efficiency,
             "regen_efficiency": t.regen_efficiency, "regen_min_speed_kmh": t.regen_min_speed_kmh,
             "aux_power_kw": t.aux_power_kw}
    if t.max_accel_ms2 is not None:
        train["max_accel_ms2"] = t.max_accel_ms2
    if t.max_decel_ms2 is not None:
        train["max_decel_ms2"] = t.max_decel_ms2
    for direction in ("traction", "regen"):  # only when set: other cases' files and fingerprints stay as they were
        efficiency_map = getattr(t, f"{direction}_efficiency_map")
        if efficiency_map is not None:
            train[f"{direction}_efficiency_map"] = _map_to_dict(efficiency_map)
    r = t.resistance
    train["resistance"] = {"a": r.a, "b": r.b, "c": r.c, "unit": r.unit, "speed_unit": r.speed_unit}
    train["traction"] = curve(t.traction)
    train["braking"] = braking
    ln = case.line
    run: dict[str, Any] = {"planned_time_s": case.planned_time_s, "dwell_s": case.dwell_s,
                           "time_margin_s": case.time_margin_s}
    if case.initial_speed_ms:
        run["initial_speed_kmh"] = case.initial_speed_ms * KMH_PER_MS
    if case.final_speed_ms:
        run["final_speed_kmh"] = case.final_speed_ms * KMH_PER_MS
    if case.final_speed_window_ms is not None:
        run["final_speed_window_kmh"] = [v * KMH_PER_MS for v in case.final_speed_window_ms]
    if case.legs:
        run["legs"] = [{"start_m": g.start_m, "end_m": g.end_m, "planned_time_s": g.planned_time_s,
                        "dwell_s": g.dwell_s} for g in case.legs]
    line = {"length_m": ln.length_m, "gradient_model": ln.gradient_model,
            "gradients": [list(r) for r in ln.gradients], "speed_limits": [list(r) for r in ln.speed_limits],
            "curves": [list(r) for r in ln.curves], "tunnels": [list(r) for r in ln.tunnels],
            "neutral_sections": [list(r) for r in ln.neutral_sections]}
    if ln.curve_model != "tang2020":  # the default stays out of the file (older files read the same)
        line["curve_model"] = ln.curve_model
    out = {"name": case.name, "source": case.source, "description": case.description}
    if case.allow_implausible:  # only when set: the files (and fingerprints) of other cases stay as they were
        out["allow_implausible"] = case.allow_implausible if isinstance(case.allow_implausible, bool) \
            else list(case.allow_implausible)
    return {**out, "run": run, "train": train, "line": line}
