"""benchmarks/suite_baseline.py's study file, its reductions (``pymoo_rail.experiments.baseline.cut_study``),
the records archive, the CPU projection and the figures."""

from __future__ import annotations

import hashlib
import tarfile

import numpy as np
import pytest


def _study(*cut):
    """The study file cut to (families, ladder, seeds, n_eval)."""
    from benchmarks.suite_baseline import ROOT, STUDIES
    from pymoo_rail.experiments import read_study
    from pymoo_rail.experiments.baseline import cut_study

    return cut_study(read_study(ROOT / "benchmarks" / f"{STUDIES['table']}.toml"), *cut)


def test_the_full_study_is_every_multi_objective_family_on_the_ladder_with_nine_algorithms_and_31_seeds():
    from pymoo_rail.suite import list_families

    study = _study(None, None, None, None)
    multi = {name for name in list_families() if name.endswith(("-bi", "-3obj"))}
    assert {p.params["family"] for p in study.problems} == multi
    assert sorted({p.params["n_var"] for p in study.problems}) == [10, 30, 100, 300, 1000]
    assert len(study.problems) == 5 * len(multi) == 40
    assert {a.name for a in study.algorithms} == {"nsga2", "sms-emoa", "nsga3", "ctaea", "moead", "age-moea", "moabc",
                                                  "grnsga2", "random"}
    assert {a.params.get("pop_size") for a in study.algorithms if a.name in ("nsga3", "ctaea")} == {100}
    assert len(study.seeds) == 31


def test_reductions_cut_the_study():
    study = _study(["generated-metro-bi"], [10, 30], 5, 2000)
    assert [p.display for p in study.problems] == ["generated-metro-bi/10", "generated-metro-bi/30"]
    assert study.seeds == (1, 2, 3, 4, 5)
    assert study.budget.value == 2000


def test_a_reduction_that_leaves_nothing_says_so():
    with pytest.raises(SystemExit, match="no problem"):
        _study(["atlantis-bi"], None, None, None)


def test_the_archive_holds_the_records_and_its_checksum_is_the_files(tmp_path):
    work = tmp_path / "work"
    (work / "runs").mkdir(parents=True)
    (work / "runs" / "a.json").write_text('{"x": 1}')
    (work / "study.toml").write_text('name = "x"')
    (work / "runs" / "a.json.lock").write_text("")
    path = tmp_path / "records.tar.gz"
    from pymoo_rail.experiments.baseline import archive_records

    digest = archive_records(work, path)
    assert digest == hashlib.sha256(path.read_bytes()).hexdigest()
    with tarfile.open(path) as tar:
        assert sorted(tar.getnames()) == ["suite_baseline/runs/a.json", "suite_baseline/study.toml"]


def test_an_interrupted_archive_leaves_no_file_under_its_name(tmp_path, monkeypatch):
    from pymoo_rail.experiments.baseline import archive_records

    work = tmp_path / "work"
    (work / "runs").mkdir(parents=True)
    for name in ("a", "b"):
        (work / "runs" / f"{name}.json").write_text('{"x": 1}')
    added = []

    def add_then_stop(tar, name, arcname=None, **kwargs):  # the user's Ctrl-C after the first record
        if added:
            raise KeyboardInterrupt
        added.append(arcname)
        return original(tar, name, arcname=arcname, **kwargs)

    original = tarfile.TarFile.add
    monkeypatch.setattr(tarfile.TarFile, "add", add_then_stop)
    with pytest.raises(KeyboardInterrupt):
        archive_records(work, tmp_path / "records.tar.gz")
    assert added and sorted(p.name for p in tmp_path.iterdir()) == ["work"]
    earlier = tmp_path / "earlier.tar.gz"  # a complete archive of an earlier call stays as it was
    earlier.write_bytes(b"an earlier archive")
    added.clear()
    with pytest.raises(KeyboardInterrupt):
        archive_records(work, earlier)
    assert earlier.read_bytes() == b"an earlier archive"
    assert sorted(p.name for p in tmp_path.iterdir()) == ["earlier.tar.gz", "work"]


