"""A closed-loop run with the driver advice shown along the way."""

from __future__ import annotations

import numpy as np

from pymoo_rail.constants import KMH_PER_MS
from pymoo_rail.plotting.profiles import plot_speed_profile
from pymoo_rail.plotting.style import REGIME_COLORS

# an advice's colour is its regime's (power is traction)
ACTION_COLORS = dict(zip(("power", "hold", "coast", "brake"), REGIME_COLORS))


def plot_advised_run(run, shown, case=None, plan=None, title: str | None = None):
    """Speed against distance of a run, the plan dashed, and each advice at its switch point.

    Parameters
    ----------
    run : Trajectory
        The run driven (e.g. :func:`pymoo_rail.control.closed_loop` with an
        :class:`~pymoo_rail.control.AdvisedDriving` driver).
    shown : sequence of (time_s, position_m, Advice)
        The advice the driver saw (:meth:`AdvisedDriving.seen`): a marker where each was first
        shown, labelled with the instruction and the time.
    case : Case, optional
        Adds the line's limits and gradient panel (as :func:`plot_speed_profile`).
    plan : Trajectory, optional
        The offline plan, dashed.

    Returns
    -------
    matplotlib.figure.Figure
    """
    others = [plan] if plan is not None else []
    fig = plot_speed_profile(run, case, others=others, other_labels=["plan"] if others else None,
                             title=title or "closed-loop run with driver advice", other_linestyle="--")
    ax = fig.axes[0]
    x = np.asarray(run.position_m, dtype=float)
    v_kmh = np.asarray(run.speed_ms, dtype=float) * KMH_PER_MS
    top = float(np.max(v_kmh)) if v_kmh.size else 1.0
    for k, (time_s, where_m, advice) in enumerate(shown):
        at = float(np.interp(where_m, x, v_kmh))
        color = ACTION_COLORS.get(advice.action, "black")
        ax.plot([where_m], [at], marker="v", color=color, markersize=7, zorder=5)
        ax.annotate(f"{advice.text()} (t {time_s:.0f} s)", (where_m, at),
                    xytext=(where_m, top * (1.05 + 0.07 * (k % 4))), fontsize=7, color=color,
                    rotation=0, ha="left", arrowprops={"arrowstyle": "-", "color": color, "lw": 0.6})
    ax.set_ylim(top=top * 1.4)
    return fig
