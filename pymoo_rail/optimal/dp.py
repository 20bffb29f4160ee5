"""Numba kernels of the exact solver: dynamic programming over (position, kinetic energy).

The state at grid node ``i`` is the speed; the cost-to-go ``V_i`` is stored on ``n_speeds``
nodes in ``u = v^2`` between 0 and the braking envelope ``env_i^2`` (the highest speed from which
every limit ahead and the platform can still be met; the nodes are packed towards it by
``bias``, see :func:`node_u`), and interpolated linearly in ``u`` between them. Interpolating, rather than snapping transitions to the nearest node, is what
lets the solver represent coasting and gentle partial traction, whose changes of speed over one
cell are far smaller than the node spacing (DESIGN.md section 8). Interpolating in ``u`` rather
than ``v`` makes the kinetic-energy part of the cost-to-go, which is linear in ``u``, exact.

Controls of one cell are exactly the simulator's driving modes (``pymoo_rail.sim.kernel``):
maximum traction, coasting, maximum braking, holding the entry speed (by partial traction, or by
partial regenerative-first braking where coasting would accelerate), and ``toward`` a target
speed, which lands exactly on a speed node of the next position by partial traction (or partial
braking); where the train has a varying traction efficiency map, also traction at a share of the
maximum force (``toward`` rows with the simulator's fourth program column, :func:`part_power_shares`).
Each transition is computed by the simulator's own step functions, including its
braking-envelope override (``clamp_to_envelope``), so a control sequence chosen here replays bit
for bit in the simulator. The cost of a cell is the simulator's own accounting
(``complete_cell``): ``traction work / eta_traction - eta_regen * electric braking work +
(P_aux + lambda) * dt``, the net energy plus ``lambda`` times time.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit, prange

from pymoo_rail.sim.kernel import (
    KIND_BRAKE,
    KIND_COAST,
    KIND_TRACTION,
    MODE_BRAKE,
    MODE_COAST,
    MODE_HOLD,
    MODE_HOLD_BRAKE,
    MODE_TOWARD,
    MODE_TRACTION,
    REGIME_COAST,
    clamp_to_envelope,
    full_step,
    scaled_step,
    share_above,
)
from pymoo_rail.sim.jit import called, inlined
from pymoo_rail.sim.physics import (
    davis_force,
    electric_braking_capped,
    landing_force,
    regen_map_shortfall,
    traction_map_excess,
)

INF = math.inf
# Cost-to-go stored for a node from which the platform cannot be reached (e.g. too slow to clear a
# neutral section on a climb). Finite, so that linear interpolation next to such a node gives a
# steep but finite penalty instead of spreading infinity over the whole interval (which, step by
# step backwards, would make every slow state look infeasible); far above any energy + lambda T.
PENALTY_J = 1.0e20
# Tolerance for a transition that ends on the envelope but above it by rounding (the simulator
# then brakes fully and records an excess of ~1e-9 m/s, or the single-precision tables round
# the envelope up): counted as the top node.
_TOP_RTOL = 1e-6
# An arrival below the end speed asked for costs m_eff / eta_traction per (m/s)^2 of u missing times
# this (:func:`terminal_cost`); 1 (twice the traction energy of the missing kinetic energy) let a
# run arrive 0.07 km/h below a window on the hilly test case, and 100 gave the same runs as 1 on a
# generated line, so the interpolated cost-to-go near the end is not distorted by it
END_PRICE_FACTOR = 100.0


@njit(cache=True, no_cfunc_wrapper=True)
def node_u(top_u, k, k_max, bias):
    """Kinetic energy of speed node ``k``: ``top_u g(k / k_max)`` with ``g(s) = s + bias s (1 - s)``.

    ``bias`` in [0, 1) packs the nodes towards the top (the braking envelope, where runs hold
    a speed limit): the spacing there is ``1 - bias`` times the uniform one.
    """
    s = k / k_max
    return top_u * (s + bias * s * (1.0 - s))


@njit(cache=True, no_cfunc_wrapper=True)
def node_position(top_u, u, k_max, bias):
    """Fractional node index of kinetic energy ``u`` (the inverse of :func:`node_u`), top_u > 0."""
    y = u / top_u
    if bias <= 0.0:
        return y * k_max
    b1 = 1.0 + bias
    disc = b1 * b1 - 4.0 * bias * y
    if disc < 0.0:
        disc = 0.0
    return (b1 - math.sqrt(disc)) / (2.0 * bias) * k_max


@inlined
def cell_outcome(m, v0, cell, mode, target, tr_u, tr_f, tr_w, co_u, co_f, co_w, br_u, br_f, br_w):
    """What the simulator's ``run_program`` does in one cell for a program row of its own.

    The mode logic of ``run_program`` (a hold row holds the speed on entering it, ``hold_brake``
    also by partial braking where coasting would accelerate; ``toward`` pulls or coasts to its
    target and lands on it), then the simulator's ``clamp_to_envelope``.
    ``tr_*``, ``co_*``, ``br_*`` are the cell's full traction, coast and brake steps from ``v0``
    (``full_step``), computed once and shared by every control. Returns ``(u1, force_n, w0_n)``.
    """
    brake_to_hold = mode == MODE_HOLD_BRAKE
    if mode == MODE_HOLD or brake_to_hold:
        if v0 <= 0.0:
            mode = MODE_TRACTION
        else:
            mode = MODE_TOWARD
            target = v0
    if mode == MODE_TOWARD:
        if v0 < target:
            u1, f, w0 = tr_u, tr_f, tr_w
            landed = u1 > target * target
        else:
            u1, f, w0 = co_u, co_f, co_w
            landed = u1 < target * target or brake_to_hold
        if landed:
            fl, w0l, ok = landing_force(m, v0, target, cell)
            if ok:
                u1, f, w0 = target * target, fl, w0l
            elif brake_to_hold and u1 >= target * target:  # too steep to hold: full braking
                u1, f, w0 = br_u, br_f, br_w
    elif mode == MODE_TRACTION:
        u1, f, w0 = tr_u, tr_f, tr_w
    elif mode == MODE_BRAKE:
        u1, f, w0 = br_u, br_f, br_w
    else:
        u1, f, w0 = co_u, co_f, co_w
    # np.int64(...): a run-time int, not a literal, so the simulator's compiled helpers serve here too
    u1, f, w0, _, _ = clamp_to_envelope(m, v0, cell, u1, f, w0, np.int64(REGIME_COAST))
    return u1, f, w0


@inlined
def cell_cost(m, v0, u1, f, w0, cell, time_price_w):
    """Net energy of the cell plus ``time_price_w`` x its time (J), and its time (s).

    The simulator's own accounting (``complete_cell``): traction work / eta_traction minus
    eta_regen x the electric braking work above the regen cut-off, with the efficiency maps at the
    cell's mean speed and force where the train has them. Infinite when the train stops
    inside the cell before the platform (the simulator ends the run there). Only the three totals
    the cost needs (time, traction work, electric braking work), in ``complete_cell``'s arithmetic
    bit for bit (``tests/optimal/test_dp_kernels.py`` holds them equal); the comfort and limit
    figures it also keeps made the tables 27 % slower.
    """
    if u1 < 0.0 or (u1 == 0.0 and cell < m.position_m.shape[0] - 2):
        return INF, INF
    v1 = math.sqrt(u1)
    if v0 + v1 <= 0.0:
        return INF, INF
    d = m.dx_m
    dt = 0.0 + 2.0 * d / (v0 + v1)
    w_trac = 0.0
    w_elec = 0.0
    extra = 0.0  # an efficiency map's excess over w_trac / eta and shortfall below eta_regen w_elec
    short = 0.0
    if f > 0.0:
        w_trac += f * d
        extra = traction_map_excess(m, 0.5 * (v0 + v1), f, f * d)
    elif f < 0.0:
        share = share_above(v0, v1, m.regen_min_speed_ms)
        f_electric = electric_braking_capped(m, 0.5 * (v0 + v1), -f)
        w_elec += f_electric * d * share
        short = regen_map_shortfall(m, 0.5 * (v0 + v1), f_electric, f_electric * d * share)
    e = w_trac / m.traction_efficiency + extra - (m.regen_efficiency * w_elec - short)
    return e + time_price_w * dt, dt


@njit(cache=True, no_cfunc_wrapper=True)
def value_position(top_u, u, k_max, bias):
    """Where kinetic energy ``u`` falls among the speed nodes over ``[0, top_u]``: a fractional index.

    ``-1`` above the top node (beyond rounding: no cost-to-go there), ``k_max`` on it. Depends on
    the grid only, not on the price of time: the solver computes it once per transition.
    """
    if u > top_u:
        if u <= top_u * (1.0 + _TOP_RTOL) + 1e-12:
            return float(k_max)
        return -1.0
    if top_u <= 0.0:
        return 0.0
    return node_position(top_u, u, k_max, bias)


@inlined
def interp_at(v_next, p):
    """Cost-to-go at fractional node index ``p`` (from :func:`value_position`), linear in ``u``."""
    if p < 0.0:
        return INF
    k_max = v_next.shape[0] - 1
    k = int(p)
    if k >= k_max:
        return v_next[k_max]
    w = p - k
    a = v_next[k]
    if w <= 0.0:
        return a
    b = v_next[k + 1]
    if a == INF or b == INF:
        return INF
    return a + w * (b - a)


@inlined
def interp_aug(v_next, p, sing_p, sing_val):
    """:func:`interp_at` with the singular speeds as further nodes between the regular ones.

    ``sing_p`` holds the fractional node index of each singular speed at this position (-1: none
    there), ``sing_val`` its cost-to-go; an interval holding one is interpolated on either side of it.
    """
    if p < 0.0:
        return INF
    k_max = v_next.shape[0] - 1
    k = int(p)
    if k >= k_max:
        return v_next[k_max]
    lp = float(k)
    lv = v_next[k]
    rp = lp + 1.0
    rv = v_next[k + 1]
    for s in range(sing_p.shape[0]):
        q = sing_p[s]
        if lp < q < rp:
            if q <= p:
                lp = q
                lv = sing_val[s]
            else:
                rp = q
                rv = sing_val[s]
    if p <= lp:
        return lv
    if lv == INF or rv == INF:
        return INF
    return lv + (p - lp) / (rp - lp) * (rv - lv)


@called
def interp_aug_called(v_next, p, sing_p, sing_val):
    """:func:`interp_aug`, called rather than inlined: the sweep's rare case (an interval holding a singular
    speed), compiled once instead of at each of the sweep's two call sites of :func:`sweep_cost`."""
    return interp_aug(v_next, p, sing_p, sing_val)


