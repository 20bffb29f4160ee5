"""The suite baseline table's figures: median IGD vs evaluations per cell, and the performance profile."""

from __future__ import annotations

import numpy as np
import pandas as pd


def plot_cell_convergence(history: pd.DataFrame, indicator: str = "igd_plus"):
    """Median ``indicator`` vs evaluations, one panel per (family, n_var), one line per algorithm.

    ``history``: ``pymoo_rail.experiments.baseline.convergence`` (columns family, n_var, algorithm,
    n_eval and the indicator: each run's checkpoints scored against the current front). The median
    is over the runs at each ``target_n_eval`` (the checkpoint a row stands for) where ``history``
    has it, else at each ``n_eval``. The panels form a grid, a row per family and a column per
    ``n_var`` (a cell not in ``history`` is left blank), with one colour per algorithm in every panel
    and one legend for the figure. Returns the matplotlib ``Figure``.
    """
    import matplotlib.pyplot as plt
    from matplotlib.ticker import FuncFormatter, LogLocator, NullFormatter

    families, ladder = sorted(history["family"].unique()), sorted(history["n_var"].unique())
    x = "target_n_eval" if "target_n_eval" in history else "n_eval"  # runs' generations end at other counts
    cycle = plt.rcParams["axes.prop_cycle"].by_key()["color"]
    colours = {name: cycle[i % len(cycle)] for i, name in enumerate(sorted(history["algorithm"].unique()))}
    fig, axes = plt.subplots(len(families), len(ladder), figsize=(3.2 * len(ladder), 2.6 * len(families) + 0.6),
                             squeeze=False)
    cells = dict(iter(history.groupby(["family", "n_var"])))  # one pass, not one scan a panel
    for row, family in zip(axes, families):
        for ax, n_var in zip(row, ladder):
            cell = cells.get((family, n_var))
            if cell is None:
                ax.set_axis_off()
                continue
            for name, runs in cell.groupby("algorithm"):
                median = runs.groupby(x)[indicator].median()
                ax.plot(median.index, median.to_numpy(), color=colours[name], label=name)
            scored = np.isfinite(cell[indicator]).any()  # a cell without a feasible run has nothing to plot on a log axis
            ax.set_xscale("log")  # the checkpoints are a log ladder: 1-2-5 ticks, written out
            ax.xaxis.set_major_locator(LogLocator(subs=(1.0, 2.0, 5.0)))
            ax.xaxis.set_major_formatter(FuncFormatter(lambda value, _: f"{value:,.0f}"))
            ax.xaxis.set_minor_formatter(NullFormatter())
            ax.set_yscale("log" if scored else "linear")
            ax.set_title(f"{family}, n_var={n_var}", fontsize=8)
            ax.tick_params(which="both", labelsize=7)
            if not scored:
                ax.text(0.5, 0.5, "no feasible run", transform=ax.transAxes, ha="center")
        row[0].set_ylabel(f"median {indicator}", fontsize=8)
    for ax in axes[-1]:
        ax.set_xlabel("evaluations", fontsize=8)
    # every algorithm, though a panel may lack one (a cell it did not run)
    handles = [plt.Line2D([], [], color=colour, label=name) for name, colour in colours.items()]
    fig.legend(handles=handles, loc="lower center", ncol=len(handles), fontsize=8, frameon=False)
    fig.tight_layout(rect=(0, 0.6 / fig.get_figheight(), 1, 1))  # room for the legend below the grid
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
