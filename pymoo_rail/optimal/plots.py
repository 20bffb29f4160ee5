"""A speed profile against the optimal one (fronts against the optimal front: ``pymoo_rail.plotting.plot_fronts``)."""

from __future__ import annotations

from pathlib import Path

from pymoo_rail.constants import KMH_PER_MS
from pymoo_rail.sim import Trajectory


def _figure(ax):
    import matplotlib.pyplot as plt

    if ax is not None:
        return ax.figure, ax
    fig, ax = plt.subplots(figsize=(7.0, 4.5), constrained_layout=True)
    return fig, ax


def plot_profile(optimal: Trajectory, others: dict[str, Trajectory] | None = None,
                 path: str | Path | None = None, ax=None, title: str | None = None):
    """Speed against distance: the optimal profile, other profiles and the speed limit.

    The limit drawn is the one the simulator enforces on the head of the train (the lowest limit
    anywhere under the train), taken from the optimal trajectory.

    Returns
    -------
    matplotlib.figure.Figure
    """
    fig, ax = _figure(ax)
    x = optimal.position_m
    ax.plot(x, optimal.limit_ms * KMH_PER_MS, "-", color="tab:red", lw=1.2, label="speed limit (under the train)")
    label = (f"optimum: {optimal.running_time_s:.1f} s, {optimal.energy.net_kwh:.2f} kWh")
    ax.plot(x, optimal.speed_kmh, "-", color="black", lw=1.8, label=label)
    for name, tr in (others or {}).items():
        ax.plot(tr.position_m, tr.speed_kmh, "-", lw=1.2,
                label=f"{name}: {tr.running_time_s:.1f} s, {tr.energy.net_kwh:.2f} kWh")
    ax.set_xlabel("Distance (m)")
    ax.set_ylabel("Speed (km/h)")
    ax.set_ylim(bottom=0.0)
    ax.grid(True, alpha=0.3)
    ax.legend(loc="lower center")
    if title:
        ax.set_title(title)
    if path is not None:
        fig.savefig(path, dpi=130)
    return fig
