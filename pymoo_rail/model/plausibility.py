"""Plausibility bounds of a case: values no train or line has, usually a unit mistake.

A case that passes the type and range checks of :class:`~pymoo_rail.model.Train`,
:class:`~pymoo_rail.model.Line` and :class:`~pymoo_rail.model.Case` can still be nonsense: a
gradient of 120 permille, a mass of 0.194 t, a traction force given in N where kN is meant. The
simulator would run it and return numbers. :func:`check_plausible` refuses such a case with a
:class:`CaseError` that names the field, the value and, where one fits, the likely unit mistake.

Each bound belongs to a kind; a research case waives kinds with ``allow_implausible`` (``True``
for all, or a list of kinds). ``docs/case-format.md`` states every bound with its reason.
"""

from __future__ import annotations

from collections.abc import Iterable

import numpy as np

from pymoo_rail.model.curves import ForceCurve
from pymoo_rail.model.errors import CaseError
from pymoo_rail.model.train import GRAVITY_MS2

# every kind of bound, in the order they are checked
IMPLAUSIBLE_KINDS = ("length", "speed", "gradient", "mass", "force", "power", "time", "efficiency")

MAX_GRADIENT_PERMILLE = 60.0          # steepest adhesion main lines and metros ~40-60 permille
SPEED_KMH = (1.0, 600.0)              # wheel-rail record 574.8 km/h; shunting limits >= 5 km/h
LINE_LENGTH_M = (10.0, 3.0e6)         # shorter than a coach / longer than any non-stop run
TRAIN_LENGTH_M = (0.001, 8000.0)      # TTOBench's point mass is 0.001 m; longest freight ~7.4 km
POINT_MASS_BELOW_M = 1.0              # a shorter train is a point mass: no mass per metre
MASS_T = (1.0, 100_000.0)             # a track trolley / the heaviest ore train (~100 kt)
MASS_PER_METRE_T = (0.3, 25.0)        # light railcars ~1 t/m, 40 t axle-load ore wagons ~13 t/m
FORCE_PER_WEIGHT = (0.001, 3.0)       # adhesion gives <= 0.35 of the weight, heavy freight >= 0.004
RESISTANCE_PER_WEIGHT = 0.3           # real W0 at top speed <= 0.05 of the weight
ACCEL_MS2 = (0.01, 5.0)               # freight ~0.05 m/s^2; emergency braking ~1.5-2.5; beyond adhesion
POWER_KW_PER_T = (0.1, 200.0)         # freight ~1 kW/t, EMUs 5-25 kW/t, a lone locomotive ~80 kW/t
AUX_POWER_KW_PER_T = 20.0             # hotel load ~0.5-3 kW/t
PEAK_EFFICIENCY = (0.5, 1.0)          # no traction chain peaks below ~0.6-0.7 (diesel-electric) at its best
MAP_COVERAGE = (0.5, 100.0)           # a map's top speed / force over the train's: half of it, or km/h vs m/s
MAX_TIME_S = 86_400.0                 # one stop-to-stop run or dwell longer than a day

UNIT_FACTOR = 1000.0  # the mistakes the messages name: N for kN, W for kW, kg for t, ms for s


def allowed_kinds(allow: bool | Iterable[str]) -> frozenset[str]:
    """The kinds of bound an ``allow_implausible`` value waives; a bad value is a :class:`CaseError`."""
    if allow is True:
        return frozenset(IMPLAUSIBLE_KINDS)
    if allow is False or allow is None:
        return frozenset()
    if isinstance(allow, (str, bytes)) or not isinstance(allow, Iterable):
        raise CaseError("allow_implausible", allow, f"must be true, false or a list of kinds of bound "
                                                    f"({', '.join(IMPLAUSIBLE_KINDS)})")
    kinds = tuple(allow)
    for kind in kinds:
        if kind not in IMPLAUSIBLE_KINDS:
            raise CaseError("allow_implausible", kind, f"unknown kind of bound (known: {', '.join(IMPLAUSIBLE_KINDS)})")
    return frozenset(kinds)


def _waiver(kind: str) -> str:
    return f"(set allow_implausible = [\"{kind}\"] in the case, or allow_implausible=... when loading, for a research case)"


