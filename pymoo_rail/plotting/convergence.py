"""Convergence of an indicator against evaluations: from a study's stored histories, or from a
pymoo result run with ``save_history=True``."""

from __future__ import annotations

import re
from typing import Sequence

import numpy as np
import pandas as pd

from pymoo_rail.plotting.style import indicator_label, new_figure, objective_label


def _step_values(n_eval: np.ndarray, values: np.ndarray, grid: np.ndarray) -> np.ndarray:
    """The value in force at each grid point (the last one recorded at or before it)."""
    idx = np.searchsorted(n_eval, grid, side="right") - 1
    out = np.full(grid.shape, np.nan)
    ok = idx >= 0
    out[ok] = values[idx[ok]]
    return out


def convergence_frame(results: pd.DataFrame, indicator: str, problem: str) -> pd.DataFrame:
    """Per algorithm and evaluation count: median, lower and upper quartile over seeds.

    Runs are aligned on the union of their evaluation counts (each run holds its last value
    between its own generations) and cut at the smallest final count, so every point
    aggregates every seed.
    """
    group = results[results["problem"] == problem]
    if group.empty:
        raise ValueError(f"problem {problem!r} is not in the results")
    rows = []
    for algorithm_name, runs in group.groupby("algorithm", sort=True):
        curves = []
        for history in runs["history"]:
            if not history or indicator not in history:
                continue
            n_eval = np.asarray(history["n_eval"], dtype=float)
            values = np.asarray([np.nan if v is None else v for v in history[indicator]], dtype=float)
            curves.append((n_eval, values))
        if not curves:
            continue
        end = min(c[0][-1] for c in curves)
        grid = np.unique(np.concatenate([c[0] for c in curves]))
        grid = grid[grid <= end]
        stacked = np.vstack([_step_values(n, v, grid) for n, v in curves])
        with np.errstate(all="ignore"):
            q1, med, q3 = np.nanpercentile(stacked, [25, 50, 75], axis=0)
        rows.append(pd.DataFrame({"algorithm": algorithm_name, "n_eval": grid, "median": med, "q1": q1, "q3": q3,
                                  "n_runs": len(curves)}))
    if not rows:
        raise ValueError(f"no run on problem {problem!r} has a history of {indicator!r} "
                         "(histories hold igd/hv with a known front, f0_min.. always)")
    return pd.concat(rows, ignore_index=True)


def plot_convergence(results: pd.DataFrame, indicator: str = "igd", problems: Sequence[str] | None = None,
                     log: bool | None = None, ylabel: str | None = None):
    """Median (line) and interquartile range (band) of an indicator over seeds, per algorithm,
    against function evaluations; one panel per problem.

    ``indicator`` is a history column: ``igd``, ``hv`` (known front), ``error`` (single
    objective with known optimum) or ``f0_min``, ``f1_min``, ... (best value of each objective).
    """
    problems = sorted(results["problem"].unique()) if problems is None else list(problems)
    n = len(problems)
    ncols = min(n, 3)
    nrows = int(np.ceil(n / ncols))
    fig, axes = new_figure(nrows, ncols, figsize=(4.6 * ncols, 3.6 * nrows))
    for k, problem in enumerate(problems):
        ax = axes[k // ncols, k % ncols]
        frame = convergence_frame(results, indicator, problem)
        for algorithm_name, curve in frame.groupby("algorithm", sort=True):
            (line,) = ax.step(curve["n_eval"], curve["median"], where="post", lw=1.6,
                              label=f"{algorithm_name} ({int(curve['n_runs'].iloc[0])} runs)")
            ax.fill_between(curve["n_eval"], curve["q1"], curve["q3"], step="post", alpha=0.2,
                            color=line.get_color(), lw=0)
        use_log = log if log is not None else (indicator != "hv" and bool((frame["median"] > 0).all())
                                                 and frame["median"].max() > 20 * frame["median"].min())
        if use_log:
            ax.set_yscale("log")
        ax.set_title(problem)
        ax.set_xlabel("function evaluations")
        ax.set_ylabel(ylabel or _panel_label(results, problem, indicator))
        ax.grid(True, alpha=0.3)
        ax.legend(fontsize="small")
    for k in range(n, nrows * ncols):
        axes[k // ncols, k % ncols].set_visible(False)
    return fig


def _panel_label(results: pd.DataFrame, problem: str, indicator: str) -> str:
    """``f0_min`` -> "best energy (kWh)" when the problem's spec names its objectives."""
    match = re.fullmatch(r"f(\d+)_min", indicator)
    if not match:
        return indicator_label(indicator)
    index = int(match.group(1))
    names = None
    if "problem_spec" in results.columns:
        spec = results.loc[results["problem"] == problem, "problem_spec"].iloc[0]
        names = spec.get("objectives") if isinstance(spec, dict) else None
    if isinstance(names, list) and index < len(names):
        return f"best {objective_label(names[index], index)}"
    return f"best f{index + 1}"


def history_curve(res, indicator: str = "igd", pf: np.ndarray | None = None) -> pd.DataFrame:
    """``n_eval`` and an indicator per generation of a pymoo result with ``save_history=True``.

    ``indicator``: ``"igd"`` or ``"hv"`` (need ``pf``, default the problem's true front) or
    ``"f_min"`` (best value of the first objective, feasible solutions only).
    """
    from pymoo_rail.experiments.metrics import normalised_hv, true_front

    if not getattr(res, "history", None):
        raise ValueError("the result has no history: run minimize(..., save_history=True)")
    if indicator in ("igd", "hv") and pf is None:
        pf = true_front(res.problem)
        if pf is None:
            raise ValueError(f"indicator {indicator!r} needs a reference front: pass pf=...")
    rows = []
    for algorithm in res.history:
        F, CV = algorithm.opt.get("F", "CV")
        F = F[CV.reshape(-1) <= 0]
        value = np.nan
        if len(F):
            if indicator == "igd":
                from pymoo.indicators.igd import IGD

                value = float(IGD(pf)(F))
            elif indicator == "hv":
                value = normalised_hv(F, pf.min(axis=0), pf.max(axis=0))
            elif indicator == "f_min":
                value = float(F[:, 0].min())
            else:
                raise ValueError(f"indicator {indicator!r} is unknown (igd, hv, f_min)")
        rows.append({"n_eval": algorithm.evaluator.n_eval, indicator: value})
    return pd.DataFrame(rows)


def plot_history(res, indicator: str = "igd", pf: np.ndarray | None = None, label: str | None = None, ax=None):
    """Convergence of one pymoo run (``minimize(..., save_history=True)``)."""
    curve = history_curve(res, indicator, pf)
    if ax is None:
        fig, axes = new_figure()
        ax = axes[0, 0]
    ax.step(curve["n_eval"], curve[indicator], where="post", lw=1.6,
            label=label or type(res.algorithm).__name__)
    ax.set_xlabel("function evaluations")
    ax.set_ylabel(indicator_label(indicator) if indicator != "f_min" else "best objective value")
    ax.grid(True, alpha=0.3)
    ax.legend(fontsize="small")
    return ax.figure
