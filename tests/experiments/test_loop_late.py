"""The study's worlds too late to be on time: the policy against the race from the start."""

import pandas as pd
import pytest

from pymoo_rail.experiments.loop_late import late_world_arrivals, late_worlds_markdown


def _rows():
    rows = []
    # world 0: on time possible (left out); worlds 1-3 too late
    for run, can, policy_s, race_s, restricted, policy_kwh in [(0, True, 100.0, 90.0, False, 9.0),
                                                               (1, False, 101.0, 100.0, False, 9.0),
                                                               (2, False, 110.0, 100.0, True, 8.0),
                                                               (3, False, 99.0, 100.0, False, 9.5)]:
        rows.append({"case": "a", "run": run, "controller": "optimal_controls", "can_be_on_time": can,
                     "running_time_s": policy_s, "restricted": restricted, "net_kwh": policy_kwh})
        rows.append({"case": "a", "run": run, "controller": "recovery", "can_be_on_time": can,
                     "running_time_s": race_s, "restricted": restricted, "net_kwh": 10.0})
    return pd.DataFrame(rows)


def test_only_worlds_too_late_are_compared_paired_by_world():
    table = late_world_arrivals(_rows()).iloc[0]
    assert table["worlds"] == 3
    assert table["median_s"] == pytest.approx(1.0)  # differences +1, +10, -1
    assert table["max_s"] == pytest.approx(10.0)
    assert table["later_than_race"] == 1 and table["restricted_among_later"] == 1
    assert table["energy_saved_pct"] == pytest.approx(10.0)  # 10 %, 20 %, 5 %


def test_markdown_names_the_case_and_the_count_later():
    text = late_worlds_markdown(_rows())
    assert "| a | 3 | +1.00 | +10.00 | 1 (1 restricted) | 10.0 % |" in text
