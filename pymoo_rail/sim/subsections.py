"""The subsection driver of Chen et al. (2017): a run built from per-subsection operating sequences.

Seed 001 (section 1) cuts the run from the station to the braking point P into subsections of one
gradient and one limit, and gives each subsection an operating sequence (table 1):

- type 2 (cruising needs traction, ``W0 + G >= 0``): traction at ``gamma`` times the maximum force
  up to a turning speed ``v_a``, traction hold at ``v_a``, then coasting down to the exit speed;
- type 3 (steep descent, ``W0 + G < 0``): traction at ``gamma`` up to ``v_a``, coasting (which
  accelerates) up to the exit speed, then brake hold (regenerative) at the exit speed;
- type 1 (from P to the platform): braking at the constant deceleration ``v_m^2 / (2 dS)``.

With the entry speed, the exit speed ``v_k`` and ``gamma_k`` fixed, the subsection time is a
decreasing function of ``v_a`` between ``dt_min`` and ``dt_max`` (table 2); the seed allots the
time left after the braking phase to the subsections by shares ``q_k`` (eq. 1) and then finds
the ``v_a`` that takes exactly that time. This module does that on the simulator's grid:

- the speed over a type-2 subsection is ``min(traction curve, v_a, backward coasting curve)``;
- over a type-3 subsection it is the traction curve capped at ``v_a``, then the forward
  coasting curve from there, capped at ``v_k``;
- the curves are integrated with the kernel's two-stage scheme and the kernel's forces
  (:mod:`pymoo_rail.sim.physics`); the force in every cell is then the one that produces the
  speed change (coasting cells get exactly zero), so the work balance holds to rounding.

Everything is SI; one run per call, :func:`drive_batch` runs a population in parallel. Energies
per cell are left for :mod:`pymoo_rail.sim.cooperation` to put on a common clock. The kernel's
programs cannot express this driver: they have no partial traction (``gamma < 1``) and brake at
the maximum service rate rather than at a chosen constant deceleration.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit, prange

from pymoo_rail.constants import J_PER_KWH
from pymoo_rail.sim.kernel import REGIME_BRAKE, REGIME_COAST, REGIME_CRUISE, REGIME_TRACTION, trace_cell_energies
from pymoo_rail.sim.physics import davis_force, max_braking, max_traction

# Columns of the per-subsection record (sub_out[j, :]).
SUB_ACTIVE = 0       # 1 when the subsection lies before the braking point
SUB_START_M = 1
SUB_END_M = 2
SUB_TYPE = 3         # 2 or 3 (table 1)
SUB_GAMMA = 4
SUB_V_ENTRY_MS = 5
SUB_V_TURN_MS = 6    # v_a: end of the traction phase
SUB_V_EXIT_MS = 7    # v_k after repair
SUB_TIME_S = 8
SUB_TMIN_S = 9
SUB_TMAX_S = 10
N_SUB = 11
SUB_NAMES = ("active", "start_m", "end_m", "type", "gamma", "v_entry_ms", "v_turn_ms", "v_exit_ms",
             "time_s", "time_min_s", "time_max_s")

# Columns of the run summary (summary[:]).
RUN_TRACTION_KWH = 0        # traction energy drawn, F v / eta_traction
RUN_REGEN_KWH = 1           # regenerated energy another train could use: eta_regen * electric braking work
RUN_RUNNING_TIME_S = 2
RUN_BRAKE_START_M = 3       # P
RUN_BRAKE_SPEED_MS = 4      # v_m
RUN_BRAKE_DECEL_MS2 = 5
RUN_LIMIT_EXCESS_MS = 6     # max(v - limit) over the nodes
RUN_ACCEL_CHANGE_MS2 = 7    # largest |change of mean acceleration| across a gradient change between subsections
RUN_FORCE_EXCESS_MS2 = 8    # largest force beyond the train's traction or braking limit, per effective mass
RUN_DECODE_EXCESS_MS = 9    # exit speeds the repair could not make feasible (m/s, summed)
RUN_TIME_SHORTFALL_S = 10   # time the fastest profile still needs beyond the plan (> 0: cannot be on time)
RUN_N_ACTIVE = 11
RUN_TRACTION_WORK_J = 12
RUN_BRAKE_WORK_J = 13
RUN_DAVIS_WORK_J = 14
RUN_LINE_WORK_J = 15
N_RUN = 16
RUN_NAMES = ("traction_kwh", "regen_kwh", "running_time_s", "brake_start_m", "brake_speed_ms", "brake_decel_ms2",
             "limit_excess_ms", "accel_change_ms2", "force_excess_ms2", "decode_excess_ms", "time_shortfall_s",
             "n_active", "traction_work_j", "brake_work_j", "davis_work_j", "line_work_j")

_LAB_TRACTION, _LAB_HOLD, _LAB_COAST, _LAB_BRAKE, _LAB_MIXED = 0, 1, 2, 3, 4
_STALL_TIME_S = 1e3  # time charged to a cell the train cannot pass (keeps the sums finite)


@njit(cache=True)
def _traction_force(m, v, cell, gamma):
    """gamma times the maximum traction, but at least the force that holds the speed (gamma > gamma_k0)."""
    fmax = max_traction(m, v, cell)
    f = gamma * fmax
    hold = davis_force(m, v) + m.line_force_n[cell]
    if f < hold:
        f = hold if hold < fmax else fmax
    return f


@njit(cache=True)
def _traction_curve(m, s, e, v_start, gamma, cap, out):
    """Speeds at nodes s..e under traction gamma from v_start, held at ``cap`` once reached."""
    dx = m.dx_m
    mass = m.effective_mass_kg
    out[s] = v_start
    for i in range(s, e):
        v0 = out[i]
        if v0 >= cap:
            out[i + 1] = cap
            continue
        wl = m.line_force_n[i]
        f = _traction_force(m, v0, i, gamma)
        u = v0 * v0 + dx * (f - davis_force(m, v0) - wl) / mass
        vh = math.sqrt(u) if u > 0.0 else 0.5 * v0
        f = _traction_force(m, vh, i, gamma)
        u = v0 * v0 + 2.0 * dx * (f - davis_force(m, vh) - wl) / mass
        v1 = math.sqrt(u) if u > 0.0 else 0.0
        out[i + 1] = v1 if v1 < cap else cap


@njit(cache=True)
def _coast_step(m, v0, cell):
    """Speed after coasting over one cell from v0 (0 when the train stalls)."""
    dx = m.dx_m
    mass = m.effective_mass_kg
    wl = m.line_force_n[cell]
    u = v0 * v0 - dx * (davis_force(m, v0) + wl) / mass
    vh = math.sqrt(u) if u > 0.0 else 0.5 * v0
    u = v0 * v0 - 2.0 * dx * (davis_force(m, vh) + wl) / mass
    return math.sqrt(u) if u > 0.0 else 0.0


@njit(cache=True)
def _coast_back_curve(m, s, e, v_end, out):
    """Speeds at nodes s..e of the coasting run that arrives at node e with v_end."""
    dx = m.dx_m
    mass = m.effective_mass_kg
    out[e] = v_end
    for i in range(e - 1, s - 1, -1):
        v1 = out[i + 1]
        wl = m.line_force_n[i]
        u = v1 * v1 + dx * (davis_force(m, v1) + wl) / mass
        vh = math.sqrt(u) if u > 0.0 else 0.5 * v1
        u = v1 * v1 + 2.0 * dx * (davis_force(m, vh) + wl) / mass
        out[i] = math.sqrt(u) if u > 0.0 else 0.0


@njit(cache=True)
def _cell_time(dx, v0, v1):
    return 2.0 * dx / (v0 + v1) if v0 + v1 > 0.0 else _STALL_TIME_S


@njit(cache=True)
def _cell_label(a, b):
    return a if a == b else _LAB_MIXED


@njit(cache=True)
def _compose_type2(vt, vcb, s, e, v_entry, v_exit, v_turn, dx, v_out, clab):
    """Type 2: min(traction curve, v_turn, backward coasting curve); returns the time.

    Writes node speeds s..e and cell labels s..e-1 (which curve holds the speed at both ends).
    """
    v_out[s] = v_entry
    t = 0.0
    prev = _LAB_MIXED
    for i in range(s + 1, e + 1):
        v = vt[i]
        lab = _LAB_TRACTION
        if v_turn < v:
            v = v_turn
            lab = _LAB_HOLD
        if vcb[i] < v:
            v = vcb[i]
            lab = _LAB_COAST
        if i == e:
            v = v_exit
        if i == s + 1:
            prev = lab  # the entry node lies on the curve that carries the first cell
        clab[i - 1] = _cell_label(prev, lab)
        prev = lab
        v_out[i] = v
        t += _cell_time(dx, v_out[i - 1], v)
    return t


@njit(cache=True)
def _compose_type3(m, vt, vcb, s, e, v_entry, v_exit, v_turn, v_out, clab):
    """Type 3: traction curve up to v_turn, then coasting (accelerating) capped at v_exit; the time."""
    dx = m.dx_m
    v_out[s] = v_entry
    coasting = v_turn <= v_entry
    prev = _LAB_COAST if coasting else _LAB_TRACTION
    t = 0.0
    for i in range(s + 1, e + 1):
        if not coasting:
            v = vt[i]
            lab = _LAB_TRACTION
            if v >= v_turn:
                v = v_turn
                coasting = True
                lab = _LAB_COAST
        else:
            v = _coast_step(m, v_out[i - 1], i - 1)
            if v < vcb[i]:
                v = vcb[i]  # integration drift only: the run must still reach v_exit by the end
            lab = _LAB_COAST
        if v >= v_exit:
            v = v_exit
            if prev == _LAB_HOLD or i < e:
                lab = _LAB_HOLD
        if i == e:
            v = v_exit
        clab[i - 1] = _cell_label(prev, lab)
        prev = lab
        v_out[i] = v
        t += _cell_time(dx, v_out[i - 1], v)
    return t


@njit(cache=True)
def _subsection_time(m, kind, vt, vcb, s, e, v_entry, v_exit, v_turn, v_out, lab):
    if kind == 3:
        return _compose_type3(m, vt, vcb, s, e, v_entry, v_exit, v_turn, v_out, lab)
    return _compose_type2(vt, vcb, s, e, v_entry, v_exit, v_turn, m.dx_m, v_out, lab)


@njit(cache=True)
def _allot_times(tmin, tmax, q, available, times):
    """Share ``available`` s beyond the minima in proportion to q, capped at the maxima (eq. 1).

    What a capped subsection cannot take goes to the others (water filling); returns the time that
    could not be placed anywhere (> 0: the run ends early).
    """
    n = tmin.shape[0]
    free = np.ones(n, dtype=np.bool_)
    for k in range(n):
        times[k] = tmin[k]
        if tmax[k] <= tmin[k]:
            free[k] = False
    left = available
    for _ in range(n + 1):
        if left <= 1e-12:
            break
        total_q = 0.0
        n_free = 0
        for k in range(n):
            if free[k]:
                total_q += q[k]
                n_free += 1
        if n_free == 0:
            break
        capped = False
        spent = 0.0
        for k in range(n):
            if not free[k]:
                continue
            share = left * (q[k] / total_q if total_q > 0.0 else 1.0 / n_free)
            room = tmax[k] - times[k]
            if share >= room:
                times[k] = tmax[k]
                free[k] = False
                spent += room
                capped = True
        if capped:
            left -= spent
            continue
        for k in range(n):
            if free[k]:
                times[k] += left * (q[k] / total_q if total_q > 0.0 else 1.0 / n_free)
        left = 0.0
    return left if left > 0.0 else 0.0


@njit(cache=True)
def _braking_point(m, sub_start, sub_end, brake_dist_m):
    """The braking point P on a node, the braking length, and the ends of the subsections before P."""
    n = m.position_m.shape[0]
    last = n - 1
    brake_nodes = int(round(brake_dist_m / m.dx_m))
    if brake_nodes < 1:
        brake_nodes = 1
    if brake_nodes > last - 1:
        brake_nodes = last - 1
    p_node = last - brake_nodes
    n_active = 0
    for j in range(sub_start.shape[0]):
        if sub_start[j] < p_node:
            n_active = j + 1
    ends = np.empty(n_active, dtype=np.int64)
    for j in range(n_active):
        ends[j] = sub_end[j] if sub_end[j] < p_node else p_node
    return p_node, brake_nodes * m.dx_m, ends


@njit(cache=True)
def _exit_speeds(m, sub_start, ends, sub_kind, sub_cap, brake_cap, gamma, v_exit, relative, v_floor_ms, vt_all,
                 vcb_all, v_scratch, lab_scratch, v_in_out, v_k_out, tmin, tmax, va_lo, va_hi):
    """Step 1: exit speeds moved into what each operating sequence can reach, and the time ranges.

    Returns the exit speeds the repair could not place (m/s, summed). The curves of subsection j
    are kept in ``vt_all[j:j + n]`` and ``vcb_all[j:j + n]``.
    """
    n = m.position_m.shape[0]
    n_active = ends.shape[0]
    decode_excess = 0.0
    v_in = 0.0
    for j in range(n_active):
        s, e = sub_start[j], ends[j]
        kind = sub_kind[j]
        g = min(max(gamma[j], 0.0), 1.0)
        cap = sub_cap[j]
        next_cap = sub_cap[j + 1] if j + 1 < n_active else brake_cap
        if next_cap > cap:
            next_cap = cap
        vt = vt_all[j:j + n]
        vcb = vcb_all[j:j + n]
        _traction_curve(m, s, e, v_in, g, cap, vt)
        if kind == 3:
            lo = v_in if v_in > v_floor_ms else v_floor_ms
        else:
            v = v_in
            for i in range(s, e):
                v = _coast_step(m, v, i)
            lo = v if v > v_floor_ms else v_floor_ms
        hi = vt[e] if vt[e] < next_cap else next_cap
        vk = lo + v_exit[j] * (hi - lo) if relative else v_exit[j]
        if vk < lo:
            vk = lo
        if vk > hi:
            vk = hi
        if lo > hi + 1e-9:
            decode_excess += lo - hi
        _coast_back_curve(m, s, e, vk, vcb)
        if kind == 3:
            lo_turn = v_in
            if vcb[s] > v_in:  # coasting from the entry would not reach v_k: traction first, up to the crossing
                lo_turn = vk
                for i in range(s, e + 1):
                    if vt[i] >= vcb[i]:
                        lo_turn = vt[i]
                        break
            hi_turn = vk
            if lo_turn > hi_turn:
                lo_turn = hi_turn
        else:
            lo_turn = v_in if v_in > vk else vk
            hi_turn = lo_turn
            for i in range(s, e + 1):
                c = vt[i] if vt[i] < vcb[i] else vcb[i]
                if c > hi_turn:
                    hi_turn = c
        va_lo[j] = lo_turn
        va_hi[j] = hi_turn
        tmin[j] = _subsection_time(m, kind, vt, vcb, s, e, v_in, vk, hi_turn, v_scratch, lab_scratch)
        tmax[j] = _subsection_time(m, kind, vt, vcb, s, e, v_in, vk, lo_turn, v_scratch, lab_scratch)
        if tmax[j] < tmin[j]:
            tmax[j] = tmin[j]
        v_in_out[j] = v_in
        v_k_out[j] = vk
        v_in = vk
    return decode_excess


@njit(cache=True)
def time_window(m, sub_start, sub_end, sub_kind, sub_cap, brake_dist_m, gamma, v_exit, service_decel_ms2, v_floor_ms,
                relative):
    """(shortest, longest) running time eq. 1 can give these genes: eq. 10 holds when the plan is inside."""
    n = m.position_m.shape[0]
    n_sub = sub_start.shape[0]
    p_node, brake_len, ends = _braking_point(m, sub_start, sub_end, brake_dist_m)
    n_active = ends.shape[0]
    vt_all = np.empty(n + n_sub)
    vcb_all = np.empty(n + n_sub)
    v_scratch = np.empty(n)
    lab = np.empty(n - 1, dtype=np.int8)
    v_in = np.empty(n_active)
    v_k = np.empty(n_active)
    tmin = np.empty(n_active)
    tmax = np.empty(n_active)
    va_lo = np.empty(n_active)
    va_hi = np.empty(n_active)
    brake_cap = math.sqrt(2.0 * service_decel_ms2 * brake_len)
    _exit_speeds(m, sub_start, ends, sub_kind, sub_cap, brake_cap, gamma, v_exit, relative, v_floor_ms, vt_all,
                 vcb_all, v_scratch, lab, v_in, v_k, tmin, tmax, va_lo, va_hi)
    v_m = v_k[n_active - 1] if n_active > 0 else 0.0
    if v_m <= 0.0:
        v_m = v_floor_ms
    brake_time = 2.0 * brake_len / v_m
    return tmin.sum() + brake_time, tmax.sum() + brake_time


@njit(cache=True)
def repair_one(m, sub_start, sub_end, sub_kind, sub_cap, brake_dist_m, gamma, v_rel, planned_time_s, service_decel_ms2,
               v_floor_ms, gamma_out, v_out, iterations):
    """The paper's repair (section 3.2, step 1) for relative speed genes: move the exit speeds until
    the planned time lies in the window of eq. 10.

    Too slow: every exit speed and traction coefficient moves the same fraction lam toward 1 (the
    fastest sequence); too fast: every exit speed moves the fraction lam toward 0 (coasting, or
    holding the entry speed on descents). lam is found by bisection and the first one that puts
    the plan inside the window is kept; genes already on time are returned unchanged. When no lam
    does (the extreme still misses, or the window is narrower than the bisection's step), the genes
    of the last step past the window's edge are kept and the constraints judge them. Returns lam
    (negative: slowed down; nan: not inside).
    """
    n_sub = gamma.shape[0]
    for j in range(n_sub):
        gamma_out[j] = gamma[j]
        v_out[j] = v_rel[j]
    lo_t, hi_t = time_window(m, sub_start, sub_end, sub_kind, sub_cap, brake_dist_m, gamma, v_rel, service_decel_ms2,
                             v_floor_ms, True)
    if lo_t <= planned_time_s <= hi_t:
        return 0.0
    faster = lo_t > planned_time_s
    g_try = np.empty(n_sub)
    v_try = np.empty(n_sub)
    lam_short = 0.0  # still on the starting side of the window
    lam_past = 1.0   # on the other side (or, at first, the extreme)
    for it in range(iterations + 1):
        lam = 1.0 if it == 0 else 0.5 * (lam_short + lam_past)
        for j in range(n_sub):
            gj = min(max(gamma[j], 0.0), 1.0)
            vj = min(max(v_rel[j], 0.0), 1.0)
            if faster:
                g_try[j] = gj + lam * (1.0 - gj)
                v_try[j] = vj + lam * (1.0 - vj)
            else:
                g_try[j] = gamma[j]
                v_try[j] = vj * (1.0 - lam)
        lo_t, hi_t = time_window(m, sub_start, sub_end, sub_kind, sub_cap, brake_dist_m, g_try, v_try,
                                 service_decel_ms2, v_floor_ms, True)
        if lo_t <= planned_time_s <= hi_t:
            for j in range(n_sub):
                gamma_out[j] = g_try[j]
                v_out[j] = v_try[j]
            return lam if faster else -lam
        short = lo_t > planned_time_s if faster else hi_t < planned_time_s
        if it == 0 and short:
            return math.nan  # even the extreme cannot make it: the genes stay, the constraints judge them
        if short:
            lam_short = lam
        else:
            lam_past = lam
            for j in range(n_sub):
                gamma_out[j] = g_try[j]
                v_out[j] = v_try[j]
    return math.nan


@njit(cache=True, parallel=True)
def repair_batch(m, sub_start, sub_end, sub_kind, sub_cap, brake_dist_m, gamma, v_rel, planned_time_s,
                 service_decel_ms2, v_floor_ms, iterations):
    """:func:`repair_one` for a population; returns repaired (gamma, v_rel) and lam per run."""
    n_runs = brake_dist_m.shape[0]
    g_out = np.empty_like(gamma)
    v_out = np.empty_like(v_rel)
    lam = np.empty(n_runs)
    for r in prange(n_runs):
        lam[r] = repair_one(m, sub_start, sub_end, sub_kind, sub_cap, brake_dist_m[r], gamma[r], v_rel[r],
                            planned_time_s, service_decel_ms2, v_floor_ms, g_out[r], v_out[r], iterations)
    return g_out, v_out, lam


@njit(cache=True)
def drive_one(m, sub_start, sub_end, sub_kind, sub_cap, sub_grade_change, brake_dist_m, gamma, v_exit, q,
              planned_time_s, service_decel_ms2, v_floor_ms, relative, comfort_window_m, v_out, t_out, f_out, e_trac,
              e_regen, regime, sub_out, summary):
    """One run of the subsection driver.

    Parameters
    ----------
    m : KernelModel
    sub_start, sub_end : (J,) int arrays
        Node indices of the subsections of the whole run (gradient and limit partition).
    sub_kind : (J,) int array
        2 or 3 (table 1).
    sub_cap : (J,) float array
        Highest speed allowed over each subsection (m/s).
    sub_grade_change : (J,) bool array
        True when the gradient changes where subsection j starts (eq. 8 applies there).
    brake_dist_m : float
        Length of the braking phase before the platform, dS_l.
    gamma, v_exit, q : (J,) float arrays
        Traction coefficient, exit speed (m/s) and time share of each subsection; entries of
        subsections beyond the braking point are ignored.
    planned_time_s, service_decel_ms2, v_floor_ms : float
        Planned running time, the deceleration the braking phase may not exceed (b), and the lowest
        exit speed of a subsection.
    relative : bool
        False: ``v_exit`` are speeds (m/s), moved into the reachable range [lo, hi] when outside it.
        True: ``v_exit`` are positions in that range, 0 -> lo, 1 -> hi.
    comfort_window_m : float
        Distance over which the acceleration on each side of a gradient change is averaged (eq. 8).
    v_out, t_out : (n_nodes,) speed (m/s) and time (s) at every node, written.
    f_out, e_trac, e_regen, regime : (n_cells,) force (N, + traction), traction energy drawn (J),
        regenerated energy usable by another train (J) and regime code per cell, written.
    sub_out : (J, N_SUB), summary : (N_RUN,) written.
    """
    n = m.position_m.shape[0]
    last = n - 1
    dx = m.dx_m
    mass = m.effective_mass_kg
    n_sub = sub_start.shape[0]
    # the traction and backward coasting curves of every subsection, kept for step 3: subsection j
    # sees nodes i at i + j, so neighbours do not overwrite each other's shared end node
    vt_all = np.empty(n + n_sub)
    vcb_all = np.empty(n + n_sub)
    lab = np.full(n - 1, _LAB_MIXED, dtype=np.int8)  # per cell

    p_node, brake_len, ends = _braking_point(m, sub_start, sub_end, brake_dist_m)
    n_active = ends.shape[0]
    brake_cap = math.sqrt(2.0 * service_decel_ms2 * brake_len)
    for j in range(n_sub):
        for c in range(N_SUB):
            sub_out[j, c] = 0.0
        sub_out[j, SUB_START_M] = m.position_m[sub_start[j]]
        sub_out[j, SUB_END_M] = m.position_m[sub_end[j]]
        sub_out[j, SUB_TYPE] = sub_kind[j]
        sub_out[j, SUB_GAMMA] = gamma[j]

    # 1. exit speeds (repaired into what the operating sequence can reach) and the time ranges
    tmin = np.empty(n_active)
    tmax = np.empty(n_active)
    va_lo = np.empty(n_active)
    va_hi = np.empty(n_active)
    v_entry = np.empty(n_active)
    v_k = np.empty(n_active)
    decode_excess = _exit_speeds(m, sub_start, ends, sub_kind, sub_cap, brake_cap, gamma, v_exit, relative, v_floor_ms,
                                 vt_all, vcb_all, v_out, lab, v_entry, v_k, tmin, tmax, va_lo, va_hi)
    for j in range(n_active):
        sub_out[j, SUB_ACTIVE] = 1.0
        sub_out[j, SUB_END_M] = m.position_m[ends[j]]
        sub_out[j, SUB_V_ENTRY_MS] = v_entry[j]
        sub_out[j, SUB_V_EXIT_MS] = v_k[j]
        sub_out[j, SUB_TMIN_S] = tmin[j]
        sub_out[j, SUB_TMAX_S] = tmax[j]
    v_in = v_k[n_active - 1] if n_active > 0 else 0.0
    v_m = v_in
    if v_m <= 0.0:
        v_m = v_floor_ms
        decode_excess += v_floor_ms
    brake_time = 2.0 * brake_len / v_m

    # 2. the running time left after the braking phase, shared out by q (eq. 1)
    sum_min = 0.0
    for j in range(n_active):
        sum_min += tmin[j]
    available = planned_time_s - brake_time - sum_min
    shortfall = -available if available < 0.0 else 0.0
    times = np.empty(n_active)
    qa = np.empty(n_active)
    for j in range(n_active):
        qa[j] = q[j] if q[j] > 0.0 else 0.0
    _allot_times(tmin, tmax, qa, available if available > 0.0 else 0.0, times)

    # 3. the turning speed v_a that takes each subsection's time (the time falls as v_a rises)
    for j in range(n_active):
        s, e = sub_start[j], ends[j]
        kind = sub_kind[j]
        vin = sub_out[j, SUB_V_ENTRY_MS]
        vk = sub_out[j, SUB_V_EXIT_MS]
        vt = vt_all[j:j + n]
        vcb = vcb_all[j:j + n]
        lo, hi = va_lo[j], va_hi[j]
        target = times[j]
        if target >= tmax[j]:
            turn = lo
        elif target <= tmin[j]:
            turn = hi
        else:
            # regula falsi with the Illinois modification on T(v_a) - target (T falls as v_a rises)
            f_lo = tmax[j] - target
            f_hi = tmin[j] - target
            turn = hi
            side = 0
            for _ in range(60):
                turn = hi - f_hi * (hi - lo) / (f_hi - f_lo) if f_hi != f_lo else 0.5 * (lo + hi)
                f_mid = _subsection_time(m, kind, vt, vcb, s, e, vin, vk, turn, v_out, lab) - target
                if abs(f_mid) < 1e-6 or hi - lo < 1e-10:
                    break
                if f_mid > 0.0:
                    lo, f_lo = turn, f_mid
                    if side == -1:
                        f_hi *= 0.5
                    side = -1
                else:
                    hi, f_hi = turn, f_mid
                    if side == 1:
                        f_lo *= 0.5
                    side = 1
        t_sub = _subsection_time(m, kind, vt, vcb, s, e, vin, vk, turn, v_out, lab)
        sub_out[j, SUB_V_TURN_MS] = turn
        sub_out[j, SUB_TIME_S] = t_sub

    # 4. the braking phase at constant deceleration v_m^2 / (2 dS) (eq. 3), onto the platform
    decel = v_m * v_m / (2.0 * brake_len)
    x_p = m.position_m[p_node]
    for i in range(p_node + 1, n):
        u = v_m * v_m - 2.0 * decel * (m.position_m[i] - x_p)
        v_out[i] = math.sqrt(u) if u > 0.0 else 0.0
        lab[i - 1] = _LAB_BRAKE
    v_out[last] = 0.0

    # 5. forces, times and energies cell by cell; limits, force limits, comfort
    t = 0.0
    t_out[0] = 0.0
    w_trac = 0.0
    w_brake = 0.0
    w_davis = 0.0
    w_line = 0.0
    e_tr_sum = 0.0
    e_rg_sum = 0.0
    limit_excess = 0.0
    force_excess = 0.0
    for i in range(n - 1):
        v0 = v_out[i]
        v1 = v_out[i + 1]
        vm = 0.5 * (v0 + v1)
        wl = m.line_force_n[i]
        w0 = davis_force(m, vm)
        if lab[i] == _LAB_COAST:
            f = 0.0  # a coasting cell: its speeds come from the coasting integration
        else:
            f = mass * (v1 * v1 - v0 * v0) / (2.0 * dx) + w0 + wl
        dt = _cell_time(dx, v0, v1)
        t += dt
        t_out[i + 1] = t
        f_out[i] = f
        if f > 0.0:
            w_trac += f * dx
            over = (f - max_traction(m, vm, i)) / mass
        else:
            brake_n = -f
            w_brake += brake_n * dx
            over = (brake_n - max_braking(m, vm, i)) / mass
        if over > force_excess:
            force_excess = over
        w_davis += w0 * dx
        w_line += wl * dx
        if lab[i] == _LAB_BRAKE:
            regime[i] = REGIME_BRAKE
        elif f == 0.0:
            regime[i] = REGIME_COAST
        elif lab[i] == _LAB_TRACTION:
            regime[i] = REGIME_TRACTION
        elif lab[i] == _LAB_HOLD:
            regime[i] = REGIME_CRUISE
        else:
            regime[i] = REGIME_TRACTION if (f > 0.0 and v1 > v0 + 1e-9) else REGIME_CRUISE
        ex = v1 - m.limit_ms[i + 1]
        if ex > limit_excess:
            limit_excess = ex

    # the energies of every cell by the kernel's own accounting
    cell_trac, cell_regen = trace_cell_energies(m, m.position_m, v_out, f_out)
    for i in range(n - 1):
        e_trac[i] = cell_trac[i]
        e_regen[i] = cell_regen[i]
        e_tr_sum += cell_trac[i]
        e_rg_sum += cell_regen[i]

    # eq. 8: change of acceleration where the gradient changes between subsections, each side's
    # acceleration taken as the mean over comfort_window_m (one cell alone would depend on the grid)
    accel_change = 0.0
    w = int(round(comfort_window_m / dx))
    if w < 1:
        w = 1
    for j in range(1, n_active):
        if not sub_grade_change[j]:
            continue
        b = sub_start[j]
        w1 = min(w, b - sub_start[j - 1])
        w2 = min(w, ends[j] - b)
        if w1 < 1 or w2 < 1:
            continue
        a_before = (v_out[b] ** 2 - v_out[b - w1] ** 2) / (2.0 * w1 * dx)
        a_after = (v_out[b + w2] ** 2 - v_out[b] ** 2) / (2.0 * w2 * dx)
        change = abs(a_after - a_before)
        if change > accel_change:
            accel_change = change

    summary[RUN_TRACTION_KWH] = e_tr_sum / J_PER_KWH
    summary[RUN_REGEN_KWH] = e_rg_sum / J_PER_KWH
    summary[RUN_RUNNING_TIME_S] = t
    summary[RUN_BRAKE_START_M] = x_p
    summary[RUN_BRAKE_SPEED_MS] = v_m
    summary[RUN_BRAKE_DECEL_MS2] = decel
    summary[RUN_LIMIT_EXCESS_MS] = limit_excess
    summary[RUN_ACCEL_CHANGE_MS2] = accel_change
    summary[RUN_FORCE_EXCESS_MS2] = force_excess
    summary[RUN_DECODE_EXCESS_MS] = decode_excess
    summary[RUN_TIME_SHORTFALL_S] = shortfall
    summary[RUN_N_ACTIVE] = n_active
    summary[RUN_TRACTION_WORK_J] = w_trac
    summary[RUN_BRAKE_WORK_J] = w_brake
    summary[RUN_DAVIS_WORK_J] = w_davis
    summary[RUN_LINE_WORK_J] = w_line


@njit(cache=True, parallel=True)
def drive_batch(m, sub_start, sub_end, sub_kind, sub_cap, sub_grade_change, brake_dist_m, gamma, v_exit, q,
                planned_time_s, service_decel_ms2, v_floor_ms, relative, comfort_window_m):
    """:func:`drive_one` for a population (rows of ``brake_dist_m``, ``gamma``, ``v_exit``, ``q``).

    Returns (speed (N, n), time (N, n), force (N, n-1), traction J (N, n-1), regen J (N, n-1),
    regime (N, n-1), subsections (N, J, N_SUB), summaries (N, N_RUN)).
    """
    n_runs = brake_dist_m.shape[0]
    n = m.position_m.shape[0]
    n_sub = sub_start.shape[0]
    v = np.empty((n_runs, n))
    t = np.empty((n_runs, n))
    f = np.empty((n_runs, n - 1))
    e_trac = np.empty((n_runs, n - 1))
    e_regen = np.empty((n_runs, n - 1))
    regime = np.empty((n_runs, n - 1), dtype=np.int8)
    subs = np.empty((n_runs, n_sub, N_SUB))
    summary = np.empty((n_runs, N_RUN))
    for r in prange(n_runs):
        drive_one(m, sub_start, sub_end, sub_kind, sub_cap, sub_grade_change, brake_dist_m[r], gamma[r], v_exit[r],
                  q[r], planned_time_s, service_decel_ms2, v_floor_ms, relative, comfort_window_m, v[r], t[r], f[r],
                  e_trac[r], e_regen[r], regime[r], subs[r], summary[r])
    return v, t, f, e_trac, e_regen, regime, subs, summary
