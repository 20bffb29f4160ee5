"""Two trains on a common clock: power profiles, shared regenerative energy, separation.

Seed 001 eqs. 4-6: while train A draws traction power ``P_A(t)`` and train B brakes with usable
regenerative power ``eta P_B(t)``, A takes ``min(P_A, eta P_B)`` from B instead of the
substation (and the other way round); the total net energy is the traction energy of both
minus what was shared.

A run is given per grid cell: the times of its nodes (from its own departure) and the energy of
each cell (J). Each cell's energy is spread evenly over the cell's duration and collected into
bins of ``dt`` seconds on the common clock, so a bin holds exactly the energy drawn (or
regenerated) in it and the totals are preserved. The shared energy of a bin is the smaller of
the two bin energies: never more than either train drew or regenerated there. (Within a bin
this is an upper bound on the integral of the pointwise minimum; with 0.1 s bins against
traction and braking phases of tens of seconds the difference is immaterial.)

Separation (eq. 9): the following train may not run faster than it could stop, at the service
deceleration b, short of the rear of the train ahead minus a safety margin:
``v^2 <= 2 b (dS - L_t - L_s)``.

Everything here is SI and free of pymoo.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit, prange


@njit(cache=True)
def bin_energy(t_nodes, e_cells, shift_s, t0_s, dt_s, out):
    """Add the energy of each cell (spread evenly over its time) to bins ``[t0 + k dt, t0 + (k+1) dt)``.

    ``t_nodes`` are node times from the train's departure, which happens at ``shift_s`` on the
    common clock. Energy outside the bins is dropped (the caller sizes the bins to the runs).
    """
    n_bins = out.shape[0]
    for i in range(e_cells.shape[0]):
        e = e_cells[i]
        if e == 0.0:
            continue
        ta = t_nodes[i] + shift_s
        tb = t_nodes[i + 1] + shift_s
        if tb <= ta:
            k = int(math.floor((ta - t0_s) / dt_s))
            if 0 <= k < n_bins:
                out[k] += e
            continue
        k0 = int(math.floor((ta - t0_s) / dt_s))
        k1 = int(math.floor((tb - t0_s) / dt_s))
        if k1 < 0 or k0 >= n_bins:
            continue
        rate = e / (tb - ta)
        for k in range(max(k0, 0), min(k1, n_bins - 1) + 1):
            lo = t0_s + k * dt_s
            hi = lo + dt_s
            a = ta if ta > lo else lo
            b = tb if tb < hi else hi
            if b > a:
                out[k] += rate * (b - a)


@njit(cache=True)
def shared_energy(trac_a, regen_a, trac_b, regen_b):
    """(energy A takes from B's braking, energy B takes from A's braking), J, from binned profiles."""
    a_from_b = 0.0
    b_from_a = 0.0
    for k in range(trac_a.shape[0]):
        a_from_b += min(trac_a[k], regen_b[k])
        b_from_a += min(trac_b[k], regen_a[k])
    return a_from_b, b_from_a


@njit(cache=True)
def separation_excess(t_f, x_f, v_f, shift_f, start_f, t_l, x_l, shift_l, start_l, gap_m, decel_ms2, t0_s, dt_s,
                      n_steps):
    """Largest ``v_f^2 / (2 b) - (dS - L_t - L_s)`` (m) of the following train while it runs.

    ``x_*`` are node positions on each train's own line, placed on a common line at ``start_*``;
    ``t_*`` node times from each departure at ``shift_*`` on the common clock. The leading train
    stands at its start before departing and at its end after arriving. Checked every ``dt_s``
    from ``t0_s`` and at the follower's arrival (> 0: the follower runs too close).
    """
    worst = -1e300
    n_f = t_f.shape[0]
    n_l = t_l.shape[0]
    i_f = 0
    i_l = 0
    t_end_f = t_f[n_f - 1] + shift_f
    for step in range(n_steps + 1):
        t = t0_s + step * dt_s
        if step == n_steps:
            t = t_end_f
        if t < shift_f or t > t_end_f:
            continue
        tau = t - shift_f
        while i_f < n_f - 2 and t_f[i_f + 1] < tau:
            i_f += 1
        span = t_f[i_f + 1] - t_f[i_f]
        w = (tau - t_f[i_f]) / span if span > 0.0 else 1.0
        if w < 0.0:
            w = 0.0
        if w > 1.0:
            w = 1.0
        # constant acceleration in a cell: v is linear in time, x advances by the mean speed
        v0 = v_f[i_f]
        v = v0 + w * (v_f[i_f + 1] - v0)
        x = x_f[i_f] + 0.5 * (v0 + v) * (tau - t_f[i_f]) if span > 0.0 else x_f[i_f + 1]
        if x > x_f[i_f + 1]:
            x = x_f[i_f + 1]
        pos_f = start_f + x
        tau_l = t - shift_l
        if tau_l <= 0.0:
            pos_l = start_l
        elif tau_l >= t_l[n_l - 1]:
            pos_l = start_l + x_l[n_l - 1]
        else:
            while i_l < n_l - 2 and t_l[i_l + 1] < tau_l:
                i_l += 1
            span_l = t_l[i_l + 1] - t_l[i_l]
            wl = (tau_l - t_l[i_l]) / span_l if span_l > 0.0 else 1.0
            pos_l = start_l + x_l[i_l] + wl * (x_l[i_l + 1] - x_l[i_l])
        excess = v * v / (2.0 * decel_ms2) - (pos_l - pos_f - gap_m)
        if excess > worst:
            worst = excess
    return worst


@njit(cache=True, parallel=True)
def cooperation_batch(t_a, e_trac_a, e_regen_a, t_b, e_trac_b, e_regen_b, shift_b_s, t0_s, dt_s, n_bins):
    """Shared energy (N, 2) in J for a population: column 0 A from B, column 1 B from A."""
    n_runs = t_a.shape[0]
    out = np.empty((n_runs, 2))
    for r in prange(n_runs):
        ta = np.zeros(n_bins)
        ra = np.zeros(n_bins)
        tb = np.zeros(n_bins)
        rb = np.zeros(n_bins)
        bin_energy(t_a[r], e_trac_a[r], 0.0, t0_s, dt_s, ta)
        bin_energy(t_a[r], e_regen_a[r], 0.0, t0_s, dt_s, ra)
        bin_energy(t_b[r], e_trac_b[r], shift_b_s, t0_s, dt_s, tb)
        bin_energy(t_b[r], e_regen_b[r], shift_b_s, t0_s, dt_s, rb)
        a_from_b, b_from_a = shared_energy(ta, ra, tb, rb)
        out[r, 0] = a_from_b
        out[r, 1] = b_from_a
    return out


@njit(cache=True, parallel=True)
def separation_batch(t_f, x_f, v_f, shift_f, start_f, t_l, x_l, shift_l, start_l, gap_m, decel_ms2, t0_s, dt_s,
                     n_steps):
    """:func:`separation_excess` for a population (rows of ``t_f``, ``v_f``, ``t_l``; shared positions)."""
    n_runs = t_f.shape[0]
    out = np.empty(n_runs)
    for r in prange(n_runs):
        out[r] = separation_excess(t_f[r], x_f, v_f[r], shift_f, start_f, t_l[r], x_l, shift_l, start_l, gap_m,
                                   decel_ms2, t0_s, dt_s, n_steps)
    return out
