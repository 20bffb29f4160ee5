"""A journey with timing points: speed and time over the track, with every window drawn."""

from __future__ import annotations

from pymoo_rail.constants import KMH_PER_MS


def plot_timed_run(timed, run):
    """Two panels over track position: speed (with speed bounds) and time (with time windows).

    ``timed`` is a :class:`~pymoo_rail.journeys.timing.TimedJourney`, ``run`` its
    :class:`~pymoo_rail.journeys.timing.TimedRun`. Each window is a vertical bar from its earliest
    to its latest time at the point's position (an open end runs to the panel's edge); the run's
    time there is a dot.
    """
    import matplotlib.pyplot as plt

    fig, (ax_v, ax_t) = plt.subplots(2, 1, sharex=True, figsize=(9, 6))
    for k, traj in enumerate(run.trajectories):
        x = traj.position_m + timed.journey.stops_m[k]
        ax_v.plot(x / 1000, traj.speed_ms * KMH_PER_MS, color="C0")
        ax_t.plot(x / 1000, traj.time_s + run.departures_s[k], color="C0")
    t_top = max(c["time_s"] for c in run.checks) * 1.05
    for c in run.checks:
        x = c["position_m"] / 1000
        if c["earliest_s"] is None and c["latest_s"] is None:
            continue  # a speed bound only
        lo = c["earliest_s"] if c["earliest_s"] is not None else 0.0
        hi = c["latest_s"] if c["latest_s"] is not None else t_top
        ax_t.plot([x, x], [lo, hi], color="C3", lw=4, alpha=0.5, solid_capstyle="butt")
        ax_t.plot(x, c["time_s"], "o", color="k" if c["time_ok"] else "C3", ms=4)
    for c in run.checks:
        x = c["position_m"] / 1000
        if c["min_speed_kmh"] is not None and c["min_speed_kmh"] > 0:
            ax_v.plot(x, c["min_speed_kmh"], "^", color="C3")
        if c["max_speed_kmh"] is not None and c["max_speed_kmh"] > 0:
            ax_v.plot(x, c["max_speed_kmh"], "v", color="C3")
    ax_v.set_ylabel("speed (km/h)")
    ax_t.set_ylabel("time (s)")
    ax_t.set_xlabel("position (km)")
    ax_v.set_title(f"{timed.journey.name}: {run.energy_kwh:.1f} kWh net; bars = time windows")
    fig.tight_layout()
    return fig


def plot_split_costs(sweep, best, equal, title: str):
    """Three panels: line energy against trip time per split, the cost of a rule of thumb, one trip's split.

    ``sweep`` is :func:`pymoo_rail.journeys.compare.split_sweep`; ``best`` and ``equal`` are the
    :class:`~pymoo_rail.journeys.Allocation` of one trip (optimal and equal supplement), drawn as
    per-section supplements in the third panel; ``title`` names the line in the first panel.
    """
    import matplotlib.pyplot as plt
    import numpy as np

    trip_min = sweep["trip_time_s"].to_numpy() / 60
    opt_e, eq_e, pr_e = (sweep[c].to_numpy() for c in ("optimal_kwh", "equal_kwh", "proportional_kwh"))
    fig, axes = plt.subplots(1, 3, figsize=(16, 4.6))
    ax = axes[0]
    ax.plot(trip_min, opt_e, label="energy-optimal split")
    ax.plot(trip_min, eq_e, "--", label="equal supplement")
    ax.plot(trip_min, pr_e, ":", label="proportional supplement")
    ax.set(xlabel="trip time incl. dwells (min)", ylabel="net energy of the line (kWh)", title=title)
    ax.legend()
    ax = axes[1]
    ax.plot(trip_min, eq_e - opt_e, "--", label="equal supplement")
    ax.plot(trip_min, pr_e - opt_e, ":", label="proportional supplement")
    ax.set(xlabel="trip time incl. dwells (min)", ylabel="extra energy over the optimal split (kWh)",
           title="cost of a rule-of-thumb split")
    ax.legend()
    ax = axes[2]
    x = np.arange(len(best.table))
    ax.bar(x - 0.2, best.table.supplement_s, 0.4, label="energy-optimal")
    ax.bar(x + 0.2, equal.table.supplement_s, 0.4, label="equal")
    ax.set_xticks(x, [f"{k}" for k in x])
    ax.set(xlabel=f"section (0 = {best.table.label.iloc[0]})", ylabel="running-time supplement over flat-out (s)",
           title=f"split of a {best.trip_time_s / 60:.0f}-min trip")
    ax.legend(loc="lower right")
    for a in axes:
        a.grid(alpha=0.3)
    fig.tight_layout()
    return fig
