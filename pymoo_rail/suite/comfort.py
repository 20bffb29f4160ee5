"""The bounded front of the 3-objective family (net energy, running time, comfort).

Comfort is the package's ``accel_variation`` (Meng et al. (2017) eq. 5): the total variation of
the acceleration over the run's cells, ``sum |a_i - a_(i-1)|`` (m/s^2), counted from rest
acceleration 0 before the first cell and back to 0 after the last. No exact solver gives this
front, so it is *bounded* on both sides:

- **Outer (lower) bound.** Any feasible run ``y = (E, T, C)`` inside the planner's window has
  ``E >= E*(T) - bound(T)`` (the line's certified energy / running-time front and its certificate,
  :mod:`pymoo_rail.optimal.reference`) and ``C >= C_lb(T)``, :func:`comfort_floor_ms2`. So ``y``
  weakly dominates-from-above a point of the curve ``(E*(T) - bound(T), T, C_lb(T))``;
  :func:`outer_points` turns the curve into finitely many corner points with the same property.
- **Inner bound.** The non-dominated feasible evaluations of a fixed recipe (:func:`inner_points`):
  every section at one speed code (:data:`N_LEVELS` levels) and the final population of one seeded
  NSGA-II run. Each is a real run, so the true front weakly dominates every inner point.

The true front lies between the two. :func:`bounded_front` states the gap two ways: the
hypervolumes at the instance's reference point, ``HV(inner) <= HV(front) <= HV(outer)``, and
the additive epsilon: every outer point is weakly dominated by some inner point shifted by
``epsilon`` times the objective ranges, so the inner set is an ``epsilon``-approximation of the
true front.

The comfort floor is kinematic and holds for any driving, not only the encoding's: the kernel's
cells have constant acceleration, so a run of duration ``T`` with accelerations in ``[-D, A]``,
entering and leaving at speeds at most ``u`` and never above ``V`` covers at most
``u T + area(k)`` metres, ``area`` the trapezoid under ``min(A t, D (T - t), V - u)`` and
``k = 1/A + 1/D``. That needs ``A + D >= 4 / k_max`` (``k`` is least at ``A = D`` for a given sum),
and the closed walk of accelerations from 0 through ``A`` and ``-D`` back to 0 has
``C >= 2 (A + D)``. Runs from rest also leave it at full traction whatever the speed codes (every
code is at least the floor, above 0), so ``A >= a_launch``, the first cell's acceleration
(:func:`launch_accel_ms2`); with ``A`` unbounded the same area argument then asks
``D >= 2 R / T^2`` (``R <= h T / 2``) or ``D >= h^2 / (2 (h T - R))``, ``R`` the metres beyond
``u T`` and ``h = V - u``. Runs that end at rest land on the platform: their last cell decelerates
by ``v^2 / (2 dx)``, ``v`` the speed one cell before, which the braking envelope and one kernel step
bound from below (:func:`landing_decel_ms2`), so ``D >= landing`` and, symmetrically, ``A`` obeys the
one-sided bound. The floor is the largest of ``A + D`` over these cases, doubled.
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

import numpy as np
import pandas as pd

from pymoo_rail.atomic import atomic_write_text
from pymoo_rail.constants import KMH_PER_MS
from pymoo_rail.model import END_SPEED_TOL_MS
from pymoo_rail.optimal.reference import CertifiedFront, cache_dir
from pymoo_rail.sim import kernel
from pymoo_rail.suite.identity import HV_MARGIN

COMFORT_OBJECTIVES = ("energy", "running_time", "accel_variation")
"""Objectives of the ``generated-<kind>-3obj`` families, in pymoo's column order."""
COMFORT_FRONT_VERSION = "1"
"""Version of the bounded-front recipe (outer corners, inner runs); bumped whenever either changes."""
N_LEVELS = 64
"""Uniform speed-code levels of the inner recipe (every section at the same share of its range)."""
INNER_POP, INNER_GENERATIONS, INNER_SEED = 100, 100, 1
"""The inner recipe's NSGA-II run (pymoo defaults otherwise): 10,000 evaluations, the baseline's budget."""
N_SUB = 8
"""Pieces each interval between two certified front nodes is cut into for the outer corners."""


