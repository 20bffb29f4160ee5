"""The profile against the optimum is written as a labelled PNG file."""

import matplotlib

matplotlib.use("Agg")

import numpy as np  # noqa: E402

from pymoo_rail.optimal.plots import plot_profile  # noqa: E402
from pymoo_rail.sim import gradient_limit_partition, speed_code_programs  # noqa: E402


def test_profile_plot(tmp_path, yizhuang, yizhuang_sim, yizhuang_solver):
    optimal = yizhuang_solver.profile(150.0)
    bounds = gradient_limit_partition(yizhuang.line)
    codes = speed_code_programs(bounds, np.full(8, 60 / 3.6))[0]
    fig = plot_profile(optimal, {"60 km/h codes": yizhuang_sim.run(codes)}, path=tmp_path / "profile.png")
    ax = fig.axes[0]
    assert ax.get_xlabel() == "Distance (m)" and ax.get_ylabel() == "Speed (km/h)"
    labels = [t.get_text() for t in ax.get_legend().get_texts()]
    assert labels[0].startswith("speed limit") and len(labels) == 3
    # the speed limit is drawn in km/h: 55 at the ends, 80 in the middle
    limit = ax.get_lines()[0].get_ydata()
    assert np.isclose(limit.min(), 55.0) and np.isclose(limit.max(), 80.0)
    assert (tmp_path / "profile.png").stat().st_size > 10_000
