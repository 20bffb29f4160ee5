"""Figures: labelled axes with units, the right data on them, non-empty image files."""

from __future__ import annotations

import matplotlib

matplotlib.use("Agg")

import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402
import pandas as pd  # noqa: E402
import pytest  # noqa: E402
from matplotlib.collections import LineCollection  # noqa: E402

from pymoo_rail.experiments import Study, algorithm, load_results, problem, run_study  # noqa: E402
from pymoo_rail.plotting import (  # noqa: E402
    as_trace,
    convergence_frame,
    plot_boxplots,
    plot_convergence,
    plot_front,
    plot_fronts,
    plot_history,
    plot_speed_profile,
    plot_speed_time,
    plot_study,
    save_figure,
)
from pymoo_rail.sim import Simulator, gradient_limit_partition, speed_code_programs  # noqa: E402
from tests.conftest import make_case  # noqa: E402


def _png_ok(path) -> None:
    image = plt.imread(path)
    assert path.stat().st_size > 5000 and image.shape[0] > 200 and image.shape[1] > 200
    assert image[..., :3].std() > 0.05  # not a blank canvas


@pytest.fixture(scope="module")
def coasting_run(yizhuang_sim, yizhuang):
    """A speed-code run of yizhuang that uses all four regimes."""
    bounds = gradient_limit_partition(yizhuang.line)
    codes = np.array([50, 70, 60, 55, 65, 60, 40, 40])[: len(bounds) - 1] / 3.6
    return yizhuang_sim.run(speed_code_programs(bounds, codes)[0])


def test_speed_profile_draws_run_limits_gradients_and_regimes(coasting_run, yizhuang, tmp_path):
    fig = plot_speed_profile(coasting_run, yizhuang, label="speed codes")
    ax, ax_line = fig.axes[0], fig.axes[1]
    assert ax.get_ylabel() == "speed (km/h)"
    assert ax_line.get_xlabel() == "position (m)" and ax_line.get_ylabel() == "altitude (m)"
    (speed,) = [c for c in ax.collections if isinstance(c, LineCollection)]
    # colour = regime code: stretch k carries its code over its len - 1 cells
    cells = np.concatenate([np.full(len(seg) - 1, code) for seg, code in zip(speed.get_segments(), speed.get_array())])
    np.testing.assert_array_equal(cells, coasting_run.regime[:-1])
    np.testing.assert_allclose(np.concatenate([seg[:-1, 1] for seg in speed.get_segments()]),
                               coasting_run.speed_ms[:-1] * 3.6)
    assert set(np.unique(coasting_run.regime)) == {0, 1, 2, 3}
    limit = next(line for line in ax.get_lines() if line.get_label() == "limit over the train length")
    np.testing.assert_allclose(limit.get_ydata(), coasting_run.limit_ms * 3.6)
    raw = next(line for line in ax.get_lines() if line.get_label() == "line speed limit")
    assert max(raw.get_ydata()) == 80.0 and min(raw.get_ydata()) == 55.0  # table 5-1
    # the altitude panel ends at the integrated gradients of table 5-1 (-0.78 m at 2265 m)
    altitude = ax_line.get_lines()[0]
    assert altitude.get_ydata()[-1] == pytest.approx(yizhuang.line.altitude_m(2265.0))
    assert "-8‰" in [t.get_text() for t in ax_line.texts]
    path = save_figure(fig, tmp_path / "profile.png")
    _png_ok(path)


def test_neutral_sections_are_shaded_in_both_panels():
    case = make_case(line={"neutral_sections": [[800.0, 1100.0]],
                           "gradients": [[0.0, 1000.0, 5.0], [1000.0, 2000.0, -5.0]]})
    run = Simulator(case).flat_out()
    fig = plot_speed_profile(run, case)
    for ax in fig.axes[:2]:
        xs = [p.get_patch_transform().transform(p.get_path().vertices)[:, 0] for p in ax.patches]
        assert (800.0, 1100.0) in [(round(x.min(), 6), round(x.max(), 6)) for x in xs]
    assert "neutral section" in [t.get_text() for t in fig.axes[0].get_legend().get_texts()]
    plt.close(fig)