@inlined
def sweep_cost(e, time_cost, position, v_next, split, sing_p, sing_val):
    """A table entry's cost in the backward sweep: energy ``e`` plus ``time_cost`` (its time priced) plus the
    cost-to-go at node position ``position`` (single precision, as the tables hold it).

    ``split[k]`` says whether a singular speed lies inside the interval ``(k, k + 1)`` of the speed nodes:
    there :func:`interp_aug`, elsewhere :func:`interp_at`'s arithmetic without the search for one and
    without its infinity checks, which never hold in the sweep (its cost-to-go is ``PENALTY_J`` at most).
    """
    p = np.float64(position)
    if p < 0.0:
        return INF
    k = int(p)
    if split[k]:
        return e + time_cost + interp_aug_called(v_next, p, sing_p, sing_val)
    k_max = v_next.shape[0] - 1
    if k >= k_max:
        return e + time_cost + v_next[k_max]
    w = p - k
    a = v_next[k]
    if w <= 0.0:
        return e + time_cost + a
    return e + time_cost + (a + w * (v_next[k + 1] - a))


@njit(cache=True, no_cfunc_wrapper=True)
def interp_value(v_next, top_u, u, bias):
    """Cost-to-go at kinetic energy ``u`` from the nodes ``v_next`` spread over ``[0, top_u]``."""
    return interp_at(v_next, value_position(top_u, u, v_next.shape[0] - 1, bias))


@njit(cache=True, no_cfunc_wrapper=True)
def psi_speed(b_nsm, c_ns2m2, psi_w):
    """The speed ``v`` with ``psi(v) = v^2 R'(v) = v^2 (b + 2 c v) = psi_w`` (m/s; Davis ``R``; 0 if none).

    ``psi`` increases with ``v``: Newton's method from above (it converges monotonically there).
    """
    if psi_w <= 0.0 or (b_nsm <= 0.0 and c_ns2m2 <= 0.0):
        return 0.0
    # a start above the root: the larger of the two one-term solutions
    v = max(math.sqrt(psi_w / b_nsm) if b_nsm > 0.0 else 0.0, (psi_w / (2.0 * c_ns2m2)) ** (1.0 / 3.0)
            if c_ns2m2 > 0.0 else 0.0)
    for _ in range(100):
        f = v * v * (b_nsm + 2.0 * c_ns2m2 * v) - psi_w
        d = 2.0 * b_nsm * v + 6.0 * c_ns2m2 * v * v
        step = f / d
        v -= step
        if abs(step) <= 1e-14 * v:
            break
    return v


@njit(cache=True, no_cfunc_wrapper=True)
def electric_force(m, v, f):
    """Electrical energy per metre (N) of the control force ``f`` (N) at speed ``v``: ``f / eta_traction(v, f)``
    when pulling, ``-eta_regen(v, |f|) |f|`` when braking electrically (the maps where the train has them;
    regen caps and cut-off aside: they do not enter the stationarity condition)."""
    if f > 0.0:
        return f / m.traction_efficiency + traction_map_excess(m, v, f, f)
    if f < 0.0:
        return -(m.regen_efficiency * -f - regen_map_shortfall(m, v, -f, -f))
    return 0.0


@njit(cache=True, no_cfunc_wrapper=True)
def map_is_constant(values, constant):
    """Whether an efficiency map gives ``constant`` everywhere (then the constant's closed form serves)."""
    for i in range(values.shape[0]):
        for j in range(values.shape[1]):
            if values[i, j] != constant:
                return False
    return True


def varying_maps(m) -> tuple[bool, bool]:
    """Whether the kernel model's traction and regenerative efficiency maps vary (a map giving its
    direction's constant everywhere is the constant: its closed forms and controls serve)."""
    return (m.traction_map_values is not None and not map_is_constant(m.traction_map_values, m.traction_efficiency),
            m.regen_map_values is not None and not map_is_constant(m.regen_map_values, m.regen_efficiency))


@njit(cache=True, no_cfunc_wrapper=True)
def hold_stationarity(m, v, line_force_n, braking):
    """``v^2 (R'(v) dg/dF + dg/dv)`` at the holding force ``F = R(v) + line force`` (N x m/s = W).

    ``g(v, F)`` is :func:`electric_force`; a holding speed of the price ``lambda + P_aux`` is a root of
    ``hold_stationarity = lambda + P_aux`` (docs/efficiency.md). With a constant efficiency it is
    ``psi(v) / eta_traction`` (``braking``: ``eta_regen psi(v)``), the condition :func:`psi_speed`
    solves. The holding force is kept on its side of zero (at least 1 N) where the gradient alone
    would hold the speed; derivatives are central differences (the maps are piecewise bilinear).
    """
    f = davis_force(m, v) + line_force_n
    if braking:
        f = f if f < -1.0 else -1.0
    else:
        f = f if f > 1.0 else 1.0
    hf = 1e-4 * abs(f)
    hv = 1e-5 * v + 1e-7
    g_f = (electric_force(m, v, f + hf) - electric_force(m, v, f - hf)) / (2.0 * hf)
    g_v = (electric_force(m, v + hv, f) - electric_force(m, v - hv, f)) / (2.0 * hv)
    return v * v * ((m.davis_b_nsm + 2.0 * m.davis_c_ns2m2 * v) * g_f + g_v)


@njit(cache=True, no_cfunc_wrapper=True)
def map_hold_speed(m, price_w, line_force_n, braking, v_top):
    """The speed below ``v_top`` where :func:`hold_stationarity` equals ``price_w``, by bisection (0 if
    there is none: the condition stays above or below the price over ``(0, v_top)``)."""
    lo, hi = 1e-3, v_top
    if hi <= lo or hold_stationarity(m, hi, line_force_n, braking) < price_w:
        return 0.0
    if hold_stationarity(m, lo, line_force_n, braking) > price_w:
        return 0.0
    for _ in range(200):
        mid = 0.5 * (lo + hi)
        if hold_stationarity(m, mid, line_force_n, braking) < price_w:
            lo = mid
        else:
            hi = mid
        if hi - lo <= 1e-13 * hi:
            break
    return 0.5 * (lo + hi)


def singular_speeds(m, time_price_w, n_speeds, bias, sing_v, sing_p) -> None:
    """The speeds at which holding is optimal for the price of time, at every grid node (Pontryagin).

    With time priced at ``lambda`` plus the auxiliary power (W), holding by partial traction is
    optimal at ``V`` with ``psi(V) = eta_traction (lambda + P_aux)``, holding by regenerative braking
    at ``W`` with ``psi(W) = (lambda + P_aux) / eta_regen`` (``psi(v) = v^2 R'(v)``, ``R`` the Davis
    resistance; gradient, curve and tunnel forces do not depend on the speed and do not enter). Writes
    ``sing_v`` (n_nodes, 2) and their fractional node indices ``sing_p`` (-1 where a speed does not
    apply: at or above the braking envelope, where the top node holds the limit; ``W`` without
    regeneration or below its cut-off speed; within 1e-3 of a regular node, which holds it already;
    at the last node). ``time_price_w`` (n_cells,) is each cell's ``lambda + P_aux``. With an
    efficiency map the speeds solve :func:`hold_stationarity` instead, the same condition with the
    map's efficiency and its slopes at the holding force of the cell (so they depend on the gradient).
    """
    # Chosen here, in Python, so that a case without a map never compiles the map's bisections
    # (about 1.5 s of a first run's compile): Numba compiles both branches of a jitted if.
    map_traction, map_regen = varying_maps(m)
    if map_traction or map_regen:
        v_hold, v_regen = map_holding_speeds(m, time_price_w, map_traction, map_regen)
    else:
        v_hold, v_regen = constant_holding_speeds(m, time_price_w)
    place_singular_speeds(m, v_hold, v_regen, n_speeds, bias, sing_v, sing_p)


@njit(cache=True, no_cfunc_wrapper=True)
def constant_holding_speeds(m, time_price_w):
    """``(V, W)`` per cell (m/s) with constant efficiencies: the closed form of :func:`psi_speed`
    (``W`` 0 without regeneration or at or below its cut-off speed)."""
    n_cells = time_price_w.shape[0]
    v_hold, v_regen = np.zeros(n_cells), np.zeros(n_cells)
    last = math.nan  # the price solved last: one price over many cells is solved once
    hold = regen = 0.0
    for i in range(n_cells):
        price = time_price_w[i]
        if price != last:
            last = price
            hold = psi_speed(m.davis_b_nsm, m.davis_c_ns2m2, m.traction_efficiency * price)
            regen = 0.0
            if m.regen_efficiency > 0.0:
                w = psi_speed(m.davis_b_nsm, m.davis_c_ns2m2, price / m.regen_efficiency)
                regen = w if w > m.regen_min_speed_ms else 0.0
        v_hold[i] = hold
        v_regen[i] = regen
    return v_hold, v_regen


