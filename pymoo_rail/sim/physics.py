"""Forces on the train: Numba functions shared by the simulator and the exact solver.

Everything here is SI (m, s, m/s, kg, N, W) and pure: the train and the grid arrive as one
:class:`KernelModel` named tuple, which Numba compiles like a struct and which pickles like data.
"""

from __future__ import annotations

import math
from typing import NamedTuple

import numpy as np
from numba import njit

from pymoo_rail.constants import KMH_PER_MS
from pymoo_rail.model import Case, InfeasibleCaseError, TrackGrid, build_grid
from pymoo_rail.sim.jit import called, inlined


class KernelModel(NamedTuple):
    """A train on a gridded line, flattened for the kernels (SI units)."""

    mass_kg: float
    effective_mass_kg: float
    davis_a_n: float
    davis_b_nsm: float
    davis_c_ns2m2: float
    traction_breaks_ms: np.ndarray
    traction_coefs: np.ndarray
    traction_max_n: float
    traction_max_w: float
    brake_breaks_ms: np.ndarray
    brake_coefs: np.ndarray
    brake_max_n: float
    brake_max_w: float
    regen_max_n: float
    regen_max_w: float
    regen_min_speed_ms: float
    max_accel_ms2: float
    max_decel_ms2: float
    traction_efficiency: float
    regen_efficiency: float
    aux_power_w: float
    dx_m: float
    position_m: np.ndarray
    limit_ms: np.ndarray
    grade_force_n: np.ndarray
    line_force_n: np.ndarray
    neutral: np.ndarray
    envelope_ms: np.ndarray
    initial_speed_ms: float = 0.0
    final_speed_ms: float = 0.0
    dx_per_mass_m_kg: float = 0.0  # dx_m / effective_mass_kg, precomputed for the kernel's step
    # efficiency maps over (speed, force magnitude) (``model.EfficiencyMap.table_si``), None without
    # one. None, not empty arrays: Numba then compiles the kernels of a train without a map without
    # the map's six arrays in every function's model and without the lookups (a None-typed argument
    # prunes its branch). Six fields, not two tables: a parallel kernel takes no tuple of arrays.
    traction_map_speeds_ms: np.ndarray | None = None
    traction_map_forces_n: np.ndarray | None = None
    traction_map_values: np.ndarray | None = None
    regen_map_speeds_ms: np.ndarray | None = None
    regen_map_forces_n: np.ndarray | None = None
    regen_map_values: np.ndarray | None = None


def efficiency_map_arrays(efficiency_map) -> tuple:
    """The kernels' arrays of an :class:`~pymoo_rail.model.EfficiencyMap`: (speeds m/s, forces N,
    values), C-contiguous (one compiled signature); three ``None`` for ``None``."""
    if efficiency_map is None:
        return None, None, None
    return tuple(np.ascontiguousarray(a) for a in efficiency_map.table_si())


def build_kernel_model(case: Case, grid: TrackGrid | None = None, dx_m: float | None = None) -> KernelModel:
    """Flatten a case (and its grid) into the kernels' model, including the braking envelope."""
    if grid is None:
        grid = build_grid(case, dx_m)
    train = case.train
    a, b, c = train.resistance.coefficients_si(train.mass_kg)
    tb, tc, tf, tp = train.traction.piecewise_si()
    bb, bc, bf, bp = train.braking.piecewise_si()
    model = KernelModel(
        mass_kg=train.mass_kg, effective_mass_kg=train.effective_mass_kg,
        davis_a_n=a, davis_b_nsm=b, davis_c_ns2m2=c,
        traction_breaks_ms=tb, traction_coefs=tc, traction_max_n=tf, traction_max_w=tp,
        brake_breaks_ms=bb, brake_coefs=bc, brake_max_n=bf, brake_max_w=bp,
        regen_max_n=train.regen_max_force_kn * 1000.0 if train.regen_max_force_kn is not None else math.inf,
        regen_max_w=train.regen_max_power_kw * 1000.0 if train.regen_max_power_kw is not None else math.inf,
        regen_min_speed_ms=train.regen_min_speed_kmh / KMH_PER_MS,
        max_accel_ms2=train.max_accel_ms2 if train.max_accel_ms2 is not None else math.inf,
        max_decel_ms2=train.max_decel_ms2 if train.max_decel_ms2 is not None else math.inf,
        traction_efficiency=train.traction_efficiency, regen_efficiency=train.regen_efficiency,
        aux_power_w=train.aux_power_kw * 1000.0,
        dx_m=grid.dx_m, position_m=grid.position_m, limit_ms=grid.limit_ms,
        grade_force_n=grid.grade_force_n, line_force_n=np.ascontiguousarray(grid.line_force_n),
        neutral=grid.neutral, envelope_ms=np.empty(0),
        initial_speed_ms=float(case.initial_speed_ms), final_speed_ms=float(case.final_speed_ms),
        dx_per_mass_m_kg=grid.dx_m / train.effective_mass_kg,
    )
    ts, tf_, tv = efficiency_map_arrays(train.traction_efficiency_map)
    rs, rf, rv = efficiency_map_arrays(train.regen_efficiency_map)
    model = model._replace(traction_map_speeds_ms=ts, traction_map_forces_n=tf_, traction_map_values=tv,
                           regen_map_speeds_ms=rs, regen_map_forces_n=rf, regen_map_values=rv)
    envelope = braking_envelope(model)
    if model.initial_speed_ms > envelope[0]:
        raise InfeasibleCaseError("run.initial_speed_kmh", case.initial_speed_ms * KMH_PER_MS,
                                  f"is above the braking envelope at the start ({envelope[0] * KMH_PER_MS:.3f} km/h): "
                                  "no braking meets the limits ahead", case.name)
    return model._replace(envelope_ms=envelope)


