"""benchmarks/efficiency_study.py and pymoo_rail.experiments.efficiency_study: the findings are
computed from the table (fast; the study itself needs an ms-eetc checkout and minutes: ``python benchmarks/efficiency_study.py --mseetc PATH``)."""

from __future__ import annotations

import os
import sys
from pathlib import Path

import pandas as pd
import pytest

from pymoo_rail.experiments.report import fill_template

MSEETC = Path(os.environ.get("MSEETC_CHECKOUT", "/tmp/mseetc"))


def test_findings_name_the_ranges_of_the_table():
    from benchmarks import efficiency_study
    from pymoo_rail.experiments.efficiency_study import findings

    rows = []
    for reserve, (own, dyn, ours, replayed, theirs) in {10: (0.2, -0.1, 123.0, 120.0, 120.5),
                                                        20: (-0.3, 1.5, 112.0, 108.0, 108.0)}.items():
        rows += [{"reserve_pct": reserve, "model": "perfect", "own_diff_pct": own, "dynamic_diff_pct": dyn},
                 {"reserve_pct": reserve, "model": "static", "own_diff_pct": 0.1, "dynamic_diff_pct": 0.5},
                 {"reserve_pct": reserve, "model": "dynamic", "own_diff_pct": 2.0, "dynamic_diff_pct": 2.0,
                  "ours_dynamic_kwh": ours, "mseetc_run_in_ours_kwh": replayed, "mseetc_dynamic_kwh": theirs}]
    values = findings(pd.DataFrame(rows))
    assert values["own_within"] == "0.30"  # the largest |own_diff_pct| of the fixed models
    text = fill_template(efficiency_study.TEMPLATE, {"intervals": 300, "reserves": "10 20", "held": 0,
                                                     "table": "", **values})
    assert "within 0.30 %" in text  # the largest |own_diff_pct| of the fixed models
    assert "-0.10 to +1.50 %" in text
    assert "-0.41 to +0.00 %" in text  # 120 / 120.5 - 1 and 108 / 108 - 1
    assert "+2.50 to +3.70 %" in text  # 123 / 120 - 1 and 112 / 108 - 1
    assert "+2.00 to +2.00 %" in text  # the dynamic rows' own_diff_pct
    rows[2].update(ours_part_power_km=3.21, mseetc_part_power_km=4.0)
    rows[5].update(ours_part_power_km=2.0, mseetc_part_power_km=2.5)
    assert findings(pd.DataFrame(rows))["part_power"] == "3.2 / 4.0 km at 10 %, 2.0 / 2.5 km at 20 %"


def test_sampled_maps_reproduce_the_loss_function_they_come_from():
    """maps_from_losses inverts its own formula: the maps give back the losses at the nodes."""
    import numpy as np

    from pymoo_rail.model.efficiency import maps_from_losses

    speeds, forces = np.array([10.0, 50.0, 100.0]), np.array([5.0, 50.0, 200.0])
    v, f = speeds[:, None] / 3.6, forces[None, :] * 1000.0
    traction_loss = 27e3 + 0.05 * f * v + 2e3 * (1 + v / 10)  # aux + proportional + no-load
    braking_loss = 27e3 + 0.08 * f * v
    traction, regen, held = maps_from_losses(speeds, forces, traction_loss, braking_loss, 27.0)
    eta_t, eta_r = np.array(traction.values), np.array(regen.values)
    assert np.allclose(f * v / eta_t - f * v, traction_loss - 27e3, rtol=1e-12)
    assert np.allclose(f * v - eta_r * f * v, braking_loss - 27e3, rtol=1e-12)
    assert held == 0
    # a braking loss above the brake power: the regen map holds the floor, and says so
    _, low, held = maps_from_losses(speeds, forces, traction_loss, braking_loss + 1e6, 27.0)
    assert held > 0 and min(min(row) for row in low.values) == 0.01


@pytest.mark.slow
@pytest.mark.skipif(not (MSEETC / "mseetc").is_dir(), reason="no ms-eetc checkout (MSEETC_CHECKOUT)")
def test_mseetc_study_driver_returns_the_run_and_the_losses():
    """ms-eetc under its dynamic losses at N = 100, with a small loss grid (~30 s)."""
    from benchmarks import efficiency_study as study
    from pymoo_rail.cases import load_case
    from pymoo_rail.experiments.efficiency_study import mseetc_run
    from pymoo_rail.optimal import efficiency_study as es

    case = es.study_case(load_case(study.BASE_CASE))
    grid = {"speeds_ms": [10.0, 30.0], "forces_n": [[50e3, -50e3], [50e3, -50e3]]}
    result = mseetc_run(MSEETC, sys.executable, 100, case, es.STUDY_MIN_TIME_S * 1.2, "dynamic", grid)
    assert len(result["loss_w"]) == 2 and all(loss > 27e3 for row in result["loss_w"] for loss in row)
    assert result["position_m"][-1] == pytest.approx(8500.0) and result["speed_ms"][-1] == pytest.approx(100 / 3.6)
    # its midpoint energy and its CVODES-integrated one agree
    assert result["dynamic_energy_kwh"] == pytest.approx(result["energy_kwh"], rel=5e-3)


def test_the_command_line_help_prints():
    import subprocess

    script = Path(__file__).resolve().parents[2] / "benchmarks" / "efficiency_study.py"
    out = subprocess.run([sys.executable, str(script), "--help"], capture_output=True, text=True, check=True)
    assert "--mseetc" in out.stdout and "time reserves (%)" in out.stdout
