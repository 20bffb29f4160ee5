"""The tracking kernel: a train driven by a controller along a reference speed-distance curve.

The run has the three phases of Liu (2019) section 5.1.3:

1. start: maximum traction until the head reaches ``x_start_m``, where the reference leaves its
   first traction phase (the reference itself is maximum traction there);
2. middle: the controller acts at fixed control instants ``period_s`` apart (honoured to within
   one cell's travel time); its command, a fraction of the maximum traction (> 0) or braking
   (< 0) force at the current speed, is held until the next instant;
3. stop: from the first cell at or past ``x_stop_m`` (the start of the reference's final braking)
   where the train meets the braking envelope, it follows the envelope onto the platform.

Whatever the controller says, the train never rises above the braking envelope (the same safety
the simulator has), so it respects every limit and stops at the platform.

The integration scheme, the force functions and the energy accounting are the simulator's
(:mod:`pymoo_rail.sim.kernel`, efficiency maps included); the summary has the same ``OUT_*`` columns.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit, prange

from pymoo_rail.constants import KMH_PER_MS
from pymoo_rail.control.controllers import CTRL_HYSTERESIS, CTRL_PID
# Numba's disk cache checks only this file: a change to the run summary (N_OUT, OUT_*) or the
# running totals of sim/kernel.py must touch this file too, or a stale cache keeps the old layout
# (last: the two efficiency-map totals, N_TOTALS = 17).
from pymoo_rail.sim.kernel import (
    N_OUT,
    TOTAL_TIME,
    REGIME_BRAKE,
    REGIME_COAST,
    REGIME_CRUISE,
    REGIME_TRACTION,
    clamp_to_envelope,
    complete_cell,
    new_totals,
    close_cell,
    run_program,
    trace_arrays,
    write_summary,
)
from pymoo_rail.sim.physics import davis_force, max_braking, max_traction

_N_STATE = 4
# controller state slots
_S_MODE, _S_INTEGRAL, _S_PREV_E, _S_HAS_PREV = 0, 1, 2, 3
# What a run carries over to the next call that continues it (a closed loop changes the reference
# at decision instants): the controller state, then these slots
C_COMMAND, C_TO_NEXT, C_SINCE_LAST, C_INSTANT, C_RESUME, C_PHASE = 4, 5, 6, 7, 8, 9
# the speed filter's estimate: speed (m/s), acceleration (m/s^2), whether it has a first reading,
# the true speed at the last reading (what an accelerometer integrates from)
C_FILTER_V, C_FILTER_A, C_FILTER_ON, C_FILTER_LAST = 10, 11, 12, 13
N_CARRY = 14


@njit(cache=True)
def filter_speed(carry, v_meas, v_true, dt_s, params):
    """One step of the speed filter ``params = (alpha, beta, accelerometer)``; returns the filtered speed (m/s).

    Predict the speed at this reading: with ``accelerometer`` > 0, the estimate plus the speed
    change the train's accelerometer integrated since the last reading (taken as exact: ``v_true``
    now minus then); else ``v + a dt`` with the filter's own acceleration estimate (an alpha-beta
    filter). Then correct the speed by ``alpha`` and the acceleration by ``beta / dt`` times the
    residual. The first reading is taken as it is; ``(1, 0, 0)`` passes the measurement through.
    The estimate lives in ``carry`` (``C_FILTER_*``).
    """
    alpha, beta, accelerometer = params[0], params[1], params[2] > 0.0
    if carry[C_FILTER_ON] == 0.0 or dt_s <= 0.0:
        if carry[C_FILTER_ON] == 0.0:
            carry[C_FILTER_V] = v_meas
            carry[C_FILTER_A] = 0.0
            carry[C_FILTER_ON] = 1.0
            carry[C_FILTER_LAST] = v_true
        return carry[C_FILTER_V]
    if accelerometer:
        predicted = carry[C_FILTER_V] + (v_true - carry[C_FILTER_LAST])
    else:
        predicted = carry[C_FILTER_V] + carry[C_FILTER_A] * dt_s
    carry[C_FILTER_LAST] = v_true
    residual = v_meas - predicted
    carry[C_FILTER_V] = predicted + alpha * residual
    carry[C_FILTER_A] += beta * residual / dt_s
    return carry[C_FILTER_V]


# ---------------------------------------------------------------- controllers
@njit(cache=True)
def _hysteresis(params, state, e_kmh):
    """Seed 000 fig. 5-2: traction below v_ref - B, coast above v_ref - A, keep in between."""
    a, b, over, frac = params[0], params[1], params[2], params[3]
    mode = state[_S_MODE]
    if e_kmh > b:
        mode = 1.0
    elif e_kmh < a and mode > 0.0:
        mode = 0.0
    if e_kmh < -over:
        mode = -1.0
    elif mode < 0.0 and e_kmh >= 0.0:
        mode = 0.0
    state[_S_MODE] = mode
    if mode > 0.0:
        return 1.0
    if mode < 0.0:
        return -frac
    return 0.0


@njit(cache=True)
def _pid_output(kp, ki, kd, state, e_kmh, de_kmhs, dt_s):
    """One PID update with conditional integration (no wind-up while saturated)."""
    integral = state[_S_INTEGRAL] + e_kmh * dt_s
    u = kp * e_kmh + ki * integral + kd * de_kmhs
    if (u > 1.0 and e_kmh > 0.0) or (u < -1.0 and e_kmh < 0.0):
        integral = state[_S_INTEGRAL]  # saturated the same way: freeze the integral
        u = kp * e_kmh + ki * integral + kd * de_kmhs
    state[_S_INTEGRAL] = integral
    if u > 1.0:
        u = 1.0
    elif u < -1.0:
        u = -1.0
    return u


@njit(cache=True)
def _error_rate(state, e_kmh, dt_s):
    """de/dt between control instants (0 at the first instant)."""
    de = 0.0
    if state[_S_HAS_PREV] > 0.0 and dt_s > 0.0:
        de = (e_kmh - state[_S_PREV_E]) / dt_s
    state[_S_PREV_E] = e_kmh
    state[_S_HAS_PREV] = 1.0
    return de


@njit(cache=True)
def _memberships(z, mu):
    """Seven triangular terms centred on -3 ... 3 (unit half-width); z saturates at the ends."""
    if z < -3.0:
        z = -3.0
    elif z > 3.0:
        z = 3.0
    for k in range(7):
        w = 1.0 - abs(z - (k - 3.0))
        mu[k] = w if w > 0.0 else 0.0


@njit(cache=True)
def fuzzy_increments(params, e_kmh, ec_kmhs):
    """(dKp, dKi, dKd) of the fuzzy tuner for one (e, ec): product inference, centre of sets."""
    mu_e = np.empty(7)
    mu_ec = np.empty(7)
    _memberships(e_kmh * 3.0 / params[3], mu_e)
    _memberships(ec_kmhs * 3.0 / params[4], mu_ec)
    out = np.zeros(3)
    total = 0.0
    for i in range(7):
        if mu_e[i] == 0.0:
            continue
        for j in range(7):
            w = mu_e[i] * mu_ec[j]
            if w == 0.0:
                continue
            total += w
            for g in range(3):
                out[g] += w * params[8 + g * 49 + i * 7 + j]
    for g in range(3):
        out[g] = out[g] / total / 3.0 * params[5 + g]
    return out


@njit(cache=True)
def controller_command(code, params, state, e_kmh, dt_s):
    """The command in [-1, 1] of controller ``code`` at one control instant."""
    if code == CTRL_HYSTERESIS:
        return _hysteresis(params, state, e_kmh)
    de = _error_rate(state, e_kmh, dt_s)
    if code == CTRL_PID:
        return _pid_output(params[0], params[1], params[2], state, e_kmh, de, dt_s)
    d = fuzzy_increments(params, e_kmh, de)
    kp = max(params[0] + d[0], 0.0)
    ki = max(params[1] + d[1], 0.0)
    kd = max(params[2] + d[2], 0.0)
    return _pid_output(kp, ki, kd, state, e_kmh, de, dt_s)


@njit(cache=True)
def align_controller(code, params, state, u):
    """Set a running controller's memory so that at zero error it commands ``u`` (bumpless transfer).

    For a new reference in a closed loop: the hysteresis takes the mode of ``u`` (traction,
    coast, brake); a PID's integral takes the value whose output is ``u``, its error history is
    cleared.
    """
    if code == CTRL_HYSTERESIS:
        state[_S_MODE] = 1.0 if u > 0.0 else (-1.0 if u < 0.0 else 0.0)
    else:
        state[_S_HAS_PREV] = 0.0
        state[_S_INTEGRAL] = u / params[1] if params[1] > 0.0 else 0.0


@njit(cache=True)
def _start_controller(m, code, params, state, v, cell):
    """Controller state on entering the middle part (coming from maximum traction)."""
    state[:] = 0.0
    if code == CTRL_HYSTERESIS:
        state[_S_MODE] = 1.0
    elif params[1] > 0.0 and v > 0.0:
        # bumpless transfer: the integral starts at the command that holds the current speed
        hold = davis_force(m, v) + m.line_force_n[cell]
        if hold > 0.0:
            top = max_traction(m, v, cell)
            u = hold / top if top > 0.0 else 1.0
        else:
            top = max_braking(m, v, cell)
            u = hold / top if top > 0.0 else -1.0
        u = min(max(u, -1.0), 1.0)
        state[_S_INTEGRAL] = u / params[1]


# ---------------------------------------------------------------- dynamics
@njit(cache=True)
def _force(m, v, cell, u):
    if u > 0.0:
        return u * max_traction(m, v, cell)
    if u < 0.0:
        return u * max_braking(m, v, cell)
    return 0.0


@njit(cache=True)
def _command_step(m, v0, cell, u):
    """The simulator's two-stage cell step, for a force command u in [-1, 1].

    Returns (u1 = v1^2, control force N, W0 N). For u in {1, 0, -1} it is the simulator's step.
    """
    dx = m.dx_m
    wl = m.line_force_n[cell]
    f = _force(m, v0, cell, u)
    u_half = v0 * v0 + dx * (f - davis_force(m, v0) - wl) / m.effective_mass_kg
    v_half = math.sqrt(u_half) if u_half > 0.0 else 0.5 * v0
    f = _force(m, v_half, cell, u)
    w0 = davis_force(m, v_half)
    u1 = v0 * v0 + 2.0 * dx * (f - w0 - wl) / m.effective_mass_kg
    return u1, f, w0


@njit(cache=True)
def reference_phases(x, regime, count):
    """(x_start, x_stop) of a reference trace: end of its first traction phase, start of its
    final braking (the line end if it never brakes to a stop)."""
    x_start = x[count - 1]
    for i in range(count - 1):
        if regime[i] != REGIME_TRACTION:
            x_start = x[i]
            break
    j = count - 1
    if regime[j] == REGIME_BRAKE:
        while j > 0 and regime[j - 1] == REGIME_BRAKE:
            j -= 1
    return x_start, x[j]


@njit(cache=True)
def track_run(m, v_ref, x_start_m, x_stop_m, code, params, period_s, out, record,
              tr_x, tr_v, tr_t, tr_a, tr_f, tr_r, tr_u, noise_ms, lag_s, filter_ab, carry, t_end_s, x_end_m):
    """One tracked run; writes the ``OUT_*`` summary into ``out`` and, if ``record``, the trace.

    The run starts at the model's first node at its ``initial_speed_ms`` (0 for a run from the
    platform; a closed loop continues a run on the model of the line ahead,
    :func:`pymoo_rail.control.policy.model_from`) and ends at the platform, or at the end of the
    first cell ending at or after ``t_end_s`` (run time) or ``x_end_m``. ``carry`` (``N_CARRY``)
    receives the controller's state, the command in force, the control clock, the noise index and
    the phase there; with ``carry[C_RESUME] > 0`` the run continues from them (no bumpless
    restart), with a new reference if need be: a run cut in pieces is the run in one piece.

    ``v_ref`` is the reference speed at each grid node. ``tr_u`` receives the command applied
    per cell (1 / -1 in the start / stop phases where the reference's own regime applies).
    Disturbances of the controlled part: ``noise_ms`` is added to the measured speed at the
    successive control instants (cycled; empty: none); the applied command follows the
    controller's through a first-order lag of time constant ``lag_s`` (0: at once), the delayed
    response of the traction and brake equipment. The controller sees the measured speed through
    the filter ``filter_ab = (alpha, beta, accelerometer)`` (:func:`filter_speed`; ``(1, 0, 0)``: none).
    Returns the number of trace nodes written.
    """
    n = m.position_m.shape[0]
    totals = new_totals()
    state = carry[:_N_STATE]
    resume = carry[C_RESUME] > 0.0
    phase = 0  # 0 start, 1 middle, 2 stop
    u_cmd = 1.0
    t_next = 0.0
    t_last = 0.0
    k_instant = 0
    u_act = 1.0
    if resume:
        phase = int(carry[C_PHASE])
        u_cmd = carry[C_COMMAND]
        u_act = u_cmd
        t_next = carry[C_TO_NEXT]
        t_last = -carry[C_SINCE_LAST]
        k_instant = int(carry[C_INSTANT])
    else:
        state[:] = 0.0
        carry[C_FILTER_ON] = 0.0
    v = m.initial_speed_ms
    t = 0.0
    reached = n > 0  # a run-time True, not the literal: one compiled close_cell for every caller
    stop_pos = m.position_m[n - 1]
    count = 1
    n_noise = noise_ms.shape[0]
    t_cell = 0.0
    if record:
        tr_x[0] = m.position_m[0]
        tr_v[0] = v
        tr_t[0] = 0.0
    for i in range(n - 1):
        x0 = m.position_m[i]
        if phase == 0 and x0 >= x_start_m - 1e-9:
            phase = 1
            _start_controller(m, code, params, state, v, i)
            t_next = t
            t_last = t - period_s
        # 1. the command
        if phase == 1 and t >= t_next - 1e-12:
            v_meas = v
            if n_noise > 0:
                v_meas = v + noise_ms[k_instant % n_noise]
                k_instant += 1
            v_meas = filter_speed(carry, v_meas, v, t - t_last, filter_ab)
            u_cmd = controller_command(code, params, state, (v_ref[i] - v_meas) * KMH_PER_MS, t - t_last)
            t_last = t
            while t_next <= t + 1e-12:
                t_next += period_s
        if phase == 0:
            u_cmd = 1.0
        elif phase == 2:
            u_cmd = 0.0  # on the envelope: the clamp below brakes along it
        if phase == 1 and lag_s > 0.0:
            u_act += (u_cmd - u_act) * (1.0 - math.exp(-(t - t_cell) / lag_s))
        else:
            u_act = u_cmd
        t_cell = t
        u1, f, w0 = _command_step(m, v, i, u_act)
        if u_act >= 1.0:
            regime = REGIME_TRACTION
        elif u_act <= -1.0:
            regime = REGIME_BRAKE
        elif u_act == 0.0:
            regime = REGIME_COAST
        else:
            regime = REGIME_CRUISE

        # 2. never above the braking envelope (limits ahead, the platform): the simulator's rule
        u1, f, w0, regime, clamped = clamp_to_envelope(m, v, i, u1, f, w0, regime)
        if clamped and phase == 1 and x0 >= x_stop_m - 1e-9:
            phase = 2
        if phase == 2:
            u_cmd = -1.0 if f < 0.0 else 0.0
            u_act = u_cmd

        # 3. the rest of the cell exactly as the simulator does it
        v, stopped, x1, a_cell, totals = complete_cell(m, totals, i, v, u1, f, w0, regime)
        t = totals[TOTAL_TIME]
        count, reached, stop_pos = close_cell(record, tr_x, tr_v, tr_t, tr_a, tr_f, tr_r, i, x1, v, t, a_cell, f,
                                              regime, stopped, reached, stop_pos)
        if record:
            tr_u[i] = u_act
        if stopped or t >= t_end_s or x1 >= x_end_m:
            break
    carry[C_COMMAND] = u_act
    carry[C_TO_NEXT] = t_next - t
    carry[C_SINCE_LAST] = t - t_last
    carry[C_INSTANT] = k_instant
    carry[C_PHASE] = phase
    write_summary(m, totals, out, v, reached, stop_pos, count, record, tr_a, tr_f, tr_r)
    if record:
        tr_u[count - 1] = 0.0
    return count


@njit(cache=True)
def track_trace(m, v_ref, x_start_m, x_stop_m, code, params, period_s, noise_ms, lag_s, filter_ab, carry, t_end_s,
                x_end_m):
    """One tracked run with its trace: (summary, x, v, t, a, force, regime, command), trimmed (see :func:`track_run`)."""
    n = m.position_m.shape[0]
    out = np.empty(N_OUT)
    x, v, t, a, f, r = trace_arrays(n)
    u = np.empty(n)
    record = n >= 0  # run-time booleans, not literals: one compiled track_run / run_program each
    count = track_run(m, v_ref, x_start_m, x_stop_m, code, params, period_s, out, record, x, v, t, a, f, r, u,
                      noise_ms, lag_s, filter_ab, carry, t_end_s, x_end_m)
    return out, x[:count], v[:count], t[:count], a[:count], f[:count], r[:count], u[:count]


@njit(cache=True, parallel=True)
def track_programs(m, programs, code, params, period_s):
    """Summaries (N, N_OUT) of tracked runs of N driving programs (N, rows, 3), in parallel.

    Each program is simulated first (the ideal run, on the same grid) and its trace is the
    reference the controller tracks.
    """
    n_runs = programs.shape[0]
    n = m.position_m.shape[0]
    out = np.empty((n_runs, N_OUT))
    empty = np.empty(0)
    empty_r = np.empty(0, dtype=np.int8)
    # run-time booleans, not literals: with literals Numba compiles run_program and track_run once
    # per value (see pymoo_rail.sim.kernel.simulate_batch)
    record, no_record = n >= 0, n < 0
    for j in prange(n_runs):
        ref_out = np.empty(N_OUT)
        x, v, t, a, f, r = trace_arrays(n)
        v[:] = 0.0
        count = run_program(m, programs[j], ref_out, record, x, v, t, a, f, r)
        v[count:] = 0.0
        x_start, x_stop = reference_phases(x, r, count)
        track_run(m, v, x_start, x_stop, code, params, period_s, out[j], no_record,
                  empty, empty, empty, empty, empty, empty_r, empty, empty, 0.0, np.array([1.0, 0.0, 0.0]),
                  np.zeros(N_CARRY), math.inf, math.inf)
    return out
