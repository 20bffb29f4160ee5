"""Pareto fronts: one front, or the fronts of several algorithms on one problem of a study."""

from __future__ import annotations

import warnings
from typing import Mapping, Sequence

import numpy as np
import pandas as pd

from pymoo_rail.plotting.style import new_figure, objective_labels


def _as_front(F, name: str = "F") -> np.ndarray:
    F = np.asarray(F, dtype=float)
    if F.ndim == 1:
        F = F[None, :]
    if F.ndim != 2 or F.shape[1] < 2:
        raise ValueError(f"{name} must be an (n, m) array with m >= 2 objectives, got shape {F.shape}")
    if not np.all(np.isfinite(F)):
        raise ValueError(f"{name} holds NaN or infinite values")
    return F


def is_disconnected(front: np.ndarray, jump: float = 5.0, flat: float = 1e-3) -> bool:
    """Whether a sampled two-objective front has gaps (like ZDT3's), so a line would bridge them.

    Objectives are scaled to their range and the points sorted by the first. A gap is a step more
    than ``jump`` times the median step long that is flat: its shorter side is below ``flat`` times
    its longer one. A flat stretch is weakly dominated, so no Pareto front runs along it; a steep
    connected stretch (ZDT1 near ``f1 = 0``, a rail front near its minimum time) changes both
    objectives and is not a gap.
    """
    F = np.asarray(front, dtype=float)
    if F.ndim != 2 or F.shape[1] != 2 or len(F) < 4:
        return False
    span = np.ptp(F, axis=0)
    if np.any(span <= 0):
        return False
    steps = np.abs(np.diff((F / span)[np.argsort(F[:, 0], kind="stable")], axis=0))
    length = np.hypot(steps[:, 0], steps[:, 1])
    long = length > jump * np.median(length)
    flat_step = steps.min(axis=1) < flat * steps.max(axis=1)
    return bool(np.any(long & flat_step))


def _as_reference(reference, n_obj: int) -> np.ndarray:
    """The reference front as an (k, n_obj) array, checked."""
    ref = np.asarray(reference.to_numpy() if isinstance(reference, pd.DataFrame) else reference, dtype=float)
    ref = _as_front(ref, "reference")
    if ref.shape[1] != n_obj:
        raise ValueError(f"reference has {ref.shape[1]} objectives, the fronts {n_obj}")
    return ref


def _draw_reference(ax, ref: np.ndarray, reference_label: str) -> None:
    """The reference front: a line (2 objectives, sparse and connected), else dots."""
    n_obj = ref.shape[1]
    if n_obj == 2 and len(ref) < 200 and not is_disconnected(ref):
        order = np.argsort(ref[:, 0])
        ax.plot(ref[order, 0], ref[order, 1], "-", marker=".", ms=4, color="0.35", lw=1.2,
                label=reference_label, zorder=1)
    elif n_obj == 2:  # dense or disconnected true front: dots, so gaps (ZDT3) are not bridged
        ax.scatter(ref[:, 0], ref[:, 1], s=1.5 if len(ref) >= 200 else 6, color="0.35",
                   label=reference_label, zorder=1)
    else:
        ax.scatter(*ref.T, s=2, color="0.6", label=reference_label)