def comfort_floor_ms2(running_time_s, length_m: float, boundary_speed_ms: float, top_speed_ms: float,
                      launch_ms2: float = 0.0, landing_ms2: float = 0.0) -> np.ndarray:
    """Least total variation of acceleration (m/s^2) of any run covering ``length_m`` in ``running_time_s``.

    Parameters
    ----------
    running_time_s : float or array
        Running times (s), > 0.
    length_m : float
        Distance the run covers at least (the line less the stop tolerance).
    boundary_speed_ms : float
        Highest speed at the start and at the end (m/s).
    top_speed_ms : float
        Speed the run never exceeds (m/s): the line's highest limit, or the train's top speed.
    launch_ms2 : float
        An acceleration every run reaches (the launch from rest at full traction); 0 if none.
    landing_ms2 : float
        A deceleration every run reaches (the last cell onto the platform); 0 if none.

    Returns
    -------
    numpy.ndarray
        ``2 max(s_min(T), launch + D_min(T), A_min(T) + landing, launch + landing)`` (see the module
        docstring); ``inf`` where no run can cover the distance in that time.
    """
    t = np.atleast_1d(np.asarray(running_time_s, dtype=float))
    if np.any(~np.isfinite(t)) or np.any(t <= 0):
        raise ValueError(f"running_time_s = {t.tolist()!r}: must be finite and > 0")
    if not top_speed_ms > boundary_speed_ms >= 0.0:
        raise ValueError(f"top_speed_ms = {top_speed_ms!r}, boundary_speed_ms = {boundary_speed_ms!r}: "
                         "need top > boundary >= 0")
    h = top_speed_ms - boundary_speed_ms
    rest = np.maximum(length_m - boundary_speed_ms * t, 0.0)  # metres beyond cruising at the boundary speed
    with np.errstate(divide="ignore", invalid="ignore"):
        # largest k = 1/A + 1/D whose area reaches `rest`: the triangle (peak under h) or the trapezoid
        k_max = np.where(rest <= h * t / 2.0, t * t / (2.0 * rest), 2.0 * (h * t - rest) / (h * h))
        symmetric = np.where(rest > 0.0, 4.0 / k_max, 0.0)
        # one side unbounded, area(D) = D T^2 / 2 while D T <= h, else h T - h^2 / (2 D) (and so for A)
        one_side = np.where(rest <= h * t / 2.0, 2.0 * rest / (t * t), h * h / (2.0 * (h * t - rest)))
    floor = 2.0 * np.maximum.reduce([symmetric, launch_ms2 + one_side, one_side + landing_ms2,
                                     np.full_like(t, launch_ms2 + landing_ms2)])
    return np.where(rest >= h * t, np.inf, floor)


def launch_accel_ms2(problem) -> float:
    """The first cell's acceleration of every run of ``problem`` from rest (m/s^2); 0 when it starts moving.

    Read from the run of the box's middle: from rest every speed code (at least the floor, above 0)
    asks for full traction in the first cell, so all runs share it.
    """
    if problem.case.initial_speed_ms > 0.0:
        return 0.0
    trajectory = problem.trajectory((problem.xl + problem.xu) / 2.0)
    return max(float(trajectory.accel_ms2[0]), 0.0)


def landing_decel_ms2(problem, n_speeds: int = 201) -> float:
    """A deceleration the last cell of every feasible run of ``problem`` reaches (m/s^2); 0 when the
    run need not end at rest.

    The last cell ends on the platform at rest, so its acceleration is ``-v^2 / (2 dx)`` with ``v``
    the speed one cell before. That speed is the envelope's there, or what one kernel step reaches
    from any speed the envelope allows a cell earlier: full traction (the train is below its code)
    or coasting (at or above it, so at least the floor code). The least of these over
    ``n_speeds`` speeds, less 0.1 % (the grid and the kernel's rounding brake), bounds it.
    """
    if problem.case.end_speed_window_ms()[1] > 0.0 or problem.stop_tolerance_m is None:
        return 0.0
    m = problem.simulator.model
    env, n = m.envelope_ms, m.position_m.shape[0]
    if n < 4:
        return 0.0
    floor_ms = float(np.min(problem.xl)) / KMH_PER_MS  # no code is lower
    cell = n - 3
    u1 = [env[n - 2] ** 2]
    u1 += [kernel.full_step(m, v, cell, kernel.KIND_TRACTION)[0] for v in np.linspace(0.0, env[cell], n_speeds)]
    if env[cell] >= floor_ms:
        u1 += [kernel.full_step(m, v, cell, kernel.KIND_COAST)[0] for v in np.linspace(floor_ms, env[cell], n_speeds)]
    least = min(u1)
    return 0.999 * least / (2.0 * m.dx_m) if least > 0.0 else 0.0


