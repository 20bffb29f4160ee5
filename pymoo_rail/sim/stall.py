"""Why a train cannot reach the platform even at full traction: the field to blame, in words.

The flat-out run stops short for one of a few physical reasons; each names the case entry a
user has to fix instead of a generic ``'line'``:

1. a neutral section (no traction) at the platform, over the whole line, or one the train
   coasts into too slowly;
2. an absurd mass: traction or braking at standstill under 1 % of the weight (not even a
   10 permille gradient could be climbed or braked on);
3. a descent steeper than the train can brake on (braking force plus running resistance below
   the downhill pull at some speed up to the limit): it could neither hold a limit nor stop;
4. a speed limit (or top speed) below 1 km/h where the train stops: it cannot move under it;
5. a power cap so low that the traction just above standstill is below the resistance;
6. traction at standstill below the resistance where the train stalls: a climb too steep, or a
   traction curve too weak on the flat.
"""

from __future__ import annotations

from dataclasses import replace

import numpy as np

from pymoo_rail.constants import KMH_PER_MS
from pymoo_rail.model import GRAVITY_MS2, Case, InfeasibleCaseError, TrackGrid

# below this share of its weight as traction (braking) a train cannot climb (brake on) even 10 permille
MIN_FORCE_PER_WEIGHT = 0.01
# a limit below this is no limit a train runs under (the lowest real ones, in yards, are ~5 km/h)
MIN_LIMIT_KMH = 1.0


def _row_at(rows: tuple, start_m: float, end_m: float, key) -> int | None:
    """Index of the row overlapping [start_m, end_m] that maximises ``key(row)``."""
    best = None
    for k, row in enumerate(rows):
        if row[0] <= end_m and row[1] >= start_m and (best is None or key(row) > key(rows[best])):
            best = k
    return best


def _neutral_cause(case: Case, grid: TrackGrid, stop_m: float) -> InfeasibleCaseError | None:
    length = case.line.length_m
    for k, (start, end) in enumerate(case.line.neutral_sections):
        field, value = f"line.neutral_sections[{k}]", [start, end]
        if start <= 1e-9 and end >= length - 1e-9:
            reason = "covers the whole line: there is no traction anywhere, so the train cannot move"
        elif start <= 1e-9:
            reason = "begins at the platform (0 m): the train has no traction to start with"
        elif start - grid.dx_m <= stop_m <= end + grid.dx_m:
            reason = (f"the train coasts into it (no traction from {start:g} to {end:g} m) and stops at "
                      f"{stop_m:.1f} m inside it, even after full traction before it")
        else:
            continue
        return InfeasibleCaseError(field, value, reason, case.name)
    return None


def _descent_cause(case: Case, grid: TrackGrid) -> InfeasibleCaseError | None:
    train = case.train
    pull_n = -(grade := grid.grade_force_n + grid.other_force_n)
    if not (pull_n > 0).any():
        return None
    speeds_kmh = np.linspace(0.0, train.max_speed_kmh, 161)
    margin_n = (train.braking.force_kn(speeds_kmh) + train.resistance.force_kn(speeds_kmh, train.mass_t)) * 1000.0
    worst = np.minimum.accumulate(margin_n)  # weakest hold from 0 up to each speed
    limit_kmh = grid.limit_ms[:-1] * KMH_PER_MS
    reach = np.clip(np.searchsorted(speeds_kmh, limit_kmh, side="right") - 1, 0, len(speeds_kmh) - 1)
    short = np.flatnonzero(worst[reach] < pull_n)
    if not short.size:
        return None
    cell = short[np.argmax(pull_n[short] - worst[reach[short]])]
    v_idx = int(np.argmin(margin_n[: reach[cell] + 1]))
    x = grid.position_m[cell]
    rows = case.line.gradients
    k = _row_at(rows, x - train.length_m, x + grid.dx_m, key=lambda row: -row[2])
    field, value = (f"line.gradients[{k}]", list(rows[k])) if k is not None else ("line.gradients", grade[cell])
    return InfeasibleCaseError(
        field, value,
        f"is a descent this train cannot brake on: at {speeds_kmh[v_idx]:.0f} km/h its braking force plus "
        f"running resistance ({margin_n[v_idx] / 1000:.4g} kN) is below the downhill pull "
        f"({pull_n[cell] / 1000:.4g} kN at {x:.0f} m, {train.mass_t:g} t), so it can neither hold a speed "
        "limit nor stop there", case.name)