def plot_fronts(fronts: Mapping[str, np.ndarray], objectives: Sequence[str] | None = None,
                reference=None, reference_label: str = "optimal front", highlight=None,
                highlight_label: str = "chosen", title: str | None = None, ax=None):
    """Several fronts on one set of axes (2 or 3 objectives), or as a scatter matrix (4 or more).

    Parameters
    ----------
    fronts : mapping label -> (n, m) array
        E.g. ``{"nsga2": F1, "moabc": F2}``.
    objectives : sequence of str, optional
        Objective names (``"energy"``, ``"time_error"``, ...) for labelled axes with units.
    reference : (k, m) array or DataFrame, optional
        The true or optimal front, drawn as a line (2 objectives) or small points (3 or more, a
        dense front, or a front with gaps such as ZDT3's: see :func:`is_disconnected`).
    highlight : (m,) array, optional
        One point to mark, e.g. the solution chosen for the speed profile.
    ax : matplotlib Axes, optional
        Only for 2 or 3 objectives; a scatter matrix needs a figure of its own.

    Returns
    -------
    matplotlib.figure.Figure

    Notes
    -----
    With four or more objectives (e.g. energy, time error, jerk and stop error) every pair of
    objectives gets a panel below the diagonal; the diagonal names the objective and shows the
    range of each front as a histogram.
    """
    if not fronts:
        raise ValueError("fronts is empty: give at least one front")
    fronts = {label: _as_front(F, f"fronts[{label!r}]") for label, F in fronts.items()}
    n_obj = next(iter(fronts.values())).shape[1]
    for label, F in fronts.items():
        if F.shape[1] != n_obj:
            raise ValueError(f"fronts[{label!r}] has {F.shape[1]} objectives, the first front {n_obj}")
    labels = objective_labels(objectives, n_obj)
    ref = None
    if reference is not None:
        ref = _as_reference(reference, n_obj)
    if n_obj > 3:
        if ax is not None:
            raise ValueError(f"{n_obj} objectives are drawn as a scatter matrix, which needs its own figure: "
                             "leave ax out")
        return _scatter_matrix(fronts, labels, ref, reference_label, highlight, highlight_label, title)
    if ax is None:
        if n_obj == 3:
            import matplotlib.pyplot as plt

            fig = plt.figure(figsize=(7.0, 5.5), layout="constrained")
            ax = fig.add_subplot(projection="3d")
        else:
            fig, axes = new_figure()
            ax = axes[0, 0]
    fig = ax.figure

    if ref is not None:
        _draw_reference(ax, ref, reference_label)
    markers = "os^Dvp<>h*"
    for i, (label, F) in enumerate(fronts.items()):
        order = np.argsort(F[:, 0])
        ax.scatter(*F[order].T, s=22, marker=markers[i % len(markers)], label=f"{label} ({len(F)})",
                   alpha=0.85, zorder=3)
    if highlight is not None:
        point = np.asarray(highlight, dtype=float).reshape(-1)
        ax.scatter(*point, s=140, facecolors="none", edgecolors="black", linewidths=1.8, label=highlight_label,
                   zorder=4)
    ax.set_xlabel(labels[0])
    ax.set_ylabel(labels[1])
    if n_obj == 3:
        ax.set_zlabel(labels[2])
    else:
        ax.grid(True, alpha=0.3)
    ax.legend(fontsize="small")
    if title:
        ax.set_title(title)
    return fig


def _scatter_matrix(fronts: dict[str, np.ndarray], labels: list[str], ref, reference_label: str, highlight,
                    highlight_label: str, title: str | None):
    """Objective pairs below the diagonal, per-objective histograms on it."""
    from pymoo_rail.plotting.style import new_figure

    m = len(labels)
    fig, axes = new_figure(m, m, figsize=(2.3 * m, 2.1 * m))
    point = None if highlight is None else np.asarray(highlight, dtype=float).reshape(-1)
    markers = "os^Dvp<>h*"
    for r in range(m):
        for c in range(m):
            ax = axes[r, c]
            if c > r:
                ax.set_axis_off()
                continue
            if c == r:
                for i, (label, F) in enumerate(fronts.items()):
                    ax.hist(F[:, c], bins=15, alpha=0.55, color=f"C{i}")
                ax.set_title(labels[c], fontsize="small")
                ax.set_yticks([])
            else:
                if ref is not None:
                    ax.scatter(ref[:, c], ref[:, r], s=2, color="0.6", zorder=1,
                               label=reference_label)
                for i, (label, F) in enumerate(fronts.items()):
                    ax.scatter(F[:, c], F[:, r], s=10, marker=markers[i % len(markers)], color=f"C{i}",
                               alpha=0.8, zorder=3, label=f"{label} ({len(F)})")
                if point is not None:
                    ax.scatter(point[c], point[r], s=90, facecolors="none", edgecolors="black", linewidths=1.5,
                               zorder=4, label=highlight_label)
                ax.grid(True, alpha=0.3)
            if r == m - 1:
                ax.set_xlabel(labels[c], fontsize="small")
            if c == 0 and r > 0:
                ax.set_ylabel(labels[r], fontsize="small")
            ax.tick_params(labelsize="x-small")
    handles, names = axes[1, 0].get_legend_handles_labels()
    fig.legend(handles, names, loc="upper right", fontsize="small")
    if title:
        fig.suptitle(title)
    return fig