def _outside(field: str, value: object, kind: str, what: str, bounds: tuple[float, float], unit: str,
             measured: float, *, low_hint: str = "", high_hint: str = "") -> None:
    """Raise when ``measured`` lies outside ``bounds``, naming a unit mistake when one fits."""
    low, high = bounds
    if low <= measured <= high:
        return
    side = "below" if measured < low else "above"
    hint = low_hint if measured < low else high_hint
    scaled = measured * UNIT_FACTOR if measured < low else measured / UNIT_FACTOR
    hint = f"; {hint}" if hint and low <= scaled <= high else ""
    raise CaseError(field, value, f"gives {what} {measured:.4g} {unit}, {side} what any train or line has "
                                  f"[{low:g}, {high:g}] {unit}{hint} {_waiver(kind)}")


def _check_length(case) -> None:
    line, train = case.line, case.train
    _outside("line.length_m", line.length_m, "length", "a line of", LINE_LENGTH_M, "m", line.length_m,
             low_hint="a length in km where m is meant?")
    _outside("train.length_m", train.length_m, "length", "a train of", TRAIN_LENGTH_M, "m", train.length_m)
    if train.length_m > line.length_m:
        raise CaseError("train.length_m", train.length_m, f"is longer than the line ({line.length_m:g} m): a "
                                                          f"stop-to-stop run needs the line to hold the train "
                                                          f"{_waiver('length')}")


def _check_speed(case) -> None:
    _outside("train.max_speed_kmh", case.train.max_speed_kmh, "speed", "a top speed of", SPEED_KMH, "km/h",
             case.train.max_speed_kmh, high_hint="m/h where km/h is meant?")
    for k, row in enumerate(case.line.speed_limits):
        _outside(f"line.speed_limits[{k}]", list(row), "speed", "a limit of", SPEED_KMH, "km/h", row[2],
                 high_hint="m/h where km/h is meant?")


def _check_gradient(case) -> None:
    rows = case.line.gradients
    steepest = max((abs(row[2]) for row in rows), default=0.0)
    if steepest <= MAX_GRADIENT_PERMILLE:
        return
    k = next(k for k, row in enumerate(rows) if abs(row[2]) > MAX_GRADIENT_PERMILLE)
    raise CaseError(f"line.gradients[{k}]", list(rows[k]),
                    f"is a gradient of {rows[k][2]:g} permille, steeper than +-{MAX_GRADIENT_PERMILLE:g} permille "
                    "(the steepest adhesion main lines and metros); percent where permille is meant? "
                    f"{_waiver('gradient')}")


def _check_mass(case) -> None:
    train = case.train
    _outside("train.mass_t", train.mass_t, "mass", "a train of", MASS_T, "t", train.mass_t,
             low_hint="the unit is tonnes (t), not kt", high_hint="kg where t is meant?")
    if train.length_m >= POINT_MASS_BELOW_M:
        _outside("train.mass_t", train.mass_t, "mass", "a mass per metre of", MASS_PER_METRE_T, "t/m",
                 train.mass_t / train.length_m, high_hint="kg where t is meant?")


def _curve_field(name: str, curve: ForceCurve) -> tuple[str, object]:
    if curve.segments is not None:
        return f"train.{name}.segments", [[v, list(p)] for v, p in curve.segments]
    if curve.table is not None:
        return f"train.{name}.table", [list(r) for r in curve.table]
    return f"train.{name}.max_force_kn", curve.max_force_kn


def _check_force(case) -> None:
    train = case.train
    weight_kn = train.mass_t * GRAVITY_MS2
    speeds_kmh = np.linspace(0.0, train.max_speed_kmh, 201)
    for name in ("traction", "braking"):
        curve = getattr(train, name)
        field, value = _curve_field(name, curve)
        force_curve = ForceCurve(segments=curve.segments, table=curve.table, max_force_kn=curve.max_force_kn)
        share = float(np.max(force_curve.force_kn(speeds_kmh))) / weight_kn
        _outside(field, value, "force", f"a largest {name} force per weight of", FORCE_PER_WEIGHT, "kN/kN",
                 share, high_hint="N where kN is meant?")
    if train.regen_max_force_kn is not None:
        _outside("train.braking.regen_max_force_kn", train.regen_max_force_kn, "force",
                 "an electric-brake force per weight of", (0.0, FORCE_PER_WEIGHT[1]), "kN/kN",
                 train.regen_max_force_kn / weight_kn, high_hint="N where kN is meant?")
    for name in ("max_accel_ms2", "max_decel_ms2"):
        cap_ms2 = getattr(train, name)
        if cap_ms2 is not None:
            _outside(f"train.{name}", cap_ms2, "force", "an acceleration cap of", ACCEL_MS2, "m/s^2", cap_ms2)
    top_kn = float(train.resistance.force_kn(train.max_speed_kmh, train.mass_t))
    _outside("train.resistance", train.resistance, "force", "a running resistance per weight at top speed of",
             (0.0, RESISTANCE_PER_WEIGHT), "kN/kN", top_kn / weight_kn,
             high_hint="N where kN is meant (or 'kN' where the coefficients are N/kN)?")


