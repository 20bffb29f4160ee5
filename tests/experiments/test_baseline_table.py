"""The suite baseline table: indicators of family-instance records, checksum refusal, ranks, profiles."""

import copy

import numpy as np
import pandas as pd
import pytest

from pymoo_rail.experiments.baseline import (baseline_indicators, baseline_table, checkpoints_kb, convergence,
                                             indicator_frame, instance_of, leaders_by_checkpoint, performance_profile,
                                             rank_by_dimension, top_group_by_dimension)
from pymoo_rail.experiments.runner import execute_run
from pymoo_rail.experiments.spec import Budget, RunSpec, algorithm, problem
from pymoo_rail.suite import get_problem

FAMILY = "generated-metro-bi"


@pytest.fixture(scope="module")
def records():
    spec = problem("suite_family", family=FAMILY, n_var=10, seed=1)
    out = []
    for seed in (1, 2, 3):
        for name, params in (("nsga2", {"pop_size": 20}), ("random", {"n_points_per_iteration": 20})):
            record = execute_run(RunSpec(spec, algorithm(name, **params), seed, Budget("n_eval", 200)))
            out.append({**record, "algorithm_label": name})
    return out


def test_the_certified_front_scores_perfectly(records):
    instance = get_problem(FAMILY, n_var=10, seed=1)
    pf = instance.pareto_front()
    record = copy.deepcopy(records[0])
    record["front"]["F"], record["front"]["CV"] = pf.tolist(), [0.0] * len(pf)
    scores = baseline_indicators(record)
    assert scores["igd_plus"] == pytest.approx(0.0, abs=1e-9)
    assert scores["hv_norm"] == pytest.approx(1.0)


def test_runs_score_inside_the_bounds(records):
    frame = indicator_frame(records)
    assert len(frame) == 6 and set(frame["algorithm"]) == {"nsga2", "random"}
    assert (frame["igd_plus"] > 0).all()
    assert ((frame["hv_norm"] > 0) & (frame["hv_norm"] < 1)).all()
    assert (frame["gap_kwh"].dropna() > -1e-6).all()  # above the optimum, up to its certificate


def test_a_record_without_feasible_members_scores_nan(records):
    record = copy.deepcopy(records[0])
    record["front"]["CV"] = [1.0] * len(record["front"]["CV"])
    assert all(np.isnan(v) for v in baseline_indicators(record).values())


def test_a_record_of_another_definition_is_refused(records):
    record = copy.deepcopy(records[0])
    record["inputs"]["problem instance checksum"] = "0" * 64
    with pytest.raises(ValueError, match="another definition"):
        instance_of(record)


def test_the_table_ranks_every_algorithm_of_a_cell(records):
    table = baseline_table(indicator_frame(records))
    assert set(table["algorithm"]) == {"nsga2", "random"}
    assert table["mean_rank"].is_monotonic_increasing
    assert table["mean_rank"].sum() == pytest.approx(3.0)  # ranks 1 and 2 share the seeds
    assert (table["mark"] == "best").sum() == 1
    assert table["runs"].tolist() == [3, 3]


def test_performance_profile_reaches_one_for_the_best_at_tau_one():
    frame = pd.DataFrame({"family": "f", "n_var": 10, "n_obj": 2, "instance_seed": 1, "seed": [1, 1, 2, 2],
                          "algorithm": ["a", "b", "a", "b"], "igd_plus": [1.0, 2.0, 1.0, 4.0]})
    profile = performance_profile(frame, taus=[1.0, 2.0, 3.0, 4.0])
    assert profile["a"].tolist() == [1.0, 1.0, 1.0, 1.0]
    assert profile["b"].tolist() == [0.0, 0.5, 0.5, 1.0]


