"""Where a study run's CPU goes: the parts add up, the kernel is among them, and nothing stays patched."""

import pymoo.core.problem
import pymoo.optimize
import pytest

from pymoo_rail.experiments import runner
from pymoo_rail.experiments.run_cost import PARTS, cpu_breakdown
from pymoo_rail.experiments.spec import Budget, RunSpec, algorithm, problem
from pymoo_rail.sim import Simulator


def test_the_parts_of_a_run_add_up_and_the_patches_are_undone():
    originals = (Simulator.run_batch, pymoo.core.problem.Problem.evaluate, pymoo.optimize.minimize,
                 runner.build_problem, runner.convergence_point)
    run = RunSpec(problem("suite_family", family="generated-metro-bi", n_var=10, seed=1),
                  algorithm("nsga2", pop_size=20), 1, Budget("n_eval", 200))
    parts, record = cpu_breakdown(run)
    assert set(parts) == {*PARTS, "total", "n_eval"} and parts["n_eval"] == 200
    assert all(parts[p] >= 0 for p in PARTS)
    assert parts["total"] == sum(parts[p] for p in PARTS)
    assert parts["kernel"] > 0 and parts["pymoo"] > 0  # 200 evaluations went through both
    assert (Simulator.run_batch, pymoo.core.problem.Problem.evaluate, pymoo.optimize.minimize,
            runner.build_problem, runner.convergence_point) == originals
    # the record of the timed run is the record of an untimed one
    untimed = runner.execute_run(run)
    assert record["front"] == untimed["front"] and record["history"] == untimed["history"]


def test_the_profile_rows_hold_each_run_and_the_shares_sum_to_a_hundred():
    from pymoo_rail.experiments.run_cost import cpu_profile, cpu_shares

    runs = [RunSpec(problem("suite_family", family="generated-metro-bi", n_var=10, seed=1),
                    alg, 1, Budget("n_eval", 200))
            for alg in (algorithm("nsga2", pop_size=20), algorithm("random"))]
    rows = list(cpu_profile(runs, warm_n_eval=40))
    assert [(row["instance"], row["algorithm"]) for row in rows] == [(r.problem.display, r.algorithm.display)
                                                                      for r in runs]  # warm-up runs not yielded
    assert all(row["n_eval"] == 200 and row["ms_per_eval"] == 1000 * row["total"] / 200 for row in rows)
    shares = cpu_shares(rows + rows)  # twice each run: same shares, same CPU per evaluation
    assert list(shares.index) == [r.algorithm.display for r in runs] and list(shares.columns) == [*PARTS, "ms_per_eval"]
    assert shares[list(PARTS)].sum(axis=1).to_numpy() == pytest.approx(100.0)
    assert shares["ms_per_eval"].to_numpy() == pytest.approx([row["ms_per_eval"] for row in rows])