def test_the_projection_interpolates_cpu_per_evaluation_over_n_var():
    import pandas as pd

    from pymoo_rail.experiments.baseline import cpu_per_evaluation_ms, projected_cpu_h

    full = _study(["generated-metro-bi"], [10, 30, 100], 2, 1000)
    names = [a.display for a in full.algorithms]
    # 1 ms per evaluation at n_var 10, 3 ms at 100: 2 ms at 55 (not asked), 1.4444 ms at 30
    frame = pd.DataFrame([{"family": "generated-metro-bi", "algorithm": name, "n_var": n, "n_eval": 100,
                           "cpu_time_s": 0.1 if n == 10 else 0.3} for name in names for n in (10, 100)])
    # a first run of a process paying the compilation (10 x) does not move the median of three
    frame = pd.concat([frame, frame, frame.assign(cpu_time_s=frame["cpu_time_s"] * 10)], ignore_index=True)
    hours, sizes = projected_cpu_h(frame, full)
    per_algorithm_s = (1e-3 + (1e-3 + 20 / 90 * 2e-3) + 3e-3) * 1000 * 2
    assert hours == pytest.approx(len(names) * per_algorithm_s / 3600)
    assert sizes == "10, 100"
    # per family: a family ten times dearer counts at its own cost, not at the median over families
    two = _study(["generated-metro-bi", "generated-suburban-bi"], [10, 100], 2, 1000)
    both = pd.concat([frame, frame.assign(family="generated-suburban-bi", cpu_time_s=frame["cpu_time_s"] * 10)])
    expected_s = len(names) * (1e-3 + 3e-3) * 11 * 1000 * 2
    assert projected_cpu_h(both, two, per_family=True)[0] == pytest.approx(expected_s / 3600)
    # a family not measured takes the algorithm's medians over the measured ones
    assert projected_cpu_h(frame, two, per_family=True)[0] == pytest.approx(projected_cpu_h(frame, two)[0])
    with pytest.raises(SystemExit, match="no stored run of NSGA-II"):
        projected_cpu_h(frame[frame["algorithm"] != "NSGA-II"], two, per_family=True)
    table = cpu_per_evaluation_ms(frame)  # what --estimate prints: the medians, ms, algorithm x n_var
    assert list(table.columns) == [10, 100] and sorted(table.index) == sorted(names)
    np.testing.assert_allclose(table.to_numpy(), [[1.0, 3.0]] * len(names))


def test_the_figures_have_a_panel_per_cell_and_a_line_per_algorithm():
    import pandas as pd

    from pymoo_rail.plotting import plot_cell_convergence, plot_performance_profile

    history = pd.DataFrame([{"family": f, "n_var": n, "algorithm": a, "seed": s, "n_eval": e, "igd_plus": 1.0 / e}
                            for f in ("x-bi", "y-bi") for n in (10, 30) for a in ("A", "B") for s in (1, 2)
                            for e in (100, 200)])
    fig = plot_cell_convergence(history)
    assert len(fig.axes) == 4 and all(len(ax.get_lines()) == 2 for ax in fig.axes)
    assert [ax.get_title() for ax in fig.axes] == ["x-bi, n_var=10", "x-bi, n_var=30", "y-bi, n_var=10", "y-bi, n_var=30"]
    width, height = fig.get_size_inches()
    assert width < 2 * height  # a row per family, a column per n_var: not one strip of panels
    assert [t.get_text() for t in fig.legends[0].get_texts()] == ["A", "B"]
    fig.canvas.draw()
    # generations end past their checkpoint at counts of their own (seed 2 here): one point per checkpoint
    jittered = history.assign(target_n_eval=history["n_eval"], n_eval=history["n_eval"] + 7 * (history["seed"] - 1))
    fig = plot_cell_convergence(jittered)
    assert all(list(line.get_xdata()) == [100, 200] for ax in fig.axes for line in ax.get_lines())
    ragged = plot_cell_convergence(history[(history["family"] == "x-bi") | (history["n_var"] == 10)])
    assert [ax.axison for ax in ragged.axes] == [True, True, True, False]  # y-bi has no n_var 30: a blank panel
    # a cell without algorithm A: B keeps its colour, and the legend still names A
    fig = plot_cell_convergence(history[(history["family"] == "x-bi") | (history["algorithm"] == "B")])
    colours_of_b = {line.get_color() for ax in fig.axes for line in ax.get_lines() if line.get_label() == "B"}
    assert len(colours_of_b) == 1, colours_of_b
    assert [t.get_text() for t in fig.legends[0].get_texts()] == ["A", "B"]
    infeasible = history.assign(igd_plus=np.where(history["family"] == "x-bi", np.nan, history["igd_plus"]))
    fig = plot_cell_convergence(infeasible)  # a cell without a feasible run: drawn, not a log-scale error
    fig.canvas.draw()
    assert [ax.get_yscale() for ax in fig.axes] == ["linear", "linear", "log", "log"]
    profile = pd.DataFrame({"A": [0.5, 1.0], "B": [0.0, 1.0]}, index=pd.Index([1.0, 2.0], name="tau"))
    assert len(plot_performance_profile(profile).axes[0].get_lines()) == 2


