"""benchmarks/reference_check.py: which committed members it reads, and how it counts one below the reference."""

from __future__ import annotations

from pathlib import Path

import pandas as pd

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
    script = _script()
    table = pd.DataFrame({"source": ["s", "s"], "case": ["c", "c"], "label": ["a", "a"], "seed": [1, 2],
                          "member": ["best", "best"], "running_time_s": [100.0, 101.0], "energy_kwh": [9.0, 10.5],
                          "optimal_kwh": [10.0, 10.0], "gap_kwh": [-1.0, 0.5], "gap_rel": [-0.1, 0.05],
                          "energy_bound_kwh": [0.1, 0.1], "below_reference": [True, False], "in_range": [True, True]})
    table.to_csv(tmp_path / "reference_check.csv", index=False)
    assert script.main(["--report-only", "--out", str(tmp_path)]) == 1
    row = script.summary(table).iloc[0]
    assert row["below_reference"] == 1 and row["least margin kWh"] == -0.9
    assert "below the reference beyond the" in (tmp_path / "reference_check.md").read_text()
