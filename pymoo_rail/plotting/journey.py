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