def test_the_profile_mode_splits_a_run_and_leaves_the_thread_count(capsys):
    import numba

    from benchmarks.suite_baseline import main

    before = numba.get_num_threads()
    assert main(["--profile", "--ladder", "10", "--families", "generated-metro-bi", "--algorithms", "random",
                 "--n-eval", "300", "--threads", "1"]) == 0
    assert numba.get_num_threads() == before
    lines = capsys.readouterr().out.splitlines()
    run = next(line for line in lines if line.startswith("generated-metro-bi/10"))
    values = [float(v) for v in run.split()[2:]]
    assert len(values) == 10 and values[-2] > 0  # 8 parts, the total, ms per evaluation
    assert values[8] == pytest.approx(sum(values[:8]), abs=6e-3)  # printed to 3 decimals
    with pytest.raises(SystemExit, match="none of the study's"):
        main(["--profile", "--ladder", "10", "--algorithms", "no-such-algorithm"])


def test_the_single_study_runs_and_reports_the_gap_to_the_optimum(tmp_path, capsys):
    from benchmarks.suite_baseline import main

    work, out = tmp_path / "work", tmp_path / "reports"
    assert main(["--study", "single", "--families", "generated-metro-single", "--ladder", "10", "--seeds", "2",
                 "--n-eval", "200", "--workers", "1", "--work", str(work), "--out", str(out), "--estimate"]) == 0
    report = (out / "suite_baseline_single.md").read_text()
    assert report.startswith("# Suite baseline table, one-objective families (reduced run")
    assert "gap_kwh" in report and "igd_plus" not in report and "${" not in report
    assert "from `benchmarks/suite_baseline_single.toml`: 1 (family, n_var) cells x 5 algorithms x 2 seeds" in report
    rows = [line for line in report.splitlines() if line.startswith("| generated-metro-single")]
    assert len(rows) == 5 and all(line.count("|") > 8 for line in rows)
    assert "| form | algorithm | 200 evals |" in report  # who leads at each checkpoint: n_eval 200 is the budget
    leaders = [line.split("|") for line in report.splitlines() if line.startswith("| single |") and "evals" not in line]
    assert sum(int(cells[-2]) for cells in leaders[-5:]) >= 1  # the last table: a leader in the one cell
    assert (out / "suite_baseline_single_convergence.png").is_file() and (out / "suite_baseline_single_profile.png").is_file()
    assert "the whole study (measured n_var 10)" in capsys.readouterr().out


def test_the_trip_study_runs_its_repaired_algorithms_trusted_and_every_run_is_feasible(tmp_path):
    from benchmarks.suite_baseline import main

    work, out = tmp_path / "work", tmp_path / "reports"
    # the package's own trip study names its algorithms by import path: the script trusts it (no --trust)
    assert main(["--study", "trip", "--families", "generated-metro-trip", "--ladder", "10", "--seeds", "2",
                 "--n-eval", "200", "--workers", "1", "--work", str(work), "--out", str(out)]) == 0
    report = (out / "suite_baseline_trip.md").read_text()
    assert report.startswith("# Suite baseline table, -trip families with the budget repair (reduced run")
    rows = [line.split("|") for line in report.splitlines() if line.startswith("| generated-metro-trip")]
    assert sorted(row[3].strip() for row in rows) == ["ABC", "DE", "GA", "PSO", "random"]
    assert all(row[-2].strip() == "2" for row in rows)  # both seeds of every algorithm scored: feasible
    assert all(float(row[4].split("+-")[0]) >= 0 for row in rows)  # mean gap: never below the exact split
