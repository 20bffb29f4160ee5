"""Results of a run: the energy breakdown and the full trajectory."""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np
import pandas as pd

from pymoo_rail.constants import KMH_PER_MS
from pymoo_rail.sim import kernel as k


@dataclass(frozen=True)
class EnergyBreakdown:
    """Energy of a run in kWh; ``net_kwh = traction_kwh + aux_kwh - regen_kwh``."""

    traction_kwh: float
    regen_kwh: float
    aux_kwh: float
    net_kwh: float


@dataclass(frozen=True, eq=False)
class Trajectory:
    """A simulated run from the start to standstill.

    Arrays are per grid node (``accel_ms2``, ``force_n`` and ``regime`` describe the cell that
    starts at the node). ``regime`` codes are 0 traction, 1 hold, 2 coast, 3 brake
    (:data:`REGIME_NAMES`). ``summary`` holds every figure of the run by name (see
    :data:`pymoo_rail.sim.kernel.OUT_NAMES`).
    """

    position_m: np.ndarray
    speed_ms: np.ndarray
    time_s: np.ndarray
    accel_ms2: np.ndarray
    force_n: np.ndarray
    regime: np.ndarray
    limit_ms: np.ndarray
    energy: EnergyBreakdown
    running_time_s: float
    stop_error_m: float
    summary: dict = field(default_factory=dict)

    @property
    def speed_kmh(self) -> np.ndarray:
        """Speed at each node (km/h)."""
        return self.speed_ms * KMH_PER_MS

    @property
    def accel_variation_ms2(self) -> float:
        """Comfort figure: total variation of the acceleration, sum of ``|a_i - a_(i-1)|`` (m/s^2).

        Includes the steps from rest at the start and to rest at the end. Meng et al. (2017) call
        it jerk; it is the time integral of ``|jerk|``, not a jerk (m/s^3).
        """
        return self.summary["jerk_ms2"]

    @property
    def jerk_ms2(self) -> float:
        """Alias of :attr:`accel_variation_ms2` (the name used by Meng et al. (2017))."""
        return self.accel_variation_ms2

    @property
    def regime_changes(self) -> int:
        """Number of changes of driving regime over the run."""
        return int(self.summary["regime_changes"])

    @property
    def reached(self) -> bool:
        """True when the train stopped at the platform rather than short of it."""
        return bool(self.summary["reached"])

    def to_frame(self) -> pd.DataFrame:
        """The trace as a table (one row per node), e.g. for CSV export."""
        return pd.DataFrame({
            "position_m": self.position_m, "time_s": self.time_s, "speed_kmh": self.speed_kmh,
            "speed_ms": self.speed_ms, "accel_ms2": self.accel_ms2, "force_kn": self.force_n / 1000.0,
            "regime": [k.REGIME_NAMES[r] for r in self.regime], "limit_kmh": self.limit_ms * KMH_PER_MS,
        })


def summary_dict(row: np.ndarray) -> dict:
    """Name the columns of one kernel summary row."""
    return {name: float(row[i]) for i, name in enumerate(k.OUT_NAMES)}


def energy_from_summary(row: np.ndarray) -> EnergyBreakdown:
    """The energy breakdown of one row of the kernel's summary output."""
    return EnergyBreakdown(traction_kwh=float(row[k.OUT_TRACTION_KWH]), regen_kwh=float(row[k.OUT_REGEN_KWH]),
                           aux_kwh=float(row[k.OUT_AUX_KWH]), net_kwh=float(row[k.OUT_NET_KWH]))
