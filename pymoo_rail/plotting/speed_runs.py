"""Speed-distance runs of several solvers or models side by side, one panel per case or time."""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np

from pymoo_rail.constants import KMH_PER_MS
from pymoo_rail.plotting.style import new_figure


def plot_speed_runs(panels: Sequence[tuple[str, Sequence[tuple[str, np.ndarray, np.ndarray, str, str]]]],
                    ncols: int = 2, figsize=(10.0, 7.0)):
    """One panel per ``(title, runs)``; each run ``(label, position_m, speed_ms, colour, linestyle)``.

    Used by ``benchmarks/efficiency_study.py`` to draw pymoo-rail's optimal runs beside ms-eetc's.

    Returns
    -------
    matplotlib.figure.Figure
    """
    nrows = max(1, -(-len(panels) // ncols))
    fig, axes = new_figure(nrows, ncols, figsize=figsize, sharex=True, sharey=True)
    for ax, (title, runs) in zip(axes.flat, panels):
        for label, position_m, speed_ms, colour, style in runs:
            ax.plot(np.asarray(position_m) / 1000.0, np.asarray(speed_ms) * KMH_PER_MS, style, color=colour,
                    label=label, lw=1.2)
        ax.set_title(title)
        ax.grid(True, alpha=0.3)
        ax.legend(fontsize=7, loc="lower center")
    for ax in axes[-1]:
        ax.set_xlabel("position (km)")
    for ax in axes[:, 0]:
        ax.set_ylabel("speed (km/h)")
    for ax in list(axes.flat)[len(panels):]:
        ax.set_visible(False)
    return fig
