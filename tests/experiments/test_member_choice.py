"""One rule picks a front member (experiments.fronts), one loop picks the best seed."""

from __future__ import annotations

import numpy as np
from pymoo.algorithms.soo.nonconvex.de import DE
from pymoo.optimize import minimize
from pymoo.problems import get_problem

import pandas as pd
import pytest

from pymoo_rail.experiments import (Study, algorithm, best_of_seeds, best_run, choose_member, load_results, problem,
                                     punctual_member, run_study, tang2020_nsga2)
from pymoo_rail.experiments.registry import build_algorithm, build_problem


def test_punctual_member_is_the_least_energy_inside_the_window_among_feasible_members():
    time_s = np.array([150.4, 149.7, 150.9, 151.5, 150.0])
    energy = np.array([19.0, 18.5, 18.0, 17.0, 18.5])
    cv = np.array([0.0, 0.0, 0.3, 0.0, 0.0])  # the cheapest one inside 1 s is infeasible
    assert punctual_member(time_s, energy, 150.0, 1.0, cv) == 1  # 18.5 kWh; the tie with index 4: the first
    assert punctual_member(time_s, energy, 150.0, 1.0) == 2  # without constraints: 18.0 kWh at 150.9 s
    assert punctual_member(time_s, energy, 150.0, 0.1, cv) == 4
    assert punctual_member(time_s, energy, 140.0, 1.0, cv) is None  # nobody near 140 s


def test_choose_member_falls_back_to_the_closest_member_when_none_is_punctual():
    F = np.array([[19.0, 5.0], [18.0, 3.0], [17.0, 3.0]])
    running = np.array([155.0, 153.0, 147.0])
    energy = F[:, 0]
    assert choose_member(F, np.zeros(3), running, energy, 150.0, window_s=1.0) == 2  # |3 s| tie: 17 kWh
    # the emu study's "most punctual" is the same rule with a zero window
    assert choose_member(F, np.zeros(3), running, energy, 153.0, window_s=0.0) == 1


def test_best_run_is_the_lowest_feasible_stored_run(tmp_path):
    study = Study("best", problems=[problem("sphere", n_var=4)], algorithms=[algorithm("de", pop_size=10)],
                  seeds=3, budget={"n_gen": 5})
    run_study(study, tmp_path, workers=1, progress=False)
    results = load_results(tmp_path, study=study)
    row, x = best_run(results, "sphere")
    assert float(row.F[0, 0]) == min(float(F[0, 0]) for F in results.F) and np.array_equal(x, row.X[0])
    res = minimize(build_problem(study.problems[0]), DE(pop_size=10), ("n_gen", 5), seed=int(row.seed))
    assert np.array_equal(res.X, x)  # the stored run is the run itself, bit for bit


def test_best_of_seeds_keeps_the_lowest_feasible_result():
    problem = get_problem("sphere", n_var=4)
    results = {seed: best_of_seeds(problem, lambda: DE(pop_size=10), ("n_gen", 5), [seed]) for seed in (1, 2, 3)}
    best = best_of_seeds(problem, lambda: DE(pop_size=10), ("n_gen", 5), [1, 2, 3])
    assert float(best.F[0]) == min(float(r.F[0]) for r in results.values())
    assert np.array_equal(best.X, results[min(results, key=lambda s: float(results[s].F[0]))].X)


def test_best_run_skips_infeasible_members_and_takes_the_first_seed_on_ties():
    frame = pd.DataFrame({"run_id": ["a", "b", "c"], "problem": ["p"] * 3, "seed": [3, 1, 2],
                          "F": [np.array([[0.5]]), np.array([[1.0], [0.1]]), np.array([[0.5]])],
                          "X": [np.array([[3.0]]), np.array([[1.0], [1.1]]), np.array([[2.0]])],
                          "CV": [np.array([0.0]), np.array([0.0, 0.2]), np.array([0.0])]})
    row, x = best_run(frame)
    assert row.seed == 2 and x.tolist() == [2.0]  # 0.1 is infeasible; 0.5 twice: the lower seed
    assert best_run(frame[frame.seed == 1].assign(CV=[np.array([0.1, 0.2])])) is None
    with pytest.raises(ValueError, match="single-objective"):
        best_run(frame.assign(F=[np.zeros((1, 2))] * 3))


def test_the_tang_nsga2_spec_builds_the_papers_operators():
    spec = tang2020_nsga2(pop_size=20)
    algorithm = build_algorithm(spec, get_problem("zdt1"))
    assert algorithm.pop_size == 20
    assert algorithm.mating.crossover.prob.value == 0.9 and algorithm.mating.crossover.eta.value == 15
    assert algorithm.mating.mutation.prob_var.value == 0.01 and algorithm.mating.mutation.eta.value == 20
