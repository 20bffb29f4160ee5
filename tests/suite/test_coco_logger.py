"""COCO logs of pymoo runs: written in cocoex's bbob-biobj and bbob formats, read back by cocopp, indicators recomputed."""

import os
import subprocess
import sys
import warnings

import numpy as np
import pytest
from pymoo.algorithms.moo.nsga2 import NSGA2
from pymoo.algorithms.soo.nonconvex.ga import GA
from pymoo.indicators.hv import HV
from pymoo.optimize import minimize
from pymoo.problems import get_problem as pymoo_problem
from pymoo.util.nds.non_dominated_sorting import NonDominatedSorting

from pymoo_rail.journeys import BudgetRepair
from pymoo_rail.suite import COCOLogger, get_problem, list_families
from pymoo_rail.suite.coco_logger import (
    COCO_SINGLE_SUITE,
    COCO_SUITE,
    INFINITE_VALUE,
    evaluation_triggers,
    function_id,
    register_cocopp_suite,
    target_of,
)

with warnings.catch_warnings():  # cocopp warns at import that it cannot reach COCO's online archives
    warnings.simplefilter("ignore")
    import cocoex
    from cocopp import pproc, testbedsettings


class Recorder(COCOLogger):
    """The logger, also keeping every evaluated point to recompute the indicator independently."""

    def log_point(self, evaluation, x, f, cv):
        self.seen.setdefault(self._algorithm, []).append((f.copy(), cv))
        super().log_point(evaluation, x, f, cv)

    seen: dict


def _read(folder):
    register_cocopp_suite()
    testbedsettings.reset_current_testbed()
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        return pproc.DataSetList(str(folder))


def _indicator(problem, F, CV):
    """COCO's hyp indicator of the feasible points, from scratch."""
    ideal, ref = problem.ideal_point(), problem.hv_reference_point()
    z = (F[CV <= 0] - ideal) / (ref - ideal)
    hv = HV(ref_point=np.ones(2))
    hv_front = hv((problem.pareto_front() - ideal) / (ref - ideal))
    inside = z[np.all(z < 1, axis=1)]
    if len(inside):
        return hv_front - hv(inside)
    return hv_front + np.min(np.linalg.norm(np.maximum(z - 1, 0), axis=1))


def test_a_bi_objective_log_round_trips_through_cocopp(tmp_path):
    problem = get_problem("generated-metro-bi", n_var=10, seed=1)  # its front is shipped: no solve here
    logger = Recorder(tmp_path, "NSGA2", "population 12, 5 generations")
    logger.seen = {}
    results = []
    with logger:
        for seed in (1, 2):
            results.append(minimize(problem, NSGA2(pop_size=12), ("n_gen", 5), seed=seed, callback=logger))
    data = _read(tmp_path / "NSGA2")
    assert len(data) == 1
    ds = data[0]
    assert (ds.suite_name, ds.funcId, ds.dim, ds.algId) == (COCO_SUITE, 1, 10, "NSGA2")
    assert list(ds.instancenumbers) == [1, 1]  # two runs of instance (seed) 1
    assert list(ds.maxevals) == [60, 60]  # 12 x 5 evaluations each
    for run, points in enumerate(logger.seen.values()):
        F = np.array([f for f, _ in points])
        CV = np.array([cv for _, cv in points])
        assert len(F) == 60
        # the best (last) indicator value is the one recomputed from every evaluated point
        assert ds.finalfunvals[run] == pytest.approx(_indicator(problem, F, CV), abs=1e-12)
        # cocopp's evaluation-indexed values fall, start at evaluation 1 and end at the budget
        evals, values = ds.funvals[:, 0], ds.funvals[:, 1 + run]
        assert evals[0] == 1 and evals[-1] == 60 and np.all(np.diff(values) <= 1e-15)
        # the final archive holds the feasible non-dominated points of the run (raw kWh and s)
        feasible = F[CV <= 0]
        front = feasible[NonDominatedSorting().do(feasible, only_non_dominated_front=True)]
        archive = _adat_runs(tmp_path / "NSGA2" / "archive" / f"{COCO_SUITE}_f01_i01_d10_nondom_final.adat")[run]
        assert {tuple(np.round(f, 9)) for f in front} == {tuple(np.round(a[1:3], 9)) for a in archive}
        assert archive.shape[1] == 1 + 2 + problem.n_var
        # pymoo's final front is dominated by (or in) the archive
        ideal = problem.ideal_point()
        assert np.all([np.any(np.all(archive[:, 1:3] <= f + 1e-9 * np.abs(ideal), axis=1))
                       for f in results[run].F])


