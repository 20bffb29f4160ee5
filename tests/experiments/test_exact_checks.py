"""The exact solver's checks: the energy moved along the front's slope, the level case, and the
closed form against the DP (the tables ``benchmarks/optimal.py`` reports)."""

from __future__ import annotations

from types import SimpleNamespace

import pytest

from pymoo_rail.constants import J_PER_KWH
from pymoo_rail.experiments.exact_checks import energy_at, level_case, level_track_table


def test_energy_moves_along_the_slope_to_the_requested_time():
    run = SimpleNamespace(energy=SimpleNamespace(net_kwh=10.0), summary={"lambda_w": 2.0 * J_PER_KWH},
                          running_time_s=150.5)
    assert energy_at(run, 150.5) == 10.0
    assert energy_at(run, 150.0) == pytest.approx(11.0)  # half a second earlier costs lambda / 2
    assert energy_at(run, 151.0) == pytest.approx(9.0)


def test_the_level_case_is_5_km_of_level_track():
    case = level_case()
    assert case.line.length_m == 5000.0 and case.planned_time_s == 300.0


@pytest.mark.slow
def test_the_dp_meets_the_closed_form_on_level_track():
    table = level_track_table(times=(300.0,))
    assert abs(table["difference %"].iloc[0]) < 0.5
