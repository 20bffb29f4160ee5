"""Speed-distance and speed-time profiles of a run, with the line drawn underneath.

A profile accepts a :class:`pymoo_rail.sim.Trajectory` or the table ``Trajectory.to_frame()``
writes (``position_m``, ``time_s``, ``speed_kmh``, ``regime``, ``limit_kmh``), so a stored
CSV re-plots exactly like a live run.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Sequence

import numpy as np
import pandas as pd

from pymoo_rail.constants import KMH_PER_MS
from pymoo_rail.plotting.style import LIMIT_COLOR, NEUTRAL_COLOR, REGIME_COLORS, REGIME_NAMES, new_figure


@dataclass(frozen=True)
class Trace:
    """The arrays a profile plot needs, from a Trajectory or its table."""

    position_m: np.ndarray
    time_s: np.ndarray
    speed_kmh: np.ndarray
    regime: np.ndarray  # codes 0 traction, 1 cruise, 2 coast, 3 brake
    limit_kmh: np.ndarray | None
    energy_kwh: float | None = None
    running_time_s: float | None = None


def as_trace(run) -> Trace:
    """A :class:`Trace` of a Trajectory or of a trajectory table (DataFrame or CSV path)."""
    if isinstance(run, Trace):
        return run
    if isinstance(run, (str, bytes)) or hasattr(run, "__fspath__"):
        run = pd.read_csv(run)
    if isinstance(run, pd.DataFrame):
        missing = [c for c in ("position_m", "time_s", "speed_kmh", "regime") if c not in run.columns]
        if missing:
            raise ValueError(f"trajectory table lacks column(s) {missing} (has {list(run.columns)})")
        regime = run["regime"].to_numpy()
        if regime.dtype.kind in "OUS":
            regime = np.where(regime == "cruise", "hold", regime)  # tables written before "hold"
            unknown = sorted(set(regime) - set(REGIME_NAMES))
            if unknown:
                raise ValueError(f"trajectory table: regime {unknown[0]!r} is unknown (known: {REGIME_NAMES})")
            regime = np.array([REGIME_NAMES.index(r) for r in regime])
        time_s = run["time_s"].to_numpy(float)
        return Trace(run["position_m"].to_numpy(float), time_s, run["speed_kmh"].to_numpy(float),
                     regime.astype(int), run["limit_kmh"].to_numpy(float) if "limit_kmh" in run.columns else None,
                     running_time_s=float(time_s[-1]))
    try:
        return Trace(np.asarray(run.position_m, float), np.asarray(run.time_s, float),
                     np.asarray(run.speed_ms, float) * KMH_PER_MS, np.asarray(run.regime, int),
                     np.asarray(run.limit_ms, float) * KMH_PER_MS, energy_kwh=float(run.energy.net_kwh),
                     running_time_s=float(run.running_time_s))
    except AttributeError:
        raise TypeError(f"cannot plot a {type(run).__name__}: give a Trajectory or its table") from None


def _regime_line(ax, x: np.ndarray, v: np.ndarray, regime: np.ndarray, lw: float = 2.0) -> None:
    """The speed curve coloured by regime: one polyline per stretch of constant regime (cell k
    from node k to node k + 1 carries ``regime[k]``)."""
    from matplotlib.collections import LineCollection
    from matplotlib.colors import ListedColormap

    codes = np.clip(np.asarray(regime[: len(x) - 1], dtype=int), 0, len(REGIME_COLORS) - 1)
    starts = np.concatenate([[0], np.flatnonzero(np.diff(codes)) + 1])
    ends = np.concatenate([starts[1:], [len(codes)]])
    points = np.column_stack([x, v])
    lines = LineCollection([points[a: b + 1] for a, b in zip(starts, ends)], cmap=ListedColormap(REGIME_COLORS),
                           linewidths=lw, zorder=3, capstyle="round", joinstyle="round")
    lines.set_array(codes[starts].astype(float))
    lines.set_clim(-0.5, len(REGIME_COLORS) - 0.5)
    ax.add_collection(lines)
    ax.set_xlim(x.min(), x.max())


def _regime_legend(ax, extra=()) -> None:
    from matplotlib.lines import Line2D

    handles = [Line2D([], [], color=c, lw=2.5, label=n) for c, n in zip(REGIME_COLORS, REGIME_NAMES)]
    ax.legend(handles=handles + list(extra), fontsize="small", loc="lower center", ncol=4, framealpha=0.9)


def _shade_neutral(axes, line) -> list:
    handles = []
    if line is None:
        return handles
    from matplotlib.patches import Patch

    for start, end in line.neutral_sections:
        for ax in axes:
            ax.axvspan(start, end, color=NEUTRAL_COLOR, alpha=0.3, lw=0, zorder=0)
    if line.neutral_sections:
        handles.append(Patch(color=NEUTRAL_COLOR, alpha=0.3, label="neutral section"))
    return handles


def _line_limits(ax, line):
    xs, vs = [], []
    for start, end, kmh in line.speed_limits:
        xs += [start, end]
        vs += [kmh, kmh]
    (handle,) = ax.plot(xs, vs, color="0.55", lw=1.0, ls=":", label="line speed limit", zorder=2)
    return handle


def _gradient_panel(ax, line) -> None:
    """Altitude (relative to the start) with each gradient section's permille written on it."""
    x = np.linspace(0.0, line.length_m, 600)
    knots = sorted({0.0, line.length_m, *(row[0] for row in line.gradients), *(row[1] for row in line.gradients)})
    x = np.union1d(x, knots)
    h = line.altitude_m(x)
    ax.fill_between(x, h, h.min() - 0.1 * (np.ptp(h) + 1.0), color="0.85", zorder=1)
    ax.plot(x, h, color="0.25", lw=1.2, zorder=2)
    span = np.ptp(h) + 1.0
    top = ax.get_xaxis_transform()  # x in metres, y as a fraction of the panel
    labelled = [row for row in line.gradients if row[1] - row[0] >= 0.035 * line.length_m]  # legible ones
    stagger = len(labelled) > 12  # many sections: alternate two rows so neighbours do not touch
    for k, (start, end, permille) in enumerate(labelled):
        ax.text(0.5 * (start + end), 0.97 - (0.14 if stagger and k % 2 else 0.0), f"{permille:+g}‰",
                transform=top, ha="center", va="top", fontsize="x-small", color="0.2")
    for row in line.gradients[1:]:
        ax.axvline(row[0], color="0.7", lw=0.5, zorder=0)
    ax.set_ylabel("altitude (m)")
    ax.set_ylim(h.min() - 0.1 * span, h.max() + 0.6 * span)


