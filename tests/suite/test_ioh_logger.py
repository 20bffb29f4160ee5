"""IOHprofiler logs of pymoo runs: written by ioh, read back by iohinspector, the HV gap recomputed."""

import numpy as np
import pytest
from iohinspector import DataManager
from pymoo.algorithms.moo.nsga2 import NSGA2
from pymoo.algorithms.soo.nonconvex.ga import GA
from pymoo.indicators.hv import HV
from pymoo.optimize import minimize

from pymoo_rail.suite import IOHLogger, get_problem


def _load(folder):
    manager = DataManager()
    manager.add_folder(str(folder))
    return manager.load(monotonic=False, include_meta_data=True).sort(["run_id", "evaluations"])


def test_a_bi_objective_log_round_trips_through_iohinspector(tmp_path):
    problem = get_problem("generated-metro-bi", n_var=10, seed=1)  # its front is shipped: no solve here
    finals = []
    with IOHLogger(tmp_path, "NSGA2", "population 12, 4 generations") as logger:
        for seed in (1, 2):
            res = minimize(problem, NSGA2(pop_size=12), ("n_gen", 4), seed=seed, callback=logger)
            finals.append(res)
    data = _load(tmp_path)
    assert set(data["function_name"]) == {"generated-metro-bi"} and set(data["algorithm_name"]) == {"NSGA2"}
    assert set(data["dimension"]) == {10} and set(data["instance"]) == {1}
    assert sorted(set(data["run_id"])) == [1, 2]
    for run_id, res in zip((1, 2), finals):
        run = data.filter(data["run_id"] == run_id)
        assert run["evaluations"].to_list() == list(range(1, 49))  # 12 x 4 evaluations, every one logged
        y = run["raw_y"].to_numpy()
        assert np.all(np.diff(y) <= 1e-12) and 0 < y[-1] < 1  # the archive's HV gap only falls
        F = np.column_stack([run["energy"].to_numpy(), run["running_time"].to_numpy()])
        feasible = run["cv"].to_numpy() <= 0
        # the final population is among the logged points
        logged = {tuple(np.round(f, 6)) for f in F}
        assert {tuple(np.round(f, 6)) for f in res.pop.get("F")} <= logged
        # the last raw_y is the HV gap of the logged feasible points, recomputed here
        ideal, ref = problem.ideal_point(), problem.hv_reference_point()
        hv = HV(ref_point=np.ones(2))
        z = (F[feasible] - ideal) / (ref - ideal)
        front = (problem.pareto_front() - ideal) / (ref - ideal)
        assert y[-1] == pytest.approx(1 - hv(z[np.all(z < 1, axis=1)]) / hv(front), abs=1e-9)


def test_a_single_objective_log_gives_the_gap_to_the_certified_optimum(tmp_path):
    problem = get_problem("generated-metro-single", n_var=6, seed=1)
    with IOHLogger(tmp_path, "GA") as logger:
        res = minimize(problem, GA(pop_size=8), ("n_gen", 3), seed=1, callback=logger)
    data = _load(tmp_path)
    energy, cv = data["energy"].to_numpy(), data["cv"].to_numpy()
    assert len(data) == 24 and (cv <= 0).any()
    best = energy[cv <= 0].min()
    optimum, ref = problem.pareto_front()[0, 0], problem.hv_reference_point()[0]
    assert data["raw_y"].to_numpy()[-1] == pytest.approx((best - optimum) / (ref - optimum), abs=1e-9)
    assert float(np.min(res.F)) == pytest.approx(best)


def test_an_algorithm_that_hides_its_evaluations_is_refused(tmp_path):
    problem = get_problem("generated-metro-bi", n_var=10, seed=1)

    class Hidden(NSGA2):
        def _advance(self, infills=None, **kwargs):
            super()._advance(infills=infills, **kwargs)
            self.off = None

    with IOHLogger(tmp_path, "hidden") as logger:
        with pytest.raises(RuntimeError, match="evaluated 12 points but reported 0"):
            minimize(problem, Hidden(pop_size=12), ("n_gen", 3), seed=1, callback=logger)
