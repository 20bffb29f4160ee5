"""OSRD railjson rolling stock to :class:`~pymoo_rail.model.Train`.

OSRD (Open Source Railway Designer, OpenRail Association, LGPL-3.0) describes a train as a railjson
*rolling stock*: SI units throughout (kg, m, m/s, N), tractive effort curves per traction *mode*
(``"25000V"``, ``"1500V"``, ``"thermal"``, ...) and per *comfort* class (``"STANDARD"``,
``"AIR_CONDITIONING"``, ``"HEATING"``), a Davis resistance ``A + B v + C v^2`` in N with v in m/s, an
inertia coefficient (accelerated mass ``mass x inertia_coefficient``), a comfort acceleration and a
constant braking deceleration ``const_gamma``.

>>> from pymoo_rail.cases.railjson_rolling_stock import read_rolling_stock
>>> stock = read_rolling_stock("tests/data/osrd/rolling_stocks/intercity-train.json")  # doctest: +SKIP
>>> stock.modes, stock.default_mode  # doctest: +SKIP
(('1500V', '25000V'), '1500V')
>>> train = stock.train(mode="25000V", comfort="AIR_CONDITIONING")  # doctest: +SKIP

Mapping (the full table is in ``docs/railjson.md``):

- ``mass`` kg -> ``mass_t``; ``length``; ``max_speed`` m/s -> km/h.
- ``inertia_coefficient`` k -> ``rotary_factor = k - 1`` (OSRD accelerates ``mass x k``).
- ``rolling_resistance`` (``type = "davis"``): A, B, C -> ``DavisResistance(A, B, C, unit="kN",
  speed_unit="ms")`` after dividing by 1000 (same force, kN).
- The effort curve of the chosen mode and comfort -> ``traction`` as a table (km/h, kN), linear
  between OSRD's points as OSRD interpolates them; the last force holds beyond the last speed.
- ``comfort_acceleration`` -> ``max_accel_ms2``: the schema's "maximum operational acceleration".
  OSRD's simulator (2025 core) passes it on but its integrator accelerates with the full effort;
  ``dataclasses.replace(train, max_accel_ms2=None)`` drives that way.
- ``const_gamma`` -> ``max_decel_ms2`` and a braking force ``const_gamma x mass x k``: the
  deceleration is ``const_gamma`` on level track, as in OSRD, which holds it on every gradient;
  :func:`pymoo_rail.cases.railjson.railjson_case` adds the force that keeps it on the steepest
  descent of the line.
- OSRD computes mechanical energy: traction efficiency 1, no regeneration, no auxiliaries.
- Kept on :class:`RailjsonRollingStock`, not in the ``Train``: ``startup_time`` /
  ``startup_acceleration`` (OSRD's simulator reads them but its integrator does not apply them),
  ``electrical_power_startup_time`` and ``raise_pantograph_time`` (used by ``railjson_case`` to
  lengthen the no-traction stretch after a neutral section), ``primary_category`` (the speed
  limit category of the train, see ``docs/railjson.md``).
- Not representable, a :class:`CaseError` naming the field: a resistance that is not Davis,
  effort curves that do not start at 0 m/s, speeds that do not increase, an inertia coefficient
  outside [1, 2], a zero comfort acceleration. Not modelled, a :class:`RailjsonWarning` naming
  the field: ``energy_sources`` (OSRD's battery/power-pack model), ``etcs_brake_params`` (OSRD
  brakes with ``const_gamma`` outside ETCS), conditional curves by electrical profile or power
  restriction.
"""

from __future__ import annotations

import math
import warnings
from collections.abc import Mapping
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from pymoo_rail.cases.json_files import Source, load_json_object
from pymoo_rail.constants import KMH_PER_MS
from pymoo_rail.model import CaseError, DavisResistance, ForceCurve, Train

class RailjsonWarning(UserWarning):
    """A railjson field that is read and checked but not modelled (the message names it)."""


def warn_field(field: str, reason: str, source: str) -> None:
    """Warn that a railjson field is not modelled."""
    warnings.warn(f"{source}: railjson field '{field}' {reason}", RailjsonWarning, stacklevel=3)