@pytest.mark.parametrize("family, repair", [("generated-metro-single", None), ("generated-metro-trip", BudgetRepair())])
def test_a_single_objective_log_round_trips_through_cocopp(tmp_path, family, repair):
    problem = get_problem(family, n_var=10, seed=1)  # the metro front is shipped; the trip's optimum is exact
    logger = Recorder(tmp_path, "GA", "population 12, 5 generations")
    logger.seen = {}
    with logger:
        for seed in (1, 2):
            minimize(problem, GA(pop_size=12, repair=repair) if repair else GA(pop_size=12), ("n_gen", 5), seed=seed,
                     callback=logger)
    data = _read(tmp_path / "GA")
    assert len(data) == 1
    ds = data[0]
    fid = list_families().index(family) + 1
    assert (ds.suite_name, ds.funcId, ds.dim, ds.algId) == (COCO_SINGLE_SUITE, fid, 10, "GA")
    assert list(ds.instancenumbers) == [1, 1] and list(ds.maxevals) == [60, 60]
    f_opt = float(problem.pareto_front()[0, 0])
    for run, points in enumerate(logger.seen.values()):
        F = np.array([f[0] for f, _ in points])
        CV = np.array([cv for _, cv in points])
        assert len(F) == 60 and (CV <= 0).any()
        # the final value is the best feasible energy minus the certified optimum (kWh), recomputed here
        assert ds.finalfunvals[run] == pytest.approx(F[CV <= 0].min() - f_opt, abs=1e-8)
        evals, values = ds.funvals[:, 0], ds.funvals[:, 1 + run]
        assert evals[0] == 1 and evals[-1] == 60 and np.all(np.diff(values) <= 0)
    # every .dat line: evaluation, 0 constraint evaluations, value, the point's energy, the best feasible energy, x
    dat = np.loadtxt(tmp_path / "GA" / f"data_f{fid}" / f"bbobexp_f{fid}_DIM10.dat", comments="%")
    assert np.all(dat[:, 1] == 0) and dat.shape[1] == 5 + problem.n_var
    finite = dat[:, 2] < INFINITE_VALUE
    np.testing.assert_allclose(dat[finite, 4] - f_opt, dat[finite, 2], atol=1e-8)
    header = (tmp_path / "GA" / f"bbobexp_f{fid}.info").read_text().splitlines()[0]
    assert f"suite = '{COCO_SINGLE_SUITE}', funcId = {fid}, DIM = 10" in header and "algId = 'GA'" in header


