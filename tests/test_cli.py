"""The pymoo-rail command: listing cases, optimising, studies, plots and clear errors."""

from __future__ import annotations

import importlib
import importlib.resources

import numpy as np
import pandas as pd
import pytest

from pymoo_rail.cases import list_cases
from pymoo_rail.cli import main
from pymoo_rail.experiments import choose_member


def run(capsys, *argv):
    code = main([str(a) for a in argv])
    out, err = capsys.readouterr()
    return code, out, err


def test_help_explains_with_examples(capsys):
    code, out, _ = run(capsys, "--help")
    assert code == 0 and "examples:" in out and "pymoo-rail optimize yizhuang" in out
    code, out, _ = run(capsys, "optimize", "--help")
    assert code == 0 and "objectives:" in out and "time_error" in out and "front.csv" in out


def test_no_command_prints_help_and_fails(capsys):
    code, out, _ = run(capsys)
    assert code == 2 and "commands" in out


def test_cases_lists_and_describes(capsys):
    code, out, _ = run(capsys, "cases")
    assert code == 0
    for name in list_cases():
        assert name in out
    yizhuang = next(line for line in out.splitlines() if line.startswith("yizhuang"))
    assert "2,265 m" in yizhuang and "150 s" in yizhuang and "Liu (2019)" in yizhuang  # Liu (2019), 5.1
    code, out, _ = run(capsys, "cases", "yizhuang")
    assert code == 0 and "2,265.0 m in 150 s planned" in out and "194.295 t" in out and "-8" in out


@pytest.mark.parametrize("argv, argument, value", [
    (["cases", "atlantis"], "CASE", "'atlantis'"),
    (["optimize", "atlantis"], "CASE", "'atlantis'"),
    (["optimize", "yizhuang", "--algorithm", "nsga9"], "--algorithm", "'nsga9'"),
    (["optimize", "yizhuang", "--objectives", "energy", "speed"], "--objectives", "'speed'"),
    (["optimize", "yizhuang", "--algorithm", "de"], "--algorithm", "single-objective"),
    (["optimize", "yizhuang", "--pop-size", "0"], "--pop-size", "0"),
    (["optimize", "yizhuang", "--n-gen", "ten"], "--n-gen", "'ten'"),
    (["optimize", "yizhuang", "--weights", "1"], "--weights", "1 weights for 2 objectives"),
    (["optimize", "yizhuang", "--encoding", "bits"], "--encoding", "'bits'"),
    (["study", "no_such_study.toml"], "FILE", "no_such_study.toml"),
    (["plot", "trajectory", "no_such.csv"], "CSV", "no_such.csv"),
])
def test_bad_arguments_exit_2_naming_argument_and_value(capsys, tmp_path, argv, argument, value):
    code, _, err = run(capsys, *argv, *(["--out", tmp_path] if argv[0] == "optimize" else []))
    assert code == 2
    assert f"argument {argument}" in err and value in err
    assert "Traceback" not in err
    assert not list(tmp_path.iterdir())  # nothing written


def test_bad_case_file_names_the_field(capsys, tmp_path):
    path = tmp_path / "mine.toml"
    path.write_text((importlib.resources.files("pymoo_rail.cases") / "yizhuang.toml").read_text()
                    .replace("planned_time_s = 150.0", "planned_time_s = -5.0"))
    code, _, err = run(capsys, "optimize", path, "--out", tmp_path / "o")
    assert code == 2 and "planned_time_s" in err and "-5.0" in err and "Traceback" not in err


def test_choose_member_least_energy_among_punctual_then_closest():
    F = np.array([[10.0, 1.0], [12.0, 0.5], [11.0, 0.5], [9.0, 0.1], [8.0, 3.0]])
    CV = np.array([0.0, 0.0, 0.0, 0.3, 0.0])  # the 9 kWh one is infeasible
    running = np.array([151.0, 150.5, 149.5, 150.0, 153.0])
    energy = F[:, 0]
    assert choose_member(F, CV, running, energy, 150.0) == 0  # within 1 s: 10 kWh is the least
    assert choose_member(F, CV, running, energy, 150.0, window_s=0.6) == 2  # |0.5| tie: 11 beats 12 kWh
    assert choose_member(F, CV, running, energy, 150.0, window_s=5.0) == 4
    assert choose_member(F[:2], CV[:2], running[:2] + 10, energy[:2], 150.0) == 1  # none punctual: closest
    assert choose_member(F[:, :1], CV, running, energy, 150.0) == 4  # single objective: the best feasible


