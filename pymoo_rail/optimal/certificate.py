"""The certificate of an optimal run: an estimated bound on its energy above the optimum at its time.

:meth:`~pymoo_rail.optimal.solver.OptimalSolver.energy_bound_kwh` adds the parts computed here
(``docs/optimal.md``, "Certificate"): the change when the speed grid is doubled, a floor, and how
far the run lies above the front's supporting line at its price of time. :func:`move_remainder_j`
bounds the error of moving a run along that line to another running time.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np

from pymoo_rail.constants import J_PER_KWH
from pymoo_rail.optimal.price_search import Solve

if TYPE_CHECKING:
    from pymoo_rail.optimal.solver import OptimalSolver

# The certificate is this many times the change when the speed nodes are doubled (see bound_parts_kwh)
CERTIFICATE_FACTOR = 2.0
# ... plus this share of the run's net energy: the two grids can agree by coincidence where a grid
# of twice the nodes or the uniform node placement still differs (at 2 of 861 times of
# ``benchmarks/reference_check.py --check coverage``, by 1.0 and 2.7 Wh beyond the two-grid part, 2.6e-5 and
# 2.3e-6 of the energy)
CERTIFICATE_FLOOR_REL = 1.0e-4
# ... or, where the run's traction energy is known (``OptimalSolver.profile``), this share of it, the larger:
# along kilometres of coasting the interpolated cost-to-go errs alike on both grids, so they agree where
# the optimum lies lower. The largest shortfall measured on generated lines (``benchmarks/peers.py``,
# ms-eetc N=2000 below a run by more than the rest of its certificate) was 2.9e-4 of the run's traction
# energy (seed 4 at 1.2 x the minimum time) when it was set, 4.6e-4 (seed 1 at 1.2 x) with the DP's coast
# curves (solver version 4): covered, by 0.008 kWh. An estimate calibrated there, not a bound
CERTIFICATE_FLOOR_TRACTION_REL = 5.0e-4


def bound_parts_kwh(solution: Solve, other: Solve, untied_j: float, traction_kwh: float = 0.0) -> dict[str, float]:
    """The parts of the certificate of ``solution`` (kWh): grid, floor, moved run, kept regimes, untied run.

    ``other`` is the optimum at the same price on a speed grid of twice the nodes (half at the
    finest grid); moved along the slope ``lambda`` to this run's time it is the other grid's
    supporting line there (one solve, and no search that a jump of the other grid's optimum could
    end on a run far from this time: measured 8.1 kWh of "grid error" on wuguang-crh3 at 1110 s
    from a moved coarse run, against 0.16 kWh through the supporting line). ``untied_j``:
    :func:`untied_excess_j`. ``traction_kwh``: the run's traction energy, for the floor (0: the
    floor is a share of the net energy alone).
    """
    moved_j = other.energy_j + solution.lambda_w * (other.time_s - solution.time_s)
    return {"grid_kwh": CERTIFICATE_FACTOR * abs(moved_j - solution.energy_j) / J_PER_KWH,
            "floor_kwh": max(CERTIFICATE_FLOOR_REL * abs(solution.energy_j) / J_PER_KWH,
                             CERTIFICATE_FLOOR_TRACTION_REL * traction_kwh),
            "moved_kwh": solution.dual_gap_j / J_PER_KWH,
            "kept_regimes_kwh": solution.tie_cost_j / J_PER_KWH,
            "untied_kwh": untied_j / J_PER_KWH}


def bound_from_parts_kwh(parts: dict[str, float]) -> float:
    """The certificate from its parts (kWh): grid + floor + the largest distance above the supporting line.

    The duality gap of a moved run and the untied run's advantage both measure how far the run lies
    above the supporting line at lambda (on a moved run they coincide): the larger counts.
    """
    return (parts["grid_kwh"] + parts["floor_kwh"]
            + max(parts["moved_kwh"], parts["kept_regimes_kwh"], parts["untied_kwh"]))


def untied_excess_j(solver: OptimalSolver, solution: Solve) -> float:
    """How much better, at the run's price of time, the forward run without the tie rule is (J, >= 0).

    Keeping the regime between near-tied controls changes the rest of the run too, so its cost
    is measured on the whole run: the forward run with ``tie_j = 0`` at the same price, compared
    in ``energy + lambda x time`` (measured: 6.1 Wh on a 1.7 km metro section, 0.07 %, ``benchmarks/reference_check.py --check parts``).
    """
    if solver.tie_j <= 0.0:
        return 0.0
    lam = solution.lambda_w
    _, _, _, done, energy, time, _, _ = solver.run_dp(lam, 0.0)
    if done < solver.simulator.grid.n_nodes - 1:
        return 0.0
    mean_price = lam if solver.price_shape is None else lam * float(np.mean(solver.price_shape))
    return max(solution.energy_j + mean_price * solution.time_s - (energy + mean_price * time), 0.0)


def move_remainder_j(history: list[Solve], time_s: float, lambda_w: float, target_s: float) -> float:
    """Bound on the error of moving a run at ``time_s`` (price ``lambda_w``) to ``target_s`` along ``lambda_w`` (J).

    The moved energy ``E + lambda (time_s - target_s)`` is the supporting line of the front at
    ``target_s``: at or below the optimum there. Above it lies the chord between the closest solves
    of ``history`` on either side of ``target_s`` (the front is convex); the chord minus the line
    bounds the error. With no solve on one side, or for a run that is not one of the solves (a
    moved run, within ``time_tol_s``; a run of the finer grid ``profile`` fell back to):
    ``lambda |time_s - target_s|``, the first-order term itself.
    """
    slow = [h for h in history if h.time_s >= target_s]
    fast = [h for h in history if h.time_s <= target_s]
    first_order = abs(lambda_w * (time_s - target_s))
    if not slow or not fast:
        return first_order
    a = min(slow, key=lambda h: h.time_s)
    b = max(fast, key=lambda h: h.time_s)
    if a.time_s - b.time_s <= 0.0:
        return 0.0
    w = (target_s - b.time_s) / (a.time_s - b.time_s)
    chord_j = b.energy_j + w * (a.energy_j - b.energy_j)
    here = min((h for h in history if abs(h.time_s - time_s) <= 1e-9 * max(time_s, 1.0)),
               key=lambda h: h.energy_j, default=None)
    if here is None:  # a moved run (not solved at a price): it is within time_tol_s of the target
        return first_order
    line_j = here.energy_j + lambda_w * (here.time_s - target_s)
    return max(chord_j - line_j, 0.0)