def test_the_single_objective_files_are_those_cocoex_writes(tmp_path, monkeypatch):
    """cocoex's own bbob observer: the same .info header keys, run header and columns; its .dat targets are ours."""
    monkeypatch.chdir(tmp_path)
    rng = np.random.default_rng(3)
    suite = cocoex.Suite("bbob", "", "dimensions: 5 instance_indices: 1 function_indices: 1")
    observer = cocoex.Observer("bbob", "result_folder: ours algorithm_name: RS")
    f = suite.get_problem(0)
    f.observe_with(observer)
    measured = [f(rng.uniform(-5, 5, 5)) for _ in range(300)]
    f.free()
    folder = tmp_path / "exdata" / "ours"
    theirs_info = (folder / "bbobexp_f1.info").read_text().splitlines()[0]
    keys = [part.split(" = ")[0] for part in theirs_info.split(", ")]
    problem = get_problem("generated-metro-single", n_var=5, seed=1)
    with COCOLogger(tmp_path, "GA") as logger:
        minimize(problem, GA(pop_size=10), ("n_gen", 3), seed=1, callback=logger)
    fid = function_id(problem)
    ours_info = (tmp_path / "GA" / f"bbobexp_f{fid}.info").read_text().splitlines()[0]
    assert [part.split(" = ")[0] for part in ours_info.split(", ")] == keys
    theirs_dat = (folder / "data_f1" / "bbobexp_f1_DIM5.dat").read_text().splitlines()
    ours_dat = (tmp_path / "GA" / f"data_f{fid}" / f"bbobexp_f{fid}_DIM5.dat").read_text().splitlines()
    assert ours_dat[0].split("(")[0] == theirs_dat[0].split("(")[0]
    assert ours_dat[0].split(")")[1] == theirs_dat[0].split(")")[1]
    assert len(ours_dat[1].split()) == len(theirs_dat[1].split())  # 5 columns and the 5 decisions
    # cocoex writes a .dat line where our rule does: the best value minus Fopt reaches a new target
    f_opt = float(theirs_dat[0].split("(")[1].split(")")[0])
    best, last, expected = np.inf, np.inf, []
    for evaluation, value in enumerate(measured, start=1):
        best = min(best, value)
        if target_of(best - f_opt) < last:
            expected.append(evaluation)
            last = target_of(best - f_opt)
    written = np.loadtxt(folder / "data_f1" / "bbobexp_f1_DIM5.dat", comments="%", ndmin=2)[:, 0].astype(int)
    assert list(written) == expected + [300]


def _adat_runs(path):
    runs, rows = [], []
    for line in path.read_text().splitlines():
        if line.startswith("% evaluations"):
            runs.append(np.array(rows))
            rows = []
        elif not line.startswith("%"):
            rows.append([float(v) for v in line.split("\t")])
    return runs


def test_the_indicator_before_and_after_the_reference_box(tmp_path):
    """None feasible: infinite (3e21 written); outside the box: HV(front) + distance; inside: HV(front) - HV."""
    problem = get_problem("generated-metro-bi", n_var=10, seed=1)
    ideal, ref = problem.ideal_point(), problem.hv_reference_point()
    logger = COCOLogger(tmp_path, "hand")
    logger.start_run(problem)
    hv_front = logger.archive.hv_front
    x = np.zeros(problem.n_var)
    centre = ideal + 0.5 * (ref - ideal)
    logger.log_point(1, x, centre, cv=1.0)  # infeasible: nothing known yet
    assert logger.indicator() == np.inf
    logger.log_point(2, x, ref + np.array([0.3, 0.4]) * (ref - ideal), cv=0.0)  # 0.3 and 0.4 beyond: distance 0.5
    assert logger.indicator() == pytest.approx(hv_front + 0.5)
    logger.log_point(3, x, centre, cv=2.0)  # infeasible: ignored
    assert logger.indicator() == pytest.approx(hv_front + 0.5)
    logger.log_point(4, x, centre, cv=0.0)  # the box's centre: dominates a quarter of it
    assert logger.indicator() == pytest.approx(hv_front - 0.25)
    logger.end_run()
    assert 0 < hv_front < 1
    dat = np.loadtxt(tmp_path / "hand" / "generated-metro-bi" / f"{COCO_SUITE}_f01_d10_hyp.dat", comments="%")
    assert dat[:, 0].tolist() == [1, 2, 4]
    assert dat[:, 1] == pytest.approx([INFINITE_VALUE, hv_front + 0.5, hv_front - 0.25])
    ds = _read(tmp_path / "hand")[0]
    assert list(ds.maxevals) == [4] and ds.finalfunvals[0] == pytest.approx(hv_front - 0.25)


