"""TTOBench loss tables to efficiency maps and back.

TTOBench states a train's efficiency either as one number per direction or, in its dynamic form
(``00_Loco_Dyn`` of the TTOBench repository, the model of Kouzoupis et al.'s ms-eetc), as a table of
power **losses** over the motor **load** and the **velocity**: rows ``[load, velocity, losses]``
under ``"efficiency traction"`` and ``"efficiency reg brake"``. The load is ms-eetc's
(``mseetc.efficiency.forceToLoad``): the force as a share of the largest force at that speed,
``F / min(F_max, P_max / v)``, with the traction caps for traction and the regenerative-braking caps
for braking. The losses include the auxiliaries (ms-eetc's convention), so the losses at zero load
are what the train draws whatever it does.

:func:`maps_from_loss_tables` turns the tables into :class:`~pymoo_rail.model.EfficiencyMap` objects
and an auxiliary power: the auxiliaries are the smallest zero-load loss (drawn for the whole run,
``Train.aux_power_kw``); the rest of each loss becomes an efficiency, ``eta = F v / (F v + loss -
aux)`` in traction and ``(F v - loss + aux) / (F v)`` in braking (as
:func:`pymoo_rail.model.efficiency.maps_from_losses`). The map's speeds are the table's velocities
above 0, its forces every ``load x F_max(v)`` of the table; at each speed the loss is linear in the
load between the table's loads (ms-eetc interpolates them too), and beyond the table's loads at that
speed the efficiency of the edge holds (the convention of :class:`EfficiencyMap`). The map is exact
at every node of the table with a positive load and speed; a node at rest or at zero load carries
no efficiency (there is no wheel power), so the map holds its edge there.
:func:`loss_table_rows` is the inverse used by the writer: a map written as a loss table and read
back gives the same map.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence

import numpy as np

from pymoo_rail.constants import KMH_PER_MS
from pymoo_rail.model import CaseError, EfficiencyMap
from pymoo_rail.model.efficiency import efficiency_of_losses

DIRECTIONS = ("traction", "regen")
# TTOBench field of each direction's efficiency
FIELDS = {"traction": "efficiency traction", "regen": "efficiency reg brake"}
# Forces of the table that differ by less than this (relative) are one column of the map: a load
# written from a force and read back gives the force to within rounding.
_SAME_FORCE_RTOL = 1e-9

# A loss equal to the auxiliary power is an efficiency of 1 within this rounding of the subtraction.
_ROUNDING = 1e-12

LossRows = Sequence[tuple[float, float, float]]  # (load as a fraction, velocity km/h, loss kW)


def max_force_kn(speed_kmh: np.ndarray | float, force_kn: float, power_kw: float) -> np.ndarray:
    """The force at 100 % load: ``min(F_max, P_max / v)`` (kN at km/h)."""
    speed = np.asarray(speed_kmh, dtype=float)
    with np.errstate(divide="ignore"):
        return np.minimum(force_kn, np.where(speed > 0.0, power_kw * KMH_PER_MS / np.maximum(speed, 1e-300), np.inf))


def no_load_loss_kw(tables: Mapping[str, LossRows]) -> float:
    """The auxiliary power (kW): the smallest loss at zero load and a positive velocity, 0 if no
    table has such a row."""
    losses = [loss for rows in tables.values() for load, speed, loss in rows if load == 0.0 and speed > 0.0]
    return min(losses, default=0.0)


def _speed_rows(rows: LossRows, field: str, source: str) -> dict[float, tuple[np.ndarray, np.ndarray]]:
    """``{velocity: (loads, losses)}`` for the velocities above 0, loads sorted."""
    by_speed: dict[float, dict[float, float]] = {}
    for k, (load, speed, loss) in enumerate(rows):
        if speed == 0.0:
            continue  # no wheel power at rest: the map holds its lowest speed's row down to 0
        loads = by_speed.setdefault(speed, {})
        if load in loads:
            raise CaseError(f"{field}.values[{k}]", [load * 100.0, speed, loss],
                            f"a second loss at load {load * 100.0:g} % and {speed:g} km/h", source)
        loads[load] = loss
    if not by_speed:
        raise CaseError(f"{field}.values", list(rows), "needs rows at a velocity above 0 (an efficiency needs "
                                                       "wheel power)", source)
    out = {}
    for speed, loads in sorted(by_speed.items()):
        if max(loads) <= 0.0:
            raise CaseError(f"{field}.values", f"{speed:g} km/h", "needs a row with a load above 0 at this "
                                                                 "velocity (an efficiency needs wheel power)", source)
        order = sorted(loads)
        out[speed] = (np.array(order), np.array([loads[x] for x in order]))
    return out


def _columns(forces_kn: np.ndarray) -> tuple[float, ...]:
    """Sorted forces, those within ``_SAME_FORCE_RTOL`` of the one before merged into it."""
    kept: list[float] = []
    for force in np.sort(forces_kn):
        if not kept or force > kept[-1] * (1.0 + _SAME_FORCE_RTOL):
            kept.append(float(force))
    return tuple(kept)


def map_from_loss_table(direction: str, rows: LossRows, force_kn: float, power_kw: float, aux_kw: float,
                        source: str) -> EfficiencyMap:
    """The efficiency map of one direction's loss table (rows ``(load fraction, km/h, kW)``).

    ``force_kn`` and ``power_kw`` are that direction's caps (100 % load), ``aux_kw`` the auxiliary
    power taken out of every loss. A node where the efficiency would leave (0, 1] is a
    :class:`CaseError` naming the TTOBench field and the operating point.
    """
    field = FIELDS[direction]
    by_speed = _speed_rows(rows, field, source)
    speeds = np.array(list(by_speed))
    forces = _columns(np.concatenate([loads[loads > 0.0] * max_force_kn(v, force_kn, power_kw)
                                      for v, (loads, _) in by_speed.items()]))
    values = []
    for speed, (loads, losses) in by_speed.items():
        top_kn = max_force_kn(speed, force_kn, power_kw)
        # beyond the loads of the table the efficiency of its edge holds (EfficiencyMap's convention)
        load = np.clip(np.asarray(forces) / top_kn, loads[0], loads[-1])
        force = load * top_kn
        loss_kw = np.interp(load, loads, losses)
        wheel_kw = force * speed / KMH_PER_MS
        eta = efficiency_of_losses(wheel_kw, loss_kw, aux_kw, braking=direction == "regen")
        bad = np.flatnonzero(~((eta > 0.0) & (eta <= 1.0 + _ROUNDING)))
        if bad.size:
            j = int(bad[0])
            reason = ("loses more than the electric brake delivers" if direction == "regen"
                      else "loses less than the auxiliary power (the smallest zero-load loss)")
            raise CaseError(field, f"{loss_kw[j]:.6g} kW at {speed:g} km/h and {force[j]:.6g} kN "
                                   f"(load {100.0 * load[j]:.6g} %)",
                            f"{reason}: an efficiency in (0, 1] cannot hold it (auxiliaries {aux_kw:g} kW)", source)
        values.append(tuple(float(x) for x in np.minimum(eta, 1.0)))  # a loss equal to aux, to rounding
    return EfficiencyMap(tuple(float(v) for v in speeds), forces, tuple(values), f"train.{direction}_efficiency_map")


def _check_edge(efficiency_map: EfficiencyMap, direction: str) -> None:
    """A row at 0 km/h or a column at 0 kN must be what a reader of losses holds there (the next one)."""
    field = f"train.{direction}_efficiency_map"
    values = np.asarray(efficiency_map.values)
    if efficiency_map.speeds_kmh[0] == 0.0 and (len(values) == 1 or np.any(values[0] != values[1])):
        raise CaseError(f"{field}.values[0]", list(values[0]),
                        "TTOBench states losses, which carry no efficiency at 0 km/h: the row at 0 km/h must "
                        "equal the next row (the value held below the lowest speed)")
    if efficiency_map.forces_kn[0] == 0.0 and (values.shape[1] == 1 or np.any(values[:, 0] != values[:, 1])):
        raise CaseError(f"{field}.forces_kn[0]", list(values[:, 0]),
                        "TTOBench states losses, which carry no efficiency at 0 kN: the column at 0 kN must "
                        "equal the next column (the value held below the lowest force)")


def loss_table_rows(efficiency_map: EfficiencyMap, direction: str, force_kn: float, power_kw: float,
                    aux_kw: float) -> list[list[float]]:
    """Rows ``[load %, velocity km/h, loss kW]`` that :func:`map_from_loss_table` reads back to
    ``efficiency_map`` (and zero-load rows carrying ``aux_kw`` when it is positive).

    A map whose row at 0 km/h or column at 0 kN differs from its neighbour is a :class:`CaseError`
    naming it: losses carry no efficiency where there is no wheel power.
    """
    _check_edge(efficiency_map, direction)
    rows: list[list[float]] = []
    forces = np.asarray(efficiency_map.forces_kn)
    for speed, eta in zip(efficiency_map.speeds_kmh, np.asarray(efficiency_map.values)):
        if speed == 0.0:
            continue
        if aux_kw > 0.0:
            rows.append([0.0, float(speed), float(aux_kw)])
        for force, value in zip(forces, eta):
            if force == 0.0:
                continue
            wheel_kw = force * speed / KMH_PER_MS
            loss_kw = wheel_kw / value - wheel_kw + aux_kw if direction == "traction" else \
                wheel_kw - value * wheel_kw + aux_kw
            load_pct = 100.0 * force / float(max_force_kn(speed, force_kn, power_kw))
            rows.append([float(load_pct), float(speed), float(loss_kw)])
    return rows


__all__ = ["DIRECTIONS", "FIELDS", "LossRows", "max_force_kn", "no_load_loss_kw", "map_from_loss_table",
           "loss_table_rows"]