def load_json(source: Source, what: str) -> tuple[dict, str]:
    """The parsed JSON object of a railjson file (or a dict as is) and a label for messages."""
    return load_json_object(source, f"railjson {what}")


def number(data: Mapping, key: str, source: str, *, field: str | None = None, positive: bool = False,
           optional: bool = False) -> float | None:
    """A finite number of a railjson object, else a :class:`CaseError` naming ``field``."""
    field = field or key
    if key not in data or data[key] is None:
        if optional:
            return None
        raise CaseError(field, None, "is required", source)
    value = data[key]
    if isinstance(value, bool) or not isinstance(value, (int, float)) or not math.isfinite(value):
        raise CaseError(field, value, "must be a finite number", source)
    if value < 0 or (positive and value == 0):
        raise CaseError(field, value, "must be > 0" if positive else "must be >= 0", source)
    return float(value)


def is_rolling_stock(data: Mapping) -> bool:
    """Whether a parsed JSON object is a railjson rolling stock (it has effort curves and a resistance)."""
    return isinstance(data, Mapping) and "effort_curves" in data and "rolling_resistance" in data


@dataclass(frozen=True)
class EffortCurve:
    """One tractive effort curve: speeds (m/s) and the maximum force at each (N)."""

    speeds_ms: tuple[float, ...]
    forces_n: tuple[float, ...]

    def force_curve(self) -> ForceCurve:
        """The curve in the case format: a table of (km/h, kN)."""
        return ForceCurve(table=tuple((v * KMH_PER_MS, f / 1000.0) for v, f in zip(self.speeds_ms, self.forces_n)))


@dataclass(frozen=True)
class TractionMode:
    """The effort curves of one traction mode: the default curve and one per comfort class."""

    name: str
    is_electric: bool
    default_curve: EffortCurve
    comfort_curves: Mapping[str, EffortCurve]


@dataclass(frozen=True)
class RailjsonRollingStock:
    """A railjson rolling stock, checked, with every field the :class:`Train` model uses or that
    matters around it (start-up, pantograph and category)."""

    name: str
    source: str
    modes: tuple[str, ...]
    default_mode: str
    traction_modes: Mapping[str, TractionMode]
    mass_kg: float
    length_m: float
    max_speed_ms: float
    inertia_coefficient: float
    davis_a_n: float
    davis_b_n_per_ms: float
    davis_c_n_per_ms2: float
    comfort_accel_ms2: float
    const_gamma_ms2: float
    startup_time_s: float
    startup_accel_ms2: float
    electrical_power_startup_time_s: float | None
    raise_pantograph_time_s: float | None
    primary_category: str | None

    def comforts(self, mode: str | None = None) -> tuple[str, ...]:
        """Comfort classes that have their own curve in a mode (default: the default mode)."""
        return tuple(self._mode(mode).comfort_curves)

    def is_electric(self, mode: str | None = None) -> bool:
        """Whether a mode draws power from an electrification (default: the default mode)."""
        return self._mode(mode).is_electric

    def _mode(self, mode: str | None) -> TractionMode:
        name = self.default_mode if mode is None else mode
        if name not in self.traction_modes:
            raise CaseError("mode", mode, f"rolling stock '{self.name}' has no such traction mode "
                                          f"(available: {', '.join(self.modes)}; default {self.default_mode})",
                            self.source)
        return self.traction_modes[name]

    def effort_curve(self, mode: str | None = None, comfort: str | None = None) -> EffortCurve:
        """The effort curve of a mode and a comfort class.

        ``mode=None`` is the file's ``default_mode``; ``comfort=None`` is the mode's
        ``default_curve``. A mode or comfort class the file lacks is a :class:`CaseError`
        listing the available ones.
        """
        chosen = self._mode(mode)
        if comfort is None:
            return chosen.default_curve
        if comfort not in chosen.comfort_curves:
            known = ", ".join(chosen.comfort_curves) or "none"
            raise CaseError("comfort", comfort, f"mode '{chosen.name}' of rolling stock '{self.name}' has no curve "
                                                f"for this comfort class (available: {known}; comfort=None "
                                                f"takes the mode's default_curve)", self.source)
        return chosen.comfort_curves[comfort]

    def train(self, mode: str | None = None, comfort: str | None = None, *,
              braking_force_kn: float | None = None) -> Train:
        """The :class:`Train` of a traction mode and comfort class.

        Parameters
        ----------
        mode, comfort : str, optional
            As :meth:`effort_curve`.
        braking_force_kn : float, optional
            The braking force; default ``const_gamma x mass x inertia_coefficient``, which gives
            ``const_gamma`` on level track (the deceleration is capped at ``const_gamma`` anyway).
        """
        curve = self.effort_curve(mode, comfort)
        effective_kg = self.mass_kg * self.inertia_coefficient
        braking = braking_force_kn if braking_force_kn is not None else self.const_gamma_ms2 * effective_kg / 1000.0
        label = self.default_mode if mode is None else mode
        name = f"{self.name} ({label}{', ' + comfort if comfort else ''})"
        try:
            return Train(
                name=name, mass_t=self.mass_kg / 1000.0, length_m=self.length_m,
                max_speed_kmh=self.max_speed_ms * KMH_PER_MS, rotary_factor=round(self.inertia_coefficient - 1.0, 12),
                max_accel_ms2=self.comfort_accel_ms2, max_decel_ms2=self.const_gamma_ms2,
                resistance=DavisResistance(self.davis_a_n / 1000.0, self.davis_b_n_per_ms / 1000.0,
                                           self.davis_c_n_per_ms2 / 1000.0, unit="kN", speed_unit="ms"),
                traction=curve.force_curve(), braking=ForceCurve(max_force_kn=braking))
        except CaseError as err:
            raise CaseError(err.field, err.value, err.reason, self.source) from None


