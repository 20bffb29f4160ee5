"""What a newcomer meets first: CLI messages and defaults, distinct fronts, names, the compile notice."""

from __future__ import annotations

import numpy as np
import pandas as pd
import pytest
from numba import njit
from pymoo.core.population import Population

from pymoo_rail.cli import main
from pymoo_rail.experiments import distinct_front, distinct_index
from pymoo_rail.problems import SpeedProfileProblem
from pymoo_rail.sim import REGIME_NAMES
from pymoo_rail.sim.jit import compile_notice


def run(capsys, *argv):
    code = main([str(a) for a in argv])
    out, err = capsys.readouterr()
    return code, out, err


# ---------------------------------------------------------------- CLI


def test_one_objective_without_tolerance_gets_a_time_constraint(capsys, tmp_path):
    code, out, err = run(capsys, "optimize", "yizhuang", "--objectives", "energy", "--algorithm", "ga",
                         "--pop-size", 8, "--n-gen", 2, "--out", tmp_path, "-q")
    assert code == 0, err
    # stop, limits and |T - T_plan| <= 1 s: three constraints, and the user is told
    assert "3 constraints" in out and "|T - T_plan| <= 1 s" in out
    front = pd.read_csv(tmp_path / "front.csv")
    ok = front[front["feasible"]]
    assert np.all(np.abs(ok["running_time_s"] - 150.0) <= 1.0 + 1e-9)
    assert "front: 1 solution (" in out  # one objective: one member, in the singular


def test_reference_with_an_impossible_time_exits_2_before_computing(capsys, tmp_path):
    out_dir = tmp_path / "ref"
    code, out, err = run(capsys, "reference", "yizhuang", "--times", 20, 150, "--out", out_dir)
    assert code == 2
    assert "argument --times" in err and "20 s is below the minimum running time" in err
    assert not out_dir.exists()  # nothing computed, nothing written


def test_plot_front_keeps_the_figure_optimize_wrote(capsys, tmp_path):
    pd.DataFrame({"chosen": [True, False], "f_energy": [12.0, 11.0], "f_time_error": [0.5, 3.0],
                  "running_time_s": [150.5, 153.0], "energy_kwh": [12.0, 11.0]}).to_csv(tmp_path / "front.csv",
                                                                                      index=False)
    sentinel = b"the figure optimize wrote"
    (tmp_path / "front.png").write_bytes(sentinel)
    code, out, err = run(capsys, "plot", "front", tmp_path / "front.csv")
    assert code == 0, err
    assert (tmp_path / "front.png").read_bytes() == sentinel
    assert (tmp_path / "front_plot.png").stat().st_size > 500 and "front_plot.png" in out


@pytest.mark.parametrize("command", ["optimize", "reference", "study", "warmup"])
def test_help_states_each_default_once(capsys, command):
    code, out, _ = run(capsys, command, "--help")
    assert code == 0
    options = out.split("options:\n", 1)[1].split("\n\n", 1)[0]  # the option list, not the description
    text = " ".join(options.split())
    assert "(default: None)" not in text and "(default: False)" not in text
    for option in text.split(" --")[1:]:
        assert option.count("default") <= 1, option


def test_outputs_say_hold(capsys, tmp_path):
    assert "hold" in REGIME_NAMES and "cruise" not in REGIME_NAMES
    from pymoo_rail.cases import load_case
    from pymoo_rail.sim import Simulator

    table = Simulator(load_case("yizhuang")).flat_out().to_frame()
    assert set(table["regime"]) <= set(REGIME_NAMES)
    # tables written before "hold" still plot
    table["regime"] = table["regime"].replace({"traction": "cruise"})
    table.to_csv(tmp_path / "old.csv", index=False)
    code, _, err = run(capsys, "plot", "trajectory", tmp_path / "old.csv", "--out", tmp_path / "old.png")
    assert code == 0, err


def test_warmup_command(capsys):
    code, out, err = run(capsys, "warmup")
    assert code == 0, err
    assert "simulator: ready" in out
    code, _, err = run(capsys, "warmup", "--all", "--bogus")
    assert code == 2