def test_a_suite_record_holds_raw_vectors_and_nothing_scored_against_the_front(records):
    record = records[0]
    assert not {"igd", "hv", "gd"} & set(record["indicators"]) and "igd" in record["unavailable"]
    assert not {"igd", "hv", "error"} & set(record["history"])
    checkpoints = record["checkpoints"]
    assert checkpoints["target_n_eval"] == [200] and checkpoints["n_eval"] == [200]  # 200 of the ladder, then the end
    F = np.asarray(checkpoints["F"][0])
    assert F.shape[1] == 2 and len(np.unique(F, axis=0)) == len(F)
    assert not any((F[j] <= F[i]).all() and (F[j] < F[i]).any() for i in range(len(F)) for j in range(len(F)))


def test_convergence_scores_each_checkpoint_and_the_final_front(records):
    spec = problem("suite_family", family=FAMILY, n_var=10, seed=1)
    longer = execute_run(RunSpec(spec, algorithm("nsga2", pop_size=70), 1, Budget("n_eval", 1200)))
    assert longer["checkpoints"]["target_n_eval"] == [200, 500, 1000]
    assert longer["checkpoints"]["n_eval"] == [210, 560, 1050]  # the first generation past each checkpoint
    history = convergence([{**longer, "algorithm_label": "nsga2"}])
    assert history["n_eval"].tolist() == [210, 560, 1050, 1260]
    assert history["target_n_eval"].tolist() == [200, 500, 1000, 1200]  # the final row stands for the budget
    final = baseline_indicators(longer)
    assert history.iloc[-1]["igd_plus"] == final["igd_plus"]
    # elitist NSGA-II: its front at 1000 evaluations is no worse than at 200 (it keeps its non-dominated members)
    assert history.iloc[2]["hv_norm"] >= history.iloc[0]["hv_norm"]
    assert set(convergence(records)["algorithm"]) == {"nsga2", "random"}


def test_a_3obj_record_scores_against_its_bounded_front(tmp_path, monkeypatch):
    monkeypatch.setenv("PYMOO_RAIL_CACHE_DIR", str(tmp_path))
    spec = problem("suite_family", family="generated-metro-3obj", n_var=10, seed=1)
    record = {**execute_run(RunSpec(spec, algorithm("ctaea", pop_size=15), 1, Budget("n_eval", 300))),
              "algorithm_label": "C-TAEA"}
    instance = get_problem("generated-metro-3obj", n_var=10, seed=1)
    bounded = instance.bounded_front()
    scores = baseline_indicators(record)
    assert scores["igd_plus"] > 0 and 0 < scores["hv_norm"] < 1 and scores["gap_kwh"] > -1e-6
    inner = copy.deepcopy(record)
    inner["front"]["F"], inner["front"]["CV"] = bounded.inner.tolist(), [0.0] * len(bounded.inner)
    best = baseline_indicators(inner)  # the inner points: IGD+ 0, HV their share of the outer bound's
    assert best["igd_plus"] == pytest.approx(0.0, abs=1e-9)
    assert best["hv_norm"] == pytest.approx(bounded.hv_inner / bounded.hv_outer)


def test_the_checkpoints_of_a_penalised_search_hold_true_objectives_and_violations():
    from pymoo.core.evaluator import Evaluator
    from pymoo.core.population import Population

    from pymoo_rail.experiments.penalty import PenalisedConstraints
    from pymoo_rail.experiments.runner import non_dominated_feasible, true_objectives

    instance = get_problem(FAMILY, n_var=10, seed=1)
    X = np.vstack([instance.xl, instance.xu, (instance.xl + instance.xu) / 2,
                   np.random.default_rng(3).uniform(instance.xl, instance.xu, (20, 10))])
    truth = Evaluator().eval(instance, Population.new(X=X))
    searched = Evaluator().eval(PenalisedConstraints(instance), Population.new(X=X))
    F, CV = true_objectives(searched, penalised=True)
    np.testing.assert_array_equal(F, truth.get("F"))
    np.testing.assert_allclose(CV, truth.get("CV").reshape(-1))
    assert (CV > 0).any() and not np.array_equal(searched.get("F"), F)  # the corners are infeasible, penalised
    kept = non_dominated_feasible(F, CV)
    feasible = F[CV <= 0]
    assert len(kept) <= len(feasible) and all(np.isclose(feasible, row, rtol=1e-9).all(axis=1).any() for row in kept)