def _curve(data: Any, field: str, source: str) -> EffortCurve:
    if not isinstance(data, Mapping):
        raise CaseError(field, data, "must be an object {speeds, max_efforts}", source)
    speeds, efforts = data.get("speeds"), data.get("max_efforts")
    for key, values in (("speeds", speeds), ("max_efforts", efforts)):
        if not isinstance(values, list) or len(values) < 2:
            raise CaseError(f"{field}.{key}", values, "must be an array of at least 2 numbers", source)
        for k, value in enumerate(values):
            number({"v": value}, "v", source, field=f"{field}.{key}[{k}]")
    if len(speeds) != len(efforts):
        raise CaseError(f"{field}.max_efforts", f"{len(efforts)} values",
                        f"must have one force per speed ({len(speeds)} speeds)", source)
    if speeds[0] != 0.0:
        raise CaseError(f"{field}.speeds[0]", speeds[0], "the curve must start at 0 m/s (a train must be able "
                                                         "to start)", source)
    for k in range(1, len(speeds)):
        if not speeds[k] > speeds[k - 1]:
            raise CaseError(f"{field}.speeds[{k}]", speeds[k], "speeds must strictly increase", source)
    return EffortCurve(tuple(float(v) for v in speeds), tuple(float(f) for f in efforts))


def _mode(name: str, data: Any, source: str) -> TractionMode:
    field = f"effort_curves.modes.{name}"
    if not isinstance(data, Mapping):
        raise CaseError(field, data, "must be an object", source)
    default = _curve(data.get("default_curve"), f"{field}.default_curve", source)
    comfort: dict[str, EffortCurve] = {}
    curves = data.get("curves", [])
    if not isinstance(curves, list):
        raise CaseError(f"{field}.curves", curves, "must be an array", source)
    for k, entry in enumerate(curves):
        cond = entry.get("cond", {}) if isinstance(entry, Mapping) else None
        if not isinstance(cond, Mapping):
            raise CaseError(f"{field}.curves[{k}]", entry, "must be an object {cond, curve}", source)
        if cond.get("electrical_profile_level") is not None or cond.get("power_restriction_code") is not None:
            warn_field(f"{field}.curves[{k}].cond", "selects a curve by electrical profile or power restriction, "
                                                    "which the model does not represent: the curve is not used", source)
            continue
        key = cond.get("comfort")
        if not isinstance(key, str) or not key:
            raise CaseError(f"{field}.curves[{k}].cond.comfort", key, "must be a comfort class name", source)
        comfort[key] = _curve(entry.get("curve"), f"{field}.curves[{k}].curve", source)
    is_electric = data.get("is_electric")
    if not isinstance(is_electric, bool):
        raise CaseError(f"{field}.is_electric", is_electric, "must be true or false", source)
    return TractionMode(name=name, is_electric=is_electric, default_curve=default, comfort_curves=comfort)