@njit(cache=True, no_cfunc_wrapper=True)
def map_holding_speeds(m, time_price_w, map_traction, map_regen):
    """``(V, W)`` per cell (m/s) where a map is not constant: the root of :func:`hold_stationarity` at
    the cell's holding force (the closed form for the side whose map is constant)."""
    v_hold, v_regen = constant_holding_speeds(m, time_price_w)
    for i in range(time_price_w.shape[0]):
        price = time_price_w[i]
        if map_traction:
            v_hold[i] = map_hold_speed(m, price, m.line_force_n[i], False, m.envelope_ms[i])
        if map_regen and m.regen_efficiency > 0.0:
            w = map_hold_speed(m, price, m.line_force_n[i], True, m.envelope_ms[i])
            v_regen[i] = w if w > m.regen_min_speed_ms else 0.0
    return v_hold, v_regen


@njit(cache=True, no_cfunc_wrapper=True)
def place_singular_speeds(m, v_hold, v_regen, n_speeds, bias, sing_v, sing_p):
    """Write the holding speeds of each cell into ``sing_v`` / ``sing_p`` (see :func:`singular_speeds`)."""
    n = m.position_m.shape[0]
    k_max = n_speeds - 1
    for i in range(n):
        for s in range(2):
            sing_v[i, s] = 0.0
            sing_p[i, s] = -1.0
        if i == n - 1:
            continue
        top_u = m.envelope_ms[i] ** 2
        for s in range(2):
            v = v_hold[i] if s == 0 else v_regen[i]
            if v <= 0.0 or v * v >= top_u:
                continue
            p = node_position(top_u, v * v, k_max, bias)
            if abs(p - round(p)) < 1e-3:
                continue
            sing_v[i, s] = v
            sing_p[i, s] = p


# The extra states (``sing_*`` arrays) begin with the two singular speeds (:func:`singular_speeds`);
# the coast curves (:func:`coast_curves`) follow in the further columns
N_SINGULAR = 2


@njit(cache=True)
def coast_curve(m, i_end, v_end, curve_v):
    """The speeds from which coasting lands exactly on ``v_end`` at node ``i_end``, backwards from it.

    Writes ``curve_v[i]`` for the nodes ``i < i_end`` the curve reaches: each the inverse of the
    simulator's own coast step over cell ``i`` (its envelope clamp included), by bisection on the
    entry speed. The curve stops where it leaves the braking envelope (no state there coasts onto
    it) or reaches a stop (every state does). Returns the first node written (``i_end``: none).
    """
    target_u = v_end * v_end
    for i in range(i_end - 1, -1, -1):
        top = m.envelope_ms[i]
        cap = m.envelope_ms[i + 1] ** 2
        if top <= 0.0 or min(full_step(m, top, i, KIND_COAST)[0], cap) < target_u:
            return i + 1
        if full_step(m, 1e-6, i, KIND_COAST)[0] >= target_u:
            return i + 1
        lo_v, hi_v = 0.0, top
        for _ in range(100):
            mid = 0.5 * (lo_v + hi_v)
            if min(full_step(m, mid, i, KIND_COAST)[0], cap) < target_u:
                lo_v = mid
            else:
                hi_v = mid
            if hi_v - lo_v <= 1e-13 * hi_v:
                break
        curve_v[i] = 0.5 * (lo_v + hi_v)
        target_u = curve_v[i] * curve_v[i]
    return 0


@njit(cache=True)
def place_curve(m, curve_v, start, stop, n_speeds, bias, out_v, out_p):
    """Write a coast curve's speeds over nodes ``start:stop`` and their fractional node indices (-1 at or above
    the braking envelope, where the top node is the state, or within 1e-3 of a regular node)."""
    k_max = n_speeds - 1
    for i in range(start, stop):
        out_v[i] = curve_v[i]
        top_u = m.envelope_ms[i] ** 2
        u = curve_v[i] * curve_v[i]
        if u < top_u:
            p = node_position(top_u, u, k_max, bias)
            if abs(p - round(p)) >= 1e-3:
                out_p[i] = p


def envelope_corners(m) -> np.ndarray:
    """The feet of the braking curves (n_corners,): the nodes where the braking envelope stops falling.

    The ends of descents held at a limit by braking are corners of the same kind in principle (a run
    along the envelope stops braking there); taken as well, they made the answer on one generated line
    worse (seed 5 at 1.5 x the minimum time, +0.44 % of traction energy above ms-eetc, against +0.10 %
    without): the run rode their curve while the cost-to-go still overstates other runs, at low speed.
    """
    env = m.envelope_ms
    return np.flatnonzero((env[:-2] > env[1:-1]) & (env[1:-1] <= env[2:])) + 1


@njit(cache=True)
def traction_curve(m, curve_v):
    """The run at full traction from the case's initial speed, up to the braking envelope: writes
    ``curve_v[i]`` for the nodes below it and returns the first node it reaches the envelope at."""
    n = m.position_m.shape[0]
    v = m.initial_speed_ms
    for i in range(n - 1):
        if v <= 0.0 and i > 0 or v >= m.envelope_ms[i]:
            return i
        curve_v[i] = v
        v = math.sqrt(max(full_step(m, v, i, KIND_TRACTION)[0], 0.0))
    return n - 1


def coast_curves(model, end_lo_ms: float, n_speeds: int, bias: float, max_curves: int = 6) -> tuple:
    """The coast curves into the corners of the braking envelope and into the end speed: kinks of the cost-to-go.

    At a corner (a node where the envelope stops falling: the foot of a braking curve at a lower
    limit, or the end of the line) the cost-to-go has a kink along the coasting run that arrives
    there exactly at the envelope: a state above it brakes its surplus away (``eta_regen`` back per
    joule of kinetic energy), a state below keeps it or pulls for it later (``1 / eta_traction``). The
    same at the end speed asked for (or the lower end of its window), below which the end costs
    traction. Interpolating across such a kink between speed nodes overestimates the cost-to-go by a
    share of a node spacing at every cell, and a run's final coast lies on the kink: measured on a
    generated line ending at 72 km/h, the DP's value above the energy + lambda x time of its own run by
    0.53 kWh at 200 nodes and 0.26 at 400, and the run 0.24 kWh (0.5 %) above the continuous optimum.
    So each curve is one more state at every node it reaches (like the singular speeds). And, from a
    moving start, the run at full traction from the initial speed (:func:`traction_curve`): at a start at
    walking pace the first speed node above it lies metres per second away, and the cost-to-go, strongly
    convex there, was overstated by 0.31 kWh over the first kilometre of a generated line (seed 5). A
    start from rest is the first node itself.

    Returns ``(curve_v, curve_p)`` (n_nodes, n_columns): speeds and fractional node indices (-1: none);
    curves that do not overlap share a column, at most ``max_curves`` columns (the nearest corners ahead
    of the end first).
    """
    env = model.envelope_ms
    n = env.shape[0]
    corners = [(n - 1, float(env[-1]))]
    if 0.0 < end_lo_ms < env[-1]:
        corners.append((n - 1, float(end_lo_ms)))
    corners += [(int(i), float(env[i])) for i in envelope_corners(model)[::-1]]
    columns: list[int] = []  # the first node each column is taken from
    curve_v = np.zeros((n, max_curves))
    curve_p = np.full((n, max_curves), -1.0)
    work = np.zeros(n)
    # a start from rest is a node: only a moving start needs its run at full traction as states
    start_curve = [(-1, 0.0)] if model.initial_speed_ms > 0.0 else []
    for i_end, v_end in corners + start_curve:
        if i_end < 0:  # the start at full traction, last: it lies before every corner
            start, i_end = 0, traction_curve(model, work)
        elif v_end <= 0.0:
            continue
        else:
            start = coast_curve(model, i_end, v_end, work)
        if start >= i_end:
            continue
        free = [c for c, first in enumerate(columns) if first >= i_end]
        if free:
            col = free[0]
        elif len(columns) < max_curves:
            col = len(columns)
            columns.append(n)
        else:
            continue
        place_curve(model, work, start, i_end, n_speeds, bias, curve_v[:, col], curve_p[:, col])
        columns[col] = start
    k = len(columns)
    return np.ascontiguousarray(curve_v[:, :k]), np.ascontiguousarray(curve_p[:, :k])


# traction, coast, brake, hold. Holding is ``hold_brake``: where coasting decelerates it is ``hold``
# (partial traction), and where coasting accelerates ``hold`` would only coast, which the coast
# control already is, while ``hold_brake`` holds the speed by partial (regenerative-first) braking.
N_FIXED = 4


@njit(cache=True, no_cfunc_wrapper=True)
def _fixed_mode(c):
    if c == 0:
        return MODE_TRACTION
    if c == 1:
        return MODE_COAST
    if c == 2:
        return MODE_BRAKE
    return MODE_HOLD_BRAKE


@njit(cache=True, no_cfunc_wrapper=True)
def _target_range(top_u, k_max, u0, tr_u, co_u, bias):
    """Speed nodes of the next position that partial traction (or braking) can land on exactly."""
    lo = co_u if co_u < u0 else u0
    hi = tr_u if tr_u < top_u else top_u
    if lo < 0.0:
        lo = 0.0
    k_lo = int(math.floor(node_position(top_u, lo, k_max, bias))) + 1
    if k_lo < 1:
        k_lo = 1
    k_hi = int(math.ceil(node_position(top_u, hi, k_max, bias))) - 1
    if k_hi > k_max:
        k_hi = k_max
    return k_lo, k_hi


@njit(cache=True, no_cfunc_wrapper=True)
def _n_targets(k_lo, k_hi, max_targets):
    count = k_hi - k_lo + 1
    if count <= 0:
        return 0, 1
    stride = 1
    if count > max_targets:
        stride = (count + max_targets - 1) // max_targets
    return (count + stride - 1) // stride, stride


