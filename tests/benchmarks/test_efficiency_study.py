"""benchmarks/efficiency_study.py: the findings are computed from the table (fast; the study itself
needs an ms-eetc checkout and minutes: ``python benchmarks/efficiency_study.py --mseetc PATH``)."""

from __future__ import annotations

import pandas as pd


def test_findings_name_the_ranges_of_the_table():
    from benchmarks import efficiency_study

    rows = []
    for reserve, (own, dyn, ours, replayed, theirs) in {10: (0.2, -0.1, 123.0, 120.0, 120.5),
                                                        20: (-0.3, 1.5, 112.0, 108.0, 108.0)}.items():
        rows += [{"reserve_pct": reserve, "model": "perfect", "own_diff_pct": own, "dynamic_diff_pct": dyn},
                 {"reserve_pct": reserve, "model": "static", "own_diff_pct": 0.1, "dynamic_diff_pct": 0.5},
                 {"reserve_pct": reserve, "model": "dynamic", "own_diff_pct": 2.0, "dynamic_diff_pct": 2.0,
                  "ours_dynamic_kwh": ours, "mseetc_run_in_ours_kwh": replayed, "mseetc_dynamic_kwh": theirs}]
    text = "\n".join(efficiency_study.findings(pd.DataFrame(rows)))
    assert "within 0.30 %" in text  # the largest |own_diff_pct| of the fixed models
    assert "-0.10 to +1.50 %" in text
    assert "-0.41 to +0.00 %" in text  # 120 / 120.5 - 1 and 108 / 108 - 1
    assert "+2.50 to +3.70 %" in text  # 123 / 120 - 1 and 112 / 108 - 1
