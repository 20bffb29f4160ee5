"""Forces on the train: Numba functions shared by the simulator and the exact solver.

Everything here is SI (m, s, m/s, kg, N, W) and pure: the train and the grid arrive as one
:class:`KernelModel` named tuple, which Numba compiles like a struct and which pickles like data.
"""

from __future__ import annotations

import math
from typing import NamedTuple

import numpy as np
from numba import njit

from pymoo_rail.model import Case, TrackGrid, build_grid


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
        regen_min_speed_ms=train.regen_min_speed_kmh / 3.6,
        max_accel_ms2=train.max_accel_ms2 if train.max_accel_ms2 is not None else math.inf,
        max_decel_ms2=train.max_decel_ms2 if train.max_decel_ms2 is not None else math.inf,
        traction_efficiency=train.traction_efficiency, regen_efficiency=train.regen_efficiency,
        aux_power_w=train.aux_power_kw * 1000.0,
        dx_m=grid.dx_m, position_m=grid.position_m, limit_ms=grid.limit_ms,
        grade_force_n=grid.grade_force_n, line_force_n=np.ascontiguousarray(grid.line_force_n),
        neutral=grid.neutral, envelope_ms=np.empty(0),
    )
    return model._replace(envelope_ms=braking_envelope(model))


@njit(cache=True, inline="always")
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


@njit(cache=True, inline="always")
def davis_force(m, v):
    """Basic running resistance W0(v) in N."""
    return m.davis_a_n + (m.davis_b_nsm + m.davis_c_ns2m2 * v) * v


@njit(cache=True, inline="always")
def max_traction(m, v, cell):
    """Largest usable traction force in a cell: the curve, the acceleration cap, neutral sections."""
    if m.neutral[cell] != 0:
        return 0.0
    f = curve_force(v, m.traction_breaks_ms, m.traction_coefs, m.traction_max_n, m.traction_max_w)
    cap = m.effective_mass_kg * m.max_accel_ms2 + davis_force(m, v) + m.line_force_n[cell]
    if cap < f:
        f = cap
    if f < 0.0:
        f = 0.0
    return f


@njit(cache=True, inline="always")
def max_braking(m, v, cell):
    """Largest usable braking force in a cell: the curve and the deceleration cap."""
    f = curve_force(v, m.brake_breaks_ms, m.brake_coefs, m.brake_max_n, m.brake_max_w)
    cap = m.effective_mass_kg * m.max_decel_ms2 - davis_force(m, v) - m.line_force_n[cell]
    if cap < f:
        f = cap
    if f < 0.0:
        f = 0.0
    return f


@njit(cache=True, inline="always")
def electric_braking_capped(m, v, brake_n):
    """The part of a braking force within the motors' regen force and power caps."""
    f = brake_n
    if f > m.regen_max_n:
        f = m.regen_max_n
    if v > 0.0 and f * v > m.regen_max_w:
        f = m.regen_max_w / v
    return f


@njit(cache=True, inline="always")
def electric_braking(m, v, brake_n):
    """The part of a braking force the motors take (and regenerate) at speed v; the rest is friction.

    Zero below the regen cut-off speed. (The simulator credits the share of a cell run above the
    cut-off instead, so that results do not jump with the grid.)
    """
    if v < m.regen_min_speed_ms:
        return 0.0
    return electric_braking_capped(m, v, brake_n)


@njit(cache=True)
def braking_envelope(m):
    """Highest speed at each node from which maximum braking still meets every limit ahead.

    Integrated backwards from standstill at the platform with the same two-stage scheme the
    forward simulation uses, and never above the node's speed limit.
    """
    n = m.position_m.shape[0]
    env = np.empty(n)
    env[n - 1] = 0.0
    dx = m.dx_m
    for i in range(n - 2, -1, -1):
        v1 = env[i + 1]
        # decelerating force at an estimate of the mean speed, refined twice
        v_mid = v1
        u = v1 * v1
        for _ in range(3):
            decel = (max_braking(m, v_mid, i) + davis_force(m, v_mid) + m.line_force_n[i]) / m.effective_mass_kg
            u = v1 * v1 + 2.0 * dx * decel
            if u < 0.0:
                u = 0.0
            v_mid = 0.5 * (v1 + math.sqrt(u))
        v0 = math.sqrt(u)
        env[i] = v0 if v0 < m.limit_ms[i] else m.limit_ms[i]
    return env