def floor_settings(problem) -> dict:
    """The keyword arguments of :func:`comfort_floor_ms2` for an instance (its line, limits, tolerance, launch)."""
    case = problem.case
    top_ms = float(problem.simulator.grid.limit_ms.max())  # the line's limits, capped by the train's top speed
    tolerance_m = problem.stop_tolerance_m or 0.0
    end_ms = case.end_speed_window_ms()[1]
    end_ms += END_SPEED_TOL_MS if end_ms > 0.0 else 0.0  # a moving end is met within the tolerance
    return dict(length_m=case.line.length_m - tolerance_m, boundary_speed_ms=max(case.initial_speed_ms, end_ms),
                top_speed_ms=top_ms, launch_ms2=launch_accel_ms2(problem), landing_ms2=landing_decel_ms2(problem))


def outer_points(front: CertifiedFront, window_s: tuple[float, float], floor: dict,
                 n_sub: int = N_SUB) -> np.ndarray:
    """Corner points (energy kWh, running time s, comfort m/s^2) below every feasible run in ``window_s``.

    ``floor`` holds the keyword arguments of :func:`comfort_floor_ms2` (:func:`floor_settings`).

    Each piece ``[a, b]`` of the window (the certified front's node intervals, cut in ``n_sub``)
    gives ``(min(E*(a), E*(b)) - B, a, C_lb(b))``, ``B`` the largest certificate on the piece
    (both ends' and the chord's): ``E*`` is linear on the piece and ``C_lb`` decreases with time.
    """
    lo, hi = front.clip(window_s)
    nodes = front.table["running_time_s"].to_numpy()
    cuts = np.union1d([lo, hi], nodes[(nodes > lo) & (nodes < hi)])
    times = np.unique(np.concatenate([np.linspace(a, b, n_sub + 1) for a, b in zip(cuts[:-1], cuts[1:])]))
    a, b = times[:-1], times[1:]
    energy_a, bound_a = front.energy_at(a)
    energy_b, bound_b = front.energy_at(b)
    _, bound_mid = front.energy_at((a + b) / 2.0)  # inside a node interval: the chord's bound, the largest
    energy = np.minimum(energy_a, energy_b) - np.maximum.reduce([bound_a, bound_b, bound_mid])
    comfort = comfort_floor_ms2(b, **floor)
    corners = np.column_stack([energy, a, comfort])
    end_energy, end_bound = front.energy_at(np.array([hi]))
    last = np.array([[end_energy[0] - end_bound[0], hi, comfort_floor_ms2(hi, **floor)[0]]])
    return np.vstack([corners, last])


def inner_points(problem) -> tuple[np.ndarray, np.ndarray]:
    """Decision vectors and non-dominated feasible (energy, running time, comfort) of the inner recipe
    (see the module docstring)."""
    from pymoo.algorithms.moo.nsga2 import NSGA2
    from pymoo.optimize import minimize
    from pymoo.util.nds.non_dominated_sorting import find_non_dominated

    res = minimize(problem, NSGA2(pop_size=INNER_POP), ("n_gen", INNER_GENERATIONS), seed=INNER_SEED)
    X = np.vstack([uniform_vectors(problem), res.pop.get("X")])
    out = problem.evaluate(X, return_values_of=["F", "G"], return_as_dictionary=True)
    feasible = np.all(out["G"] <= 0.0, axis=1)
    X, F = X[feasible], out["F"][feasible]
    _, first = np.unique(F, axis=0, return_index=True)
    X, F = X[np.sort(first)], F[np.sort(first)]
    keep = find_non_dominated(F)
    return X[keep], F[keep]


def uniform_vectors(problem) -> np.ndarray:
    """Every section at one share of its code range (:data:`N_LEVELS` shares from 0 to 1): the same
    runs at every ``n_var`` of an instance."""
    levels = np.linspace(0.0, 1.0, N_LEVELS)
    return problem.xl + levels[:, None] * (problem.xu - problem.xl)


