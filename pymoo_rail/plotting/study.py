"""Every standard figure of a study, written to files."""

from __future__ import annotations

from pathlib import Path
from typing import Sequence

import pandas as pd

from pymoo_rail.plotting.comparison import plot_boxplots
from pymoo_rail.plotting.convergence import plot_convergence
from pymoo_rail.plotting.fronts import plot_study_fronts
from pymoo_rail.plotting.style import save_figure


def _history_indicators(results: pd.DataFrame) -> list[str]:
    """History columns worth a convergence plot: igd and hv where known, else best objectives."""
    keys: list[str] = []
    for history in results["history"]:
        for key in history or {}:
            if key not in keys and key not in ("n_gen", "n_eval"):
                keys.append(key)
    preferred = [k for k in ("igd", "hv", "error") if k in keys]
    return preferred or [k for k in keys if k.endswith("_min")][:1]


def plot_study(results: pd.DataFrame, directory: str | Path, indicators: Sequence[str] | None = None,
               dpi: int = 150, trusted: bool = False) -> list[Path]:
    """Box plots per indicator, convergence curves, and the median fronts of each problem.

    Files: ``box_<indicator>.png``, ``convergence_<indicator>.png``, ``front_<problem>.png``
    (problems with 2 or 3 objectives). Returns the paths written. ``trusted``: rebuild problems
    given as ``"module:factory"`` for their true fronts (see :func:`plot_study_fronts`).
    """
    from pymoo_rail.experiments.results import indicator_columns

    directory = Path(directory)
    written = []
    indicators = indicator_columns(results) if indicators is None else list(indicators)
    for name in indicators:
        if results[name].notna().any():
            written.append(save_figure(plot_boxplots(results, name), directory / f"box_{name}.png", dpi=dpi))
    if "history" in results.columns:
        for name in _history_indicators(results):
            problems = [p for p, g in results.groupby("problem")
                        if any(h and name in h for h in g["history"])]
            if problems:
                written.append(save_figure(plot_convergence(results, name, problems),
                                           directory / f"convergence_{name}.png", dpi=dpi))
    if "F" in results.columns:
        for problem, group in results.groupby("problem", sort=True):
            if 2 <= int(group["n_obj"].iloc[0]) <= 3 and group["feasible"].any():
                safe = "".join(c if c.isalnum() or c in "-_." else "_" for c in str(problem))
                written.append(save_figure(plot_study_fronts(results, problem, trusted=trusted), directory / f"front_{safe}.png",
                                           dpi=dpi))
    return written