def plot_front(F, objectives: Sequence[str] | None = None, reference=None, highlight=None, label: str = "front",
               title: str | None = None, ax=None):
    """One Pareto front (see :func:`plot_fronts`)."""
    return plot_fronts({label: F}, objectives, reference=reference, highlight=highlight, title=title, ax=ax)


def representative_runs(results: pd.DataFrame, problem: str, indicator: str | None = None) -> pd.DataFrame:
    """Per algorithm, the run with the median value of ``indicator`` on ``problem``.

    Default indicator: ``igd`` where known, else ``hv_ref``/``igd_ref``, else ``n_front``
    (largest). Ties and the even-count median go to the lower seed, so the choice is stable.
    """
    group = results[results["problem"] == problem]
    if group.empty:
        raise ValueError(f"problem {problem!r} is not in the results ({', '.join(sorted(results['problem'].unique()))})")
    if indicator is None:
        for candidate in ("igd", "igd_ref", "spacing", "n_front"):
            if candidate in group.columns and group[candidate].notna().any():
                indicator = candidate
                break
    rows = []
    for _, runs in group.groupby("algorithm", sort=True):
        runs = runs.dropna(subset=[indicator]) if indicator in runs.columns else runs
        if runs.empty:
            continue
        runs = runs.sort_values([indicator, "seed"], kind="stable")
        rows.append(runs.iloc[(len(runs) - 1) // 2])
    return pd.DataFrame(rows)


def plot_study_fronts(results: pd.DataFrame, problem: str, reference=None, objectives: Sequence[str] | None = None,
                      indicator: str | None = None, ax=None, trusted: bool = False):
    """The median run's front of each algorithm on one problem of a study.

    The true front is drawn when the problem knows one (rebuilt from its stored spec), or
    ``reference`` when given (e.g. ``optimal_front`` for rail problems). A spec that names code to
    import (``"module:factory"``) is rebuilt only when ``trusted``; otherwise its true front is left
    out with a warning, and nothing the results name is imported.
    """
    runs = representative_runs(results, problem, indicator)
    fronts = {row["algorithm"]: row["F"][row["CV"] <= 0] for _, row in runs.iterrows()}
    fronts = {k: v for k, v in fronts.items() if len(v)}
    if not fronts:
        raise ValueError(f"no feasible front on problem {problem!r}")
    if reference is None and "problem_spec" in runs.columns:
        reference = _true_front_of(runs.iloc[0]["problem_spec"], trusted)
    if objectives is None and "problem_spec" in runs.columns:
        names = runs.iloc[0]["problem_spec"].get("objectives")
        if isinstance(names, list) and len(names) == next(iter(fronts.values())).shape[1]:
            objectives = names
    title = f"{problem}: median run of each algorithm"
    return plot_fronts(fronts, objectives, reference=reference,
                       reference_label="true front" if reference is not None else "", title=title, ax=ax)


def _true_front_of(spec: dict, trusted: bool):
    from pymoo_rail.experiments.metrics import true_front
    from pymoo_rail.experiments.registry import build_problem
    from pymoo_rail.experiments.spec import ProblemSpec, StudyError

    try:
        problem = build_problem(ProblemSpec.from_dict(spec), trusted)
    except (StudyError, ValueError, ImportError, OSError) as err:  # a spec that no longer builds (module or case
        # gone) or is not trusted: the fronts are still worth drawing, without the true one
        name = spec.get("problem") if isinstance(spec, dict) else spec
        warnings.warn(f"the true front of problem {name!r} is not drawn: {err}", stacklevel=3)
        return None
    pf = true_front(problem)
    return pf if pf is not None and pf.shape[1] >= 2 else None