def _end_speed_marker(ax, case):
    """The arrival speed the case asks for at the end of the line: a point, or a bar for a window."""
    lo, hi = (v * KMH_PER_MS for v in case.end_speed_window_ms())
    x = case.line.length_m
    h = ax.errorbar([x], [0.5 * (lo + hi)], yerr=[[0.5 * (hi - lo)], [0.5 * (hi - lo)]], fmt="D", color="k",
                    ms=5, capsize=4, zorder=4, label="end speed asked for" if lo == hi else "end speed window")
    return h


def plot_speed_profile(run, case=None, label: str | None = None, others: Sequence = (), other_labels=None,
                       title: str | None = None, show_line_limits: bool = True, other_linestyle: str = "-"):
    """Speed against distance, coloured by regime, over the line.

    Parameters
    ----------
    run : Trajectory or trajectory table
    case : Case, optional
        Adds the raw line limits, the neutral sections (shaded) and a gradient panel (altitude
        with the permille of each section). Without it only the run and its limit are drawn.
    label : str, optional
        Name of the run in the title.
    others : sequence of runs, optional
        Further runs drawn as thin grey lines for comparison (e.g. the optimal profile).
    title : str, optional
    show_line_limits : bool
    other_linestyle : str
        Matplotlib line style of ``others`` (e.g. ``"--"`` for the optimal profile).

    Returns
    -------
    matplotlib.figure.Figure
        Top axes: ``position (m)`` / ``speed (km/h)``; bottom axes (with a case): altitude.
    """
    trace = as_trace(run)
    line = case.line if case is not None else None
    if line is not None:
        fig, axes = new_figure(2, 1, figsize=(9.0, 6.0), sharex=True, gridspec_kw={"height_ratios": [3, 1]})
        ax, ax_line = axes[0, 0], axes[1, 0]
    else:
        fig, axes = new_figure(figsize=(9.0, 4.5))
        ax, ax_line = axes[0, 0], None

    extra = []
    if trace.limit_kmh is not None:
        (h,) = ax.plot(trace.position_m, trace.limit_kmh, color=LIMIT_COLOR, lw=1.2, ls="--",
                       label="limit over the train length", zorder=2)
        extra.append(h)
    if line is not None and show_line_limits:
        extra.append(_line_limits(ax, line))
    other_labels = list(other_labels) if other_labels is not None else [f"run {i + 2}" for i in range(len(others))]
    for other, other_label in zip(others, other_labels):
        o = as_trace(other)
        (h,) = ax.plot(o.position_m, o.speed_kmh, color="0.4", lw=1.0, ls=other_linestyle, label=other_label,
                       zorder=2)
        extra.append(h)
    if case is not None and case.end_speed_window_ms()[1] > 0.0:
        extra.append(_end_speed_marker(ax, case))
    _regime_line(ax, trace.position_m, trace.speed_kmh, trace.regime)
    top = max(np.nanmax(trace.speed_kmh), np.nanmax(trace.limit_kmh) if trace.limit_kmh is not None else 0.0)
    ax.set_ylim(0.0, 1.15 * top + 1.0)
    ax.set_xlim(0.0, line.length_m if line is not None else trace.position_m.max())
    ax.set_ylabel("speed (km/h)")
    ax.grid(True, alpha=0.3)
    if ax_line is not None:
        _gradient_panel(ax_line, line)
        ax_line.set_xlabel("position (m)")
    else:
        ax.set_xlabel("position (m)")
    extra += _shade_neutral([ax] + ([ax_line] if ax_line is not None else []), line)
    _regime_legend(ax, extra)
    if title is None:
        parts = [label] if label else []
        if case is not None:
            parts.append(case.name)
        if trace.running_time_s is not None:
            parts.append(f"T = {trace.running_time_s:.1f} s")
        if trace.energy_kwh is not None:
            parts.append(f"E = {trace.energy_kwh:.2f} kWh")
        title = ", ".join(parts)
    if title:
        ax.set_title(title)
    return fig