def test_optimize_yizhuang_writes_front_trajectory_and_plots(capsys, tmp_path, yizhuang):
    code, out, err = run(capsys, "optimize", "yizhuang", "--pop-size", 12, "--n-gen", 4, "--seed", 3,
                         "--out", tmp_path, "--quiet")
    assert code == 0, err
    for name in ("front.csv", "trajectory.csv", "front.png", "profile.png", "speed_time.png"):
        assert (tmp_path / name).stat().st_size > 500, name
        assert f"wrote {tmp_path / name}" in out
    front = pd.read_csv(tmp_path / "front.csv")
    assert {"f_energy", "f_time_error", "running_time_s", "energy_kwh", "stop_error_m", "feasible"} <= set(front)
    assert front["chosen"].sum() == 1
    np.testing.assert_allclose(front["f_time_error"], np.abs(front["running_time_s"] - 150.0), atol=1e-9)
    np.testing.assert_allclose(front["f_energy"], front["energy_kwh"])
    feasible = front[front["feasible"]]
    chosen = front[front["chosen"]].iloc[0]
    punctual = feasible[np.abs(feasible["running_time_s"] - 150) <= 1.0]
    assert len(punctual) > 0 and chosen["energy_kwh"] == punctual["energy_kwh"].min()
    trajectory = pd.read_csv(tmp_path / "trajectory.csv")
    assert trajectory["position_m"].iloc[-1] == pytest.approx(yizhuang.line.length_m, abs=1.0)
    assert trajectory["speed_kmh"].iloc[-1] == pytest.approx(0.0, abs=1e-6)  # stopped at the platform
    assert (trajectory["speed_kmh"] <= trajectory["limit_kmh"] + 1e-6).all()
    assert trajectory["time_s"].iloc[-1] == pytest.approx(chosen["running_time_s"])
    again, out2, _ = run(capsys, "optimize", "yizhuang", "--pop-size", 12, "--n-gen", 4, "--seed", 3,
                         "--out", tmp_path / "again", "--quiet")
    assert again == 0
    pd.testing.assert_frame_equal(front, pd.read_csv(tmp_path / "again" / "front.csv"))  # same seed

    code, out, _ = run(capsys, "plot", "trajectory", tmp_path / "trajectory.csv", "--case", "yizhuang",
                       "--out", tmp_path / "replot.png")
    assert code == 0 and (tmp_path / "replot.png").stat().st_size > 500
    code, out, _ = run(capsys, "plot", "front", tmp_path / "front.csv", "--x", "running_time_s", "--y",
                       "energy_kwh")
    assert code == 0 and (tmp_path / "front.png").is_file()
    code, _, err = run(capsys, "plot", "front", tmp_path / "front.csv", "--x", "speed")
    assert code == 2 and "argument --x" in err and "'speed'" in err


def test_single_objective_with_time_tolerance(capsys, tmp_path):
    code, out, err = run(capsys, "optimize", "yizhuang", "--objectives", "energy", "--time-tolerance", "5",
                         "--algorithm", "ga", "--pop-size", 10, "--n-gen", 3, "--out", tmp_path, "-q")
    assert code == 0, err
    front = pd.read_csv(tmp_path / "front.csv")
    assert list(front.columns[:2]) == ["chosen", "f_energy"] and front["chosen"].sum() == 1
    assert not (tmp_path / "front.png").exists()  # one objective: no front to draw
    assert (tmp_path / "profile.png").is_file()


def test_study_and_replot(capsys, tmp_path):
    study = tmp_path / "s.toml"
    study.write_text('name = "mini"\nseeds = 2\nbaseline = "nsga2"\n[budget]\nn_gen = 3\n'
                     '[[problems]]\nproblem = "zdt1"\nn_var = 5\n'
                     '[[algorithms]]\nalgorithm = "nsga2"\npop_size = 8\n'
                     '[[algorithms]]\nalgorithm = "sms-emoa"\npop_size = 8\n')
    code, out, err = run(capsys, "study", study, "--workers", 1, "--out", tmp_path / "mini", "-q")
    assert code == 0, err
    assert "4 runs: 0 already stored, 4 run now, 0 failed" in out
    assert (tmp_path / "mini" / "tables" / "igd.md").is_file()
    assert (tmp_path / "mini" / "tables" / "ranksum.csv").is_file()
    assert (tmp_path / "mini" / "figures" / "box_igd.png").is_file()
    code, out, _ = run(capsys, "study", study, "--workers", 1, "--out", tmp_path / "mini", "-q", "--no-plots",
                       "--seed-major")
    assert code == 0 and "4 already stored, 0 run now" in out
    code, out, _ = run(capsys, "plot", "study", tmp_path / "mini", "--out", tmp_path / "again")
    assert code == 0 and (tmp_path / "again" / "figures" / "front_zdt1.png").is_file()
    code, _, err = run(capsys, "plot", "study", tmp_path / "mini", "--baseline", "moead")
    assert code == 2 and "argument --baseline" in err and "'moead'" in err