# ---------------------------------------------------------------- distinct fronts


def test_distinct_index_keeps_one_member_per_objective_vector():
    F = np.array([[1.0, 2.0], [0.5, 3.0], [1.0, 2.0], [0.5, 3.0], [2.0, 1.0]])
    CV = np.array([0.3, 0.0, 0.0, 0.0, 0.0])
    keep = distinct_index(F, CV)
    np.testing.assert_array_equal(keep, [1, 2, 4])  # the feasible copy of [1, 2], the first of [0.5, 3]
    assert len(np.unique(F[keep], axis=0)) == len(keep)
    pop = Population.new(X=np.arange(10.0).reshape(5, 2), F=F, CV=CV[:, None])
    front = distinct_front(pop)
    np.testing.assert_array_equal(front.get("X")[:, 0], [2.0, 4.0, 8.0])
    assert len(distinct_front(None)) == 0


def test_moabc_front_written_by_the_cli_has_distinct_objective_vectors(capsys, tmp_path):
    code, out, err = run(capsys, "optimize", "yizhuang", "--algorithm", "moabc", "--pop-size", 10, "--n-gen", 4,
                         "--out", tmp_path, "-q")
    assert code == 0, err
    F = pd.read_csv(tmp_path / "front.csv")[["f_energy", "f_time_error"]].to_numpy()
    assert len(np.unique(F, axis=0)) == len(F)


def test_study_records_have_distinct_objective_vectors():
    from pymoo_rail.experiments import Budget, RunSpec, algorithm, execute_run, problem

    run_ = RunSpec(problem("zdt1", n_var=4), algorithm("moabc", pop_size=10), 1, Budget("n_gen", 5))
    F = np.asarray(execute_run(run_)["front"]["F"])
    assert len(F) and len(np.unique(F, axis=0)) == len(F)


# ---------------------------------------------------------------- names


def test_accel_variation_is_the_objective_jerk_names(yizhuang):
    by_jerk = SpeedProfileProblem(yizhuang, objectives=("energy", "jerk"))
    by_name = SpeedProfileProblem(yizhuang, objectives=("energy", "accel_variation"))
    X = by_name.xl + (by_name.xu - by_name.xl) * np.random.default_rng(3).uniform(0.3, 1.0, (5, by_name.n_var))
    np.testing.assert_array_equal(by_jerk.evaluate(X, return_values_of=["F"]),
                                  by_name.evaluate(X, return_values_of=["F"]))
    with pytest.raises(ValueError, match="alias"):
        SpeedProfileProblem(yizhuang, objectives=("jerk", "accel_variation"))
    tr = by_name.trajectory(X[0])
    # what it measures: the total variation of the acceleration from rest to rest, in m/s^2
    a = np.concatenate([[0.0], tr.accel_ms2[:-1], [0.0]])
    assert tr.accel_variation_ms2 == pytest.approx(np.abs(np.diff(a)).sum(), rel=1e-9)
    assert tr.jerk_ms2 == tr.accel_variation_ms2
    weighted = SpeedProfileProblem(yizhuang, objectives=("energy", "jerk"), weights=(1.0, 1.0))
    assert weighted.scales[1] == pytest.approx(max(by_name.simulator.flat_out().accel_variation_ms2, 1e-9))


# ---------------------------------------------------------------- first run


def test_compile_notice_says_once_and_sums_up():
    def probe(x):
        return x + 1.0

    probe.__module__ = "pymoo_rail.probe"  # the notice is for the package's kernels only
    lines = []
    with compile_notice(say=lines.append) as watch:
        fast = njit(probe)
        fast(1.0)
        fast(2)  # a second specialisation: compiled, not announced again
    assert lines[0].startswith("compiling the simulator") and "first run only" in lines[0]
    assert len(lines) == 2 and lines[1].startswith("compiled 2 simulator functions")
    assert watch.n_compiled == 2 and watch.compile_s > 0
    lines.clear()
    with compile_notice(say=lines.append):
        fast(3.0)  # already compiled: silent
        njit(lambda x: x * 2)(1.0)  # not ours: silent
    assert lines == []