@njit(cache=True, no_cfunc_wrapper=True, _nrt=False)
def control_table(m, cell, v0, sing_v, sing_p, k_max, max_targets, bias, table, steps_out):
    """Every control of one cell from speed ``v0``, written into ``table``; returns their number.

    ``table`` is ``(modes, targets, positions, energies, times, u1)``, arrays of at least
    ``N_FIXED + sing_v.shape[0] + max_targets`` entries: per control its mode and target speed, the
    node position it reaches among the next position's ``k_max + 1`` speed nodes
    (:func:`value_position`; -1 where the train stops in the cell), its net energy without the price
    of time (infinite where it stops), its time and the ``u = v^2`` it reaches (the simulator's
    ``cell_outcome`` and ``cell_cost``). The controls: the fixed ones, entries ``0 .. N_FIXED - 1``
    in the order of :func:`_fixed_mode` (holding, the last, needs a speed to hold), ``toward`` each
    of the next position's singular speeds ``sing_v`` in reach (where ``sing_p`` >= 0: landing on
    them and holding them exactly), and ``toward`` speed nodes of the next position in reach by
    partial traction (or braking). They depend on the kind of the cell (:func:`cell_types`),
    ``v0`` and the next position's singular speeds, not on the price of time or the cost-to-go.
    ``steps_out`` (9,) receives the cell's full steps from ``v0`` (:func:`cell_steps`).
    """
    modes, targets, pos, energy, dt, u1s = table
    top_u = m.envelope_ms[cell + 1] ** 2
    steps = cell_steps(m, v0, cell)
    for q in range(9):  # for a caller that adds controls of its own (:func:`_singular_rows`)
        steps_out[q] = steps[q]
    tr_u, co_u = steps[0], steps[3]
    n_fixed = N_FIXED if v0 > 0.0 else N_FIXED - 1  # holding needs a speed to hold
    n_sing = sing_v.shape[0]
    k_lo, stride, n_nodes = 1, 1, 0
    if top_u > 0.0 and k_max > 0:
        k_lo, k_hi = _target_range(top_u, k_max, v0 * v0, tr_u, co_u, bias)
        n_nodes, stride = _n_targets(k_lo, k_hi, max_targets)
    p = 0
    for c in range(n_fixed + n_sing + n_nodes):
        if c < n_fixed:
            mode = _fixed_mode(c)
            target = 0.0
        elif c < n_fixed + n_sing:
            mode = MODE_TOWARD
            target = sing_v[c - n_fixed]
            if sing_p[c - n_fixed] < 0.0:
                continue
            if out_of_reach(v0, target, tr_u, co_u):
                continue
        else:  # partial traction (or braking) landing exactly on a speed node of the next position
            mode = MODE_TOWARD
            target = math.sqrt(node_u(top_u, k_lo + (c - n_fixed - n_sing) * stride, k_max, bias))
        u1s[p], energy[p], dt[p], pos[p] = control_entry(m, cell, v0, mode, target, steps, top_u, k_max, bias, 0.0)
        modes[p] = mode
        targets[p] = target
        p += 1
    return p


@inlined
def cell_steps(m, v0, cell):
    """The cell's full traction, coast and brake steps from ``v0`` (``full_step``), shared by every control:
    ``(tr_u, tr_f, tr_w, co_u, co_f, co_w, br_u, br_f, br_w)``."""
    tr_u, tr_f, tr_w, _ = full_step(m, v0, cell, KIND_TRACTION)
    co_u, co_f, co_w, _ = full_step(m, v0, cell, KIND_COAST)
    br_u, br_f, br_w, _ = full_step(m, v0, cell, KIND_BRAKE)
    return tr_u, tr_f, tr_w, co_u, co_f, co_w, br_u, br_f, br_w


@inlined
def out_of_reach(v0, target, tr_u, co_u):
    """Whether ``toward target`` from ``v0`` is only the traction or coast step (``cell_outcome``'s rule), an
    entry of the control table already: then it is not a control of its own."""
    return (tr_u <= target * target) if v0 < target else (co_u >= target * target)


@inlined
def control_entry(m, cell, v0, mode, target, steps, top_u, k_max, bias, time_price_w):
    """One control of a cell from ``v0``: ``(u1, cost J, time s, node position)`` (``cell_outcome``, ``cell_cost``).

    The cost is the net energy plus ``time_price_w`` x the time: a control table (:func:`control_table`)
    prices at 0 (``e + 0.0 x dt`` is ``e`` exactly, and :func:`entry_cost` adds the price as ``cell_cost``
    does), the transition tables at the auxiliary power. The position is -1 where the train stops in
    the cell (infinite cost). ``steps``: the cell's full steps from ``v0`` (:func:`cell_steps`).
    """
    u1, f, w0 = cell_outcome(m, v0, cell, mode, target, steps[0], steps[1], steps[2], steps[3], steps[4], steps[5],
                             steps[6], steps[7], steps[8])
    e, d = cell_cost(m, v0, u1, f, w0, cell, time_price_w)
    return u1, e, d, (value_position(top_u, u1, k_max, bias) if e < INF else -1.0)


@inlined
def entry_cost(table, p, time_price_w, v_next, sing_p, sing_val):
    """Cost of entry ``p`` of a control table (:func:`control_table`) plus the cost-to-go it reaches.

    The cell priced as ``cell_cost`` prices it, then the cost-to-go interpolated in ``v_next`` with the
    next position's singular speeds as further nodes (:func:`interp_aug`); infinite where the train
    stops in the cell.
    """
    e = table[3][p]
    if e < INF:
        cost = e + time_price_w * table[4][p]
        cost += interp_aug(v_next, table[2][p], sing_p, sing_val)
        return cost
    return INF


@inlined
def table_minimum(table, n_entries, time_price_w, v_next, sing_p, sing_val):
    """The entry of a control table (:func:`control_table`) of least :func:`entry_cost`, and that cost:
    ``(cost, entry)``, entry -1 (cost infinite) if every control stops in the cell; the first of equals.

    ``sing_p``, ``sing_val``: the next position's singular speeds (:func:`singular_speeds`), further
    nodes of the cost-to-go (and, in the table, further ``toward`` targets: a run lands on them and
    holds them exactly). A cost at least ``PENALTY_J``: no control can reach the platform.
    """
    best = INF
    best_p = -1
    for p in range(n_entries):
        cost = entry_cost(table, p, time_price_w, v_next, sing_p, sing_val)
        if cost < best:
            best = cost
            best_p = p
    return best, best_p


def cell_types(m) -> tuple[np.ndarray, np.ndarray]:
    """Cells whose transitions are equal, found once so that each kind of cell is tabulated once.

    A cell's transitions (:func:`transitions`) read, of the line, only its line force, its neutral
    flag, the braking envelope at both its ends and whether it is the last cell (``cell_outcome``,
    ``cell_cost``, ``value_position``); cells agreeing bit for bit in these give bit-identical
    tables. Long stretches at one limit are one kind: 717 kinds for the 9707 cells of the 48.5 km
    intercity case, 2247 for the 10000 of the level 10 km one (the braking curves stay distinct).

    Returns ``(cell_type, first_cell)``: the kind of every cell (n_cells,), numbered in order of
    first appearance, and the first cell of each kind (n_types,).
    """
    n_cells = m.position_m.shape[0] - 1
    last = np.zeros(n_cells)
    last[-1] = 1.0
    signature = np.column_stack([m.line_force_n[:n_cells], m.neutral[:n_cells].astype(float),
                                 m.envelope_ms[:n_cells], m.envelope_ms[1:n_cells + 1], last])
    # compared as bit patterns: -0.0 and 0.0 may not give the same bits downstream
    bits = np.ascontiguousarray(signature).view(np.int64)
    # a stable sort of the rows (np.lexsort: 8 times faster than np.unique(axis=0)); a kind begins where a
    # row differs from the one before, and its first cell comes first (stable)
    by_row = np.lexsort(bits.T[::-1])
    rows = bits[by_row]
    starts = np.ones(n_cells, dtype=bool)
    np.any(rows[1:] != rows[:-1], axis=1, out=starts[1:])
    inverse = np.empty(n_cells, dtype=np.int64)
    inverse[by_row] = np.cumsum(starts) - 1
    first = by_row[starts]
    order = np.argsort(first)  # kinds in order of first appearance: the sweep reads them in line order
    rank = np.empty_like(order)
    rank[order] = np.arange(order.shape[0])
    return rank[inverse].astype(np.int64), first[order].astype(np.int64)


@inlined
def _kind_cell(m, first_cell, p_type):
    """Kind ``t`` of a table loop's ``prange`` index, its first cell ``i`` and the envelope's ``u`` at both ends."""
    t = np.int64(p_type)  # callers pass np.int64(p_type): prange counts in uint64 (one compiled copy)
    i = first_cell[t]
    return t, i, m.envelope_ms[i] ** 2, m.envelope_ms[i + 1] ** 2


# serial: some 25 ns a state, and a parallel region's threads cost more CPU than they save here
# (generated seeds 0, 1, 5, 10 at 200 nodes, best of 7 under load: 6-16 ms of CPU in parallel, 2.5-8 ms serial)
@njit(cache=True, no_cfunc_wrapper=True)
def _count_targets(m, n_speeds, max_targets, bias, first_cell, counts):
    k_max = n_speeds - 1
    for p_type in range(first_cell.shape[0]):
        t, i, top0, top1 = _kind_cell(m, first_cell, np.int64(p_type))
        for j in range(n_speeds):
            counts[t * n_speeds + j] = 0
            if top1 <= 0.0:
                continue
            v0 = math.sqrt(node_u(top0, j, k_max, bias))
            tr_u = full_step(m, v0, i, KIND_TRACTION)[0]
            co_u = full_step(m, v0, i, KIND_COAST)[0]
            k_lo, k_hi = _target_range(top1, k_max, v0 * v0, tr_u, co_u, bias)
            counts[t * n_speeds + j] = _n_targets(k_lo, k_hi, max_targets)[0]


