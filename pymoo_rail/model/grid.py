"""The line on a distance grid: what the simulator and the exact solver read per step.

Line resistances are per unit weight (N/kN): gradient ``i`` permille gives ``i`` N/kN (Liu (2019)
eq. 2-10), a curve of radius R gives ``600 / R`` (Liu (2019) eq. 2-11, Tang et al. (2020) eq. 2;
``line.curve_model = "tang2020"``) or Roeckl's standard-gauge ``650 / (R - 55)`` for R >= 300 m and
``500 / (R - 30)`` below (``"roeckl"``), a tunnel of length Ls gives ``0.00013 Ls`` (Liu (2019)
eq. 2-12). Averaged over the train, ``600 / R`` is Tang et al.'s ``10.5 alpha / L_c`` branch for a
curve shorter than the train (alpha in degrees: ``10.5 alpha / L_c = 601.6 L_r / (R L_c)``). With
``gradient_model = "train_length"`` they act on the train as the average over its length (eq. 4-14); the stations beyond both ends count as flat. Each grid cell
stores the exact mean of that (piecewise linear) average over the cell, so the work done against
gradients over a run equals ``m g`` times the rise of the train's centre of mass exactly.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np
from numba import njit

from pymoo_rail.model.case import Case
from pymoo_rail.constants import KMH_PER_MS
from pymoo_rail.model.errors import CaseError
from pymoo_rail.model.train import GRAVITY_MS2

CURVE_RESISTANCE_A = 600.0  # Liu (2019) eq. 2-11, the usual value in [450, 800]
OSRD_CURVE_RESISTANCE_A = 800.0  # OSRD's equivalent gradient of a curve, 800 / |R| m/km
TUNNEL_RESISTANCE_PER_M = 0.00013  # Liu (2019) eq. 2-12, N/kN per metre of tunnel


@dataclass(frozen=True, eq=False)
class TrackGrid:
    """Per-node and per-cell arrays of one line for one train.

    Attributes
    ----------
    position_m : (n,) node positions, from 0 to the line length
    limit_ms : (n,) the speed limit at each node for the head of the train, the lowest limit that
        applies anywhere under the train or within the next cell (so it holds over the whole length)
    grade_force_n : (n-1,) gradient force per cell, + resists motion
    other_force_n : (n-1,) curve and tunnel resistance per cell (always >= 0)
    neutral : (n-1,) 1 where the cell touches a neutral section (no traction), else 0
    """

    dx_m: float
    position_m: np.ndarray
    limit_ms: np.ndarray
    grade_force_n: np.ndarray
    other_force_n: np.ndarray
    neutral: np.ndarray

    @property
    def n_nodes(self) -> int:
        """Number of grid nodes (cells + 1)."""
        return self.position_m.shape[0]

    @property
    def line_force_n(self) -> np.ndarray:
        """All line resistance per cell (gradient + curves + tunnels)."""
        return self.grade_force_n + self.other_force_n


Rows = Sequence[Sequence[float]]


@njit(cache=True, no_cfunc_wrapper=True)
def _running_integrals(knots: np.ndarray, slope: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """W and WW at the knots of a piecewise-constant w (``slope`` on each knot interval)."""
    n = knots.shape[0]
    w_cum = np.zeros(n)
    ww_cum = np.zeros(n)
    for k in range(1, n):
        h = knots[k] - knots[k - 1]
        w_cum[k] = w_cum[k - 1] + slope[k - 1] * h
        ww_cum[k] = ww_cum[k - 1] + w_cum[k - 1] * h + 0.5 * slope[k - 1] * h * h
    return w_cum, ww_cum


def _add_rows(slope: np.ndarray, knots: np.ndarray, rows: np.ndarray) -> None:
    """Add each row's value to ``slope`` on the knots it covers, ``[start, end)``.

    Rows that do not overlap (each starts at or after the previous one's end: the line's rows
    are checked to be so, up to 1e-9 m) cover each knot at most once, found by one search
    (linear in the rows); rows that overlap are added one by one, as the sum in row order.
    """
    starts, ends, values = rows[:, 0], rows[:, 1], rows[:, 2]
    if rows.shape[0] > 1 and not np.all(starts[1:] >= ends[:-1]):
        for start, end, value in rows:
            slope[(knots >= start) & (knots < end)] += value
        return
    j = np.searchsorted(starts, knots, side="right") - 1
    covered = (j >= 0) & (knots < ends[np.maximum(j, 0)])
    slope += np.where(covered, values[np.maximum(j, 0)], 0.0)


def _integrals(groups: Sequence[Rows], x: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """W(x) = int_0^x w and WW(x) = int_0^x W for w the sum of piecewise-constant groups of rows
    ``(start, end, value)`` (0 outside the rows).

    W and WW are 0 for x <= 0 and continue (linearly resp. quadratically) beyond the last row.
    Linear in the number of rows: a 1.2 M-row line takes about a second.
    """
    arrays = [np.asarray(rows, dtype=float).reshape(-1, 3) for rows in groups]
    knots = np.unique(np.concatenate([np.zeros(1)] + [a[:, :2].ravel() for a in arrays]))
    slope = np.zeros(knots.shape[0])  # w on [knot_k, knot_{k+1})
    for rows in arrays:
        if rows.shape[0]:
            _add_rows(slope, knots, rows)
    w_cum, ww_cum = _running_integrals(knots, slope)
    xc = np.maximum(x, 0.0)
    k = np.clip(np.searchsorted(knots, xc, side="right") - 1, 0, knots.shape[0] - 1)
    h = xc - knots[k]
    return w_cum[k] + slope[k] * h, ww_cum[k] + w_cum[k] * h + 0.5 * slope[k] * h * h


def cell_means(groups: Sequence[Rows], position_m: np.ndarray, train_length_m: float | None) -> np.ndarray:
    """Exact mean over each cell of w (point mass) or of its average over the train length.

    ``groups`` are lists of rows ``(start_m, end_m, value)``; w is the sum of all of them.
    """
    a, b = position_m[:-1], position_m[1:]
    if train_length_m is None:
        w_b, _ = _integrals(groups, b)
        w_a, _ = _integrals(groups, a)
        return (w_b - w_a) / (b - a)
    length = train_length_m
    _, ww_b = _integrals(groups, b)
    _, ww_a = _integrals(groups, a)
    _, ww_bl = _integrals(groups, b - length)
    _, ww_al = _integrals(groups, a - length)
    return (ww_b - ww_a - ww_bl + ww_al) / (length * (b - a))


def curve_resistance_n_per_kn(radius_m: float, model: str = "tang2020") -> float:
    """Curve resistance per unit weight (N/kN) of a curve of radius ``radius_m`` under ``model``.

    ``"tang2020"``: ``600 / R`` (Tang et al. (2020) eq. 2, Liu (2019) eq. 2-11). ``"roeckl"``:
    Roeckl's formula for standard gauge, ``650 / (R - 55)`` for R >= 300 m, ``500 / (R - 30)`` below.
    ``"osrd"``: ``800 / R``, the equivalent gradient OSRD adds for a curve.
    """
    if model == "tang2020":
        return CURVE_RESISTANCE_A / radius_m
    if model == "roeckl":
        return 650.0 / (radius_m - 55.0) if radius_m >= 300.0 else 500.0 / (radius_m - 30.0)
    if model == "osrd":
        return OSRD_CURVE_RESISTANCE_A / radius_m
    raise CaseError("line.curve_model", model, "unknown curve model (known: tang2020, roeckl, osrd)")


FINE_DX_M, COARSE_DX_M = 1.0, 5.0
MAX_GRID_CELLS = 10_000_000  # 80 MB per array: a longer grid is a mistake, not a run
FINE_UP_TO_M, COARSE_FROM_M = 10_000.0, 40_000.0


def default_dx_m(case: Case) -> float:
    """Grid step used when none is given: 1 m up to 10 km, 5 m from 40 km, linear in between.

    The step grows with the line so that the number of cells (the cost of a run) stays between
    8000 and 10 000 from 10 to 40 km instead of dropping fivefold at one length.
    """
    share = (case.line.length_m - FINE_UP_TO_M) / (COARSE_FROM_M - FINE_UP_TO_M)
    return FINE_DX_M + (COARSE_DX_M - FINE_DX_M) * min(max(share, 0.0), 1.0)


def build_grid(case: Case, dx_m: float | None = None) -> TrackGrid:
    """Discretise the case's line for its train.

    Parameters
    ----------
    case : Case
    dx_m : float, optional
        Requested step; the actual step divides the line into equal cells no longer than this.
    """
    explicit_dx = dx_m is not None
    if dx_m is None:
        dx_m = default_dx_m(case)
    if not (np.isfinite(dx_m) and dx_m > 0):
        raise CaseError("dx_m", dx_m, "the grid step must be a positive number")
    line, train = case.line, case.train
    cells = line.length_m / dx_m
    if cells > MAX_GRID_CELLS:  # refused before any array is allocated
        field, value = ("dx_m", dx_m) if explicit_dx else ("line.length_m", line.length_m)
        raise CaseError(field, value, f"a {line.length_m:g} m line in steps of {dx_m:g} m needs {cells:.3g} grid "
                                      f"cells, more than {MAX_GRID_CELLS:.0e}: choose a longer step or a shorter "
                                      "line")
    n_cells = max(int(np.ceil(cells - 1e-9)), 2)
    position = np.linspace(0.0, line.length_m, n_cells + 1)
    dx = line.length_m / n_cells

    averaging = train.length_m if line.gradient_model == "train_length" else None
    weight_kn = train.mass_kg * GRAVITY_MS2 / 1000.0
    grade = cell_means([line.gradients], position, averaging) * weight_kn
    curve_rows = [(s, e, curve_resistance_n_per_kn(r, line.curve_model)) for s, e, r in line.curves]
    tunnel_rows = [(s, e, TUNNEL_RESISTANCE_PER_M * (e - s)) for s, e in line.tunnels]
    other = cell_means([curve_rows, tunnel_rows], position, averaging) * weight_kn \
        if curve_rows or tunnel_rows else np.zeros(n_cells)

    # The head at x must respect every limit on [x - L, x + dx): the whole train, plus the cell ahead.
    limit_kmh = np.full(position.shape[0], train.max_speed_kmh)
    for start, end, value in line.speed_limits:
        covered = (start < position + dx) & (end > position - train.length_m)
        limit_kmh[covered] = np.minimum(limit_kmh[covered], value)
    neutral = np.zeros(n_cells, dtype=np.uint8)
    for start, end in line.neutral_sections:
        neutral[(position[:-1] < end) & (position[1:] > start)] = 1
    return TrackGrid(dx_m=dx, position_m=position, limit_ms=limit_kmh / KMH_PER_MS,
                     grade_force_n=grade, other_force_n=other, neutral=neutral)