def test_reference_without_the_solver_is_a_clear_error(capsys, tmp_path):
    optimal = importlib.import_module("pymoo_rail.optimal")
    if hasattr(optimal, "optimal_front"):
        pytest.skip("the exact solver is installed: see test_reference_writes_the_optimal_front")
    code, _, err = run(capsys, "reference", "yizhuang", "--out", tmp_path)
    assert code == 1 and "pymoo_rail.optimal" in err and "Traceback" not in err


@pytest.mark.slow
def test_reference_writes_the_optimal_front(capsys, tmp_path):
    optimal = importlib.import_module("pymoo_rail.optimal")
    if not hasattr(optimal, "optimal_front"):
        pytest.skip("pymoo_rail.optimal is not merged yet")
    code, out, err = run(capsys, "reference", "yizhuang", "--times", 140, 150, 170, "--out", tmp_path)
    assert code == 0, err
    front = pd.read_csv(tmp_path / "optimal_front.csv")
    assert len(front) == 3 and np.all(np.diff(front["energy_kwh"]) < 0)  # more time, less energy
    assert (tmp_path / "optimal_profile.png").is_file()


def test_four_objectives_give_a_scatter_matrix_front(capsys, tmp_path):
    code, _, err = run(capsys, "optimize", "yizhuang", "--objectives", "energy", "time_error", "jerk", "stop_error",
                       "--pop-size", 12, "--n-gen", 3, "--out", tmp_path, "-q")
    assert code == 0, err
    assert list(pd.read_csv(tmp_path / "front.csv").columns[1:5]) == [
        "f_energy", "f_time_error", "f_jerk", "f_stop_error"]
    from PIL import Image

    with Image.open(tmp_path / "front.png") as image:
        assert min(image.size) > 600  # a 4 x 4 grid, not an empty canvas


def _release():
    from pathlib import Path

    return Path(__file__).resolve().parent / "data" / "ttobench"


def test_optimize_a_ttobench_track_and_train(capsys, tmp_path):
    root = _release()
    code, out, err = run(capsys, "optimize", "--track", root / "tracks" / "CN_Songjiazhuang_Yizhuang.json",
                         "--train", root / "trains" / "CN_Beijing_Subway.json", "--from", 9, "--to", 10,
                         "--time", 150, "--pop-size", 8, "--n-gen", 2, "--out", tmp_path, "--quiet")
    assert code == 0, err
    trajectory = pd.read_csv(tmp_path / "trajectory.csv")
    assert trajectory["position_m"].iloc[-1] == pytest.approx(2265.0, abs=1.0)
    assert (tmp_path / "front.png").is_file()
    code, _, err = run(capsys, "optimize", "yizhuang", "--track", root / "tracks" / "CN_Songjiazhuang_Yizhuang.json")
    assert code == 2 and "either CASE or --track" in err
    code, _, err = run(capsys, "optimize", "--track", root / "tracks" / "CN_Songjiazhuang_Yizhuang.json")
    assert code == 2 and "--train" in err


def test_journey_command_reports_an_unreachable_window(capsys, tmp_path):
    root = _release()
    code, _, err = run(capsys, "journey", root / "journeys" / "CH_StGallen_Wil_Journey_01.json", "--train",
                       root / "trains" / "CH_Stadler_KISS_SBB.json", "--out", tmp_path)
    assert code == 1 and "timing point at 29556.1 m" in err and "345.4 s" in err
    assert "before 1545.4 s (latest allowed 1450 s)" in err and "Traceback" not in err


def test_optimize_takes_every_registered_encoding_and_objective(capsys, tmp_path):
    # choices come from the encoding registry and the objective table: paced codes, peak power;
    # the front's decision columns carry each variable's unit (shape shares, then the running time)
    code, out, err = run(capsys, "optimize", "metro-a", "--encoding", "paced_speed_codes", "--objectives", "energy",
                         "time_error", "peak_power", "--pop-size", 8, "--n-gen", 2, "--no-reference", "--quiet",
                         "--out", tmp_path)
    assert code == 0, err
    front = pd.read_csv(tmp_path / "front.csv")
    assert {"f_energy", "f_time_error", "f_peak_power"} <= set(front)
    decisions = [c for c in front.columns if c.startswith("x")]
    assert decisions[0] == "x0_share" and decisions[-1] == f"x{len(decisions) - 1}_s"
    assert (front["f_peak_power"] > 0).all()
    code, _, err = run(capsys, "optimize", "metro-a", "--encoding", "switching_points", "--partition", "equal",
                       "--out", tmp_path / "points")
    assert code == 2 and "partition = 'equal' does not apply to encoding = 'switching_points'" in err
