"""Figures researchers publish: Pareto fronts, speed profiles over the line, convergence, box plots.

Every function returns a matplotlib ``Figure``; :func:`save_figure` writes it (PNG, PDF, SVG
from the suffix). matplotlib is imported when a figure is made, not at import time.
"""

from pymoo_rail.plotting.advice import plot_advised_run
from pymoo_rail.plotting.baseline import plot_cell_convergence, plot_performance_profile
from pymoo_rail.plotting.comparison import plot_boxplots
from pymoo_rail.plotting.convergence import convergence_frame, history_curve, plot_convergence, plot_history
from pymoo_rail.plotting.fronts import plot_front, plot_fronts, plot_study_fronts, representative_runs
from pymoo_rail.plotting.journey import plot_timed_run
from pymoo_rail.plotting.loop_study import plot_gap_lateness
from pymoo_rail.plotting.profiles import Trace, as_trace, plot_speed_profile, plot_speed_time
from pymoo_rail.plotting.speed_runs import plot_speed_runs
from pymoo_rail.plotting.study import plot_study
from pymoo_rail.plotting.style import OBJECTIVE_LABELS, REGIME_COLORS, save_figure

__all__ = ["plot_advised_run", "plot_front", "plot_fronts", "plot_study_fronts", "representative_runs", "plot_speed_profile",
           "plot_speed_time", "Trace", "as_trace", "plot_convergence", "convergence_frame", "plot_history",
           "history_curve", "plot_boxplots", "plot_study", "save_figure", "OBJECTIVE_LABELS", "REGIME_COLORS", "plot_timed_run",
           "plot_speed_runs", "plot_cell_convergence", "plot_performance_profile",
           "plot_gap_lateness"]
