"""The closed-loop study's figure: energy above the exact optimum against lateness, per case."""

from __future__ import annotations

from collections.abc import Sequence

import pandas as pd


def plot_gap_lateness(runs: pd.DataFrame, controllers: Sequence[str]):
    """Energy above the real train's exact optimum at the run's own time, against lateness; one panel per case.

    ``runs``: the study's per-run rows (case, controller, lateness_s, gap_pct), ``controllers`` every
    controller name that may appear (its colour is its place there). Each run is a dot, each
    controller's median a diamond. Returns the matplotlib ``Figure``.
    """
    import matplotlib.pyplot as plt

    cases = list(dict.fromkeys(runs["case"]))
    fig, axes = plt.subplots(1, len(cases), figsize=(4.2 * len(cases), 4.0), squeeze=False)
    palette = plt.get_cmap("tab20").colors
    colors = dict(zip(controllers, palette[::2] + palette[1::2]))
    for ax, case in zip(axes[0], cases):
        g = runs[runs["case"] == case]
        for name, h in g.groupby("controller", sort=False):
            ax.scatter(h["lateness_s"], h["gap_pct"], s=8, alpha=0.5, color=colors[name])
            ax.scatter([h["lateness_s"].median()], [h["gap_pct"].median()], s=60, marker="D", edgecolor="black",
                       color=colors[name], label=name)
        ax.axvline(0.0, color="grey", lw=0.6)
        ax.set_title(case)
        ax.set_xlabel("lateness (s)")
        ax.set_ylabel("energy above the exact optimum at the same time (%)")
        ax.grid(alpha=0.3)
    axes[0][0].legend(fontsize=7, loc="upper right")
    fig.tight_layout()
    return fig