@pytest.mark.parametrize("checkpoints", [{"n_eval": [200], "F": []}, {"n_eval": [200], "F": [[[1.0, 2.0, 3.0]]]},
                                         {"F": [[[1.0, 2.0]]]}, "200", {"n_eval": [200], "F": [[["a", 2.0]]]}])
def test_a_record_with_malformed_checkpoints_is_refused_naming_the_field(records, tmp_path, checkpoints):
    from pymoo_rail.experiments.store import RecordError, ResultStore

    store = ResultStore(tmp_path)
    store.prepare()
    good = copy.deepcopy(records[0])
    store.write(good)
    assert store.load(good["run_id"])["checkpoints"] == records[0]["checkpoints"]
    store.write({**good, "checkpoints": checkpoints})
    with pytest.raises(RecordError, match="field 'checkpoints'"):
        store.load(good["run_id"])


def test_the_report_states_the_size_of_the_checkpoints(records):
    import json

    sizes = sorted(len(json.dumps(r["checkpoints"], separators=(",", ":"))) / 1000 for r in records)
    assert checkpoints_kb(records) == f"median {np.median(sizes):.1f} kB, largest {sizes[-1]:.1f} kB"
    assert 0 < sizes[-1] < 30
    assert checkpoints_kb([]) == "no records"


def test_a_record_with_no_feasible_member_at_its_checkpoints_loads(records, tmp_path):
    from pymoo_rail.experiments.store import ResultStore

    store = ResultStore(tmp_path)
    store.prepare()
    record = {**copy.deepcopy(records[0]), "checkpoints": {"target_n_eval": [200], "n_eval": [200], "F": [[]]}}
    store.write(record)
    assert store.load(record["run_id"])["checkpoints"]["F"] == [[]]
    history = convergence([{**record, "front": {**record["front"], "CV": [1.0] * len(record["front"]["CV"])}}])
    assert history["igd_plus"].isna().all()  # nothing feasible: NaN at the checkpoint and at the end


def test_rank_by_dimension_averages_the_families_of_a_form():
    table = pd.DataFrame({
        "family": ["generated-metro-bi", "generated-metro-bi", "generated-suburban-bi", "generated-suburban-bi",
                   "generated-metro-bi", "generated-metro-bi", "generated-metro-3obj", "generated-metro-3obj"],
        "n_var": [10, 10, 10, 10, 300, 300, 10, 10],
        "algorithm": ["A", "B", "A", "B", "A", "B", "A", "B"],
        "mean_rank": [1.0, 2.0, 2.0, 1.0, 2.0, 1.0, 1.2, 1.8],
    })
    ranks = rank_by_dimension(table).set_index(["form", "algorithm"])
    assert list(ranks.columns) == ["n_var 10", "n_var 300"]
    assert ranks.loc[("bi", "A"), "n_var 10"] == pytest.approx(1.5)  # the mean of metro's 1 and suburban's 2
    assert ranks.loc[("bi", "B"), "n_var 300"] == pytest.approx(1.0)
    assert ranks.loc[("3obj", "A"), "n_var 10"] == pytest.approx(1.2)
    assert np.isnan(ranks.loc[("3obj", "A"), "n_var 300"])  # no 3obj cell at 300
    # within a form, sorted by the rank at the largest dimension: B first at 300
    assert list(ranks.loc["bi"].index) == ["B", "A"]


def test_rank_by_dimension_of_a_real_table(records):
    table = baseline_table(indicator_frame(records))
    ranks = rank_by_dimension(table)
    merged = ranks.merge(table, on="algorithm")
    assert np.allclose(merged["n_var 10"], merged["mean_rank"])


