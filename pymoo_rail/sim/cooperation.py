"""Trains on a common clock: power profiles, shared regenerative energy, separation.

Seed 001 eqs. 4-6 (Chen et al. 2017): while train A draws traction power ``P_A(t)`` and train B
brakes with usable regenerative power ``eta P_B(t)``, A takes ``min(P_A, eta P_B)`` from B instead
of the substation (and the other way round); the total net energy is the traction energy of both
minus what was shared. For several trains in one power-supply section, any train's regenerated
power can feed any other train's traction through the supply, with a transmission efficiency
(:func:`shared_energy_bins`); for a pair that is eq. 5.

Runs come from the simulator's own traces (:class:`ClockedRun`): the times of their nodes (from
their own departure) and the energy of each cell from the kernel's accounting
(:func:`pymoo_rail.sim.kernel.trace_cell_energies`). Each cell's energy is spread evenly over the
cell's duration and collected into bins of ``dt`` seconds on the common clock, so a bin holds
exactly the energy drawn (or regenerated) in it and the totals are preserved. The shared energy of
a bin is the smaller of the bin energies: never more than was drawn or regenerated there. (Within
a bin this is an upper bound on the integral of the pointwise minimum; with 0.1 s bins against
traction and braking phases of tens of seconds the difference is immaterial.)

Separation (eq. 9): the following train may not run faster than it could stop, at the service
deceleration b, short of the rear of the train ahead minus a safety margin:
``v^2 <= 2 b (dS - L_t - L_s)``.

Everything here is SI and free of pymoo.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
import pandas as pd
from numba import njit

from pymoo_rail.constants import J_PER_KWH
from pymoo_rail.sim.kernel import trace_cell_energies
from pymoo_rail.sim.physics import KernelModel
from pymoo_rail.sim.trajectory import Trajectory



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
def shared_energy_bins(trac, regen, transmission_efficiency):
    """Energy (J) the trains' traction takes from the other trains' braking, per bin of the common clock.

    ``trac`` and ``regen`` are (n_trains, n_bins): traction energy drawn and regenerated energy
    delivered (already times each train's utilisation eta) per bin. In a bin every train's
    regenerated energy, times ``transmission_efficiency`` (the supply's losses), can feed any
    *other* train's traction. The most that can be shared is a maximum flow from the braking to
    the drawing trains; its minimum cut is ``min(R, T, min_j (R - r_j + T - t_j))`` with ``R``, ``T``
    the sums. For two trains this is exactly seed 001 eq. 5 both ways,
    ``min(t_A, r_B) + min(t_B, r_A)``, and a train alone shares nothing with itself.
    """
    n_trains, n_bins = trac.shape
    out = np.zeros(n_bins)
    for k in range(n_bins):
        t_sum = 0.0
        r_sum = 0.0
        for j in range(n_trains):
            t_sum += trac[j, k]
            r_sum += transmission_efficiency * regen[j, k]
        best = t_sum if t_sum < r_sum else r_sum
        for j in range(n_trains):
            cut = r_sum - transmission_efficiency * regen[j, k] + t_sum - trac[j, k]
            if cut < best:
                best = cut
        out[k] = best if best > 0.0 else 0.0
    return out


@njit(cache=True)
def separation_excess(t_f, x_f, v_f, shift_f, start_f, t_l, x_l, shift_l, start_l, gap_m, decel_ms2, t0_s, dt_s,
                      n_steps, clear_s=math.inf):
    """Largest ``v_f^2 / (2 b) - (dS - L_t - L_s)`` (m) of the following train while it runs.

    ``x_*`` are node positions on each train's own line, placed on a common line at ``start_*``;
    ``t_*`` node times from each departure at ``shift_*`` on the common clock. The leading train
    stands at its start before departing and at its end after arriving, until ``clear_s`` on the
    common clock, when it leaves the line (a terminus cleared). Checked every ``dt_s``
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
        if t >= clear_s:
            continue
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


# ------------------------------------------------------------------ runs on the common clock
@dataclass(frozen=True, eq=False)
class ClockedRun:
    """A simulated run (or a journey of runs and dwells) placed on the common clock and line.

    Arrays are per node (``time_s`` from the departure, ``position_m`` from ``start_m``,
    ``speed_ms``) and per cell (``traction_j`` drawn, ``regen_j`` delivered), the energies from
    the kernel's own accounting (:func:`pymoo_rail.sim.kernel.trace_cell_energies`).
    """

    time_s: np.ndarray
    position_m: np.ndarray
    speed_ms: np.ndarray
    traction_j: np.ndarray
    regen_j: np.ndarray
    departure_s: float
    start_m: float

    @property
    def arrival_s(self) -> float:
        """Arrival time on the common clock (s)."""
        return self.departure_s + float(self.time_s[-1])

    @property
    def traction_kwh(self) -> float:
        """Traction energy of the run (kWh)."""
        return float(self.traction_j.sum() / J_PER_KWH)

    @property
    def regen_kwh(self) -> float:
        """Regenerated energy of the run (kWh)."""
        return float(self.regen_j.sum() / J_PER_KWH)


def clocked_run(model: KernelModel, trajectory: Trajectory, departure_s: float = 0.0,
                start_m: float = 0.0) -> ClockedRun:
    """Place a simulator run (of the case behind ``model``) at ``departure_s`` and ``start_m``."""
    if not (math.isfinite(departure_s) and math.isfinite(start_m)):
        raise ValueError(f"departure_s = {departure_s!r}, start_m = {start_m!r}: must be finite")
    x = np.ascontiguousarray(trajectory.position_m)
    v = np.ascontiguousarray(trajectory.speed_ms)
    trac, regen = trace_cell_energies(model, x, v, np.ascontiguousarray(trajectory.force_n))
    return ClockedRun(time_s=np.ascontiguousarray(trajectory.time_s), position_m=x, speed_ms=v, traction_j=trac,
                      regen_j=regen, departure_s=float(departure_s), start_m=float(start_m))


def chain_runs(runs) -> ClockedRun:
    """One journey of consecutive runs (each placed on its own): standing still between them."""
    first = runs[0]
    t, x, v, trac, regen = [first.time_s], [first.position_m], [first.speed_ms], [first.traction_j], [first.regen_j]
    for prev, r in zip(runs[:-1], runs[1:]):
        if r.departure_s < prev.arrival_s - 1e-9:
            raise ValueError(f"a run departs at {r.departure_s} s, before the previous one arrives at "
                             f"{prev.arrival_s} s")
        # the dwell is one cell of no distance and no energy, then the run
        t.append(r.time_s + (r.departure_s - first.departure_s))
        x.append(r.position_m + (r.start_m - first.start_m))
        v.append(r.speed_ms)
        trac += [np.zeros(1), r.traction_j]
        regen += [np.zeros(1), r.regen_j]
    return ClockedRun(time_s=np.concatenate(t), position_m=np.concatenate(x), speed_ms=np.concatenate(v),
                      traction_j=np.concatenate(trac), regen_j=np.concatenate(regen), departure_s=first.departure_s,
                      start_m=first.start_m)


def clock_span(runs, time_step_s: float) -> tuple[float, int]:
    """Start and number of bins of a clock covering every run."""
    if not (math.isfinite(time_step_s) and time_step_s > 0):
        raise ValueError(f"time_step_s = {time_step_s!r}: must be a positive number of seconds")
    t0 = min(r.departure_s for r in runs)
    t_end = max(r.arrival_s for r in runs)
    return t0, int(math.ceil((t_end - t0) / time_step_s)) + 1


def power_bins(runs, t0_s: float, time_step_s: float, n_bins: int) -> tuple[np.ndarray, np.ndarray]:
    """Traction and regenerated energy (J) of each run per bin: two (n_runs, n_bins) arrays."""
    trac = np.zeros((len(runs), n_bins))
    regen = np.zeros((len(runs), n_bins))
    for j, r in enumerate(runs):
        t = r.time_s
        bin_energy(t, r.traction_j, r.departure_s, t0_s, time_step_s, trac[j])
        bin_energy(t, r.regen_j, r.departure_s, t0_s, time_step_s, regen[j])
    return trac, regen


def shared_energy_kwh(runs, transmission_efficiency: float = 1.0, time_step_s: float = 0.1) -> float:
    """Regenerated energy the runs' traction takes from each other's braking (kWh), seed 001 eq. 5."""
    t0, n_bins = clock_span(runs, time_step_s)
    trac, regen = power_bins(runs, t0, time_step_s, n_bins)
    return float(shared_energy_bins(trac, regen, float(transmission_efficiency)).sum() / J_PER_KWH)


def power_profiles(runs, labels, transmission_efficiency: float = 1.0, time_step_s: float = 0.1) -> pd.DataFrame:
    """Power of every run on the common clock (kW per bin) and the shared power.

    Columns ``time_s`` (bin start), ``traction_<label>_kw``, ``regen_<label>_kw`` per run, and
    ``shared_kw``.
    """
    labels = list(labels)
    if len(labels) != len(runs):
        raise ValueError(f"{len(labels)} labels for {len(runs)} runs")
    t0, n_bins = clock_span(runs, time_step_s)
    trac, regen = power_bins(runs, t0, time_step_s, n_bins)
    to_kw = 1.0 / time_step_s / 1000.0
    cols = {"time_s": t0 + time_step_s * np.arange(n_bins)}
    for j, label in enumerate(labels):
        cols[f"traction_{label}_kw"] = trac[j] * to_kw
        cols[f"regen_{label}_kw"] = regen[j] * to_kw
    cols["shared_kw"] = shared_energy_bins(trac, regen, float(transmission_efficiency)) * to_kw
    return pd.DataFrame(cols)


def separation_m(follower: ClockedRun, leader: ClockedRun, gap_m: float, decel_ms2: float,
                 time_step_s: float = 0.1, clear_s: float = math.inf) -> float:
    """Largest excess (m) of the follower's braking distance over its room behind the leader (eq. 9).

    ``gap_m`` is the train length plus the safety margin; > 0 means the follower runs too close.
    The leader stands at its last stop after arriving until ``clear_s`` (common clock), then leaves.
    """
    t0, n_bins = clock_span((follower, leader), time_step_s)
    f, lead = follower, leader
    return float(separation_excess(f.time_s, f.position_m, f.speed_ms, follower.departure_s, follower.start_m,
                                   lead.time_s, lead.position_m, leader.departure_s, leader.start_m, float(gap_m), float(decel_ms2), t0,
                                   time_step_s, n_bins, float(clear_s)))
