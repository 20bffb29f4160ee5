"""The pymoo-rail command on a bad day: options that need care, a failing reference, bad paths, Ctrl-C, waits."""

from __future__ import annotations

import errno
import re

import numpy as np
import pandas as pd
import pytest

from pymoo_rail.cli import main

OUTPUTS = ("front.csv", "trajectory.csv", "front.png", "profile.png", "speed_time.png")


def run(capsys, *argv):
    code = main([str(a) for a in argv])
    out, err = capsys.readouterr()
    return code, out, err


# ---------------------------------------------------------------- MOEA/D on constrained problems


def test_moead_searches_with_the_constraints_as_a_penalty_and_reports_true_values(capsys, tmp_path):
    code, out, err = run(capsys, "optimize", "yizhuang", "--algorithm", "moead", "--pop-size", 12, "--n-gen", 4,
                         "--no-reference", "--out", tmp_path, "-q")
    assert code == 0, err
    assert "moead has no constraint handling" in out and "penalty" in out and "nsga2" in out
    front = pd.read_csv(tmp_path / "front.csv")
    # the table holds the problem's own objectives and violations, not the penalised ones
    np.testing.assert_allclose(front["f_energy"], front["energy_kwh"])
    np.testing.assert_allclose(front["f_time_error"], np.abs(front["running_time_s"] - 150.0), atol=1e-9)
    assert (front["feasible"] == (front["cv"] <= 0)).all() and front["feasible"].any()


def test_penalised_constraints_add_the_violation_to_every_objective(yizhuang):
    from pymoo.core.individual import calc_cv

    from pymoo_rail.experiments.penalty import PenalisedConstraints
    from pymoo_rail.problems import SpeedProfileProblem

    problem = SpeedProfileProblem(yizhuang, time_window_s=(150.0, 160.0))
    X = np.random.default_rng(4).uniform(problem.xl, problem.xu, (16, problem.n_var))
    F, G = problem.evaluate(X, return_values_of=["F", "G"])
    violation = calc_cv(G=G)
    assert (violation > 0).any() and (violation == 0).any()  # both kinds of rows are checked
    wrapped = PenalisedConstraints(problem, 7.0)
    assert wrapped.n_ieq_constr == 0 and wrapped.n_obj == 2
    np.testing.assert_allclose(wrapped.evaluate(X, return_values_of=["F"]), F + 7.0 * violation[:, None])
    with pytest.raises(ValueError, match="penalty = -1"):
        PenalisedConstraints(problem, -1.0)


def test_optimize_profile_refuses_moead_on_a_constrained_problem_without_a_penalty(yizhuang):
    from pymoo.algorithms.moo.moead import MOEAD
    from pymoo.util.ref_dirs import get_reference_directions

    from pymoo_rail.experiments.optimize import optimize_profile
    from pymoo_rail.problems import SpeedProfileProblem

    algorithm = MOEAD(ref_dirs=get_reference_directions("uniform", 2, n_partitions=7))
    with pytest.raises(ValueError, match="MOEAD has no constraint handling .* penalty="):
        optimize_profile(SpeedProfileProblem(yizhuang), algorithm, ("n_gen", 2), seed=1)


# ---------------------------------------------------------------- a reference that fails


def test_a_failed_reference_keeps_the_run_and_names_the_nearest_optimum(capsys, tmp_path):
    # on a 250 m grid the exact solver jumps over some of the front's running times
    code, out, err = run(capsys, "optimize", "yizhuang", "--dx", 250, "--pop-size", 8, "--n-gen", 2,
                         "--out", tmp_path, "-q")
    assert code == 0, err
    for name in OUTPUTS:
        assert (tmp_path / name).is_file() and f"wrote {tmp_path / name}" in out
    line = next(line for line in out.splitlines() if line.startswith("optimum:"))
    assert "the certified front could not be computed" in line and "the closest optimum takes" in line
    chosen = pd.read_csv(tmp_path / "front.csv").query("chosen").iloc[0]
    nearest_s = float(re.search(r"the nearest optimum takes ([0-9.]+) s \(([-+0-9.]+) s from the chosen run", line)[1])
    assert abs(nearest_s - chosen["running_time_s"]) <= 0.5  # the solver never returns a run more than 0.5 s off
    assert re.search(r"now 226.5 m; --dx 113.2 ", line)  # 2265 m in 10 cells of the coarse grid, and half that


