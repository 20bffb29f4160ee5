"""The benchmark-function and ZDT studies (benchmarks/abc_functions.py, moabc_zdt.py,
grnsga2_zdt.py) run through the study runner: their specs build the algorithms the reports
describe (same seeded run, same front as the pymoo objects built by hand), and a reduced study
goes from ``run_study`` to the per-run CSV, the report and the figures."""

from __future__ import annotations

import importlib.util
import shutil
import sys
from pathlib import Path

import numpy as np
import pandas as pd
import pytest
from pymoo.optimize import minimize
from pymoo.problems import get_problem

from pymoo_rail.experiments import build_algorithm, build_problem, load_results, run_study

BENCHMARKS = Path(__file__).resolve().parents[2] / "benchmarks"


def _script(name: str):
    spec = importlib.util.spec_from_file_location(name, BENCHMARKS / f"{name}.py")
    module = importlib.util.module_from_spec(spec)
    sys.modules.setdefault(name, module)
    spec.loader.exec_module(module)
    return module


def _same_front(spec, problem_spec, by_hand, problem, termination, seed: int) -> None:
    built = build_algorithm(spec, build_problem(problem_spec))
    a = minimize(build_problem(problem_spec), built, termination, seed=seed).F
    b = minimize(problem, by_hand, termination, seed=seed).F
    np.testing.assert_array_equal(a, b)


def test_grnsga2_specs_are_the_seed_settings():
    from pymoo.algorithms.moo.nsga2 import NSGA2
    from pymoo.operators.crossover.sbx import SBX
    from pymoo.operators.mutation.pm import PM

    from pymoo_rail.algorithms import GoldenRatioNSGA2

    gr = _script("grnsga2_zdt")
    study = gr.build_study(1, problems=("zdt2",), budget=1200)
    specs = {a.display: a for a in study.algorithms}
    assert study.baseline == "NSGA-II" and study.budget.to_dict() == {"n_eval": 1200}
    term = ("n_eval", 1200)
    _same_front(specs["NSGA-II"], study.problems[0], NSGA2(pop_size=200, crossover=SBX(prob=0.9, eta=15),
                mutation=PM(prob=1.0, prob_var=0.01, eta=20)), get_problem("zdt2"), term, 4)
    _same_front(specs["NSGA-II pm=1/n"], study.problems[0], NSGA2(pop_size=200, crossover=SBX(prob=0.9, eta=15),
                mutation=PM(prob=1.0, eta=20)), get_problem("zdt2"), term, 4)
    _same_front(specs["GR-NSGA-II"], study.problems[0],
                GoldenRatioNSGA2(pop_size=200, local_size=40, pc_max=0.9, pm_max=0.1), get_problem("zdt2"), term, 4)


def test_grnsga2_reduced_study_gives_runs_report_and_fronts(tmp_path):
    gr = _script("grnsga2_zdt")
    study = gr.build_study(2, problems=("zdt1",), budget=800)
    report = run_study(study, tmp_path / "work", workers=1, progress=False, seed_major=True)
    assert (report.n_runs, report.n_finished) == (8, 8)
    out = tmp_path / "rep"
    out.mkdir()
    gr.write_report_files(out, load_results(tmp_path / "work", study=study), ["zdt1"], list(gr.ALGORITHMS))
    table = pd.read_csv(out / "grnsga2_zdt_runs.csv")
    assert len(table) == 8 and set(table.algorithm) == set(gr.ALGORITHMS) and set(table.seed) == {1, 2}
    assert (table.n_eval >= 800).all() and (table.cpu_s > 0).all() and (table.igd > 0).all()
    # the local search is counted only where there is one
    local = table.set_index("algorithm")["n_accepted"]
    assert (local.loc["GR-NSGA-II"] > 0).all() and (local.loc["GR-NSGA-II no LS"] == 0).all()
    assert local.loc[["NSGA-II", "NSGA-II pm=1/n"]].isna().all()
    text = (out / "grnsga2_zdt.md").read_text()
    assert "Runs per problem and algorithm: 2" in text and (out / "grnsga2_zdt1_fronts.png").stat().st_size > 0
    assert "Reading (30-run study)" not in text  # the 30-run reading is not shown for other studies
    _rebuilt_from_csv_alone(out, "grnsga2_zdt_runs.csv", "grnsga2_zdt.md", tmp_path / "none",
                            lambda o, r: gr.write_report_files(o, r, ["zdt1"], list(gr.ALGORITHMS)))


def _rebuilt_from_csv_alone(out: Path, csv_name: str, report_name: str, no_records: Path, write) -> None:
    """Without records, the report is rebuilt from the exported CSV alone, with the same numbers."""
    again = out.parent / "from_csv"
    shutil.copytree(out, again)  # the committed CSV and figures
    (again / report_name).unlink()
    write(again, load_results(no_records))
    assert (again / csv_name).read_bytes() == (out / csv_name).read_bytes()  # not rewritten
    first, second = (d / report_name for d in (out, again))
    differ = [(a, b) for a, b in zip(first.read_text().splitlines(), second.read_text().splitlines()) if a != b]
    assert len(first.read_text().splitlines()) == len(second.read_text().splitlines())
    assert len(differ) == 1 and "run records" in differ[0][1], differ  # only the sentence naming the source
    with pytest.raises(FileNotFoundError, match=csv_name):
        write(out.parent / "empty", load_results(no_records))