def _mass_cause(case: Case, stop_m: float) -> InfeasibleCaseError | None:
    train = case.train
    weight_kn = train.mass_kg * GRAVITY_MS2 / 1000.0
    for name, curve in (("traction", train.traction), ("braking", train.braking)):
        force_kn = float(curve.force_kn(0.0)[0])
        share = force_kn / weight_kn
        if share < MIN_FORCE_PER_WEIGHT:
            return InfeasibleCaseError(
                "train.mass_t", train.mass_t,
                f"the maximum {name} force at standstill ({force_kn:.4g} kN) is {100 * share:.3g} % of the train's "
                f"weight ({weight_kn:.4g} kN; real trains have 10-35 %): the train stops at {stop_m:.1f} m. "
                "Check the mass (tonnes) and the force curves (kN)", case.name)
    return None


def _limit_cause(case: Case, grid: TrackGrid, stop_m: float) -> InfeasibleCaseError | None:
    train = case.train
    if train.max_speed_kmh < MIN_LIMIT_KMH:
        return InfeasibleCaseError("train.max_speed_kmh", train.max_speed_kmh,
                                   f"is below {MIN_LIMIT_KMH:g} km/h: the train stops at {stop_m:.1f} m", case.name)
    rows = case.line.speed_limits
    k = _row_at(rows, stop_m - train.length_m, stop_m + grid.dx_m, key=lambda row: -row[2])
    if k is not None and rows[k][2] < MIN_LIMIT_KMH:
        return InfeasibleCaseError(f"line.speed_limits[{k}]", list(rows[k]),
                                   f"is a limit below {MIN_LIMIT_KMH:g} km/h: the train stops under it at "
                                   f"{stop_m:.1f} m", case.name)
    return None


def _resistance_kn(case: Case, grid: TrackGrid, stop_m: float, speed_kmh: float) -> float:
    """Running and line resistance (kN) at ``speed_kmh`` in the cell where the train stopped."""
    train = case.train
    cell = int(np.clip(np.searchsorted(grid.position_m, stop_m, side="right") - 1, 0, grid.grade_force_n.shape[0] - 1))
    return float(train.resistance.force_kn(speed_kmh, train.mass_t)) + (
        grid.grade_force_n[cell] + grid.other_force_n[cell]) / 1000.0


def _power_cause(case: Case, grid: TrackGrid, stop_m: float) -> InfeasibleCaseError | None:
    traction = case.train.traction
    if traction.max_power_kw is None:
        return None
    crawl_kmh = MIN_LIMIT_KMH
    capped_kn = float(traction.force_kn(crawl_kmh)[0])
    uncapped_kn = float(replace(traction, max_power_kw=None).force_kn(crawl_kmh)[0])
    resist_kn = _resistance_kn(case, grid, stop_m, crawl_kmh)
    if not capped_kn < resist_kn <= uncapped_kn:  # the cap, not the curve or a climb, stops the train
        return None
    return InfeasibleCaseError(
        "train.traction.max_power_kw", traction.max_power_kw,
        f"caps the traction at {crawl_kmh:g} km/h to {capped_kn:.4g} kN, below the resistance ({resist_kn:.4g} kN): "
        f"the train stops at {stop_m:.1f} m (a power in MW where kW is meant?)", case.name)


def _traction_cause(case: Case, grid: TrackGrid, stop_m: float) -> InfeasibleCaseError | None:
    train = case.train
    traction_kn = float(train.traction.force_kn(0.0)[0])
    resist_kn = _resistance_kn(case, grid, stop_m, 0.0)
    if traction_kn > resist_kn:
        return None
    rows = case.line.gradients
    k = _row_at(rows, stop_m - train.length_m, stop_m + grid.dx_m, key=lambda row: row[2])
    if k is not None and rows[k][2] > 0:
        return InfeasibleCaseError(
            f"line.gradients[{k}]", list(rows[k]),
            f"is a climb too steep for this train: at standstill its maximum traction ({traction_kn:.4g} kN) is "
            f"below the resistance ({resist_kn:.4g} kN) at {stop_m:.1f} m, where it stalls", case.name)
    return InfeasibleCaseError(
        "train.traction", traction_kn,
        f"the maximum traction at standstill (kN) is below the resistance ({resist_kn:.4g} kN) at {stop_m:.1f} m, "
        "where the train stalls", case.name)


def explain_stall(case: Case, grid: TrackGrid, stop_position_m: float) -> InfeasibleCaseError:
    """The error for a flat-out run that stops at ``stop_position_m`` before the platform.

    Returns (does not raise) an :class:`InfeasibleCaseError` whose field is the entry to fix.
    """
    causes = (lambda: _neutral_cause(case, grid, stop_position_m), lambda: _mass_cause(case, stop_position_m),
              lambda: _descent_cause(case, grid), lambda: _limit_cause(case, grid, stop_position_m),
              lambda: _power_cause(case, grid, stop_position_m), lambda: _traction_cause(case, grid, stop_position_m))
    for find in causes:
        cause = find()
        if cause is not None:
            return cause
    return InfeasibleCaseError("line", case.name, f"the train stops at {stop_position_m:.1f} m even at full "
                                                  "traction", case.name)
