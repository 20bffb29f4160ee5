"""The suite baseline table's figures: median IGD vs evaluations per cell, and the performance profile."""

from __future__ import annotations

import numpy as np
import pandas as pd


def plot_cell_convergence(history: pd.DataFrame, indicator: str = "igd_plus"):
    """Median ``indicator`` vs evaluations, one panel per (family, n_var), one line per algorithm.

    ``history``: ``pymoo_rail.experiments.baseline.convergence`` (columns family, n_var, algorithm,
    n_eval and the indicator: each run's checkpoints scored against the current front). Returns the
    matplotlib ``Figure``.
    """
    import matplotlib.pyplot as plt

    cells = sorted(set(zip(history["family"], history["n_var"])))
    fig, axes = plt.subplots(1, len(cells), figsize=(4 * len(cells), 3.2), squeeze=False)
    for ax, (family, n_var) in zip(axes[0], cells):
        cell = history[(history["family"] == family) & (history["n_var"] == n_var)]
        for name, runs in cell.groupby("algorithm"):
            median = runs.groupby("n_eval")[indicator].median()
            ax.plot(median.index, median.to_numpy(), label=name)
        scored = np.isfinite(cell[indicator]).any()  # a cell without a feasible run has nothing to plot on a log axis
        ax.set(title=f"{family} n_var={n_var}", xlabel="evaluations", ylabel=f"median {indicator}", xscale="log",
               yscale="log" if scored else "linear")  # the checkpoints are a log ladder
        if not scored:
            ax.text(0.5, 0.5, "no feasible run", transform=ax.transAxes, ha="center")
    axes[0][0].legend(fontsize=7)
    fig.tight_layout()
    return fig


def plot_performance_profile(profile: pd.DataFrame, indicator: str = "IGD+"):
    """The share of runs within tau of the best ``indicator`` (its name on the axis), one step line per algorithm.

    ``profile``: ``pymoo_rail.experiments.baseline.performance_profile`` (index tau, one column per
    algorithm). Returns the matplotlib ``Figure``.
    """
    import matplotlib.pyplot as plt

    fig, ax = plt.subplots(figsize=(5, 3.5))
    for name in profile.columns:
        ax.step(profile.index, profile[name], where="post", label=name)
    ax.set(xscale="log", xlabel=f"tau ({indicator} / best on the run's instance and seed)", ylabel="share of runs")
    ax.legend(fontsize=7)
    fig.tight_layout()
    return fig
