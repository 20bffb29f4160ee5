"""The train: mass, inertia, length, limits, efficiencies."""

from __future__ import annotations

from dataclasses import dataclass

from pymoo_rail.constants import KMH_PER_MS
from pymoo_rail.model.curves import DavisResistance, ForceCurve
from pymoo_rail.model.efficiency import EfficiencyMap
from pymoo_rail.model.errors import CaseError, check_number

GRAVITY_MS2 = 9.81


def _require(field: str, value: float | None, **kwargs) -> None:
    check_number(field, value, **kwargs)


def _check_map(direction: str, efficiency_map: EfficiencyMap | None, constant: float) -> None:
    if efficiency_map is None:
        return
    if not isinstance(efficiency_map, EfficiencyMap):
        raise CaseError(f"train.{direction}_efficiency_map", efficiency_map, "must be an EfficiencyMap")
    if constant != efficiency_map.peak:
        raise CaseError(f"train.{direction}_efficiency", constant,
                        f"must be the peak of train.{direction}_efficiency_map ({efficiency_map.peak!r}) when a map "
                        "is given: the constant is what closed forms and estimates use")


@dataclass(frozen=True)
class Train:
    """A train as a point mass with a length (for limits and averaged gradients).

    Units follow the case file: tonnes, metres, km/h, kN, kW; ``*_si`` properties give SI.
    ``rotary_factor`` is gamma: the effective inertial mass is ``mass (1 + gamma)``.
    ``traction_efficiency_map`` and ``regen_efficiency_map`` (optional) make the efficiency a
    function of the operating point (speed, force); with one, the constant of that direction must be
    the map's peak (the value the closed forms and estimates see), see docs/efficiency.md.
    """

    mass_t: float
    length_m: float
    max_speed_kmh: float
    resistance: DavisResistance
    traction: ForceCurve
    braking: ForceCurve
    rotary_factor: float = 0.0
    max_accel_ms2: float | None = None
    max_decel_ms2: float | None = None
    traction_efficiency: float = 1.0
    regen_efficiency: float = 0.0
    regen_min_speed_kmh: float = 0.0
    regen_max_force_kn: float | None = None
    regen_max_power_kw: float | None = None
    aux_power_kw: float = 0.0
    name: str = ""
    traction_efficiency_map: EfficiencyMap | None = None
    regen_efficiency_map: EfficiencyMap | None = None

    def __post_init__(self) -> None:
        if not isinstance(self.name, str):
            raise CaseError("train.name", self.name, f"must be a string, not {type(self.name).__name__}")
        _require("train.mass_t", self.mass_t, positive=True)
        _require("train.length_m", self.length_m, positive=True)
        _require("train.max_speed_kmh", self.max_speed_kmh, positive=True)
        _require("train.rotary_factor", self.rotary_factor, nonneg=True, upper=1.0)
        _require("train.max_accel_ms2", self.max_accel_ms2, positive=True, optional=True)
        _require("train.max_decel_ms2", self.max_decel_ms2, positive=True, optional=True)
        _require("train.traction_efficiency", self.traction_efficiency, positive=True, upper=1.0)
        _require("train.regen_efficiency", self.regen_efficiency, nonneg=True, upper=1.0)
        _require("train.regen_min_speed_kmh", self.regen_min_speed_kmh, nonneg=True)
        _require("train.braking.regen_max_force_kn", self.regen_max_force_kn, positive=True, optional=True)
        _require("train.braking.regen_max_power_kw", self.regen_max_power_kw, positive=True, optional=True)
        _require("train.aux_power_kw", self.aux_power_kw, nonneg=True)
        for direction in ("traction", "regen"):
            _check_map(direction, getattr(self, f"{direction}_efficiency_map"), getattr(self, f"{direction}_efficiency"))
        for name in ("traction", "braking"):
            curve = getattr(self, name)
            if not isinstance(curve, ForceCurve):
                raise CaseError(f"train.{name}", curve, "must be a ForceCurve")
            curve.check_nonnegative(f"train.{name}", self.max_speed_kmh)

    @property
    def mass_kg(self) -> float:
        """Mass (kg)."""
        return self.mass_t * 1000.0

    @property
    def effective_mass_kg(self) -> float:
        """Mass including rotating inertia, ``m (1 + gamma)``."""
        return self.mass_kg * (1.0 + self.rotary_factor)

    @property
    def max_speed_ms(self) -> float:
        """Maximum speed (m/s)."""
        return self.max_speed_kmh / KMH_PER_MS

    @property
    def weight_kn(self) -> float:
        """Weight ``m g`` (kN)."""
        return self.mass_kg * GRAVITY_MS2 / 1000.0