def feasible_objectives(problem, X: np.ndarray) -> np.ndarray:
    """Objective vectors of the feasible rows of ``X``."""
    out = problem.evaluate(X, return_values_of=["F", "G"], return_as_dictionary=True)
    return out["F"][np.all(out["G"] <= 0.0, axis=1)]


def uniform_points(problem) -> np.ndarray:
    """Objective vectors of the feasible runs of :func:`uniform_vectors`."""
    return feasible_objectives(problem, uniform_vectors(problem))


def inner_path(problem) -> Path:
    """Cache file of an instance's inner points (keyed by its checksum and :data:`COMFORT_FRONT_VERSION`)."""
    return cache_dir() / f"{problem.suite_name}-{problem.checksum[:16]}-inner-v{COMFORT_FRONT_VERSION}.csv"


def cached_inner_points(problem) -> np.ndarray:
    """The objective vectors of :func:`inner_points`, computed once per instance and kept in the
    front cache directory (with their decision vectors)."""
    path = inner_path(problem)
    if path.is_file():
        return pd.read_csv(path)[list(COMFORT_OBJECTIVES)].to_numpy(dtype=float)
    X, F = inner_points(problem)
    table = pd.DataFrame(np.column_stack([F, X]), columns=[*COMFORT_OBJECTIVES, *(f"x{j}" for j in range(X.shape[1]))])
    path.parent.mkdir(parents=True, exist_ok=True)
    atomic_write_text(path, table.to_csv(index=False, float_format="%.17g"))
    return F


@dataclass(frozen=True)
class BoundedFront:
    """Both sides of a 3-objective instance's front and the gap between them.

    Attributes
    ----------
    outer : numpy.ndarray
        (n, 3) corner points every feasible objective vector weakly dominates-from-above.
    inner : numpy.ndarray
        (m, 3) non-dominated feasible objective vectors (real runs).
    ref_point : numpy.ndarray
        The instance's fixed hypervolume reference point.
    hv_outer, hv_inner : float
        Hypervolumes at ``ref_point``: the true front's lies between them.
    hv_gap : float
        ``(hv_outer - hv_inner) / hv_outer``.
    epsilon : float
        Additive epsilon of ``inner`` over ``outer`` in units of ``ref_point - ideal`` per objective.
    epsilon_by_objective : dict
        The shift each objective needs at the worst outer point (raw units).
    """

    outer: np.ndarray
    inner: np.ndarray
    ref_point: np.ndarray
    hv_outer: float
    hv_inner: float
    hv_gap: float
    epsilon: float
    epsilon_by_objective: dict


def additive_epsilon(inner: np.ndarray, outer: np.ndarray, scale: np.ndarray) -> tuple[float, np.ndarray]:
    """``max_o min_i max_k (i_k - o_k) / scale_k`` and the raw shifts at the worst outer point."""
    shifts = (inner[None, :, :] - outer[:, None, :]) / scale  # (outer, inner, objective)
    worst_per_pair = shifts.max(axis=2)
    best = worst_per_pair.argmin(axis=1)
    per_outer = worst_per_pair[np.arange(len(outer)), best]
    o = int(per_outer.argmax())
    return float(per_outer[o]), (inner[best[o]] - outer[o])


def bound_front(outer: np.ndarray, inner: np.ndarray, ref_point: np.ndarray) -> BoundedFront:
    """The :class:`BoundedFront` of given outer corners and inner points."""
    from pymoo.indicators.hv import HV

    hv = HV(ref_point=ref_point)
    hv_outer, hv_inner = float(hv(outer)), float(hv(inner))
    scale = ref_point - outer.min(axis=0)
    epsilon, shift = additive_epsilon(inner, outer, scale)
    return BoundedFront(outer=outer, inner=inner, ref_point=ref_point, hv_outer=hv_outer, hv_inner=hv_inner,
                        hv_gap=(hv_outer - hv_inner) / hv_outer, epsilon=epsilon,
                        epsilon_by_objective=dict(zip(COMFORT_OBJECTIVES, shift.tolist())))


__all__ = ["COMFORT_OBJECTIVES", "COMFORT_FRONT_VERSION", "BoundedFront", "comfort_floor_ms2", "launch_accel_ms2", "landing_decel_ms2", "floor_settings",
           "outer_points", "inner_points", "uniform_points", "uniform_vectors", "feasible_objectives", "cached_inner_points", "bound_front",
           "additive_epsilon"]
