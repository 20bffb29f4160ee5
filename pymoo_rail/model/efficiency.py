"""Efficiency at the operating point: a table over speed and force, interpolated bilinearly.

A constant efficiency per direction (``Train.traction_efficiency``, ``Train.regen_efficiency``)
is the default. Where a source gives the efficiency as a function of the operating point (motor
maps, the "dynamic" model of Kouzoupis et al.'s ms-eetc), an :class:`EfficiencyMap` holds it as a
table over the speed (km/h) and the magnitude of the force at the wheel (kN): the electrical
power of traction is ``F v / eta(v, F)``, that of regenerative braking ``eta(v, F) F v``. Between
the table's nodes the efficiency is bilinear; beyond its edges it is the edge's value (the
convention of ms-eetc's loss tables, stated here so that no extrapolation is silent).

Where a source gives parts (motor, gear, converter), :meth:`EfficiencyMap.chain` multiplies them.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, field as dataclass_field

import numpy as np

from pymoo_rail.constants import KMH_PER_MS
from pymoo_rail.model.errors import CaseError, check_number


def _axis(field: str, values: tuple[float, ...]) -> None:
    if len(values) < 1:
        raise CaseError(field, list(values), "needs at least one value")
    for k, value in enumerate(values):
        check_number(f"{field}[{k}]", value, nonneg=True)
        if k and not values[k] > values[k - 1]:
            raise CaseError(f"{field}[{k}]", value, "must be larger than the value before it (strictly increasing)")


@dataclass(frozen=True)
class EfficiencyMap:
    """Efficiency over speed and force, bilinear between the nodes of a table.

    Parameters
    ----------
    speeds_kmh : tuple of float
        Speeds of the table's rows (km/h), strictly increasing from >= 0.
    forces_kn : tuple of float
        Force magnitudes of the table's columns (kN), strictly increasing from >= 0.
    values : tuple of tuple of float
        ``values[i][j]`` is the efficiency at ``speeds_kmh[i]`` and ``forces_kn[j]``, in (0, 1].
    field : str
        The field path errors name (``train.traction_efficiency_map`` in a case file).
    """

    speeds_kmh: tuple[float, ...]
    forces_kn: tuple[float, ...]
    values: tuple[tuple[float, ...], ...]
    field: str = dataclass_field(default="efficiency_map", compare=False)  # where it came from, not what it is

    def __post_init__(self) -> None:
        _axis(f"{self.field}.speeds_kmh", self.speeds_kmh)
        _axis(f"{self.field}.forces_kn", self.forces_kn)
        if len(self.values) != len(self.speeds_kmh):
            raise CaseError(f"{self.field}.values", f"{len(self.values)} rows",
                            f"needs one row per speed ({len(self.speeds_kmh)})")
        for i, row in enumerate(self.values):
            if len(row) != len(self.forces_kn):
                raise CaseError(f"{self.field}.values[{i}]", list(row),
                                f"needs one value per force ({len(self.forces_kn)})")
            for j, value in enumerate(row):
                check_number(f"{self.field}.values[{i}][{j}]", value, positive=True, upper=1.0)

    @property
    def peak(self) -> float:
        """The largest efficiency of the table."""
        return max(max(row) for row in self.values)

    def table_si(self) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """(speeds m/s, forces N, values (n_speeds, n_forces)) for the kernels."""
        return (np.asarray(self.speeds_kmh, dtype=float) / KMH_PER_MS, np.asarray(self.forces_kn, dtype=float) * 1000.0,
                np.asarray(self.values, dtype=float))

    def efficiency(self, speed_kmh: np.ndarray | float, force_kn: np.ndarray | float) -> np.ndarray:
        """Bilinear efficiency at ``speed_kmh`` and the magnitude of ``force_kn`` (plain numpy;
        the kernels use :func:`pymoo_rail.sim.physics.map_efficiency` on :meth:`table_si`)."""
        v, f = np.broadcast_arrays(np.asarray(speed_kmh, dtype=float), np.abs(np.asarray(force_kn, dtype=float)))
        vs, fs, table = np.asarray(self.speeds_kmh), np.asarray(self.forces_kn), np.asarray(self.values)
        i, ti = _cell(vs, v)
        j, tj = _cell(fs, f)
        i1 = np.minimum(i + 1, len(vs) - 1)
        j1 = np.minimum(j + 1, len(fs) - 1)
        low = table[i, j] + tj * (table[i, j1] - table[i, j])
        high = table[i1, j] + tj * (table[i1, j1] - table[i1, j])
        return low + ti * (high - low)

    @classmethod
    def from_function(cls, function: Callable[[np.ndarray, np.ndarray], np.ndarray], speeds_kmh, forces_kn,
                      field: str = "efficiency_map") -> EfficiencyMap:
        """Tabulate a formula ``function(speed_kmh, force_kn) -> efficiency`` on a grid (broadcast)."""
        v = np.asarray(speeds_kmh, dtype=float)[:, None]
        f = np.asarray(forces_kn, dtype=float)[None, :]
        values = np.broadcast_to(np.asarray(function(v, f), dtype=float), (v.shape[0], f.shape[1]))
        return cls(tuple(float(x) for x in v[:, 0]), tuple(float(x) for x in f[0]),
                   tuple(tuple(float(x) for x in row) for row in values), field)

    @classmethod
    def chain(cls, parts: tuple[EfficiencyMap | float, ...], field: str = "efficiency_map") -> EfficiencyMap:
        """The product of efficiencies in series (motor x gear x converter), on the union of the
        maps' nodes. Numbers are constant parts; at least one part must be a map."""
        maps = [p for p in parts if isinstance(p, EfficiencyMap)]
        if not maps:
            raise CaseError(field, list(parts), "a chain needs at least one map (a product of numbers is a constant)")
        for k, part in enumerate(parts):
            if not isinstance(part, EfficiencyMap):
                check_number(f"{field}.chain[{k}]", part, positive=True, upper=1.0)
        speeds = sorted({s for m in maps for s in m.speeds_kmh})
        forces = sorted({f for m in maps for f in m.forces_kn})

        def product(v: np.ndarray, f: np.ndarray) -> np.ndarray:
            out = np.ones(np.broadcast_shapes(v.shape, f.shape))
            for part in parts:
                out = out * (part.efficiency(v, f) if isinstance(part, EfficiencyMap) else part)
            return out

        return cls.from_function(product, speeds, forces, field)