def test_speed_time_and_replot_from_csv(coasting_run, yizhuang, tmp_path):
    fig = plot_speed_time(coasting_run, yizhuang)
    ax = fig.axes[0]
    assert (ax.get_xlabel(), ax.get_ylabel()) == ("time (s)", "speed (km/h)")
    planned = next(line for line in ax.get_lines() if line.get_label().startswith("planned time"))
    assert planned.get_xdata()[0] == 150.0
    _png_ok(save_figure(fig, tmp_path / "st.png"))

    csv = tmp_path / "trajectory.csv"
    coasting_run.to_frame().to_csv(csv, index=False)
    trace = as_trace(csv)
    np.testing.assert_allclose(trace.speed_kmh, coasting_run.speed_ms * 3.6)
    np.testing.assert_array_equal(trace.regime, coasting_run.regime)
    fig = plot_speed_profile(csv)
    assert fig.axes[0].get_xlabel() == "position (m)"
    plt.close(fig)
    with pytest.raises(ValueError, match="lacks column"):
        as_trace(pd.DataFrame({"x": [1.0]}))


def test_front_plots_label_objectives_with_units(tmp_path):
    F = np.column_stack([np.linspace(14, 20, 10), np.linspace(20, 0, 10)])
    reference = np.column_stack([np.linspace(13, 19, 30), np.linspace(20, 0, 30)])
    fig = plot_front(F, ["energy", "time_error"], reference=reference, highlight=F[-1])
    ax = fig.axes[0]
    assert ax.get_xlabel() == "energy (kWh)" and ax.get_ylabel().endswith("(s)")
    ref_line = next(line for line in ax.get_lines() if line.get_label() == "optimal front")
    np.testing.assert_allclose(ref_line.get_xdata(), reference[:, 0])
    _png_ok(save_figure(fig, tmp_path / "front.png"))
    fig = plot_fronts({"a": np.random.default_rng(1).random((20, 3))})
    assert fig.axes[0].get_zlabel() == "f3"
    plt.close(fig)
    with pytest.raises(ValueError, match="4 objectives are drawn as a scatter matrix"):
        plot_front(np.ones((3, 4)), ax=fig.axes[0])
    with pytest.raises(ValueError, match="reference has 2 objectives"):
        plot_front(np.ones((3, 4)), reference=reference)
    with pytest.raises(ValueError, match="NaN"):
        plot_front(np.array([[1.0, np.nan]]))


def test_four_objectives_make_a_scatter_matrix_with_every_pair(tmp_path):
    rng = np.random.default_rng(2)
    F = rng.random((25, 4))
    names = ["energy", "time_error", "jerk", "stop_error"]
    fig = plot_fronts({"nsga2": F, "moabc": rng.random((10, 4))}, names, reference=rng.random((40, 4)),
                      highlight=F[3], title="four objectives")
    panels = [ax for ax in fig.axes if ax.axison]
    assert len(panels) == 4 * 5 // 2  # 6 pairs below the diagonal and 4 histograms on it
    pair = fig.axes[1 * 4 + 0]  # row 1 (time_error) against column 0 (energy)
    np.testing.assert_allclose(pair.collections[1].get_offsets(), F[:, [0, 1]])
    assert pair.get_ylabel().endswith("(s)") and fig.axes[3 * 4 + 0].get_xlabel() == "energy (kWh)"
    assert [t.get_text() for t in fig.legends[0].get_texts()] == ["optimal front", "nsga2 (25)", "moabc (10)",
                                                                  "chosen"]
    _png_ok(save_figure(fig, tmp_path / "front4.png"))


def test_convergence_frame_by_hand():
    results = pd.DataFrame({"problem": ["P", "P"], "algorithm": ["A", "A"], "history": [
        {"n_eval": [10, 20, 30], "igd": [3.0, 2.0, 1.0]},
        {"n_eval": [10, 25, 30], "igd": [4.0, 2.0, 0.0]},
    ]})
    frame = convergence_frame(results, "igd", "P")
    np.testing.assert_array_equal(frame["n_eval"], [10, 20, 25, 30])
    # the runs hold (3, 2, 2, 1) and (4, 4, 2, 0) on that grid
    np.testing.assert_array_equal(frame["median"], [3.5, 3.0, 2.0, 0.5])


@pytest.fixture(scope="module")
def tiny_results(tmp_path_factory):
    directory = tmp_path_factory.mktemp("tiny")
    study = Study("tiny", [problem("zdt1", n_var=6), problem("zdt2", n_var=6)],
                  [algorithm("nsga2", pop_size=10), algorithm("moead", pop_size=10)], seeds=3, budget={"n_gen": 6})
    run_study(study, directory, workers=1, progress=False)
    return load_results(directory)