@njit(cache=True, no_cfunc_wrapper=True, parallel=True)
def _fill_transitions(m, n_speeds, max_targets, bias, first_cell, offsets, fixed_u1, fixed_e, fixed_dt, tgt_u1, tgt_e,
                      tgt_dt):
    k_max = n_speeds - 1
    aux = m.aux_power_w
    for p_type in prange(first_cell.shape[0]):
        t, i, top0, top1 = _kind_cell(m, first_cell, np.int64(p_type))
        for j in range(n_speeds):
            v0 = math.sqrt(node_u(top0, j, k_max, bias))
            steps = cell_steps(m, v0, i)
            s = t * n_speeds + j
            n_tgt = offsets[s + 1] - offsets[s]
            k_lo, stride = 1, 1
            if n_tgt > 0:
                k_lo, k_hi = _target_range(top1, k_max, v0 * v0, steps[0], steps[3], bias)
                stride = _n_targets(k_lo, k_hi, max_targets)[1]
            # one loop over the fixed controls and the targets: one inlined copy of the cell's physics
            for c in range(N_FIXED + n_tgt):
                if c < N_FIXED:
                    mode = _fixed_mode(c)
                    target = 0.0
                else:
                    mode = MODE_TOWARD
                    target = math.sqrt(node_u(top1, k_lo + (c - N_FIXED) * stride, k_max, bias))
                _, e, dt, pos = control_entry(m, i, v0, mode, target, steps, top1, k_max, bias, aux)
                if c < N_FIXED:
                    fixed_u1[t, j, c] = pos
                    fixed_e[t, j, c] = e
                    fixed_dt[t, j, c] = dt
                else:
                    q = offsets[s] + c - N_FIXED
                    tgt_u1[q] = pos
                    tgt_e[q] = e
                    tgt_dt[q] = dt


def transitions(m, n_speeds: int, max_targets: int, bias: float, share: bool = True):
    """Every kind of cell's transitions from every speed node, which do not depend on the price of time.

    Returns a tuple ``(fixed_u1, fixed_e, fixed_dt, offsets, tgt_u1, tgt_e, tgt_dt, cell_type)``:
    for the four fixed controls (and, where the train has a varying traction efficiency map, the
    part-power shares after them, :func:`part_power_shares`) arrays (n_types, n_speeds, 4 [+ n_shares])
    of where the speed reached falls
    among the next position's speed nodes (:func:`value_position`, computed once here rather than
    in every sweep), the net energy (J, with auxiliary power) and the time of the cell; for partial
    traction onto speed nodes the same in flat arrays, state ``s = t * n_speeds + j`` owning entries
    ``offsets[s]:offsets[s + 1]``; and ``cell_type`` (n_cells,), the row ``t`` of each cell.
    Cells of one kind (:func:`cell_types`) share their rows; ``share=False`` gives every cell its
    own (the same numbers, for tests). Infeasible transitions (a stop before the platform) have
    infinite energy. Stored in single precision.
    """
    if share:
        cell_type, first_cell = cell_types(m)
    else:
        cell_type = first_cell = np.arange(m.position_m.shape[0] - 1, dtype=np.int64)
    n_types = first_cell.shape[0]
    counts = np.zeros(n_types * n_speeds, dtype=np.int64)
    _count_targets(m, n_speeds, max_targets, bias, first_cell, counts)
    offsets = np.zeros(counts.shape[0] + 1, dtype=np.int64)
    np.cumsum(counts, out=offsets[1:])
    # single precision halves the memory; the tables only shape the cost-to-go (an error of 1e-7
    # of a node spacing or of a cell's energy), the forward run recomputes every step exactly
    fixed = [np.empty((n_types, n_speeds, N_FIXED), dtype=np.float32) for _ in range(3)]
    tgt = [np.empty(offsets[-1], dtype=np.float32) for _ in range(3)]
    _fill_transitions(m, n_speeds, max_targets, bias, first_cell, offsets, *fixed, *tgt)
    shares = part_power_shares(m)
    if shares.shape[0] > 0:  # a varying traction map: the part-power controls after the fixed ones
        part = part_power_transitions(m, n_speeds, bias, first_cell, shares)
        fixed = [np.concatenate((a, b), axis=2) for a, b in zip(fixed, part)]
    return (*fixed, offsets, *tgt, cell_type)


def curve_controls(m, curve_v: np.ndarray, curve_p: np.ndarray, n_speeds: int, max_targets: int, bias: float) -> tuple:
    """The controls from the coast curves' states that do not depend on the price of time, built once per grid.

    ``curve_v``, ``curve_p`` (n_nodes, n_curves): the curves' speeds and node positions (:func:`coast_curves`,
    -1: no state). A curve's speed changes from node to node, so its control table
    (:func:`control_table`) is its own at every node; it depends on the price only through its
    ``toward`` entries onto the singular speeds ``V``, ``W`` of the next position. The rest (fixed
    controls, node targets, ``toward`` the next position's curve speeds) is tabulated here, once, rather
    than in every sweep (:func:`backward_sweep` adds the ``V``, ``W`` entries per price, from the cell's
    full steps kept here).

    Returns ``(row, n_entries, entries, steps)``: ``row`` (n_nodes, n_curves) the row of each state (-1:
    none), per row its number of entries, ``entries`` (n_rows, 3, size): node position, net energy
    (J, without the price of time) and time (s) of each entry, and ``steps`` (n_rows, 9), the cell's full
    steps from the state (:func:`cell_steps`).
    """
    n, n_curves = curve_v.shape
    active = curve_p >= 0.0
    active[-1] = False  # no cell after the last node
    row = np.full((n, n_curves), -1, dtype=np.int64)
    n_rows = int(active.sum())
    row[active] = np.arange(n_rows)
    n_entries = np.zeros(n_rows, dtype=np.int64)
    entries = np.empty((n_rows, 3, N_FIXED + n_curves + max_targets))
    steps = np.empty((n_rows, 9))
    if n_rows > 0:  # a case without curves compiles nothing here
        _fill_curve_controls(m, np.ascontiguousarray(curve_v), np.ascontiguousarray(curve_p), row, n_speeds - 1,
                             max_targets, bias, n_entries, entries, steps)
    return row, n_entries, entries, steps


@njit(cache=True, no_cfunc_wrapper=True)
def _fill_curve_controls(m, curve_v, curve_p, row, k_max, max_targets, bias, n_entries, entries, steps):
    size = entries.shape[2]
    table = (np.empty(size, dtype=np.int64), np.empty(size), np.empty(size), np.empty(size), np.empty(size),
             np.empty(size))
    for i in range(row.shape[0] - 1):
        for c in range(row.shape[1]):
            r = row[i, c]
            if r < 0:
                continue
            v0 = curve_v[i, c]
            count = control_table(m, i, v0, curve_v[i + 1], curve_p[i + 1], k_max, max_targets, bias, table, steps[r])
            n_entries[r] = count
            for p in range(count):
                entries[r, 0, p] = table[2][p]
                entries[r, 1, p] = table[3][p]
                entries[r, 2, p] = table[4][p]


@called
def _toward_states(m, i, v0, lo, hi, steps, price_w, v_next, bias, sing_v, sp_next, sv_next, best):
    """:func:`_singular_rows`' entries ``toward`` the next position's extra states ``lo .. hi - 1`` from ``v0``
    (those in reach, :func:`out_of_reach`), each priced as :func:`entry_cost` prices it: the least of
    them and ``best``."""
    k_max = v_next.shape[0] - 1
    top_u = m.envelope_ms[i + 1] ** 2
    # as a tuple, as :func:`control_table` passes them: one compiled copy of :func:`control_entry`
    st = (steps[0], steps[1], steps[2], steps[3], steps[4], steps[5], steps[6], steps[7], steps[8])
    for q in range(lo, hi):
        target = sing_v[i + 1, q]
        if sp_next[q] < 0.0 or out_of_reach(v0, target, st[0], st[3]):
            continue
        e, d, p = control_entry(m, i, v0, np.int64(MODE_TOWARD), target, st, top_u, k_max, bias, 0.0)[1:]
        if e < INF:
            cost = e + price_w * d
            cost += interp_aug(v_next, p, sp_next, sv_next)
            if cost < best:
                best = cost
    return best


