"""benchmarks/reference_check.py: which committed members it reads, how it counts one below the reference
or a miss of the certificate, and the full coverage sweep (slow)."""

from __future__ import annotations

from pathlib import Path

import pandas as pd
import pytest

from pymoo_rail.experiments.reference_audit import coverage_summary, members_summary

SCRIPT = Path(__file__).resolve().parents[2] / "benchmarks" / "reference_check.py"


def _script():
    from benchmarks import reference_check

    return reference_check


def test_every_committed_member_is_read():
    from pymoo_rail.experiments.report import committed_members

    table = committed_members(SCRIPT.parent / "reports")
    counts = table.groupby("source").size().to_dict()
    # 180 yizhuang runs, 3 members of each of 58 wuguang runs, the 13 sections' strategy fronts
    assert counts["yizhuang_seed000"] == 180 and counts["emu_wuguang"] == 3 * 58
    sections = pd.read_csv(SCRIPT.parent / "reports" / "journeys_fronts_simulated.csv")
    assert counts["journeys"] == len(sections) and table["case"].nunique() == 2 + 13
    assert table[["running_time_s", "energy_kwh"]].notna().all().all()


def test_a_member_below_the_certificate_is_counted_and_fails_the_run(tmp_path):
    table = pd.DataFrame({"source": ["s", "s"], "case": ["c", "c"], "label": ["a", "a"], "seed": [1, 2],
                          "member": ["best", "best"], "running_time_s": [100.0, 101.0], "energy_kwh": [9.0, 10.5],
                          "optimal_kwh": [10.0, 10.0], "gap_kwh": [-1.0, 0.5], "gap_rel": [-0.1, 0.05],
                          "energy_bound_kwh": [0.1, 0.1], "below_reference": [True, False], "in_range": [True, True]})
    table.to_csv(tmp_path / "reference_check.csv", index=False)
    assert _script().main(["--report-only", "--out", str(tmp_path)]) == 1
    row = members_summary(table).iloc[0]
    assert row["below_reference"] == 1 and row["least margin kWh"] == -0.9
    assert "below the reference beyond the" in (tmp_path / "reference_check.md").read_text()


def test_report_only_without_the_stored_table_names_it(tmp_path):
    with pytest.raises(SystemExit, match="reference_check.csv"):
        _script().main(["--report-only", "--out", str(tmp_path)])
    assert not (tmp_path / "reference_check.md").exists()


def test_another_solve_lower_than_the_certificate_allows_is_a_miss():
    table = pd.DataFrame({"case": ["c", "c", "c"], "running_time_s": [100.0, 101.0, 102.0],
                          "default_kwh": [10.0, 10.0, 10.0], "certificate_kwh": [0.1, 0.1, 0.1],
                          "uniform_kwh": [9.95, 9.85, 10.2], "fine_kwh": [10.0, 10.0, 10.0]})
    s, lines = coverage_summary(table)
    uniform = s[s["other"] == "uniform"].iloc[0]
    fine = s[s["other"] == "fine"].iloc[0]
    # 9.95 is within the certificate of 10.0; 9.85 is 0.05 kWh beyond it; 10.2 is not lower
    assert uniform["other lower"] == 2 and uniform["misses"] == 1
    assert uniform["worst margin kWh"] == pytest.approx(-0.05)
    assert fine["other lower"] == 0 and fine["misses"] == 0
    assert "**1**" in lines[0] and "**0**" in lines[1]


@pytest.mark.slow
def test_the_certificate_covers_the_uniform_placement_and_twice_the_nodes_at_every_member_time(tmp_path):
    # about 100-250 CPU s: every distinct running time of the members reference_check reads
    assert _script().main(["--check", "coverage", "--out", str(tmp_path)]) == 0
    assert "misses: **0**" in (tmp_path / "certificate_coverage.md").read_text()