def _package_dispatchers():
    """Every Numba dispatcher defined in a module of the package (imported here)."""
    import importlib
    import pkgutil

    import pymoo_rail
    from numba.core.registry import CPUDispatcher

    found = {}
    for info in pkgutil.walk_packages(pymoo_rail.__path__, "pymoo_rail."):
        module = importlib.import_module(info.name)
        for name, value in vars(module).items():
            if isinstance(value, CPUDispatcher) and value.py_func.__module__ == info.name:
                found[f"{info.name}.{name}"] = value
    return found


def test_no_kernel_uses_numba_ir_inlining():
    # inline="always" re-types a helper's body at every call site, recursively: it was 66 % of the
    # first run's compile; helpers are inlined by LLVM instead (pymoo_rail.sim.jit.inlined)
    dispatchers = _package_dispatchers()
    assert len(dispatchers) > 40
    assert [name for name, d in dispatchers.items() if d.targetoptions.get("inline") == "always"] == []
    # every kernel keeps its Python wrapper: without one, a call from Python crashes the interpreter
    assert [name for name, d in dispatchers.items() if d.targetoptions.get("no_cpython_wrapper")] == []
    from pymoo_rail.sim import kernel, physics

    for helper in (kernel.full_step, kernel.drive_cell, kernel.complete_cell, kernel.clamp_to_envelope,
                   physics.max_traction, physics.max_braking, physics.landing_force, physics.curve_force):
        # inlined by LLVM (a cell's speed) and without reference counting (a call would incref the model)
        assert helper.targetoptions["forceinline"] and helper.targetoptions["_nrt"] is False


def test_compile_profile_charges_each_function_its_own_time():
    from pymoo_rail.sim.jit import compile_profile

    def inner(x):
        return x * 2.0

    fast_inner = njit(inner)

    def outer(x):
        return fast_inner(x) + 1.0

    with compile_profile() as profile:
        assert njit(outer)(1.0) == 3.0
    table = {name.split(".")[-1]: (total, stages) for name, total, stages in profile.table()}
    assert {"inner", "outer"} <= set(table)
    compiles = {name.split(".")[-1]: n for name, n in profile.compiles.items()}
    signatures = {name.split(".")[-1]: sigs for name, sigs in profile.signatures.items()}
    assert compiles["inner"] == 1 and signatures["outer"] == ["(float64,)"]
    assert "nopython_type_inference" in table["outer"][1] and "llvm:module passes" in table["outer"][1]
    # exclusive times: the callee's compile (inside the caller's type inference) is not the caller's
    assert all(s >= 0.0 for _, (_, stages) in table.items() for s in stages.values())
    from numba.core import codegen

    assert "timed" not in codegen.CPUCodeLibrary._optimize_final_module.__name__  # restored


@pytest.mark.slow
def test_first_run_compiles_each_kernel_once(tmp_path):
    # a cold compile of the README's main command (about 15-20 s of CPU): no package kernel is
    # compiled for two signatures (a literal argument, prange's uint64 index, float32 and float64
    # positions), and a train without an efficiency map compiles no map lookup (its model's map
    # fields are None, which prunes the lookup)
    import subprocess
    import sys
    from pathlib import Path

    root = Path(__file__).resolve().parents[1]
    env = {**__import__("os").environ, "NUMBA_CACHE_DIR": str(tmp_path / "cache"), "MPLBACKEND": "Agg",
           "PYTHONPATH": str(root)}
    done = subprocess.run([sys.executable, str(root / "benchmarks" / "compile_profile.py"), "--signatures",
                           "--top", "1000", "--", "optimize", "yizhuang", "--algorithm", "nsga2", "-q"],
                          cwd=root, env=env, capture_output=True, text=True, check=True)
    compiled, twice = done.stdout.split("more than one signature")
    ours = {line.split(":")[0].strip() for line in twice.splitlines()[1:] if line.strip().startswith("pymoo_rail")}
    assert ours == set(), done.stdout
    assert "pymoo_rail.sim.kernel.run_pairs" in compiled, done.stdout
    assert "map_efficiency" not in compiled and "map_node" not in compiled, done.stdout