def _cell(nodes: np.ndarray, x: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Index of the table cell holding each ``x`` and the fraction across it (0 beyond the edges)."""
    if len(nodes) == 1:
        return np.zeros(x.shape, dtype=int), np.zeros(x.shape)
    k = np.clip(np.searchsorted(nodes, x, side="right") - 1, 0, len(nodes) - 2)
    t = np.clip((x - nodes[k]) / (nodes[k + 1] - nodes[k]), 0.0, 1.0)
    return k, t


def efficiency_of_losses(wheel_power: np.ndarray, loss: np.ndarray, aux_power: float | np.ndarray,
                         braking: bool) -> np.ndarray:
    """Efficiency at operating points whose losses include the auxiliary power (any one power unit).

    Traction: ``P / (P + loss - aux)``; braking: ``(P - loss + aux) / P``, ``P`` the wheel power
    (> 0). Not clipped: a value outside (0, 1] is for the caller to refuse or hold.
    """
    wheel = np.asarray(wheel_power, dtype=float)
    lost = np.asarray(loss, dtype=float) - aux_power
    return (wheel - lost) / wheel if braking else wheel / (wheel + lost)


def maps_from_losses(speeds_kmh, forces_kn, traction_loss_w, braking_loss_w, aux_power_kw: float = 0.0,
                     min_efficiency: float = 0.01) -> tuple[EfficiencyMap, EfficiencyMap, int]:
    """Traction and regeneration maps of a source that gives power losses (W) at the operating point.

    ``traction_loss_w[i][j]`` is the power lost (beyond the wheel power) when the train pulls with
    ``forces_kn[j]`` at ``speeds_kmh[i]``, ``braking_loss_w[i][j]`` when it brakes electrically with
    it; both include ``aux_power_kw`` (ms-eetc's convention), which the train model draws separately
    (``Train.aux_power_kw``). Then ``eta_traction = F v / (F v + loss - aux)`` and ``eta_regen =
    (F v - loss + aux) / (F v)``. Where braking loses more than the brake delivers (a regen
    efficiency below ``min_efficiency``), the map holds ``min_efficiency``, and 1 where a loss is
    below the auxiliary power: the number of such nodes is returned so that a caller can report it. Forces and speeds must be > 0 (no efficiency at rest).

    Returns
    -------
    (traction map, regen map, nodes held at ``min_efficiency`` or 1)
    """
    v = np.asarray(speeds_kmh, dtype=float)[:, None] / KMH_PER_MS
    f = np.asarray(forces_kn, dtype=float)[None, :] * 1000.0
    if np.any(v <= 0.0) or np.any(f <= 0.0):
        raise CaseError("speeds_kmh|forces_kn", (list(speeds_kmh), list(forces_kn)),
                        "must all be > 0: an efficiency needs wheel power")
    aux_w = aux_power_kw * 1000.0
    wheel_w = f * v
    traction = efficiency_of_losses(wheel_w, traction_loss_w, aux_w, braking=False)
    regen = efficiency_of_losses(wheel_w, braking_loss_w, aux_w, braking=True)
    raised = int(sum(np.count_nonzero((e < min_efficiency) | (e > 1.0)) for e in (traction, regen)))

    def table(values: np.ndarray, field: str) -> EfficiencyMap:
        values = np.clip(values, min_efficiency, 1.0)
        return EfficiencyMap(tuple(float(s) for s in speeds_kmh), tuple(float(x) for x in forces_kn),
                             tuple(tuple(float(x) for x in row) for row in values), field)

    return table(traction, "train.traction_efficiency_map"), table(regen, "train.regen_efficiency_map"), raised
