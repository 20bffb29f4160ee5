"""The profile against the optimum: the one speed-profile plot (pymoo_rail.plotting) draws both runs."""

import matplotlib

matplotlib.use("Agg")

import numpy as np  # noqa: E402

from pymoo_rail.plotting import plot_speed_profile, save_figure  # noqa: E402
from pymoo_rail.sim import gradient_limit_partition, speed_code_programs  # noqa: E402


def test_profile_against_the_optimum(tmp_path, yizhuang, yizhuang_sim, yizhuang_solver):
    optimal = yizhuang_solver.profile(150.0)
    bounds = gradient_limit_partition(yizhuang.line)
    codes = yizhuang_sim.run(speed_code_programs(bounds, np.full(8, 60 / 3.6))[0])
    fig = plot_speed_profile(optimal, yizhuang, others=[codes], other_labels=["60 km/h codes"])
    ax = fig.axes[0]
    assert ax.get_xlabel() == "" and fig.axes[1].get_xlabel() == "position (m)"  # the gradient panel below
    assert ax.get_ylabel() == "speed (km/h)"
    lines = {line.get_label(): line for line in ax.get_lines()}
    # the limit over the train length is drawn in km/h: 55 at the ends, 80 in the middle
    limit = lines["limit over the train length"].get_ydata()
    assert np.isclose(limit.min(), 55.0) and np.isclose(limit.max(), 80.0)
    np.testing.assert_allclose(lines["60 km/h codes"].get_ydata(), codes.speed_kmh)
    assert f"E = {optimal.energy.net_kwh:.2f} kWh" in ax.get_title()
    save_figure(fig, tmp_path / "profile.png")
    assert (tmp_path / "profile.png").stat().st_size > 10_000
