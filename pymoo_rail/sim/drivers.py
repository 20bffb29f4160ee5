"""Driving strategies turned into kernel programs (rows ``end_m, mode, target_ms``).

Two encodings of the seeds:

- speed codes (Liu (2019) sections 4.3-4.4): the line is cut into sections, by the gradient and
  speed-limit breakpoints (non-equal partition, fig. 4-4) or into equal lengths (fig. 4-3); each
  section carries one target speed, reached by maximum traction or by coasting and then held
  (fig. 4-5); braking onto the platform happens at the latest moment the braking curve allows.
- switching points (Meng et al. (2017) and Tang et al. (2020)): a fixed sequence of regimes (traction, hold, coast, brake)
  with the positions where one gives way to the next.
"""

from __future__ import annotations

import numpy as np

from pymoo_rail.model import CaseError, Line
from pymoo_rail.sim.kernel import (
    MODE_BRAKE,
    MODE_COAST,
    MODE_DECEL,
    MODE_HOLD,
    MODE_HOLD_BRAKE,
    MODE_TOWARD,
    MODE_TRACTION,
)

# "hold" coasts where coasting accelerates; "hold_brake" brakes there to keep the speed
REGIME_MODES = {"traction": MODE_TRACTION, "hold": MODE_HOLD, "cruise": MODE_HOLD, "coast": MODE_COAST,
                "brake": MODE_BRAKE, "hold_brake": MODE_HOLD_BRAKE}


def gradient_limit_partition(line: Line, min_length_m: float = 0.0) -> np.ndarray:
    """Section boundaries at every gradient or limit change (Liu (2019) fig. 4-4).

    Sections shorter than ``min_length_m`` are merged into their successor.
    """
    points = line.breakpoints_m()
    if min_length_m > 0:
        kept = [points[0]]
        for p in points[1:-1]:
            if p - kept[-1] >= min_length_m:
                kept.append(p)
        if points[-1] - kept[-1] < min_length_m and len(kept) > 1:
            kept.pop()
        kept.append(points[-1])
        points = kept
    return np.asarray(points, dtype=float)


def equal_partition(line: Line, n_sections: int) -> np.ndarray:
    """``n_sections`` equal sections (Liu (2019) fig. 4-3)."""
    if not isinstance(n_sections, (int, np.integer)) or n_sections < 1:
        raise CaseError("n_sections", n_sections, "must be a positive integer")
    return np.linspace(0.0, line.length_m, n_sections + 1)


def _check_finite(name: str, values: np.ndarray) -> None:
    bad = np.argwhere(~np.isfinite(values))
    if bad.size:
        idx = tuple(int(i) for i in bad[0])
        raise ValueError(f"{name}{list(idx)} = {float(values[idx])}: the driving vector must be finite")


def speed_code_programs(boundaries_m: np.ndarray, codes_ms: np.ndarray) -> np.ndarray:
    """Programs for speed codes: ``codes_ms`` is (n_sections,) or (N, n_sections)."""
    codes = np.atleast_2d(np.asarray(codes_ms, dtype=float))
    _check_finite("speed_codes", codes)
    n_sections = boundaries_m.shape[0] - 1
    if codes.shape[1] != n_sections:
        raise ValueError(f"speed_codes has {codes.shape[1]} values per run: the partition has {n_sections} sections")
    if (codes < 0).any():
        idx = tuple(int(i) for i in np.argwhere(codes < 0)[0])
        raise ValueError(f"speed_codes{list(idx)} = {float(codes[idx])}: speeds must be >= 0")
    programs = np.empty((codes.shape[0], n_sections, 3))
    programs[:, :, 0] = boundaries_m[1:]
    programs[:, :, 1] = MODE_TOWARD
    programs[:, :, 2] = codes
    return programs


def switching_programs(positions_m: np.ndarray, regimes: tuple[str, ...], length_m: float) -> np.ndarray:
    """Programs for switching points.

    Parameters
    ----------
    positions_m : (n_switch,) or (N, n_switch)
        Where regime k gives way to regime k + 1; sorted along each row before use.
    regimes : sequence of str
        ``n_switch + 1`` names among traction, hold, coast, brake, hold_brake
        ("cruise" is accepted as an older name of hold).
    length_m : float
        The line length (the last regime runs to the end).
    """
    pos = np.atleast_2d(np.asarray(positions_m, dtype=float))
    _check_finite("switching_points", pos)
    if len(regimes) != pos.shape[1] + 1:
        raise ValueError(f"regimes has {len(regimes)} entries: {pos.shape[1]} switching points need {pos.shape[1] + 1}")
    modes = []
    for r in regimes:
        if r not in REGIME_MODES:
            raise ValueError(f"regime {r!r} is unknown (known: {sorted(REGIME_MODES)})")
        modes.append(REGIME_MODES[r])
    programs = np.empty((pos.shape[0], len(regimes), 3))
    programs[:, :-1, 0] = np.sort(np.clip(pos, 0.0, length_m), axis=1)
    programs[:, -1, 0] = length_m
    programs[:, :, 1] = modes
    programs[:, :, 2] = 0.0
    return programs


def braking_programs(positions_m: np.ndarray, regimes: tuple[str, ...], decel_ms2: np.ndarray,
                     length_m: float) -> np.ndarray:
    """Programs whose last regime is braking at a chosen constant deceleration (``MODE_DECEL``).

    Parameters
    ----------
    positions_m : (n_switch,) or (N, n_switch)
        Switching positions of ``regimes`` followed by the braking onset; sorted along each row,
        so the largest is the onset.
    regimes : sequence of str
        ``n_switch`` regimes run before braking (traction, hold, coast ...).
    decel_ms2 : (N,) or float
        Service deceleration of the braking phase (m/s^2, > 0).
    length_m : float
        Where the braking row ends (the end of the simulated track).
    """
    pos = np.atleast_2d(np.asarray(positions_m, dtype=float))
    decel = np.broadcast_to(np.asarray(decel_ms2, dtype=float), (pos.shape[0],))
    _check_finite("braking_decel_ms2", decel[:, None])
    if (decel <= 0).any():
        idx = int(np.argwhere(decel <= 0)[0, 0])
        raise ValueError(f"braking_decel_ms2[{idx}] = {float(decel[idx])}: the deceleration must be > 0")
    programs = switching_programs(pos, tuple(regimes) + ("brake",), length_m)
    programs[:, -1, 1] = MODE_DECEL
    programs[:, -1, 2] = decel
    return programs


def flat_out_program(length_m: float) -> np.ndarray:
    """Maximum traction everywhere: the limits and the platform brake it (the fastest run)."""
    return np.array([[length_m, MODE_TRACTION, 0.0]])


def replaced_rows(program: np.ndarray, rows: slice, mode: int) -> np.ndarray:
    """A copy of ``program`` whose ``rows`` say ``mode`` (no target; full traction where the program
    has a fourth column, the traction share of part-power rows)."""
    p = program.copy()
    p[rows, 1:3] = (mode, 0.0)
    p[rows, 3:] = 1.0
    return p