@inlined
def curve_force(v, breaks, coefs, max_n, max_w):
    """Piecewise polynomial force limit at speed v, capped by a force and a power."""
    k = 0
    n = breaks.shape[0]
    while k < n - 1 and v > breaks[k]:
        k += 1
    f = 0.0
    p = 1.0
    for j in range(coefs.shape[1]):
        f += coefs[k, j] * p
        p *= v
    if f > max_n:
        f = max_n
    if v > 0.0 and f * v > max_w:
        f = max_w / v
    if f < 0.0:
        f = 0.0
    return f


@inlined
def davis_force(m, v):
    """Basic running resistance W0(v) in N."""
    return m.davis_a_n + (m.davis_b_nsm + m.davis_c_ns2m2 * v) * v


@inlined
def capped_force(f, cap):
    """Force ``f`` (N) limited to ``cap`` (N) and never below zero (a cap below zero gives zero)."""
    if cap < f:
        f = cap
    if f < 0.0:
        f = 0.0
    return f


@inlined
def max_traction(m, v, cell):
    """Largest usable traction force in a cell: the curve, the acceleration cap, neutral sections."""
    if m.neutral[cell] != 0:
        return 0.0
    f = curve_force(v, m.traction_breaks_ms, m.traction_coefs, m.traction_max_n, m.traction_max_w)
    cap = m.effective_mass_kg * m.max_accel_ms2 + davis_force(m, v) + m.line_force_n[cell]
    return capped_force(f, cap)


@inlined
def max_braking(m, v, cell):
    """Largest usable braking force in a cell: the curve and the deceleration cap."""
    f = curve_force(v, m.brake_breaks_ms, m.brake_coefs, m.brake_max_n, m.brake_max_w)
    cap = m.effective_mass_kg * m.max_decel_ms2 - davis_force(m, v) - m.line_force_n[cell]
    return capped_force(f, cap)


@inlined
def electric_braking_capped(m, v, brake_n):
    """The part of a braking force within the motors' regen force and power caps."""
    f = brake_n
    if f > m.regen_max_n:
        f = m.regen_max_n
    if v > 0.0 and f * v > m.regen_max_w:
        f = m.regen_max_w / v
    return f


@called
def map_node(nodes, x):
    """Table cell of ``x`` among ascending ``nodes`` and the fraction across it (held at the edges)."""
    n = nodes.shape[0]
    if n == 1 or x <= nodes[0]:
        return 0, 0.0
    if x >= nodes[n - 1]:
        return n - 2, 1.0
    lo, hi = 0, n - 1  # bisection: nodes[lo] <= x < nodes[hi] (maps from loss tables have ~100 nodes)
    while hi - lo > 1:
        mid = (lo + hi) // 2
        if x >= nodes[mid]:
            lo = mid
        else:
            hi = mid
    return lo, (x - nodes[lo]) / (nodes[lo + 1] - nodes[lo])


@called
def map_efficiency(speeds, forces, values, v, f):
    """Bilinear efficiency of a map at speed ``v`` (m/s) and force magnitude ``f`` (N), the edge
    values beyond its nodes (``EfficiencyMap.efficiency`` in SI)."""
    i, ti = map_node(speeds, v)
    j, tj = map_node(forces, abs(f))
    i1 = i + 1 if speeds.shape[0] > 1 else i
    j1 = j + 1 if forces.shape[0] > 1 else j
    low = values[i, j] + tj * (values[i, j1] - values[i, j])
    high = values[i1, j] + tj * (values[i1, j1] - values[i1, j])
    return low + ti * (high - low)


@inlined
def map_excess(speeds, forces, values, eta_ref, v, f, work_j):
    """Electrical energy of the traction work ``work_j`` at (``v``, ``f``) by a map beyond ``work_j /
    eta_ref`` (J): zero without a map (``values`` None: Numba prunes the lookup), and exactly zero
    where the map gives ``eta_ref``, so that a constant map reproduces the constant bit for bit."""
    if values is None:
        return 0.0
    eta = map_efficiency(speeds, forces, values, v, f)
    if eta == eta_ref:
        return 0.0
    return work_j / eta - work_j / eta_ref


