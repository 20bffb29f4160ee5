"""The simulation kernel: one run of a driving program over the grid, and a parallel batch.

Integration is over distance on the kinetic-energy variable u = v^2 with a two-stage
(midpoint) scheme per cell; time per cell is ``2 dx / (v0 + v1)``, exact for constant
acceleration. Forces are recorded at the speeds the scheme used, so the work balance
(traction - braking - resistance = change of kinetic energy) holds to rounding.

A driving program is an array of rows ``(end_m, mode, target_ms)``: row k applies until the
cell midpoint passes ``end_m``. A program may carry a fourth column, the traction share
``gamma`` in (0, 1] a ``MODE_TOWARD`` row accelerates with (the partial traction of Chen et al.
(2017) table 1; never less than the force that holds the speed); without it every row uses full
traction. Modes:

- ``MODE_TOWARD``: maximum traction below the target, coasting above it, holding it once reached
  by partial traction (the speed-code connection strategy of Liu (2019) fig. 4-5). It never brakes:
  where coasting accelerates (a steep descent) the train runs above the target until a limit's
  braking envelope stops it;
- ``MODE_TRACTION``: maximum traction (speed limits still hold);
- ``MODE_HOLD``: ``MODE_TOWARD`` with the speed the train had on entering the row as its target:
  partial traction holds it, and on a steep descent the train coasts faster (no braking);
- ``MODE_COAST``: no force;
- ``MODE_BRAKE``: maximum service braking until standstill;
- ``MODE_HOLD_BRAKE``: hold the entry speed by partial traction or, where coasting would
  accelerate, by partial braking (electric first, so it regenerates); maximum braking where even
  that cannot hold it. The cruise control of an ATO on a descent.
- ``MODE_DECEL``: brake at the constant deceleration ``target`` (m/s^2, resistance and gradient
  included) until standstill, the service-brake command of a stopping programme (seed 002's
  braking phase); maximum braking where that is not enough, coasting where the line alone
  decelerates more. Where it stops is the programme's consequence (short of or past the platform).
- ``MODE_STOP``: brake at the constant deceleration that stops the train exactly at the platform
  from where it is, ``v^2 / (2 s)`` with ``s`` the distance to go (Chen et al. (2017) type 1,
  ``v_m^2 / (2 dS)``): recomputed every cell, it stays constant along the run.

Whatever the program says, the train never rises above the braking envelope: it brakes onto every
lower limit ahead and onto the platform at the latest moment the braking curve allows.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit, prange

from pymoo_rail.constants import J_PER_KWH
from pymoo_rail.sim.jit import inlined
from pymoo_rail.sim.physics import (
    davis_force,
    electric_braking_capped,
    landing_force,
    max_braking,
    max_traction,
    regen_map_shortfall,
    traction_map_excess,
)

MODE_TOWARD, MODE_TRACTION, MODE_HOLD, MODE_COAST, MODE_BRAKE, MODE_HOLD_BRAKE = 0, 1, 2, 3, 4, 5
MODE_DECEL, MODE_STOP = 6, 7
MODE_NAMES = ("toward", "traction", "hold", "coast", "brake", "hold_brake", "decel", "stop")
REGIME_TRACTION, REGIME_HOLD, REGIME_COAST, REGIME_BRAKE = 0, 1, 2, 3
REGIME_CRUISE = REGIME_HOLD  # the older name of the same regime
# "hold": the speed is held (partial traction or braking); one word in every output and doc
REGIME_NAMES = ("traction", "hold", "coast", "brake")

# Columns of a run summary.
OUT_TRACTION_KWH = 0
OUT_REGEN_KWH = 1
OUT_AUX_KWH = 2
OUT_NET_KWH = 3
OUT_RUNNING_TIME_S = 4
OUT_STOP_POSITION_M = 5
OUT_STOP_ERROR_M = 6
OUT_JERK_MS2 = 7
OUT_REGIME_CHANGES = 8
OUT_LIMIT_EXCESS_MS = 9
OUT_TRACTION_WORK_J = 10
OUT_BRAKE_WORK_J = 11
OUT_DAVIS_WORK_J = 12
OUT_LINE_WORK_J = 13
OUT_GRADE_WORK_J = 14
OUT_FINAL_SPEED_MS = 15
OUT_REACHED = 16
OUT_ELECTRIC_BRAKE_WORK_J = 17
OUT_MAX_ABS_ACCEL_MS2 = 18
OUT_NEUTRAL_TRACTION_J = 19
OUT_PEAK_TRACTION_KW = 20
N_OUT = 21
OUT_NAMES = ("traction_kwh", "regen_kwh", "aux_kwh", "net_kwh", "running_time_s", "stop_position_m",
             "stop_error_m", "jerk_ms2", "regime_changes", "limit_excess_ms", "traction_work_j",
             "brake_work_j", "davis_work_j", "line_work_j", "grade_work_j", "final_speed_ms", "reached",
             "electric_brake_work_j", "max_abs_accel_ms2", "neutral_traction_j", "peak_traction_kw")

# the three full-force steps of ``full_step`` (public for the DP). NumPy integers, not Python ones:
# Numba types a Python int constant as a literal and compiled full_step and scaled_step once per
# kind (about 1 s of the first run's compile); inlined, LLVM folds the constant kind all the same
KIND_TRACTION, KIND_COAST, KIND_BRAKE = np.int64(0), np.int64(1), np.int64(2)


@inlined
def full_step(m, v0, cell, kind):
    """Two-stage step over one cell at maximum traction, coasting or maximum braking.

    Returns (u1, control force N (+ traction, - braking), W0 N, mean speed m/s).
    """
    return scaled_step(m, v0, cell, kind, 1.0)


@inlined
def _traction(m, v, cell, share):
    """``share`` of the maximum traction, but at least the force that holds the speed (Chen et al.
    (2017): gamma above the holding ratio); exactly the maximum when ``share`` is 1."""
    fmax = max_traction(m, v, cell)
    if share >= 1.0:
        return fmax
    f = share * fmax
    hold = davis_force(m, v) + m.line_force_n[cell]
    if f < hold:
        f = hold if hold < fmax else fmax
    return f


@inlined
def scaled_step(m, v0, cell, kind, share):
    """:func:`full_step` with the traction step at ``share`` of the maximum force (see ``_traction``)."""
    wl = m.line_force_n[cell]
    if kind == KIND_TRACTION:
        f = _traction(m, v0, cell, share)
    elif kind == KIND_BRAKE:
        f = -max_braking(m, v0, cell)
    else:
        f = 0.0
    gain = m.dx_per_mass_m_kg  # dx / M: a multiplication instead of a division on the critical path
    u_half = v0 * v0 + (f - davis_force(m, v0) - wl) * gain
    v_half = math.sqrt(u_half) if u_half > 0.0 else 0.5 * v0
    if kind == KIND_TRACTION:
        f = _traction(m, v_half, cell, share)
    elif kind == KIND_BRAKE:
        f = -max_braking(m, v_half, cell)
    w0 = davis_force(m, v_half)
    u1 = v0 * v0 + 2.0 * ((f - w0 - wl) * gain)
    return u1, f, w0, v_half


@inlined
def _decel_step(m, v0, cell, decel_ms2):
    """One cell braking at the constant deceleration ``decel_ms2`` (MODE_DECEL).

    Returns (u1, control force N, W0 N, regime). u1 < 0 means the train stops inside the cell,
    exactly ``v0^2 / (2 decel)`` after its start (``complete_cell`` measures it).
    """
    u1 = v0 * v0 - 2.0 * m.dx_m * decel_ms2
    v1 = math.sqrt(u1) if u1 > 0.0 else 0.0
    v_mid = 0.5 * (v0 + v1)
    w0 = davis_force(m, v_mid)
    f = -m.effective_mass_kg * decel_ms2 + w0 + m.line_force_n[cell]
    if f > 0.0:  # resistance and gradient alone decelerate more: coast
        u1, f, w0, _ = full_step(m, v0, cell, KIND_COAST)
        return u1, f, w0, REGIME_COAST
    if -f > max_braking(m, v_mid, cell):  # more than the brakes give: brake fully
        u1, f, w0, _ = full_step(m, v0, cell, KIND_BRAKE)
    return u1, f, w0, REGIME_BRAKE


@inlined
def share_above(v0, v1, v_cut):
    """Share of a cell run above the speed v_cut (v^2 is linear in distance within a cell)."""
    lo, hi = (v0, v1) if v0 < v1 else (v1, v0)
    if lo >= v_cut:
        return 1.0
    if hi <= v_cut:
        return 0.0
    return (hi * hi - v_cut * v_cut) / (hi * hi - lo * lo)


# the landing force lives with the braking envelope it must agree with (``physics.landing_force``)


# Slots of the running totals of a run (see ``new_totals``): public for the kernels that drive the
# train themselves (the DP, the tracking controllers).
TOTAL_TIME, TOTAL_TRACTION_J, TOTAL_BRAKE_J, TOTAL_ELECTRIC_BRAKE_J = 0, 1, 2, 3
TOTAL_DAVIS_J, TOTAL_LINE_J, TOTAL_GRADE_J, TOTAL_NEUTRAL_TRACTION_J = 4, 5, 6, 7
TOTAL_ACCEL_VARIATION, TOTAL_PREV_ACCEL, TOTAL_MAX_ABS_ACCEL = 8, 9, 10
TOTAL_PREV_REGIME, TOTAL_REGIME_CHANGES, TOTAL_LIMIT_EXCESS = 11, 12, 13
TOTAL_PEAK_TRACTION_W = 14  # the highest traction power of a cell, F (v0 + v1) / 2, x eta_ref / eta(v, F)
# what an efficiency map adds to traction energy and takes from regeneration (J; 0 without a map)
TOTAL_TRACTION_EXCESS_J, TOTAL_REGEN_SHORTFALL_J = 15, 16
N_TOTALS = 17


@inlined
def new_totals():
    """Running totals of a run (time, works, comfort and limit figures) as a tuple.

    A tuple, not an array: the kernels rebind it every cell and Numba keeps it in registers.
    """
    return (0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, -1.0, 0.0, -1e300, 0.0, 0.0, 0.0)


@inlined
def clamp_to_envelope(m, v, cell, u1, f, w0, regime):
    """Keep a step under the braking envelope and name its regime by the force applied.

    Whatever a driver or controller asked for, the train lands on the envelope at the end of the
    cell if it would rise above it. Returns (u1, force, W0, regime, clamped).
    """
    cap = m.envelope_ms[cell + 1]
    clamped = u1 > cap * cap
    if clamped:
        fl, w0l, ok = landing_force(m, v, cap, cell)
        if ok:
            u1, f, w0 = cap * cap, fl, w0l
        else:  # cannot brake hard enough by a rounding margin: brake fully, record the excess
            u1, f, w0, _ = full_step(m, v, cell, KIND_BRAKE)
        if cap < m.limit_ms[cell + 1] - 1e-9:
            # on a braking curve, not on a limit: the landing finishes the regime that reached it
            # (partial traction at the top of a traction-then-braking run is still traction)
            if f < 0.0:
                regime = REGIME_BRAKE
            elif f > 0.0 and regime != REGIME_TRACTION:
                regime = REGIME_CRUISE
        elif f != 0.0:
            regime = REGIME_CRUISE
    if f == 0.0:
        regime = REGIME_COAST
    elif f > 0.0 and regime == REGIME_COAST:
        regime = REGIME_CRUISE
    return u1, f, w0, regime, clamped


@inlined
def complete_cell(m, totals, cell, v, u1, f, w0, regime):
    """Finish one cell: standstill inside it, time, energy accounting, comfort.

    Returns (v1, stopped, position reached, acceleration, updated totals). No arrays beyond the
    model go in: array arguments of a per-cell function cost reference counting every cell.
    """
    n = m.position_m.shape[0]
    dx = m.dx_m
    # only a landing on the platform node ends at exactly zero speed without stopping short
    stopped = u1 < 0.0 or (u1 == 0.0 and cell < n - 2)
    a_cell = (u1 - v * v) / (2.0 * dx)  # before clamping: it sets the stopping distance
    d = dx
    if stopped:
        d = -v * v / (2.0 * a_cell) if a_cell < 0.0 else 0.0
        if d > dx:
            d = dx
    if u1 < 0.0:
        u1 = 0.0
    v1 = math.sqrt(u1)
    (time_s, w_trac, w_brake, w_elec, w_davis, w_line, w_grade, w_neutral,
     jerk, prev_acc, max_acc, prev_regime, changes, excess, peak_w, trac_excess, regen_short) = totals
    time_s += 2.0 * d / (v + v1) if v + v1 > 0.0 else 0.0
    brake_n = -f if f < 0.0 else 0.0
    if f > 0.0:
        w_trac += f * d
        if m.neutral[cell] != 0:
            w_neutral += f * d
        extra = traction_map_excess(m, 0.5 * (v + v1), f, f * d)
        trac_excess += extra
        # the cell's mean power, its work over its duration: f d / (2 d / (v + v1)); with a map, the
        # electrical power over eta_ref (write_summary divides by it)
        power_w = f * 0.5 * (v + v1)
        if extra != 0.0:
            power_w *= (f * d + extra * m.traction_efficiency) / (f * d)
        if power_w > peak_w:
            peak_w = power_w
    w_brake += brake_n * d
    if brake_n > 0.0:
        share = share_above(v, v1, m.regen_min_speed_ms)
        f_electric = electric_braking_capped(m, 0.5 * (v + v1), brake_n)
        w_elec += f_electric * d * share
        regen_short += regen_map_shortfall(m, 0.5 * (v + v1), f_electric, f_electric * d * share)
    w_davis += w0 * d
    w_line += m.line_force_n[cell] * d
    w_grade += m.grade_force_n[cell] * d
    jerk += abs(a_cell - prev_acc)
    if abs(a_cell) > max_acc:
        max_acc = abs(a_cell)
    if prev_regime >= 0.0 and regime != prev_regime:
        changes += 1.0
    if v1 - m.limit_ms[cell + 1] > excess:
        excess = v1 - m.limit_ms[cell + 1]
    x1 = m.position_m[cell] + d
    totals = (time_s, w_trac, w_brake, w_elec, w_davis, w_line, w_grade, w_neutral,
              jerk, a_cell, max_acc, float(regime), changes, excess, peak_w, trac_excess, regen_short)
    return v1, stopped, x1, a_cell, totals


@njit(cache=True, no_cfunc_wrapper=True)
def trace_cell_energies(m, x, v, f):
    """Per-cell energies of a recorded run (J): traction drawn and regeneration delivered.

    ``x``, ``v`` are the trace's node positions and speeds, ``f`` its per-cell forces. The same
    accounting as :func:`complete_cell` (traction ``F dx / eta_traction``; regeneration
    ``eta_regen`` times the electric share of braking above the cut-off speed), so the sums equal
    the run's ``traction_kwh`` and ``regen_kwh``; used to put runs on a common clock.
    """
    n_cells = x.shape[0] - 1
    trac = np.zeros(n_cells)
    regen = np.zeros(n_cells)
    for i in range(n_cells):
        d = x[i + 1] - x[i]
        v_mid = 0.5 * (v[i] + v[i + 1])
        if f[i] > 0.0:
            trac[i] = f[i] * d / m.traction_efficiency + traction_map_excess(m, v_mid, f[i], f[i] * d)
        elif f[i] < 0.0:
            share = share_above(v[i], v[i + 1], m.regen_min_speed_ms)
            f_electric = electric_braking_capped(m, v_mid, -f[i])
            regen[i] = (m.regen_efficiency * f_electric * d * share
                        - regen_map_shortfall(m, v_mid, f_electric, f_electric * d * share))
    return trac, regen


@inlined
def close_cell(record, tr_x, tr_v, tr_t, tr_a, tr_f, tr_r, cell, x1, v1, t, a_cell, f, regime, stopped, reached,
               stop_pos):
    """The run loop's bookkeeping after a cell: its trace node (if ``record``), the node count and
    where the train came to rest if it ``stopped`` in the cell.

    Returns ``(count, reached, stop_pos)``; the caller leaves its loop when ``stopped``.
    """
    if record:
        tr_x[cell + 1] = x1
        tr_v[cell + 1] = v1
        tr_t[cell + 1] = t
        tr_a[cell] = a_cell
        tr_f[cell] = f
        tr_r[cell] = regime
    if stopped:
        return cell + 2, False, x1
    return cell + 2, reached, stop_pos


@inlined
def write_summary(m, totals, out, v, reached, stop_pos, count, record, tr_a, tr_f, tr_r):
    """Close a run (back to rest) and write its ``OUT_*`` summary."""
    length = m.position_m[m.position_m.shape[0] - 1]
    jerk = totals[TOTAL_ACCEL_VARIATION] + abs(totals[TOTAL_PREV_ACCEL])
    if record:
        tr_a[count - 1] = 0.0
        tr_f[count - 1] = 0.0
        tr_r[count - 1] = REGIME_BRAKE if reached else REGIME_COAST
    t = totals[TOTAL_TIME]
    # + 0.0 / - 0.0 without a map: the constant-efficiency figures bit for bit
    out[OUT_TRACTION_KWH] = (totals[TOTAL_TRACTION_J] / m.traction_efficiency
                             + totals[TOTAL_TRACTION_EXCESS_J]) / J_PER_KWH
    out[OUT_REGEN_KWH] = (m.regen_efficiency * totals[TOTAL_ELECTRIC_BRAKE_J]
                          - totals[TOTAL_REGEN_SHORTFALL_J]) / J_PER_KWH
    out[OUT_AUX_KWH] = m.aux_power_w * t / J_PER_KWH
    out[OUT_NET_KWH] = out[OUT_TRACTION_KWH] + out[OUT_AUX_KWH] - out[OUT_REGEN_KWH]
    out[OUT_RUNNING_TIME_S] = t
    out[OUT_STOP_POSITION_M] = stop_pos
    out[OUT_STOP_ERROR_M] = abs(length - stop_pos)
    out[OUT_JERK_MS2] = jerk
    out[OUT_REGIME_CHANGES] = totals[TOTAL_REGIME_CHANGES]
    out[OUT_LIMIT_EXCESS_MS] = totals[TOTAL_LIMIT_EXCESS] if totals[TOTAL_LIMIT_EXCESS] > 0.0 else 0.0
    out[OUT_TRACTION_WORK_J] = totals[TOTAL_TRACTION_J]
    out[OUT_BRAKE_WORK_J] = totals[TOTAL_BRAKE_J]
    out[OUT_DAVIS_WORK_J] = totals[TOTAL_DAVIS_J]
    out[OUT_LINE_WORK_J] = totals[TOTAL_LINE_J]
    out[OUT_GRADE_WORK_J] = totals[TOTAL_GRADE_J]
    out[OUT_FINAL_SPEED_MS] = v
    out[OUT_REACHED] = 1.0 if reached else 0.0
    out[OUT_ELECTRIC_BRAKE_WORK_J] = totals[TOTAL_ELECTRIC_BRAKE_J]
    out[OUT_MAX_ABS_ACCEL_MS2] = totals[TOTAL_MAX_ABS_ACCEL]
    out[OUT_NEUTRAL_TRACTION_J] = totals[TOTAL_NEUTRAL_TRACTION_J]
    out[OUT_PEAK_TRACTION_KW] = totals[TOTAL_PEAK_TRACTION_W] / m.traction_efficiency / 1000.0


@inlined
def drive_cell(m, program, totals, i, v, row, hold_speed):
    """One cell of a driving program: the program's control, the envelope, the accounting.

    ``row`` is the program row in force and ``hold_speed`` the speed a hold row keeps (-1 before
    it starts). Returns (v1, row, hold_speed, stopped, position reached, acceleration, force,
    regime, totals). Inlined: the run state stays in registers.
    """
    n_rows = program.shape[0]
    x_mid = m.position_m[i] + 0.5 * m.dx_m
    while row < n_rows - 1 and x_mid > program[row, 0]:
        row += 1
        hold_speed = -1.0
    mode = int(program[row, 1])
    target = program[row, 2]
    if mode == MODE_STOP:  # the constant deceleration onto the platform from here
        to_go = m.position_m[m.position_m.shape[0] - 1] - m.position_m[i]
        mode = MODE_DECEL
        target = v * v / (2.0 * to_go) if to_go > 0.0 else 0.0
        if to_go <= 1.5 * m.dx_m:
            # the last cell: aim a hair past the platform, the envelope lands the train on it
            # (a rounding shortfall would count as stopping short)
            target *= 1.0 - 1e-9

    # what the program asks for
    brake_to_hold = mode == MODE_HOLD_BRAKE
    if mode == MODE_HOLD or brake_to_hold:
        if hold_speed < 0.0:
            hold_speed = v
        if hold_speed <= 0.0:
            mode = MODE_TRACTION  # nothing to hold from standstill
        else:
            mode = MODE_TOWARD
            target = hold_speed
    if mode == MODE_TOWARD:
        landed = False
        if v < target:
            share = program[row, 3] if program.shape[1] > 3 else 1.0
            u1, f, w0, vm = scaled_step(m, v, i, KIND_TRACTION, share)
            regime = REGIME_TRACTION
            landed = u1 > target * target
        else:
            u1, f, w0, vm = full_step(m, v, i, KIND_COAST)
            regime = REGIME_COAST
            landed = u1 < target * target or brake_to_hold  # the second: brake down onto it
        if landed:
            fl, w0l, ok = landing_force(m, v, target, i)
            if ok:
                u1, f, w0 = target * target, fl, w0l
                regime = REGIME_CRUISE
            elif brake_to_hold and u1 >= target * target:
                u1, f, w0, vm = full_step(m, v, i, KIND_BRAKE)  # the descent is too steep to hold
                regime = REGIME_BRAKE
    elif mode == MODE_TRACTION:
        u1, f, w0, vm = full_step(m, v, i, KIND_TRACTION)
        regime = REGIME_TRACTION
    elif mode == MODE_BRAKE:
        u1, f, w0, vm = full_step(m, v, i, KIND_BRAKE)
        regime = REGIME_BRAKE
    elif mode == MODE_DECEL:
        u1, f, w0, regime = _decel_step(m, v, i, target)
    else:
        u1, f, w0, vm = full_step(m, v, i, KIND_COAST)
        regime = REGIME_COAST

    u1, f, w0, regime, _ = clamp_to_envelope(m, v, i, u1, f, w0, regime)
    v1, stopped, x1, a_cell, totals = complete_cell(m, totals, i, v, u1, f, w0, regime)
    return v1, row, hold_speed, stopped, x1, a_cell, f, regime, totals


# No reference counting inside: the run allocates nothing, and NRT incref/decref pairs on the
# model's arrays in every inlined helper call were half the cost of a cell (benchmarks/throughput.py --jit).
@njit(cache=True, no_cfunc_wrapper=True, _nrt=False)
def run_program(m, program, out, record, tr_x, tr_v, tr_t, tr_a, tr_f, tr_r):
    """Simulate one run; write the summary into ``out`` and, if ``record``, the trace arrays.

    Returns the number of trace nodes written (nodes 0..count-1 are valid).
    """
    n = m.position_m.shape[0]
    totals = new_totals()
    v = m.initial_speed_ms
    row = n - n  # a run-time 0, not the literal: one compiled drive_cell for both loops
    hold_speed = -1.0
    reached = n > 0  # a run-time True, not the literal: one compiled close_cell for every caller
    stop_pos = m.position_m[n - 1]
    count = 1
    if record:
        tr_x[0] = 0.0
        tr_v[0] = v
        tr_t[0] = 0.0
    for i in range(n - 1):
        v, row, hold_speed, stopped, x1, a_cell, f, regime, totals = drive_cell(
            m, program, totals, i, v, row, hold_speed)
        count, reached, stop_pos = close_cell(record, tr_x, tr_v, tr_t, tr_a, tr_f, tr_r, i, x1, v,
                                              totals[TOTAL_TIME], a_cell, f, regime, stopped, reached, stop_pos)
        if stopped:
            break
    write_summary(m, totals, out, v, reached, stop_pos, count, record, tr_a, tr_f, tr_r)
    return count


@inlined
def advance_run(m, program, totals, i, v, row, hold_speed, moving, stop_pos):
    """One cell of a run without traces, or nothing once the run has stopped (``moving`` False)."""
    if moving:
        v, row, hold_speed, stopped, x1, _, _, _, totals = drive_cell(m, program, totals, i, v, row, hold_speed)
        if stopped:
            return v, row, hold_speed, False, x1, totals
    return v, row, hold_speed, moving, stop_pos, totals


# Two runs advanced cell by cell in one loop. A single run is a chain of dependent operations
# (two square roots and two force-curve evaluations per cell, each waiting for the last), which
# leaves most of the core idle; the cells of two independent runs interleave in the out-of-order
# core and nearly halve the time per cell (docs/performance.md). Each run does exactly the
# arithmetic of ``run_program``, so results are bitwise the same. The loop over the pairs is in the
# same kernel, not a caller of a pair kernel: each compiled caller makes LLVM optimise and emit the
# callee's run loops again (about 1 s of the first run's compile).
@njit(cache=True, no_cfunc_wrapper=True, _nrt=False)
def run_pairs(m, programs, out, empty, empty_r, spare):
    """Summaries of runs ``programs`` (N, rows, 3) into ``out`` (N, N_OUT), two side by side, in this
    thread (no traces; ``empty``, ``empty_r``: the empty float and int8 trace arrays
    ``write_summary`` takes). An odd last run goes beside a copy of itself, whose summary goes
    into ``spare`` (N_OUT,)."""
    n_runs = programs.shape[0]
    n = m.position_m.shape[0]
    record = n < 0  # a run-time False: one compiled write_summary for every caller
    no_count = n - n  # no trace nodes; a run-time 0: one compiled write_summary for every caller
    for pair in range((n_runs + 1) // 2):
        a = 2 * pair
        b = a + 1 if a + 1 < n_runs else a
        program_a = programs[a]
        program_b = programs[b]
        out_a = out[a]
        out_b = out[b] if b > a else spare
        totals_a = new_totals()
        totals_b = new_totals()
        v_a = m.initial_speed_ms
        v_b = m.initial_speed_ms
        row_a = n - n  # run-time zeros, not literals (see run_program)
        row_b = n - n
        hold_a = -1.0
        hold_b = -1.0
        moving_a = n > 0  # run-time Trues, not literals: one compiled advance_run
        moving_b = n > 0
        stop_a = m.position_m[n - 1]
        stop_b = m.position_m[n - 1]
        for i in range(n - 1):
            v_a, row_a, hold_a, moving_a, stop_a, totals_a = advance_run(
                m, program_a, totals_a, i, v_a, row_a, hold_a, moving_a, stop_a)
            v_b, row_b, hold_b, moving_b, stop_b, totals_b = advance_run(
                m, program_b, totals_b, i, v_b, row_b, hold_b, moving_b, stop_b)
            if not (moving_a or moving_b):
                break
        write_summary(m, totals_a, out_a, v_a, moving_a, stop_a, no_count, record, empty, empty, empty_r)
        write_summary(m, totals_b, out_b, v_b, moving_b, stop_b, no_count, record, empty, empty, empty_r)


@njit(cache=True, no_cfunc_wrapper=True, parallel=True)
def simulate_batch(m, programs):
    """Summaries of many runs, one per program, in parallel. ``programs`` is (N, rows, 3).

    Runs go to the threads in pairs (:func:`run_pairs`).
    """
    n_runs = programs.shape[0]
    out = np.empty((n_runs, N_OUT))
    n_pairs = (n_runs + 1) // 2
    spare = np.empty((n_pairs, N_OUT))
    empty = np.empty(0)
    empty_r = np.empty(0, dtype=np.int8)
    for j in prange(n_pairs):
        run_pairs(m, programs[2 * j: 2 * j + 2], out[2 * j: 2 * j + 2], empty, empty_r, spare[j])
    return out


def simulate_batch_serial(m, programs):
    """:func:`simulate_batch` in the calling thread: no thread start-up cost for small batches.

    Plain Python around :func:`run_pairs`: a compiled wrapper would be one more Numba
    function (and one more copy of the run loops for LLVM) in the first run's compile.
    """
    out = np.empty((programs.shape[0], N_OUT))
    run_pairs(m, programs, out, np.empty(0), np.empty(0, dtype=np.int8), np.empty(N_OUT))
    return out


@njit(cache=True, no_cfunc_wrapper=True)
def trace_arrays(n):
    """Uninitialised trace buffers for ``n`` nodes: (x, v, t, a, force, regime); regime is int8.

    Plain ``njit`` (not ``inlined``): it returns new arrays, which needs Numba's runtime.
    """
    x = np.empty(n)
    v = np.empty(n)
    t = np.empty(n)
    a = np.empty(n)
    f = np.empty(n)
    r = np.empty(n, dtype=np.int8)
    return x, v, t, a, f, r


def simulate_trace(m, program):
    """One run with its full trace: (summary, x, v, t, a, force, regime), trimmed to the run.

    Plain Python around :func:`run_program` (see :func:`simulate_batch_serial`); called from
    Python, ``record`` is typed ``bool``, so the batch kernels' ``run_program`` serves it too.
    """
    out = np.empty(N_OUT)
    x, v, t, a, f, r = trace_arrays(m.position_m.shape[0])
    count = run_program(m, program, out, True, x, v, t, a, f, r)
    return out, x[:count], v[:count], t[:count], a[:count], f[:count], r[:count]
