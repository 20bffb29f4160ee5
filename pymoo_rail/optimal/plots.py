"""Plots against the optimum: a front against the optimal front, a profile against the optimal one."""

from __future__ import annotations

from pathlib import Path

import numpy as np

from pymoo_rail.constants import KMH_PER_MS
from pymoo_rail.sim import Trajectory


def _figure(ax):
    import matplotlib.pyplot as plt

    if ax is not None:
        return ax.figure, ax
    fig, ax = plt.subplots(figsize=(7.0, 4.5), constrained_layout=True)
    return fig, ax


def _points(front) -> np.ndarray:
    if hasattr(front, "columns"):
        return front[["running_time_s", "energy_kwh"]].to_numpy(dtype=float)
    points = np.asarray(front, dtype=float)
    if points.ndim != 2 or points.shape[1] != 2:
        raise ValueError(f"a front has shape {points.shape}: expected (n, 2) rows of (running_time_s, energy_kwh)")
    return points


def plot_front(reference, fronts: dict | None = None, path: str | Path | None = None, ax=None,
               title: str | None = None):
    """Energy against running time: the optimal front as a line, other fronts as markers.

    Parameters
    ----------
    reference : DataFrame or array (n, 2)
        The optimal front (``running_time_s``, ``energy_kwh``).
    fronts : dict of label -> DataFrame or array (n, 2), optional
        Fronts to compare (e.g. an optimiser's non-dominated set, seed results).
    path : str or Path, optional
        Save the figure there (PNG by the suffix).

    Returns
    -------
    matplotlib.figure.Figure
    """
    fig, ax = _figure(ax)
    ref = _points(reference)
    ref = ref[np.argsort(ref[:, 0])]
    ax.plot(ref[:, 0], ref[:, 1], "-", color="black", lw=1.8, label="optimum (DP)")
    ax.plot(ref[:, 0], ref[:, 1], "o", color="black", ms=3)
    markers = "s^vDP*X"
    for k, (label, front) in enumerate((fronts or {}).items()):
        pts = _points(front)
        ax.plot(pts[:, 0], pts[:, 1], markers[k % len(markers)], ms=5, alpha=0.8, label=label)
    ax.set_xlabel("Running time (s)")
    ax.set_ylabel("Net energy (kWh)")
    ax.grid(True, alpha=0.3)
    ax.legend()
    if title:
        ax.set_title(title)
    if path is not None:
        fig.savefig(path, dpi=130)
    return fig


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
