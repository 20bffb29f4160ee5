"""The one-objective baseline table: gaps to the certified (-single) and exact (-trip) optima, ranks, refusals."""

import copy

import numpy as np
import pytest

from pymoo_rail.experiments import read_study
from pymoo_rail.experiments.baseline import (ONE_OBJECTIVE, baseline_indicators, baseline_table, convergence,
                                             front_scorer, indicator_frame, instance_of, one_objective_optimum,
                                             performance_profile)
from pymoo_rail.experiments.registry import ALGORITHMS, canonical_name
from pymoo_rail.experiments.runner import execute_run
from pymoo_rail.experiments.spec import Budget, RunSpec, algorithm, problem
from pymoo_rail.suite import get_problem, list_families

SINGLE, TRIP = "generated-metro-single", "generated-metro-trip"
ALGORITHMS_RUN = (("ga", {"pop_size": 10}), ("random", {"n_points_per_iteration": 10}))


def _runs(family: str, n_eval: int = 200) -> list[dict]:
    spec = problem("suite_family", family=family, n_var=10, seed=1)
    return [{**execute_run(RunSpec(spec, algorithm(name, **params), seed, Budget("n_eval", n_eval))),
             "algorithm_label": name} for seed in (1, 2, 3) for name, params in ALGORITHMS_RUN]


@pytest.fixture(scope="module")
def single_records():
    return _runs(SINGLE)


@pytest.fixture(scope="module")
def trip_records():
    return _runs(TRIP)


def _with_front(record: dict, F) -> dict:
    record = copy.deepcopy(record)
    record["front"]["F"], record["front"]["CV"] = np.asarray(F, dtype=float).tolist(), [0.0] * len(F)
    return record


def test_the_certified_optimum_scores_gap_zero(single_records):
    instance = get_problem(SINGLE, n_var=10, seed=1)
    optimum, certificate = one_objective_optimum(instance)
    assert optimum == pytest.approx(instance.pareto_front()[0, 0], abs=1e-12)  # what pymoo's pareto_front() gives
    assert 0 < certificate < 0.01 * abs(optimum)
    scores = baseline_indicators(_with_front(single_records[0], [[optimum]]))
    assert scores["gap_kwh"] == 0.0 and scores["gap_pct"] == 0.0
    scale = instance.hv_reference_point()[0] - optimum
    assert scores["gap_resolved_pct"] == pytest.approx(100 * certificate / scale)  # raised to the certificate


def test_a_runs_gap_is_above_minus_the_certificate_and_its_pct_on_the_reference_distance(single_records):
    instance = get_problem(SINGLE, n_var=10, seed=1)
    optimum, certificate = one_objective_optimum(instance)
    frame = indicator_frame(single_records)
    assert len(frame) == 6 and (frame["n_obj"] == 1).all() and "igd_plus" not in frame
    assert (frame["gap_kwh"] >= -certificate).all()
    for record, (_, row) in zip(single_records, frame.iterrows()):
        F, CV = np.asarray(record["front"]["F"]).reshape(-1), np.asarray(record["front"]["CV"])
        assert row["gap_kwh"] == pytest.approx(F[CV <= 0].min() - optimum)
    scale = instance.hv_reference_point()[0] - optimum
    np.testing.assert_allclose(frame["gap_pct"], 100 * frame["gap_kwh"] / scale)


def test_a_trip_record_scores_against_the_exact_split(trip_records):
    from pymoo.core.evaluator import Evaluator
    from pymoo.core.population import Population

    from pymoo_rail.journeys import project_to_budget

    instance = get_problem(TRIP, n_var=10, seed=1)
    times, energy = instance.optimum
    assert one_objective_optimum(instance) == (energy, 0.0)
    X = np.vstack([times, project_to_budget(np.random.default_rng(2).uniform(instance.xl, instance.xu),
                                            instance.xl, instance.xu, instance.total_time_s)])
    pop = Evaluator().eval(instance, Population.new(X=X))  # the exact split and another split of the same budget
    assert (pop.get("CV") <= 0).all()
    F = pop.get("F")
    assert baseline_indicators(_with_front(trip_records[0], F[:1]))["gap_kwh"] == pytest.approx(0.0, abs=1e-9)
    other = baseline_indicators(_with_front(trip_records[0], F[1:]))["gap_kwh"]
    assert other == pytest.approx(F[1, 0] - energy) and other > 0.1


def test_trip_runs_without_a_repair_find_no_feasible_split_and_score_nan(trip_records):
    # the trip's budget is an equality (pymoo's tolerance 1e-4 s): GA and random search never meet it
    # unrepaired, so their records are infeasible and score NaN (docs/suite.md, "Baseline table")
    frame = indicator_frame(trip_records)
    assert not any(r["feasible"] for r in trip_records)
    assert frame["gap_kwh"].isna().all() and frame["gap_pct"].isna().all()