@njit(cache=True, no_cfunc_wrapper=True, _nrt=False)
def _singular_rows(m, i, t, price_w, v_next, max_targets, bias, floor_k, sing_v, sing_p, sing_val, memo_key,
                   memo_n, memo, memo_steps, curves):
    """Cost-to-go of the extra states at node ``i`` (:func:`backward_sweep`): every control from them.

    The least :func:`entry_cost` of their control tables (:func:`control_table`), as a set (the least
    cost does not depend on the order of the entries). For the singular speeds ``V``, ``W`` the table
    without the ``toward`` entries onto the coast curves is kept per kind of cell ``t`` and singular
    speed ``s`` in row ``t * N_SINGULAR + s`` of ``memo``: a cell of the kind last tabulated from the
    same singular speed with the same next singular speeds (``memo_key``) reuses it, the same numbers bit
    for bit, so a sweep pays the simulator's steps once per kind of cell rather than once per cell and
    price of time (``benchmarks/peers.py --sweep-cpu``). The coast curves' entries (their speeds change
    per node) are added per node from the cell's full steps kept in ``memo_steps``. A coast curve's own
    table comes from ``curves`` (:func:`curve_controls`, built once per grid), its ``toward`` entries
    onto ``V``, ``W`` added here.
    """
    sp_next = sing_p[i + 1]
    sv_next = sing_val[i + 1]
    n_sing = sing_v.shape[1]
    n_own = min(n_sing, N_SINGULAR)
    curve_row, curve_n, curve_entries, curve_steps = curves
    for s in range(n_sing):
        sing_val[i, s] = PENALTY_J
        if sing_p[i, s] < 0.0 or sing_p[i, s] < floor_k:
            continue
        v0 = sing_v[i, s]
        if s < N_SINGULAR:
            row = t * N_SINGULAR + s
            table = (memo[0][row], memo[1][row], memo[2][row], memo[3][row], memo[4][row], memo[5][row])
            # the table's key: the speed held and the next position's singular targets (-1: none there)
            key = memo_key[row]
            same = key[0] == v0
            for q in range(n_own):
                same = same and key[q + 1] == (sing_v[i + 1, q] if sp_next[q] >= 0.0 else -1.0)
            if not same:
                memo_n[row] = control_table(m, i, v0, sing_v[i + 1, :n_own], sp_next[:n_own], v_next.shape[0] - 1,
                                            max_targets, bias, table, memo_steps[row])
                key[0] = v0
                for q in range(n_own):
                    key[q + 1] = sing_v[i + 1, q] if sp_next[q] >= 0.0 else -1.0
            best = table_minimum(table, memo_n[row], price_w, v_next, sp_next, sv_next)[0]
            best = _toward_states(m, i, v0, n_own, n_sing, memo_steps[row], price_w, v_next, bias, sing_v, sp_next,
                                  sv_next, best)
        else:
            r = curve_row[i, s - N_SINGULAR]
            if r < 0:  # not a state of ``curves``: the sweep's extra states and ``curves`` come from one arrival
                continue
            best = INF
            for p in range(curve_n[r]):
                e = curve_entries[r, 1, p]
                if e < INF:
                    cost = e + price_w * curve_entries[r, 2, p]
                    cost += interp_aug(v_next, curve_entries[r, 0, p], sp_next, sv_next)
                    if cost < best:
                        best = cost
            # np.int64(0): a run-time int, not a literal (one compiled copy of _toward_states)
            best = _toward_states(m, i, v0, np.int64(0), n_own, curve_steps[r], price_w, v_next, bias, sing_v, sp_next,
                                  sv_next, best)
        sing_val[i, s] = best if best < PENALTY_J else PENALTY_J


@njit(cache=True, no_cfunc_wrapper=True)
def backward_sweep(m, time_price_w, fixed_u1, fixed_e, fixed_dt, offsets, tgt_u1, tgt_e, tgt_dt, cell_type, value,
                   floor_k, terminal_j, sing_v, sing_p, sing_val, max_targets, bias, curves):
    """Fill ``value`` (n_nodes, n_speeds) with the cost-to-go, from the end of the line backwards.

    ``time_price_w`` (n_cells,) is each cell's price of time beyond the auxiliary power (already in
    the energies; one value everywhere for one running time, one per stretch between timing points);
    ``fixed_u1`` and ``tgt_u1`` hold node positions (:func:`value_position`), one row per kind of
    cell, ``cell_type`` (n_cells,) the row of each cell (:func:`transitions`). ``floor_k`` (n_nodes,)
    is the lowest speed node allowed at each position (0 everywhere but at a timing point's minimum
    speed and at the end, where the case's end speed sets it): the nodes below it cost
    ``PENALTY_J``, so no run passes there slower. ``terminal_j`` (n_speeds,) is the cost-to-go at
    the end of the line (:func:`terminal_cost`).

    The singular speeds (:func:`singular_speeds`: ``sing_v``, ``sing_p``, both (n_nodes, 2)) are
    further states: their cost-to-go ``sing_val`` (n_nodes, 2) is found by evaluating every control
    from them with the simulator's steps (:func:`control_table`, as in the forward run, prices
    ``time_price_w`` + the auxiliary power), and every interpolation between regular nodes passes
    through them (:func:`interp_aug`). A speed grid meets them only by luck: this way the DP holds
    them exactly. Singular arrays with every ``sing_p`` at -1 give the speed grid alone. Their columns
    after the first ``N_SINGULAR`` are the coast curves (:func:`coast_curves`), whose price-independent
    controls ``curves`` holds (:func:`curve_controls` of those columns, built once per grid).
    """
    n, n_speeds = value.shape
    # at the end of the line the top node is the final speed (the envelope ends there; 0 at a
    # platform: one state); ``terminal_j`` prices an arrival below the speeds the case asks for
    # (:func:`terminal_cost`)
    for j in range(n_speeds):
        value[n - 1, j] = terminal_j[j] if j >= floor_k[n - 1] else PENALTY_J
    for s in range(sing_val.shape[1]):
        sing_val[n - 1, s] = PENALTY_J
    # the singular speeds' control tables, one per kind of cell and singular speed, filled as the sweep
    # meets them (:func:`_singular_rows`); a key of NaN matches nothing
    n_sing = sing_v.shape[1]
    n_rows = (offsets.shape[0] - 1) // n_speeds * N_SINGULAR
    memo_key = np.full((n_rows, 1 + N_SINGULAR), np.nan)
    split = np.zeros(n_speeds, dtype=np.bool_)  # :func:`sweep_cost`
    memo_n = np.zeros(n_rows, dtype=np.int64)
    memo_steps = np.empty((n_rows, 9))
    size = N_FIXED + N_SINGULAR + max_targets
    memo = (np.empty((n_rows, size), dtype=np.int64), np.empty((n_rows, size)), np.empty((n_rows, size)),
            np.empty((n_rows, size)), np.empty((n_rows, size)), np.empty((n_rows, size)))
    for i in range(n - 2, -1, -1):
        v_next = value[i + 1]
        sp_next = sing_p[i + 1]
        sv_next = sing_val[i + 1]
        t = cell_type[i]
        for s in range(n_sing):  # the intervals of the next position's nodes a singular speed splits
            q = sp_next[s]
            if q >= 0.0 and q != math.floor(q):
                split[int(q)] = True
        _singular_rows(m, i, t, time_price_w[i] + m.aux_power_w, v_next, max_targets, bias, floor_k[i], sing_v, sing_p,
                       sing_val, memo_key, memo_n, memo, memo_steps, curves)
        price = time_price_w[i]
        for j in range(n_speeds):
            best = INF
            for c in range(fixed_e.shape[2]):  # N_FIXED, and the part-power shares where the train has them
                e = fixed_e[t, j, c]
                if e < INF:
                    cost = sweep_cost(e, price * fixed_dt[t, j, c], fixed_u1[t, j, c], v_next, split, sp_next, sv_next)
                    if cost < best:
                        best = cost
            s = t * n_speeds + j
            for p in range(offsets[s], offsets[s + 1]):
                e = tgt_e[p]
                if e < INF:
                    cost = sweep_cost(e, price * tgt_dt[p], tgt_u1[p], v_next, split, sp_next, sv_next)
                    if cost < best:
                        best = cost
            value[i, j] = best if best < PENALTY_J and j >= floor_k[i] else PENALTY_J
        for s in range(n_sing):
            if sp_next[s] >= 0.0:
                split[int(sp_next[s])] = False


@inlined
def _fixed_entry(mode, v0):
    """The entry of a fixed control ``mode`` in a control table from ``v0`` (:func:`control_table`): the
    fixed controls come first, in the order of :func:`_fixed_mode`; holding from a standstill is traction."""
    for c in range(N_FIXED):
        if _fixed_mode(c) == mode:
            break
    if c == N_FIXED - 1 and v0 <= 0.0:
        c = 0
    return c


@njit(cache=True, no_cfunc_wrapper=True)
def forward_rollout(m, time_price_w, value, max_targets, bias, tie_j, modes, targets, speeds, sing_v=None,
                    sing_p=None, sing_val=None):
    """Drive from the case's initial speed choosing each cell's control from the cost-to-go (continuous state).

    Between controls whose costs differ by at most ``tie_j`` (J) the run keeps its previous mode,
    or holds its speed after a partial-traction landing: near-ties otherwise make the regime
    chatter (coast, land on a node, coast...) for no measurable energy.

    Writes per cell ``modes``, ``targets`` and per node ``speeds``. Returns
    ``(n_cells_done, net_energy_j, time_s, tie_cost_j)``; ``n_cells_done < n_nodes - 1`` means no
    feasible control was found at that cell; ``tie_cost_j`` is what keeping the regime cost over
    the best control, summed over the cells where it was kept (by the cost-to-go's estimate).
    """
    n = m.position_m.shape[0]
    if sing_p is None:  # no singular speeds (:func:`singular_speeds`)
        sv_all = np.zeros((n, 0))
        sp_all = np.full((n, 0), -1.0)
        sval_all = np.zeros((n, 0))
    else:
        sv_all = sing_v
        sp_all = sing_p
        sval_all = sing_val
    size = N_FIXED + sp_all.shape[1] + max_targets  # a control table (:func:`control_table`), rewritten every cell
    table = (np.empty(size, dtype=np.int64), np.empty(size), np.empty(size), np.empty(size), np.empty(size),
             np.empty(size))
    steps = np.empty(9)  # the cell's full steps (:func:`control_table`), not read here
    k_max = value.shape[1] - 1
    v = m.initial_speed_ms
    speeds[0] = v
    energy = 0.0
    time = 0.0
    tie_cost = 0.0
    previous = MODE_TRACTION
    for i in range(n - 1):
        v_next, sp_next, sval_next = value[i + 1], sp_all[i + 1], sval_all[i + 1]
        n_entries = control_table(m, i, v, sv_all[i + 1], sp_next, k_max, max_targets, bias, table, steps)
        cost, p = table_minimum(table, n_entries, time_price_w[i], v_next, sp_next, sval_next)
        if cost >= PENALTY_J:  # every control leads to a stop short of the platform
            return i, energy, time, tie_cost
        mode, target = table[0][p], table[1][p]
        if i > 0 and mode != previous and tie_j > 0.0:
            keep = MODE_HOLD_BRAKE if previous == MODE_TOWARD else previous
            if keep != mode:
                c = _fixed_entry(keep, v)
                c_keep = entry_cost(table, c, time_price_w[i], v_next, sp_next, sval_next)
                if c_keep < INF and c_keep <= cost + tie_j:
                    tie_cost += c_keep - cost
                    mode, target, p = keep, 0.0, c
        # the chosen control's cell, as ``cell_cost`` prices it with the auxiliary power alone
        energy += table[3][p] + m.aux_power_w * table[4][p]
        time += table[4][p]
        modes[i] = mode
        targets[i] = target
        previous = mode
        v = math.sqrt(table[5][p])
        speeds[i + 1] = v
    return n - 1, energy, time, tie_cost


