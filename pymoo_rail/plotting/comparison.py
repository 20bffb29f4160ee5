"""Comparison of algorithms across seeds: box plots of an indicator."""

from __future__ import annotations

from typing import Sequence

import numpy as np
import pandas as pd

from pymoo_rail.plotting.style import indicator_label, new_figure


def plot_boxplots(results: pd.DataFrame, indicator: str = "igd", problems: Sequence[str] | None = None,
                  algorithms: Sequence[str] | None = None, ylabel: str | None = None):
    """Box plots of ``indicator`` over seeds, one box per algorithm, one panel per problem.

    Every run is drawn on top of its box as a point, so small samples stay honest.
    """
    if indicator not in results.columns:
        raise ValueError(f"indicator {indicator!r} is not in the results")
    data = results.dropna(subset=[indicator])
    problems = sorted(data["problem"].unique()) if problems is None else list(problems)
    if not problems:
        raise ValueError(f"no run has a value of {indicator!r}")
    algorithms = sorted(data["algorithm"].unique()) if algorithms is None else list(algorithms)
    n = len(problems)
    ncols = min(n, 3)
    nrows = int(np.ceil(n / ncols))
    fig, axes = new_figure(nrows, ncols, figsize=(max(3.2, 1.1 * len(algorithms) + 1.5) * ncols, 3.8 * nrows))
    for k, problem in enumerate(problems):
        ax = axes[k // ncols, k % ncols]
        group = data[data["problem"] == problem]
        present = [a for a in algorithms if (group["algorithm"] == a).any()]
        values = [group.loc[group["algorithm"] == a, indicator].to_numpy(float) for a in present]
        style = {"widths": 0.6, "medianprops": {"color": "black"}, "showfliers": False}  # points drawn below
        try:
            ax.boxplot(values, tick_labels=present, **style)
        except TypeError:  # matplotlib < 3.9
            ax.boxplot(values, labels=present, **style)
        for i, v in enumerate(values, start=1):
            jitter = np.linspace(-0.12, 0.12, len(v)) if len(v) > 1 else np.zeros(1)
            ax.scatter(i + jitter, v, s=12, alpha=0.7, zorder=3)
        ax.set_title(problem)
        ax.set_xlabel("algorithm")
        ax.set_ylabel(ylabel or indicator_label(indicator))
        ax.grid(True, axis="y", alpha=0.3)
        if len(present) > 3:
            ax.tick_params(axis="x", labelrotation=30)
    for k in range(n, nrows * ncols):
        axes[k // ncols, k % ncols].set_visible(False)
    return fig
