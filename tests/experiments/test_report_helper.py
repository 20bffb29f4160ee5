"""pymoo_rail.experiments.report: the number formats and tables every benchmark report is written with."""

from __future__ import annotations

import math

import numpy as np
import pandas as pd
import pytest

from pymoo_rail.experiments.report import fixed, markdown, markdown_rows, mean_std, significant, write_report


def test_fixed_writes_decimals_and_says_what_is_missing():
    assert fixed(3.14159) == "3.14" and fixed(np.float64(2.5), 0) == "2"
    assert fixed(None) == fixed(float("nan")) == fixed(math.inf) == "-"
    assert fixed(float("nan"), missing="n/a") == "n/a"
    assert fixed(np.True_) == "yes" and fixed(False) == "no"
    assert fixed(np.int64(7)) == "7" and fixed("label") == "label"


def test_significant_switches_to_scientific_notation_outside_1e_3_to_1e5():
    assert significant(1234.5678) == "1235" and significant(0.5) == "0.5" and significant(0) == "0"
    assert significant(0.00012345) == "1.234e-04" and significant(123456.0) == "1.235e+05"
    assert significant(float("nan")) == "" and significant(None, missing="nan") == "nan"
    assert mean_std([1.0, 2.0, 3.0, None, float("nan")]) == "2 +- 1" and mean_std([2.5]) == "2.5"
    assert mean_std([]) == ""


def test_markdown_formats_float_cells_only(tmp_path):
    frame = pd.DataFrame({"case": ["a", "b"], "runs": [3, 4], "energy kWh": [1.23456, float("nan")]})
    assert markdown(frame, 2).splitlines() == ["| case | runs | energy kWh |", "|---|---|---|",
                                               "| a | 3 | 1.23 |", "| b | 4 | nan |"]
    assert markdown(frame, 1, missing="-").splitlines()[-1] == "| b | 4 | - |"
    assert markdown_rows(["x", "y"], [[1, "z"]]) == "| x | y |\n|---|---|\n| 1 | z |"
    assert markdown_rows(["x", "y", "w"], [[1, "z", 2]], right_from=1).splitlines()[1] == "|---|---:|---:|"
    path = write_report(tmp_path / "r.md", ["# title", "", "text"])
    assert path.read_text() == "# title\n\ntext\n"
    assert write_report(tmp_path / "s.md", ["a", "b"], newline=False).read_text() == "a\nb"


def test_fill_template_fills_every_placeholder_and_names_what_is_missing_or_unused(tmp_path):
    import pytest

    from pymoo_rail.experiments.report import fill_template

    template = tmp_path / "r.md"
    template.write_text("# ${title}\n\n${table} costs $$5, ${n} runs\n")
    assert fill_template(template, {"title": "T", "table": "| a |", "n": 3}) == "# T\n\n| a | costs $5, 3 runs\n"
    with pytest.raises(KeyError, match=r"no value for \$\{n\}"):
        fill_template(template, {"title": "T", "table": ""})
    with pytest.raises(ValueError, match="no placeholder for the value.s. runs"):
        fill_template(template, {"title": "T", "table": "", "n": 1, "runs": 2})


def test_require_runs_names_the_missing_record(tmp_path):
    from pymoo_rail.experiments import Study, algorithm, problem
    from pymoo_rail.experiments.report import require_runs

    study = Study("s", problems=[problem("zdt1")], algorithms=[algorithm("nsga2", pop_size=10)], seeds=2,
                  budget={"n_gen": 2})
    first, second = study.runs()
    require_runs(pd.DataFrame({"run_id": [first.run_id, second.run_id]}), study, tmp_path)  # all there
    with pytest.raises(FileNotFoundError, match=r"1 of the 2 runs of study 's' \(e.g. zdt1 / nsga2 / seed 2\)"):
        require_runs(pd.DataFrame({"run_id": [first.run_id]}), study, tmp_path)
    with pytest.raises(FileNotFoundError, match="2 of the 2 runs"):
        require_runs(pd.DataFrame(), study, tmp_path)


def test_script_figures_are_ready_with_records_or_committed_inputs(tmp_path):
    from pymoo_rail.experiments.report import ScriptFigures

    entry = ScriptFigures("x", ("x.png",), records="out/x")
    assert not entry.has_records(tmp_path) and not entry.ready(tmp_path)
    (tmp_path / "out" / "x" / "sub").mkdir(parents=True)
    assert not entry.ready(tmp_path)  # an empty folder holds no records
    (tmp_path / "out" / "x" / "sub" / "run.json").write_text("{}")
    assert entry.has_records(tmp_path) and entry.ready(tmp_path)
    assert ScriptFigures("y", ("y.png",), from_committed=("y.png",)).ready(tmp_path)
    assert not ScriptFigures("z", ("z.png",)).has_records(tmp_path)


def test_a_failing_report_mode_returns_its_exit_status(tmp_path, capsys):
    from pymoo_rail.experiments.report import ScriptFigures

    (tmp_path / "benchmarks").mkdir()
    (tmp_path / "benchmarks" / "bad.py").write_text("raise SystemExit('no records')\n")
    assert ScriptFigures("bad", ("bad.png",)).rebuild(tmp_path) == 1
    assert "failed (1): no records" in capsys.readouterr().out


def test_write_filled_writes_exactly_the_filled_template(tmp_path):
    from pymoo_rail.experiments.report import write_filled

    template = tmp_path / "t.md"
    template.write_text("# ${title}\n\n${body}\n", encoding="utf-8")
    text = write_filled(tmp_path / "out.md", template, {"title": "T", "body": "b"})
    assert text == "# T\n\nb\n" == (tmp_path / "out.md").read_text(encoding="utf-8")


def test_committed_members_limit_keeps_the_first_of_each_case():
    from pathlib import Path

    from pymoo_rail.experiments.report import committed_members

    reports = Path(__file__).resolve().parents[2] / "benchmarks" / "reports"
    every, first = committed_members(reports), committed_members(reports, limit=1)
    assert len(first) == every["case"].nunique()
    assert first.reset_index(drop=True).equals(every.groupby("case", sort=False).head(1).reset_index(drop=True))