def read_rolling_stock(source: Source) -> RailjsonRollingStock:
    """Read and check a railjson rolling stock file (or its parsed JSON object).

    Raises
    ------
    CaseError
        Naming the railjson field of anything the model cannot represent.
    """
    data, label = load_json(source, "rolling stock")
    if not is_rolling_stock(data):
        raise CaseError("effort_curves", None, "is required: not a railjson rolling stock "
                                               "(needs effort_curves and rolling_resistance)", label)
    curves = data["effort_curves"]
    if not isinstance(curves, Mapping) or not isinstance(curves.get("modes"), Mapping) or not curves["modes"]:
        raise CaseError("effort_curves.modes", curves, "must be an object with at least one mode", label)
    modes = {name: _mode(name, mode, label) for name, mode in curves["modes"].items()}
    default_mode = curves.get("default_mode")
    if default_mode not in modes:
        raise CaseError("effort_curves.default_mode", default_mode, f"must be one of the modes ({', '.join(modes)})",
                        label)
    resistance = data["rolling_resistance"]
    if not isinstance(resistance, Mapping) or resistance.get("type") != "davis":
        raise CaseError("rolling_resistance.type", resistance.get("type") if isinstance(resistance, Mapping)
                        else resistance, "only the Davis formula (type 'davis') can be represented", label)
    davis = [number(resistance, key, label, field=f"rolling_resistance.{key}") for key in ("A", "B", "C")]
    inertia = number(data, "inertia_coefficient", label, positive=True)
    if not 1.0 <= inertia <= 2.0:
        raise CaseError("inertia_coefficient", inertia, "must be in [1, 2]: the accelerated mass is mass x "
                                                        "inertia_coefficient, at least the mass itself", label)
    if data.get("energy_sources"):
        warn_field("energy_sources", "(batteries, power packs, catenary limits) is not modelled: the effort "
                                     "curves alone limit the traction", label)
    if data.get("etcs_brake_params") is not None:
        warn_field("etcs_brake_params", "is not modelled: braking uses const_gamma (OSRD's braking outside "
                                        "ETCS)", label)
    name = data.get("name")
    category = data.get("primary_category")
    return RailjsonRollingStock(
        name=name if isinstance(name, str) and name else Path(label).stem, source=label,
        modes=tuple(modes), default_mode=default_mode, traction_modes=modes,
        mass_kg=number(data, "mass", label, positive=True), length_m=number(data, "length", label, positive=True),
        max_speed_ms=number(data, "max_speed", label, positive=True), inertia_coefficient=inertia,
        davis_a_n=davis[0], davis_b_n_per_ms=davis[1], davis_c_n_per_ms2=davis[2],
        comfort_accel_ms2=number(data, "comfort_acceleration", label, positive=True),
        const_gamma_ms2=number(data, "const_gamma", label, positive=True),
        startup_time_s=number(data, "startup_time", label, optional=True) or 0.0,
        startup_accel_ms2=number(data, "startup_acceleration", label, optional=True) or 0.0,
        electrical_power_startup_time_s=number(data, "electrical_power_startup_time", label, optional=True),
        raise_pantograph_time_s=number(data, "raise_pantograph_time", label, optional=True),
        primary_category=category if isinstance(category, str) else None)


__all__ = ["RailjsonRollingStock", "TractionMode", "EffortCurve", "RailjsonWarning", "read_rolling_stock",
           "is_rolling_stock"]