def test_the_triggers_are_those_cocoex_writes(tmp_path, monkeypatch):
    """cocoex's own bbob-biobj observer on f1, d 2 and 5: its .tdat evaluations and .dat targets are ours."""
    monkeypatch.chdir(tmp_path)
    budget = 300
    rng = np.random.default_rng(3)
    for dim in (2, 5):
        suite = cocoex.Suite("bbob-biobj", "", f"dimensions: {dim} instance_indices: 1 function_indices: 1")
        observer = cocoex.Observer("bbob-biobj", f"result_folder: d{dim} algorithm_name: RS log_nondominated: none")
        f = suite.get_problem(0)
        f.observe_with(observer)
        for _ in range(budget):
            f(rng.uniform(-5, 5, dim))
        f.free()
        folder = next((tmp_path / "exdata" / f"d{dim}").glob("*/"))
        tdat = np.loadtxt(next(folder.glob("*.tdat")), comments="%", ndmin=2)
        assert set(tdat[:, 0].astype(int)) == evaluation_triggers(dim, budget) | {budget}
        dat = np.loadtxt(next(folder.glob("*_hyp.dat")), comments="%", ndmin=2)
        for value, target in dat[:, 1:]:
            assert target_of(value) == pytest.approx(target, rel=1e-12)


def test_a_second_logger_in_the_same_folder_numbers_its_data(tmp_path):
    problem = get_problem("generated-metro-bi", n_var=10, seed=1)
    for _ in range(2):
        with COCOLogger(tmp_path, "NSGA2") as logger:
            minimize(problem, NSGA2(pop_size=8), ("n_gen", 2), seed=1, callback=logger)
    assert sorted(p.name for p in tmp_path.iterdir()) == ["NSGA2", "NSGA2_001"]
    first, second = (_read(tmp_path / name)[0] for name in ("NSGA2", "NSGA2_001"))
    assert first.finalfunvals == pytest.approx(second.finalfunvals)  # same seed, same run


def test_problems_coco_cannot_hold_are_refused(tmp_path):
    with pytest.raises(ValueError, match="algorithm_name = 'my alg'"):
        COCOLogger(tmp_path, "my alg")
    with pytest.raises(ValueError, match="n_obj = 3"):
        minimize(get_problem("generated-metro-3obj", n_var=10, seed=1), NSGA2(pop_size=8), ("n_gen", 1),
                 callback=COCOLogger(tmp_path, "three"))
    with pytest.raises(ValueError, match="'ZDT1' is not a family instance"):
        function_id(pymoo_problem("zdt1"))
    assert function_id(get_problem("generated-metro-bi", n_var=10, seed=1)) == 1
    # a named problem has no fixed HV reference point: refused at the first generation, no run left open
    logger = COCOLogger(tmp_path, "named")
    with pytest.raises(ValueError, match="'yizhuang-bi' is not a family instance"):
        minimize(get_problem("yizhuang-bi"), NSGA2(pop_size=8), ("n_gen", 1), callback=logger)
    logger.close()
    assert not (tmp_path / "named").exists()


@pytest.mark.slow
@pytest.mark.parametrize("family", ["generated-metro-bi", "generated-metro-single"])
def test_cocopp_main_post_processes_a_log(tmp_path, family):
    """cocopp's whole post-processing (figures, tables, HTML) on a log, in a fresh process."""
    problem = get_problem(family, n_var=10, seed=1)
    name = "NSGA2" if problem.n_obj == 2 else "GA"
    with COCOLogger(tmp_path / "data", name) as logger:
        for seed in (1, 2, 3):
            algorithm = NSGA2(pop_size=12) if problem.n_obj == 2 else GA(pop_size=12)
            minimize(problem, algorithm, ("n_gen", 5), seed=seed, callback=logger)
    script = ("import warnings; warnings.simplefilter('ignore'); import cocopp; "
              "from pymoo_rail.suite.coco_logger import register_cocopp_suite; register_cocopp_suite(); "
              f"cocopp.main('-o {tmp_path / 'pp'} {tmp_path / 'data' / name}')")
    done = subprocess.run([sys.executable, "-c", script], capture_output=True, text=True, cwd=tmp_path,
                          env={**os.environ, "MPLBACKEND": "Agg"})
    assert done.returncode == 0, done.stderr[-3000:]
    pages = list((tmp_path / "pp").rglob("index1.html"))
    assert pages and name in pages[0].read_text()