def test_convergence_and_box_plots_of_a_study(tiny_results, tmp_path):
    fig = plot_convergence(tiny_results, "igd")
    assert [ax.get_title() for ax in fig.axes if ax.get_visible()] == ["zdt1", "zdt2"]
    for ax in fig.axes:
        assert (ax.get_xlabel(), ax.get_ylabel()) == ("function evaluations", "IGD")
        assert {t.get_text() for t in ax.get_legend().get_texts()} == {"moead (3 runs)", "nsga2 (3 runs)"}
    _png_ok(save_figure(fig, tmp_path / "conv.png"))
    fig = plot_boxplots(tiny_results, "hv")
    ax = fig.axes[0]
    assert ax.get_ylabel() == "hypervolume (normalised)" and ax.get_xlabel() == "algorithm"
    assert [t.get_text() for t in ax.get_xticklabels()] == ["moead", "nsga2"]
    _png_ok(save_figure(fig, tmp_path / "box.png"))
    written = plot_study(tiny_results, tmp_path / "figures")
    assert {p.name for p in written} >= {"box_igd.png", "convergence_igd.png", "front_zdt1.png", "front_zdt2.png"}
    for path in written:
        assert path.stat().st_size > 5000


def test_history_of_a_pymoo_result():
    from pymoo.algorithms.moo.nsga2 import NSGA2
    from pymoo.optimize import minimize
    from pymoo.problems import get_problem

    res = minimize(get_problem("zdt1", n_var=5), NSGA2(pop_size=10), ("n_gen", 5), seed=1, save_history=True)
    fig = plot_history(res, "igd", label="nsga2")
    ax = fig.axes[0]
    assert ax.get_xlabel() == "function evaluations" and ax.get_ylabel() == "IGD"
    x = ax.get_lines()[0].get_xdata()
    np.testing.assert_array_equal(x, [10, 20, 30, 40, 50])
    plt.close(fig)


def test_saved_png_figures_use_a_palette_and_are_smaller(tmp_path):
    from PIL import Image

    def figure():
        fig, ax = plt.subplots(figsize=(7.0, 4.5))
        x = np.linspace(0.0, 10.0, 400)
        for k in range(6):
            ax.plot(x, np.sin(x + k), label=f"run {k}")
        ax.legend()
        ax.grid(True, alpha=0.3)
        return fig

    small = save_figure(figure(), tmp_path / "palette.png")
    full = save_figure(figure(), tmp_path / "full.png", palette=False)
    with Image.open(small) as a, Image.open(full) as b:
        assert a.mode == "P" and b.mode in ("RGB", "RGBA") and a.size == b.size
        # the palette keeps the picture: every pixel within a few levels of the full-colour one
        diff = np.abs(np.asarray(a.convert("RGB"), dtype=int) - np.asarray(b.convert("RGB"), dtype=int))
    assert np.percentile(diff, 99) <= 16
    assert small.stat().st_size < 0.6 * full.stat().st_size


def test_disconnected_true_front_is_drawn_as_points_connected_as_a_line():
    """ZDT3's five pieces are not bridged by a line; ZDT1's connected front (steep near f1 = 0) is one."""
    from pymoo.problems import get_problem

    from pymoo_rail.plotting.fronts import is_disconnected

    drawn = {}
    for name in ("zdt1", "zdt3"):
        pf = get_problem(name).pareto_front()
        fig = plot_fronts({"run": pf[::7]}, reference=pf)
        ax = fig.axes[0]
        drawn[name] = ([line.get_label() for line in ax.lines],
                       [c.get_label() for c in ax.collections])
        plt.close(fig)
    assert drawn["zdt1"][0] == ["optimal front"]
    assert drawn["zdt3"][0] == [] and "optimal front" in drawn["zdt3"][1]
    assert is_disconnected(get_problem("zdt3").pareto_front())
    # a flat step is a gap only where it is long: a small flat step inside a front is not
    line = np.column_stack([np.linspace(0, 1, 50), np.linspace(1, 0, 50)])
    assert not is_disconnected(line)
    gapped = np.vstack([line[:20], line[20:] + [0.3, -1e-9 - (line[20, 1] - line[19, 1])]])
    assert is_disconnected(gapped)