def terminal_cost(model, n_speeds: int, bias: float, end_lo_ms: float) -> np.ndarray:
    """Cost-to-go at the end of the line (n_speeds,): what arriving below ``end_lo_ms`` costs.

    The top node is the final speed (the braking envelope ends there). Arriving slower than the
    case asks for (``end_lo_ms``: the final speed itself, or its window's lower end) costs
    ``END_PRICE_FACTOR x m_eff / eta_traction`` per (m/s)^2 of ``u`` missing: far more than the
    missing kinetic energy could have saved, so the optimum arrives at the speed asked for wherever
    it can. A price linear in ``u`` rather than an infinite wall: the cost-to-go
    is interpolated linearly in ``u``, so it is exact between the nodes, and the states from which
    the end speed is barely reachable are not cut off by a node spacing every cell (a wall at the
    nodes below the floor made those states infeasible back over the whole final approach).
    """
    top_u = model.envelope_ms[-1] ** 2
    k_max = n_speeds - 1
    lo_u = min(end_lo_ms ** 2, top_u)
    price = END_PRICE_FACTOR * model.effective_mass_kg / model.traction_efficiency
    # node_u's Python function: the same arithmetic, without loading a kernel for it on every run
    u = np.array([node_u.py_func(top_u, k, k_max, bias) for k in range(n_speeds)])
    return price * np.maximum(lo_u - u, 0.0)


def solve(model, tables, lambda_w, max_targets: int, bias: float, tie_j: float, value: np.ndarray,
          floor_k: np.ndarray | None = None, terminal_j: np.ndarray | None = None, singular: bool = True,
          sing: tuple | None = None, reuse: bool = False, arrival: tuple | None = None, curves: tuple | None = None):
    """One DP solve at a price of time ``lambda_w`` (W, i.e. J per second of running time).

    ``lambda_w`` is one price, or one per cell (n_cells,): a journey's timing points give each
    stretch between them its own price. ``floor_k`` (n_nodes,), optional, is the lowest speed node
    allowed at each position (:func:`speed_floor_nodes`): a journey's minimum speeds. ``terminal_j``
    (n_speeds,), optional, the cost-to-go at the end (:func:`terminal_cost`; default 0: any arrival).

    ``tables`` are the model's :func:`transitions`; ``value`` (n_nodes, n_speeds) receives the
    cost-to-go. ``singular`` adds the singular speeds of the price as states (:func:`singular_speeds`).
    Returns the forward run: (modes, targets, speeds, cells done, net energy J, time s, cost of the kept
    regimes J) and the cost-to-go from the initial speed (J). Where the train has a varying traction
    efficiency map, ``targets`` is (n_cells, 2): target and traction share (:func:`forward_rollout_part_power`),
    the program's third and fourth columns.
    Time is priced at ``lambda + P_aux`` in the forward run: auxiliary energy is part of the net
    energy, and the tables already hold it.

    ``sing``: arrays ``(sing_v, sing_p, sing_val)`` (each (n_nodes, 2), or more columns with ``arrival``) to hold the singular speeds and
    their cost-to-go (default: new ones). ``reuse``: ``value`` and ``sing`` still hold the sweep of an
    earlier solve at the same price and settings: only the forward run is made (the certificate's run
    without the tie rule reuses the chosen run's sweep). ``arrival``: ``(curve_v, curve_p)`` of
    :func:`coast_curves`, the coast curves as further states (the columns of ``sing`` after the first
    ``N_SINGULAR``; with ``singular`` only). ``curves``: :func:`curve_controls` of ``arrival`` on this grid
    (the caller keeps them across prices; default: built here).
    """
    n = model.position_m.shape[0]
    if sing is None:
        n_extra = N_SINGULAR + (0 if arrival is None else arrival[0].shape[1])
        sing = tuple(np.empty((n, n_extra)) for _ in range(3))
    sing_v, sing_p, sing_val = sing
    if reuse:
        return _rollout(model, lambda_w, max_targets, bias, tie_j, value, sing_v, sing_p, sing_val)
    prices = np.ascontiguousarray(np.broadcast_to(np.asarray(lambda_w, dtype=float), (n - 1,)))
    if floor_k is None:
        floor_k = np.zeros(n, dtype=np.int64)
    if terminal_j is None:
        terminal_j = np.zeros(value.shape[1])
    price = prices + model.aux_power_w
    if singular:
        singular_speeds(model, price, value.shape[1], float(bias), sing_v, sing_p)
        if arrival is not None:
            sing_v[:, N_SINGULAR:], sing_p[:, N_SINGULAR:] = arrival
    else:
        sing_v[:] = 0.0
        sing_p[:] = -1.0
    if curves is None or not singular:
        curves = curve_controls(model, sing_v[:, N_SINGULAR:], sing_p[:, N_SINGULAR:], value.shape[1], max_targets,
                                bias)
    backward_sweep(model, prices, *tables, value, floor_k, terminal_j, sing_v, sing_p, sing_val, int(max_targets),
                   float(bias), curves)
    return _rollout(model, lambda_w, max_targets, bias, tie_j, value, sing_v, sing_p, sing_val)


def _rollout(model, lambda_w, max_targets, bias, tie_j, value, sing_v, sing_p, sing_val):
    """The forward run of :func:`solve` on a swept cost-to-go, and the cost-to-go from the initial speed."""
    n = model.position_m.shape[0]
    price = np.ascontiguousarray(np.broadcast_to(np.asarray(lambda_w, dtype=float), (n - 1,))) + model.aux_power_w
    run = forward_run(model, price, value, max_targets, bias, tie_j, sing_v, sing_p, sing_val)
    start_j = interp_aug(value[0], value_position(model.envelope_ms[0] ** 2, model.initial_speed_ms ** 2,
                                                  value.shape[1] - 1, float(bias)), sing_p[0], sing_val[0])
    return (*run, start_j)


def forward_run(model, time_price_w, value, max_targets, bias, tie_j, sing_v, sing_p, sing_val) -> tuple:
    """The forward run on a swept cost-to-go: :func:`forward_rollout`, or where the train has a varying
    traction efficiency map :func:`forward_rollout_part_power` (chosen here, in Python: a case without
    one compiles no part-power kernel).

    ``time_price_w`` (n_cells,) includes the auxiliary power. Returns ``(modes, targets, speeds,
    n_cells_done, net_energy_j, time_s, tie_cost_j)``; ``targets`` is (n_cells,), or (n_cells, 2) with
    the traction share beside the target where part power is among the controls, so that
    ``np.column_stack([end_m, modes, targets])`` is the simulator's program either way.
    """
    n = model.position_m.shape[0]
    modes = np.zeros(n - 1, dtype=np.int64)
    speeds = np.zeros(n)
    shares = part_power_shares(model)
    if shares.shape[0] > 0:
        targets = np.zeros((n - 1, 2))
        done, energy, time, tie_cost = forward_rollout_part_power(model, time_price_w, value, int(max_targets),
                                                                  float(bias), float(tie_j), shares, modes, targets,
                                                                  speeds, sing_v, sing_p, sing_val)
    else:
        targets = np.zeros(n - 1)
        done, energy, time, tie_cost = forward_rollout(model, time_price_w, value, int(max_targets), float(bias),
                                                       float(tie_j), modes, targets, speeds, sing_v, sing_p, sing_val)
    return modes, targets, speeds, done, energy, time, tie_cost


def speed_floor_nodes(model, floor_ms: np.ndarray, n_speeds: int, bias: float) -> np.ndarray:
    """The lowest speed node at or above ``floor_ms`` at each position (n_nodes,), for :func:`solve`.

    A node above the top one (a floor above the braking envelope) is ``n_speeds``: no state is
    allowed there. Rounding up to a node makes the floor hold in the forward run, at most one node
    spacing above the bound asked for.
    """
    out = np.zeros(model.position_m.shape[0], dtype=np.int64)
    k_max = n_speeds - 1
    for i in np.flatnonzero(floor_ms > 0.0):
        top_u = model.envelope_ms[i] ** 2
        u = floor_ms[i] ** 2
        out[i] = n_speeds if u > top_u or top_u <= 0.0 else int(math.ceil(node_position(top_u, u, k_max, bias) - 1e-9))
    return out


# ---------------------------------------------------------------- part-power traction (efficiency maps)
# With a traction efficiency that depends on the force, pulling at part of the maximum force can be
# cheaper than full traction and coasting (docs/efficiency.md, "Part-power traction"). Where the train
# has such a map, the DP adds these shares of the maximum traction force (the simulator's fourth program
# column, ``scaled_step``) as further controls of every cell; the forward run refines the share of its
# best one between the neighbouring shares (:func:`best_part_power`). A case without a varying map
# never reaches these functions (chosen in Python: nothing more to compile on its first run).
PART_POWER_SHARES = np.linspace(0.1, 0.9, 9)
# golden-section steps of the forward run's refinement: the bracket (two share steps, 0.2) shrinks to 1e-5
PART_POWER_REFINE_STEPS = 24
_GOLDEN = 0.5 * (math.sqrt(5.0) - 1.0)