def test_when_no_optimum_can_be_found_the_run_is_still_written(capsys, tmp_path, monkeypatch):
    from pymoo_rail.experiments import optimize

    def fails(case, running_time_s, **settings):
        raise RuntimeError(f"running_time_s = {running_time_s}: the closest optimum takes 1.00 s; refine the grid")

    monkeypatch.setattr(optimize, "optimal_profile", fails)
    code, out, err = run(capsys, "optimize", "yizhuang", "--dx", 250, "--pop-size", 8, "--n-gen", 2,
                         "--out", tmp_path, "-q")
    assert code == 0, err
    assert all((tmp_path / name).is_file() for name in OUTPUTS)
    line = next(line for line in out.splitlines() if line.startswith("optimum:"))
    assert "no optimal run at" in line and "no gap reported" in line and "--dx 113.2 " in line


# ---------------------------------------------------------------- errors: one line and a hint


@pytest.mark.parametrize("argv, argument", [
    (["optimize", "atlantis"], "argument CASE"),
    (["optimize", "yizhuang", "--pop-size", "0"], "argument --pop-size"),
    (["optimize", "yizhuang", "--bogus"], "unrecognized arguments: --bogus"),
])
def test_usage_errors_are_one_line_and_a_hint(capsys, argv, argument):
    code, _, err = run(capsys, *argv)
    lines = err.strip().splitlines()
    assert code == 2 and len(lines) == 2 and "usage:" not in err
    assert lines[0].startswith("pymoo-rail optimize: error: ") and argument in lines[0]
    assert "'pymoo-rail optimize --help'" in lines[1]


def test_an_out_that_cannot_be_written_names_out_and_the_path(capsys, tmp_path, monkeypatch):
    code, _, err = run(capsys, "optimize", "yizhuang", "--out", "/proc/x")
    assert code == 2 and "argument --out" in err and "/proc/x" in err and "Traceback" not in err
    from pymoo_rail.cli import arguments

    def read_only(*args, **kwargs):
        raise OSError(errno.EROFS, "Read-only file system")

    monkeypatch.setattr(arguments.tempfile, "TemporaryFile", read_only)
    code, _, err = run(capsys, "optimize", "yizhuang", "--out", tmp_path / "ro")
    assert code == 2 and "argument --out" in err and "Read-only file system" in err and str(tmp_path / "ro") in err


# ---------------------------------------------------------------- Ctrl-C


def test_ctrl_c_in_optimize_says_what_was_kept(capsys, tmp_path, monkeypatch):
    from pymoo_rail.experiments import optimize

    def interrupted(*args, **kwargs):
        raise KeyboardInterrupt

    monkeypatch.setattr(optimize, "optimal_profile", interrupted)  # during the reference, after the tables
    code, _, err = run(capsys, "optimize", "yizhuang", "--pop-size", 8, "--n-gen", 2, "--out", tmp_path, "-q")
    assert code == 130 and "study" not in err
    assert f"kept {tmp_path / 'front.csv'}, {tmp_path / 'trajectory.csv'}" in err and "run it again" in err


def test_ctrl_c_in_a_study_says_the_finished_runs_are_kept(capsys, tmp_path, monkeypatch):
    import pymoo_rail.experiments as experiments

    def interrupted(*args, **kwargs):
        raise KeyboardInterrupt

    monkeypatch.setattr(experiments, "run_study", interrupted)
    study = tmp_path / "s.toml"
    study.write_text('name = "mini"\nseeds = 1\n[budget]\nn_gen = 2\n[[problems]]\nproblem = "zdt1"\n'
                     '[[algorithms]]\nalgorithm = "nsga2"\npop_size = 8\n')
    code, out, err = run(capsys, "study", study, "--workers", 1, "--out", tmp_path / "mini", "-q")
    assert code == 130 and "every run finished so far is stored" in err
    assert "runs on this process" in out and "process pool" not in out