@inlined
def map_shortfall(speeds, forces, values, eta_ref, v, f_electric, work_j):
    """Regenerated energy of the electric braking work ``work_j`` at (``v``, ``f_electric``) by a map
    short of ``eta_ref x work_j`` (J): zero without a map (``values`` None) or where it gives ``eta_ref``."""
    if values is None:
        return 0.0
    eta = map_efficiency(speeds, forces, values, v, f_electric)
    if eta == eta_ref:
        return 0.0
    return eta_ref * work_j - eta * work_j


@inlined
def traction_map_excess(m, v, f, work_j):
    """Electrical energy of the traction work ``work_j`` at (``v``, ``f``) beyond ``work_j /
    traction_efficiency`` (J): zero without a map, and exactly zero where the map gives the constant,
    so that a constant map reproduces the constant efficiency bit for bit."""
    return map_excess(m.traction_map_speeds_ms, m.traction_map_forces_n, m.traction_map_values, m.traction_efficiency,
                      v, f, work_j)


@inlined
def regen_map_shortfall(m, v, f_electric, work_j):
    """Regenerated energy of the electric braking work ``work_j`` at (``v``, ``f_electric``) short of
    ``regen_efficiency x work_j`` (J): zero without a map or where it gives the constant."""
    return map_shortfall(m.regen_map_speeds_ms, m.regen_map_forces_n, m.regen_map_values, m.regen_efficiency,
                         v, f_electric, work_j)


# Relative tolerance of a landing: the force it needs may exceed what the train has by this much
# (rounding of the force-speed curves); the braking envelope itself is built with none.
LANDING_RTOL = 1e-8


@inlined
def landing_force(m, v0, v1, cell):
    """Control force that brings the train from v0 to exactly v1 over one cell, and W0 used.

    The forces are taken at the mean speed ``(v0 + v1) / 2``, the second stage of the simulator's
    step. Returns (force N, + traction / - braking, W0 N, feasible): feasible is False when the
    force exceeds what the train has beyond :data:`LANDING_RTOL`.
    """
    v_mid = 0.5 * (v0 + v1)
    w0 = davis_force(m, v_mid)
    f = m.effective_mass_kg * (v1 * v1 - v0 * v0) / (2.0 * m.dx_m) + w0 + m.line_force_n[cell]
    if f > 0.0:
        f_max = max_traction(m, v_mid, cell)
        feasible = f <= f_max + 1e-9 + LANDING_RTOL * f_max
    else:
        f_max = max_braking(m, v_mid, cell)
        feasible = -f <= f_max + 1e-9 + LANDING_RTOL * f_max
    return f, w0, feasible


@inlined
def braking_shortfall(m, v0, v1, cell):
    """Braking force a landing from v0 onto v1 needs beyond the train's maximum (N, <= 0 if it can).

    The exact expression of :func:`landing_force`, so that an envelope speed with a shortfall
    <= 0 is, by construction, a speed from which the landing succeeds.
    """
    v_mid = 0.5 * (v0 + v1)
    need = m.effective_mass_kg * (v0 * v0 - v1 * v1) / (2.0 * m.dx_m) - davis_force(m, v_mid) - m.line_force_n[cell]
    return need - max_braking(m, v_mid, cell)


@njit(cache=True, no_cfunc_wrapper=True)
def braking_envelope(m):
    """Highest speed at each node from which maximum braking still meets every limit ahead.

    Integrated backwards from the final speed at the end of the line (standstill at the platform
    by default), never above the node's speed limit. Each node's speed is the largest ``v0`` for
    which :func:`landing_force` onto the next node's envelope is feasible without tolerance
    (:func:`braking_shortfall` <= 0): a fixed-point estimate at the mean speed, then bisection
    on the landing condition itself, so that the simulator can always land on the envelope.
    """
    n = m.position_m.shape[0]
    env = np.empty(n)
    v_end = m.final_speed_ms
    env[n - 1] = v_end if v_end < m.limit_ms[n - 1] else m.limit_ms[n - 1]
    dx = m.dx_m
    for i in range(n - 2, -1, -1):
        v1 = env[i + 1]
        # decelerating force at an estimate of the mean speed, refined to a fixed point
        v_mid = v1
        u = v1 * v1
        for _ in range(8):
            decel = (max_braking(m, v_mid, i) + davis_force(m, v_mid) + m.line_force_n[i]) / m.effective_mass_kg
            u = v1 * v1 + 2.0 * dx * decel
            if u < 0.0:
                u = 0.0
            v_new = 0.5 * (v1 + math.sqrt(u))
            if abs(v_new - v_mid) <= 1e-15 * (1.0 + v_mid):
                break
            v_mid = v_new
        v0 = math.sqrt(u)
        if v0 > m.limit_ms[i]:
            v0 = m.limit_ms[i]
        if braking_shortfall(m, v0, v1, i) > 0.0:
            # the estimate is a rounding residue too fast: bisect down to a speed that lands
            lo = v1 if braking_shortfall(m, v1, v1, i) <= 0.0 else 0.0
            hi = v0
            for _ in range(200):
                mid = 0.5 * (lo + hi)
                if mid <= lo or mid >= hi:
                    break
                if braking_shortfall(m, mid, v1, i) <= 0.0:
                    lo = mid
                else:
                    hi = mid
            v0 = lo
        env[i] = v0
    return env
