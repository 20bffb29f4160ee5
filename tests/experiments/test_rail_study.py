"""A study on the rail speed-profile problem: extras per front member, reference indicators,
the optional energy gap, and the wiring of GoldenRatioNSGA2's fixed genes."""

from __future__ import annotations


import numpy as np
import pandas as pd
import pytest

pytest.importorskip("pymoo_rail.problems")

from pymoo_rail.experiments import Study, algorithm, build_algorithm, build_problem, load_results, problem, run_study  # noqa: E402
from pymoo_rail.experiments.stats import add_energy_gap, add_reference_indicators  # noqa: E402


@pytest.fixture(scope="module")
def rail_results(tmp_path_factory):
    directory = tmp_path_factory.mktemp("rail")
    study = Study("rail", [problem("speed_profile", label="yizhuang", case="yizhuang",
                                   objectives=["energy", "time_error"])],
                  [algorithm("nsga2", pop_size=10), algorithm("sms-emoa", pop_size=10)], seeds=2,
                  budget={"n_gen": 3})
    report = run_study(study, directory, workers=1, progress=False)
    assert report.n_finished == 4 and not report.failures, str(report)
    return load_results(directory)


def test_rail_records_hold_running_time_energy_and_stop_error(rail_results, yizhuang):
    assert "igd" not in rail_results.columns  # no true front for a rail problem
    for _, row in rail_results.iterrows():
        extras = row["extras"]
        assert set(extras) == {"energy_kwh", "running_time_s", "stop_error_m"}
        np.testing.assert_allclose(row["F"][:, 0], extras["energy_kwh"])  # objective 1 is net energy
        np.testing.assert_allclose(row["F"][:, 1], np.abs(extras["running_time_s"] - yizhuang.planned_time_s))
        assert row["spacing"] >= 0
        assert "f0_min" in row["history"] and "igd" not in row["history"]


def test_reference_indicators_on_a_rail_problem(rail_results):
    out = add_reference_indicators(rail_results)
    assert out["igd_ref"].notna().all() and (out["igd_ref"] >= 0).all()
    assert ((out["hv_ref"] > 0) & (out["hv_ref"] <= 1.21)).all()


def test_energy_gap_uses_the_stored_feasible_front(rail_results):
    # the real indicator on a hand-made convex reference front (the solver is not needed for this)
    from pymoo_rail.indicators.energy import energy_gap

    reference = pd.DataFrame({"running_time_s": [130.0, 150.0, 200.0, 600.0],
                              "energy_kwh": [20.0, 12.0, 8.0, 2.0]})
    out = add_energy_gap(rail_results, {"yizhuang": reference})
    assert {"energy_gap", "energy_gap_max", "hv_ratio"} <= set(out.columns)
    for i, row in out.iterrows():
        feasible = rail_results["CV"][i] <= 0
        if not feasible.any():
            assert np.isnan(row["energy_gap"])
            continue
        extras = rail_results["extras"][i]
        front = pd.DataFrame({"running_time_s": extras["running_time_s"][feasible],
                              "energy_kwh": extras["energy_kwh"][feasible]})
        expected = energy_gap(front, reference)
        assert row["energy_gap"] == pytest.approx(expected["mean_gap_rel"], nan_ok=True)
        assert row["hv_ratio"] == pytest.approx(expected["hv_ratio"])


def test_golden_ratio_nsga2_keeps_neutral_section_genes_fixed():
    pytest.importorskip("pymoo_rail.algorithms.golden_ratio_nsga2")
    rail = build_problem(problem("speed_profile", case="wuguang-crh3"))
    mask = rail.encoding.fixed()
    assert mask.sum() == 2  # two neutral sections (seed 003, 4.2)
    gr = build_algorithm(algorithm("grnsga2", pop_size=20, local_size=4), rail)
    np.testing.assert_array_equal(gr.fixed_genes, mask)


def test_rail_convergence_is_labelled_with_the_objective(rail_results):
    import matplotlib.pyplot as plt

    from pymoo_rail.plotting import plot_convergence

    fig = plot_convergence(rail_results, "f0_min")
    assert fig.axes[0].get_ylabel() == "best energy (kWh)"
    assert fig.axes[0].get_xlabel() == "function evaluations"
    plt.close(fig)


def test_a_study_spec_names_the_tracking_controller_as_a_table():
    from pymoo_rail.control import Hysteresis
    from pymoo_rail.experiments import StudyError

    tracked = build_problem(problem("speed_profile", case="yizhuang", objectives=["energy"],
                                    tracking={"controller": "hysteresis", "a_kmh": 2.0, "b_kmh": 3.0}))
    assert tracked.tracker.controller == Hysteresis(2.0, 3.0)
    for bad in ({"a_kmh": 2.0}, {"controller": "bang-bang"}, "hysteresis"):
        with pytest.raises(StudyError, match="tracking"):
            build_problem(problem("speed_profile", case="yizhuang", objectives=["energy"], tracking=bad))
