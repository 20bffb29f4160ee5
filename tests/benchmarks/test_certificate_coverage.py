"""benchmarks/certificate_coverage.py: how it counts a miss, and the full sweep (slow)."""

from __future__ import annotations

import pandas as pd
import pytest


def _script():
    from benchmarks import certificate_coverage

    return certificate_coverage


def test_another_solve_lower_than_the_certificate_allows_is_a_miss():
    script = _script()
    table = pd.DataFrame({"case": ["c", "c", "c"], "running_time_s": [100.0, 101.0, 102.0],
                          "default_kwh": [10.0, 10.0, 10.0], "certificate_kwh": [0.1, 0.1, 0.1],
                          "uniform_kwh": [9.95, 9.85, 10.2], "fine_kwh": [10.0, 10.0, 10.0]})
    s, lines = script.summary(table)
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
    assert _script().main(["--out", str(tmp_path)]) == 0
    assert "misses: **0**" in (tmp_path / "certificate_coverage.md").read_text()