def test_rank_by_dimension_leaves_a_dimension_without_every_familys_ranks_empty():
    table = pd.DataFrame({
        "family": ["generated-metro-bi", "generated-suburban-bi", "generated-metro-bi", "generated-suburban-bi"],
        "n_var": [10, 10, 300, 300],
        "algorithm": ["A", "A", "A", "A"],
        "mean_rank": [1.0, 2.0, 1.0, np.nan],  # suburban at 300: too few paired seeds
    })
    ranks = rank_by_dimension(table).set_index(["form", "algorithm"])
    assert list(ranks.columns) == ["n_var 10", "n_var 300"]  # the column stays
    assert ranks.loc[("bi", "A"), "n_var 10"] == pytest.approx(1.5)
    assert np.isnan(ranks.loc[("bi", "A"), "n_var 300"])  # not metro's 1.0 alone


def test_top_group_counts_the_families_an_algorithm_wins_or_ties():
    table = pd.DataFrame({
        "family": ["generated-metro-bi"] * 2 + ["generated-suburban-bi"] * 2 + ["generated-metro-bi"] * 2
                  + ["generated-suburban-bi"] * 2,
        "n_var": [10, 10, 10, 10, 300, 300, 300, 300],
        "algorithm": ["A", "B"] * 4,
        "mean_rank": [1.0, 2.0, 1.9, 1.1, 1.0, 2.0, np.nan, np.nan],
        "mark": ["best", "-", "=", "best", "best", "=", "n/a", "n/a"],  # suburban at 300: too few seeds
    })
    top = top_group_by_dimension(table).set_index(["form", "algorithm"])
    assert list(top.columns) == ["n_var 10", "n_var 300"]
    assert top.loc[("bi", "A"), "n_var 10"] == "1 / 2"  # best on metro, tied with the best on suburban
    assert top.loc[("bi", "B"), "n_var 10"] == "1 / 1"  # separated from the best on metro
    assert top.loc[("bi", "B"), "n_var 300"] == "0 / 1"  # of metro alone: suburban has no ranks
    assert list(top.index) == list(rank_by_dimension(table).set_index(["form", "algorithm"]).index)


def test_leaders_count_the_cells_with_the_lowest_median_at_each_checkpoint():
    rows = []
    for family, n_var, checkpoint, values in [
            ("generated-metro-bi", 10, 200, {"A": (1, 2, 3), "B": (2, 3, 4)}),     # A's median 2 < B's 3
            ("generated-metro-bi", 10, 1000, {"A": (5, 5, 9), "B": (1, 1, 9)}),    # B leads later
            ("generated-metro-bi", 30, 200, {"A": (1, 1, 1), "B": (1, 1, 1)}),     # a tie: both count
            ("generated-metro-bi", 30, 1000, {"A": (np.nan,) * 3, "B": (np.nan,) * 3}),  # no feasible run: no leader
            ("generated-metro-3obj", 10, 200, {"A": (3, 3, 3), "B": (1, 9, 9)})]:  # the median, not the best seed
        for name, scores in values.items():
            rows += [{"family": family, "n_var": n_var, "algorithm": name, "seed": seed, "target_n_eval": checkpoint,
                      "igd_plus": score} for seed, score in enumerate(scores, start=1)]
    leaders = leaders_by_checkpoint(pd.DataFrame(rows), "igd_plus")
    assert list(leaders.columns) == ["form", "algorithm", "200 evals", "1,000 evals"]
    table = leaders.set_index(["form", "algorithm"])
    assert table.loc[("bi", "A")].tolist() == [2, 0] and table.loc[("bi", "B")].tolist() == [1, 1]
    assert table.loc[("3obj", "A")].tolist() == [1, 0] and table.loc[("3obj", "B")].tolist() == [0, 0]
    assert list(leaders["form"]) == ["3obj", "3obj", "bi", "bi"]
    assert list(leaders.loc[leaders["form"] == "bi", "algorithm"]) == ["B", "A"]  # most cells led at the budget first


def test_top_group_of_a_real_table(records):
    table = baseline_table(indicator_frame(records))
    top = top_group_by_dimension(table).set_index("algorithm")["n_var 10"]
    best = table.loc[table["mark"] == "best", "algorithm"].item()
    assert top[best].startswith("1 / ")


def test_an_empty_frame_is_named():
    with pytest.raises(ValueError, match="no records"):
        baseline_table(pd.DataFrame(columns=["family", "n_var", "n_obj", "seed", "algorithm"]))