def part_power_shares(m) -> np.ndarray:
    """The traction shares the DP tries as part-power controls: :data:`PART_POWER_SHARES` where the kernel
    model has a varying traction efficiency map (:func:`varying_maps`), none otherwise."""
    return PART_POWER_SHARES.copy() if varying_maps(m)[0] else np.empty(0)


@njit(cache=True, no_cfunc_wrapper=True, _nrt=False)
def part_power_target(m, cell):
    """The target speed of a part-power row (m/s): the braking envelope at the cell's end, which the
    ``toward`` row lands on rather than overshoot (the envelope would stop it there anyway)."""
    return m.envelope_ms[cell + 1]


@njit(cache=True, no_cfunc_wrapper=True, _nrt=False)
def part_power_outcome(m, v0, cell, share):
    """The simulator's cell of a ``toward`` row at traction ``share`` (:func:`part_power_target`):
    ``(u1, force_n, w0_n)``, as :func:`cell_outcome` gives it for a row of full traction."""
    tr_u, tr_f, tr_w, _ = scaled_step(m, v0, cell, KIND_TRACTION, share)
    co_u, co_f, co_w, _ = full_step(m, v0, cell, KIND_COAST)
    # a toward row never brakes: the braking step is not read, the coast step stands in for it
    return cell_outcome(m, v0, cell, np.int64(MODE_TOWARD), part_power_target(m, cell), tr_u, tr_f, tr_w,
                        co_u, co_f, co_w, co_u, co_f, co_w)


@njit(cache=True, no_cfunc_wrapper=True, parallel=True)
def _fill_part_power(m, n_speeds, bias, first_cell, shares, pp_u1, pp_e, pp_dt):
    k_max = n_speeds - 1
    for p_type in prange(first_cell.shape[0]):
        t, i, top0, top1 = _kind_cell(m, first_cell, np.int64(p_type))
        for j in range(n_speeds):
            v0 = math.sqrt(node_u(top0, j, k_max, bias))
            for c in range(shares.shape[0]):
                u1, f, w0 = part_power_outcome(m, v0, i, shares[c])
                e, dt = cell_cost(m, v0, u1, f, w0, i, m.aux_power_w)
                pp_u1[t, j, c] = value_position(top1, u1, k_max, bias)
                pp_e[t, j, c] = e
                pp_dt[t, j, c] = dt


def part_power_transitions(m, n_speeds: int, bias: float, first_cell: np.ndarray, shares: np.ndarray) -> list:
    """The part-power controls' transitions (``[u1, e, dt]``, each (n_types, n_speeds, n_shares), single
    precision), for :func:`transitions` to append to its fixed controls."""
    out = [np.empty((first_cell.shape[0], n_speeds, shares.shape[0]), dtype=np.float32) for _ in range(3)]
    _fill_part_power(m, n_speeds, bias, first_cell, shares, *out)
    return out


@njit(cache=True, no_cfunc_wrapper=True, _nrt=False)
def part_power_cost(m, v0, cell, share, time_price_w, v_next, top_u, bias, sing_p, sing_val):
    """Cell cost plus interpolated cost-to-go of traction at ``share`` from ``v0`` (:func:`entry_cost`'s sum)."""
    u1, f, w0 = part_power_outcome(m, v0, cell, share)
    cost, _ = cell_cost(m, v0, u1, f, w0, cell, time_price_w)
    if cost < INF:
        cost += interp_aug(v_next, value_position(top_u, u1, v_next.shape[0] - 1, bias), sing_p, sing_val)
    return cost


@njit(cache=True, no_cfunc_wrapper=True, _nrt=False)
def best_part_power(m, cell, v0, time_price_w, v_next, bias, sing_p, sing_val, shares):
    """The best traction share from ``v0``: the best of ``shares``, refined by golden section between its
    neighbours (0 and 1 at the ends). Returns ``(total_cost, share)``.

    The refinement is the Pontryagin condition of part-power traction taken on the cell itself: the
    share minimising the cell's electrical energy and time plus the cost-to-go where it ends is the
    one where the marginal electrical energy of force, ``d(F / eta(v, F))/dF``, equals the value of
    the kinetic energy it buys, ``-dV/dE_kin`` (docs/efficiency.md).
    """
    top_u = m.envelope_ms[cell + 1] ** 2
    best = INF
    best_c = -1
    for c in range(shares.shape[0]):
        cost = part_power_cost(m, v0, cell, shares[c], time_price_w, v_next, top_u, bias, sing_p, sing_val)
        if cost < best:
            best = cost
            best_c = c
    if best_c < 0:
        return INF, 1.0
    best_share = shares[best_c]
    lo = shares[best_c - 1] if best_c > 0 else 0.0
    hi = shares[best_c + 1] if best_c < shares.shape[0] - 1 else 1.0
    a = hi - _GOLDEN * (hi - lo)
    b = lo + _GOLDEN * (hi - lo)
    fa = part_power_cost(m, v0, cell, a, time_price_w, v_next, top_u, bias, sing_p, sing_val)
    fb = part_power_cost(m, v0, cell, b, time_price_w, v_next, top_u, bias, sing_p, sing_val)
    for _ in range(PART_POWER_REFINE_STEPS):
        if fa <= fb:
            hi, b, fb = b, a, fa
            a = hi - _GOLDEN * (hi - lo)
            fa = part_power_cost(m, v0, cell, a, time_price_w, v_next, top_u, bias, sing_p, sing_val)
        else:
            lo, a, fa = a, b, fb
            b = lo + _GOLDEN * (hi - lo)
            fb = part_power_cost(m, v0, cell, b, time_price_w, v_next, top_u, bias, sing_p, sing_val)
    if fa < best and a < 1.0:
        best, best_share = fa, a
    if fb < best and b < 1.0:
        best, best_share = fb, b
    return best, best_share


@njit(cache=True, no_cfunc_wrapper=True)
def forward_rollout_part_power(m, time_price_w, value, max_targets, bias, tie_j, shares, modes, targets, speeds,
                               sing_v, sing_p, sing_val):
    """:func:`forward_rollout` with part-power traction among the controls (:func:`best_part_power`).

    ``targets`` is (n_cells, 2): each cell's target speed and traction share (1 but on a part-power
    cell), the simulator's third and fourth program columns. The tie rule keeps the previous control
    as :func:`forward_rollout` does, a part-power cell its share. Returns what :func:`forward_rollout` does.
    """
    n = m.position_m.shape[0]
    size = N_FIXED + sing_v.shape[1] + max_targets  # a control table (:func:`control_table`), rewritten every cell
    table = (np.empty(size, dtype=np.int64), np.empty(size), np.empty(size), np.empty(size), np.empty(size),
             np.empty(size))
    steps = np.empty(9)  # the cell's full steps (:func:`control_table`), not read here
    k_max = value.shape[1] - 1
    v = m.initial_speed_ms
    speeds[0] = v
    energy = time = tie_cost = 0.0
    previous, previous_share = MODE_TRACTION, 1.0  # the control of the cell before
    for i in range(n - 1):
        price = time_price_w[i]
        n_entries = control_table(m, i, v, sing_v[i + 1], sing_p[i + 1], k_max, max_targets, bias, table, steps)
        cost, p = table_minimum(table, n_entries, price, value[i + 1], sing_p[i + 1], sing_val[i + 1])
        if cost >= PENALTY_J:  # every control leads to a stop short of the platform
            return i, energy, time, tie_cost
        mode, target = table[0][p], table[1][p]
        share = 1.0
        pp_cost, pp_share = best_part_power(m, i, v, price, value[i + 1], bias, sing_p[i + 1], sing_val[i + 1],
                                            shares)
        if pp_cost < cost:
            cost, mode, target, share = pp_cost, MODE_TOWARD, part_power_target(m, i), pp_share
        if i > 0 and tie_j > 0.0 and (mode != previous or share != previous_share):
            top_u = m.envelope_ms[i + 1] ** 2
            c = p
            if previous_share < 1.0:  # keep pulling at the previous share
                c_keep = part_power_cost(m, v, i, previous_share, price, value[i + 1], top_u, bias, sing_p[i + 1],
                                         sing_val[i + 1])
                keep, keep_target = MODE_TOWARD, part_power_target(m, i)
            else:
                keep = MODE_HOLD_BRAKE if previous == MODE_TOWARD else previous
                keep_target = 0.0
                c_keep = INF
                if keep != mode or share < 1.0:
                    c = _fixed_entry(keep, v)
                    c_keep = entry_cost(table, c, price, value[i + 1], sing_p[i + 1], sing_val[i + 1])
            if c_keep < INF and c_keep <= cost + tie_j:
                tie_cost += c_keep - cost
                mode, target, share, p = keep, keep_target, previous_share, c
        if share < 1.0:
            u1, f, w0 = part_power_outcome(m, v, i, share)
            c_energy, dt = cell_cost(m, v, u1, f, w0, i, m.aux_power_w)
        else:  # the table's entry, as ``cell_cost`` prices it with the auxiliary power alone
            u1, c_energy, dt = table[5][p], table[3][p] + m.aux_power_w * table[4][p], table[4][p]
        energy += c_energy
        time += dt
        modes[i] = mode
        targets[i, 0] = target
        targets[i, 1] = share
        previous = mode
        previous_share = share
        v = math.sqrt(u1)
        speeds[i + 1] = v
    return n - 1, energy, time, tie_cost