def test_the_table_ranks_on_the_gap(single_records):
    table = baseline_table(indicator_frame(single_records))
    assert set(table.columns) >= {"gap_kwh", "gap_pct", "mean_rank", "mark"} and "igd_plus" not in table
    assert set(table["algorithm"]) == {"ga", "random"}
    assert table["mean_rank"].sum() == pytest.approx(3.0) and (table["mark"] == "best").sum() == 1
    profile = performance_profile(indicator_frame(single_records), taus=[1.0, 1e6])
    assert profile.loc[1.0].sum() >= 1.0  # the best of each pair is within tau = 1
    assert (profile.loc[1e6] == 1.0).all()  # every feasible run's resolved gap is positive and finite


def test_convergence_scores_the_best_energy_at_each_checkpoint():
    spec = problem("suite_family", family=SINGLE, n_var=10, seed=1)
    record = {**execute_run(RunSpec(spec, algorithm("ga", pop_size=20), 1, Budget("n_eval", 600))),
              "algorithm_label": "ga"}
    assert record["checkpoints"]["n_eval"] == [200, 500]
    assert all(len(F) <= 1 for F in record["checkpoints"]["F"])  # the best feasible energy, or none
    history = convergence([record])
    assert history["n_eval"].tolist() == [200, 500, 600] and set(ONE_OBJECTIVE.columns) <= set(history)
    gaps = history["gap_kwh"].dropna().to_numpy()
    assert (np.diff(gaps) <= 0).all()  # elitist GA: its best never gets worse


def test_bad_records_are_refused_or_score_nan(single_records):
    other = copy.deepcopy(single_records[0])
    other["inputs"]["problem instance checksum"] = "0" * 64
    with pytest.raises(ValueError, match="another definition"):
        instance_of(other)
    infeasible = copy.deepcopy(single_records[0])
    infeasible["front"]["CV"] = [1.0] * len(infeasible["front"]["CV"])
    assert set(baseline_indicators(infeasible)) == set(ONE_OBJECTIVE.columns)
    assert all(np.isnan(v) for v in baseline_indicators(infeasible).values())
    mixed = indicator_frame(single_records).assign(n_obj=[1, 1, 1, 2, 2, 2])
    with pytest.raises(ValueError, match="separate tables"):
        baseline_table(mixed)


def test_a_scorer_for_one_objective_has_the_optimum_as_its_front():
    scorer = front_scorer(get_problem(TRIP, n_var=10, seed=1))
    assert scorer.pf.shape == (1, 1) and scorer.certificate_kwh == 0.0 and scorer.hv_whole > 0
    assert scorer.indicators is ONE_OBJECTIVE


def _study_file(name: str):
    from pathlib import Path

    return read_study(Path(__file__).resolve().parents[2] / "benchmarks" / f"{name}.toml")


def _cells(study) -> list[tuple]:
    return sorted((p.params["family"], p.params["n_var"], p.params["seed"]) for p in study.problems)


def test_the_single_study_file_lists_every_single_family_on_the_ladder():
    study = _study_file("suite_baseline_single")
    single = {f for f in list_families() if f.endswith("-single")}
    assert len(single) == 4
    assert _cells(study) == sorted((f, n, 1) for f in single for n in (10, 30, 100, 300, 1000))
    assert [a.display for a in study.algorithms] == ["GA", "DE", "PSO", "ABC", "random"]
    assert all(ALGORITHMS[canonical_name(a.name)].objectives in ("single", "any") for a in study.algorithms)
    assert study.seeds == tuple(range(1, 32)) and study.budget.kind == "n_eval"
    assert len(list(study.runs())) == 3100


def test_the_trip_study_file_runs_the_same_five_algorithms_repaired_on_both_trip_families():
    study, single = _study_file("suite_baseline_trip"), _study_file("suite_baseline_single")
    trip = {f for f in list_families() if f.endswith("-trip")}
    assert len(trip) == 2
    assert _cells(study) == sorted((f, n, 1) for f in trip for n in (10, 30, 100, 300, 1000))
    assert [a.display for a in study.algorithms] == [a.display for a in single.algorithms]
    assert {a.name for a in study.algorithms} == {"pymoo_rail.journeys.repaired:repaired_algorithm"}
    # the same populations as the single table, each algorithm the repaired form of the same method
    for repaired, plain in zip(study.algorithms, single.algorithms):
        assert repaired.params == {"method": canonical_name(plain.name), **plain.params}
    assert study.seeds == single.seeds and study.budget == single.budget
    assert len(list(study.runs())) == 2 * 5 * 5 * 31