# ---------------------------------------------------------------- waits


def test_a_wait_longer_than_the_delay_shows_a_ticking_line(capsys):
    import time

    from pymoo_rail.cli.progress import ticking

    with ticking("quick"):
        pass
    with ticking("solving the front", delay_s=0.0):
        time.sleep(1.2)
    err = capsys.readouterr().err
    assert "quick" not in err and "solving the front: 00:01" in err


def test_optimize_says_what_a_first_run_compiles():
    from pymoo_rail.cli.commands.optimize import COMPILE_NOTICE

    assert COMPILE_NOTICE.startswith("compiling the simulator") and "first run only" in COMPILE_NOTICE
    assert "s of CPU" in COMPILE_NOTICE  # roughly how long (benchmarks/first_run.py)


def test_a_small_job_runs_in_one_thread_and_gives_the_threads_back(capsys, tmp_path, monkeypatch):
    # the parallel batch kernel costs more to compile than it saves on a small job; results are the same
    import numba

    from pymoo_rail.experiments import optimize

    seen = []
    real = optimize.minimize

    def counting(*args, **kwargs):
        seen.append(numba.get_num_threads())
        return real(*args, **kwargs)

    monkeypatch.setattr(optimize, "minimize", counting)
    before = numba.get_num_threads()
    code, _, err = run(capsys, "optimize", "yizhuang", "--pop-size", 8, "--n-gen", 2, "--no-reference",
                       "--out", tmp_path, "-q")
    assert code == 0, err
    assert seen == [1] and numba.get_num_threads() == before


# ---------------------------------------------------------------- a finished study leaves no lock files


def test_a_finished_study_leaves_no_lock_files(capsys, tmp_path):
    study = tmp_path / "s.toml"
    study.write_text('name = "mini"\nseeds = 2\n[budget]\nn_gen = 2\n[[problems]]\nproblem = "zdt1"\nn_var = 5\n'
                     '[[algorithms]]\nalgorithm = "nsga2"\npop_size = 8\n')
    code, _, err = run(capsys, "study", study, "--workers", 1, "--out", tmp_path / "mini", "-q", "--no-plots")
    assert code == 0, err
    assert len(list((tmp_path / "mini" / "runs").glob("*.json"))) == 2
    assert not (tmp_path / "mini" / "locks").exists()


def test_remove_idle_locks_keeps_held_claims_and_unfinished_runs(tmp_path):
    from filelock import FileLock

    from pymoo_rail.experiments import ResultStore

    store = ResultStore(tmp_path)
    store.runs_dir.mkdir(parents=True, exist_ok=True)
    store.locks_dir.mkdir(parents=True, exist_ok=True)
    for run_id in ("done", "held", "unfinished"):
        (store.locks_dir / f"{run_id}.lock").touch()
    for run_id in ("done", "held"):
        store.path(run_id).write_text("{}")
    holder = FileLock(store.locks_dir / "held.lock", thread_local=False)
    holder.acquire()
    try:
        assert store.remove_idle_locks() == 1
    finally:
        holder.release()
    assert sorted(p.name for p in store.locks_dir.iterdir()) == ["held.lock", "unfinished.lock"]


def test_the_readme_lists_every_command():
    from pathlib import Path

    from pymoo_rail.cli.parser import command_modules

    readme = (Path(__file__).resolve().parents[1] / "README.md").read_text()
    names = [module.__name__.rsplit(".", 1)[1] for module in command_modules()]
    assert len(names) >= 10 and [n for n in names if f"| `pymoo-rail {n}" not in readme] == []


def test_plot_to_a_path_that_cannot_be_written_names_out(capsys, tmp_path):
    pd.DataFrame({"chosen": [True, False], "f_energy": [12.0, 11.0], "f_time_error": [0.5, 3.0]}).to_csv(
        tmp_path / "front.csv", index=False)
    code, _, err = run(capsys, "plot", "front", tmp_path / "front.csv", "--out", "/proc/x/front.png")
    assert code == 2 and "argument --out" in err and "/proc/x/front.png" in err and "Traceback" not in err