def test_moabc_study_cells_and_report(tmp_path):
    from pymoo.algorithms.moo.moead import MOEAD
    from pymoo.util.ref_dirs import get_reference_directions

    from pymoo_rail.algorithms import MOABC

    mz = _script("moabc_zdt")
    study = mz.build_study(1, budget=1000)
    assert [a.display for a in study.algorithms] == list(mz.ALGORITHMS) and study.seeds == (1000,)
    specs = {a.display: a for a in study.algorithms}
    term = ("n_eval", 1000)
    _same_front(specs["MOABC-literal"], study.problems[0],
                MOABC(pop_size=100, archive_size=100, move="literal"), get_problem("zdt1"), term, 1000)
    _same_front(specs["MOEAD"], study.problems[0],
                MOEAD(get_reference_directions("uniform", 2, n_partitions=99), n_neighbors=20),
                get_problem("zdt1"), term, 1000)

    small = type(study)(study.name, study.problems[:1], study.algorithms[:1] + study.algorithms[3:4],
                        seeds=study.seeds, budget=study.budget, baseline="NSGA2")
    run_study(small, tmp_path / "work", workers=1, progress=False)
    out = tmp_path / "rep"
    out.mkdir()
    mz.report(out, load_results(tmp_path / "work", study=small))
    table = pd.read_csv(out / "moabc_zdt.csv")
    assert list(table.algorithm) == ["MOABC-centred", "NSGA2"] and list(table.run) == [0, 0]
    assert (table.IGD > 0).all() and (table.HV >= 0).all() and table.SP.notna().all()
    assert (out / "moabc_zdt_fronts.png").exists() and "## ZDT1" in (out / "moabc_zdt.md").read_text()
    _rebuilt_from_csv_alone(out, "moabc_zdt.csv", "moabc_zdt.md", tmp_path / "none", mz.report)


def test_abc_function_studies_give_equal_budgets_curves_and_report(tmp_path):
    from pymoo.algorithms.soo.nonconvex.de import DE
    from pymoo.algorithms.soo.nonconvex.pso import PSO

    from pymoo_rail.experiments.functions import Sphere

    af = _script("abc_functions")
    studies = af.build_studies(1)
    assert sorted(studies) == [(10, 500), (20, 1000), (30, 1000), (30, 3000), (50, 5000)]
    assert studies[(50, 5000)].budget.to_dict() == {"n_eval": 30 * 5001}
    assert [p.display for p in studies[(30, 3000)].problems] == ["sphere"]
    assert [a.display for a in studies[(30, 3000)].algorithms] == ["ABC", "ABC-inverse"]

    specs = {a.display: a for a in studies[(10, 500)].algorithms}
    sphere = studies[(10, 500)].problems[0]
    term = ("n_eval", 600)
    _same_front(specs["PSO"], sphere, PSO(pop_size=30, w=0.8, c1=1.5, c2=1.5, adaptive=False, pertube_best=False),
                Sphere(10), term, 1000)
    _same_front(specs["DE"], sphere, DE(pop_size=30, variant="DE/rand/1/bin", CR=0.5, F=0.6, prob_mut=0.0),
                Sphere(10), term, 1000)

    settings, extra = [(3, 10)], [("sphere", 4, 12)]
    for (dim, iterations), study in af.build_studies(2, settings, extra).items():
        run_study(study, af.study_directory(tmp_path, dim, iterations), workers=1, progress=False)
    table, results = af.load_runs(tmp_path, 2, settings, extra)
    assert len(table) == 3 * 4 * 2 + 2 * 2
    assert (table.n_eval >= 30 * 11).all() and set(table.seed) == {1000, 1001}
    runs = results[(3, 10)]
    history = runs[(runs.problem == "rosenbrock") & (runs.algorithm == "ABC")].sort_values("seed").iloc[0].history
    curve = np.column_stack([history["n_eval"], history["f0_min"]])
    assert curve[0, 0] == 30 and np.all(np.diff(curve[:, 1]) <= 0)  # best-so-far never worsens
    best = table[(table.function == "rosenbrock") & (table.dim == 3) & (table.algorithm == "ABC")].best
    assert curve[-1, 1] == best.iloc[0]
    out = tmp_path / "rep"
    out.mkdir()
    af.report(out, table, results)
    assert len(pd.read_csv(out / "abc_functions.csv")) == len(table)
    assert (out / "abc_functions_d3-it10.png").exists() and "## What reproduces" in (out / "abc_functions.md").read_text()


@pytest.mark.parametrize("name", ["abc_functions", "moabc_zdt", "grnsga2_zdt"])
def test_scripts_keep_no_pool_or_csv_of_their_own(name):
    """Issue 5: the scripts run many seeds through the study runner, not a pool of their own."""
    text = (BENCHMARKS / f"{name}.py").read_text()
    assert "run_study(" in text and "ProcessPoolExecutor" not in text and "Pool(" not in text