def plot_speed_time(run, case=None, title: str | None = None):
    """Speed against time, coloured by regime, with the planned running time when a case is given."""
    trace = as_trace(run)
    fig, axes = new_figure(figsize=(9.0, 4.5))
    ax = axes[0, 0]
    extra = []
    if trace.limit_kmh is not None:
        (h,) = ax.plot(trace.time_s, trace.limit_kmh, color=LIMIT_COLOR, lw=1.2, ls="--",
                       label="limit over the train length", zorder=2)
        extra.append(h)
    _regime_line(ax, trace.time_s, trace.speed_kmh, trace.regime)
    if case is not None:
        extra.append(ax.axvline(case.planned_time_s, color="0.3", lw=1.0, ls="-.",
                                label=f"planned time {case.planned_time_s:g} s"))
    right = max(trace.time_s.max(), case.planned_time_s if case is not None else 0.0)
    ax.set_xlim(0.0, 1.02 * right)
    top = max(np.nanmax(trace.speed_kmh), np.nanmax(trace.limit_kmh) if trace.limit_kmh is not None else 0.0)
    ax.set_ylim(0.0, 1.15 * top + 1.0)
    ax.set_xlabel("time (s)")
    ax.set_ylabel("speed (km/h)")
    ax.grid(True, alpha=0.3)
    _regime_legend(ax, extra)
    if title is None and trace.running_time_s is not None:
        title = (f"{case.name + ', ' if case is not None else ''}T = {trace.running_time_s:.1f} s"
                 + (f", E = {trace.energy_kwh:.2f} kWh" if trace.energy_kwh is not None else ""))
    if title:
        ax.set_title(title)
    return fig