def _check_power(case) -> None:
    train = case.train
    for field, power_kw in (("train.traction.max_power_kw", train.traction.max_power_kw),
                            ("train.braking.max_power_kw", train.braking.max_power_kw),
                            ("train.braking.regen_max_power_kw", train.regen_max_power_kw)):
        if power_kw is not None:
            _outside(field, power_kw, "power", "a power per tonne of", POWER_KW_PER_T, "kW/t",
                     power_kw / train.mass_t, low_hint="MW where kW is meant?", high_hint="W where kW is meant?")
    _outside("train.aux_power_kw", train.aux_power_kw, "power", "an auxiliary power per tonne of",
             (0.0, AUX_POWER_KW_PER_T), "kW/t", train.aux_power_kw / train.mass_t, high_hint="W where kW is meant?")


def _check_time(case) -> None:
    times = [("run.planned_time_s", case.planned_time_s), ("run.dwell_s", case.dwell_s),
             ("run.time_margin_s", case.time_margin_s)]
    for k, leg in enumerate(case.legs):
        times += [(f"run.legs[{k}].planned_time_s", leg.planned_time_s), (f"run.legs[{k}].dwell_s", leg.dwell_s)]
    for field, seconds in times:
        _outside(field, seconds, "time", "a time of", (0.0, MAX_TIME_S), "s", seconds,
                 high_hint="ms where s is meant?")
    if case.time_margin_s > case.planned_time_s:
        raise CaseError("run.time_margin_s", case.time_margin_s,
                        f"is longer than the planned running time ({case.planned_time_s:g} s): any arrival "
                        f"would count as on time {_waiver('time')}")


def _check_efficiency(case) -> None:
    train = case.train
    top_force_kn = float(np.max(train.traction.force_kn(np.linspace(0.0, train.max_speed_kmh, 201))))
    for direction in ("traction", "regen"):
        efficiency_map = getattr(train, f"{direction}_efficiency_map")
        if efficiency_map is None:
            continue
        field = f"train.{direction}_efficiency_map"
        _outside(f"{field}.values", efficiency_map.peak, "efficiency", "a peak efficiency of", PEAK_EFFICIENCY, "",
                 efficiency_map.peak)
        _outside(f"{field}.speeds_kmh", list(efficiency_map.speeds_kmh), "efficiency",
                 "a top speed over the train's top speed (m/s for km/h below 0.3) of", MAP_COVERAGE, "",
                 efficiency_map.speeds_kmh[-1] / train.max_speed_kmh)
        _outside(f"{field}.forces_kn", list(efficiency_map.forces_kn), "efficiency",
                 "a top force over the train's largest traction force of", MAP_COVERAGE, "",
                 efficiency_map.forces_kn[-1] / top_force_kn, high_hint="N where kN is meant?")


_CHECKS = {"length": _check_length, "speed": _check_speed, "gradient": _check_gradient, "mass": _check_mass,
           "force": _check_force, "power": _check_power, "time": _check_time,
           "efficiency": _check_efficiency}


def check_plausible(case, allow: bool | Iterable[str] = False) -> None:
    """Raise :class:`CaseError` for the first value of ``case`` outside the plausibility bounds.

    Parameters
    ----------
    case : Case
    allow : bool or iterable of str
        Kinds of bound to waive (:data:`IMPLAUSIBLE_KINDS`); ``True`` waives all.
    """
    waived = allowed_kinds(allow)
    for kind in IMPLAUSIBLE_KINDS:
        if kind not in waived:
            _CHECKS[kind](case)

