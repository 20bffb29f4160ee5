"""benchmarks/peers.py: the parsing of ms-eetc's output (fast) and a live run when a checkout exists (slow)."""

from __future__ import annotations

import os
from pathlib import Path

import pandas as pd
import pytest

MSEETC = Path(os.environ.get("MSEETC_CHECKOUT", "/tmp/mseetc"))
MSEETC_PYTHON = os.environ.get("MSEETC_PYTHON", "/work/venv-mseetc/bin/python")


def _script():
    from benchmarks import peers

    return peers


def test_the_last_json_line_is_the_result():
    peers = _script()
    out = "This is Ipopt version 3.14\nEXIT: Optimal Solution Found.\n" '{"energy_kwh": 441.08, "cpu_s": 3.47}\n\n'
    assert peers.parse_mseetc_output(out) == (441.08, 3.47)
    # a line that descends enough regenerates more than the train draws: net energy < 0 is a result
    assert peers.parse_mseetc_output('{"energy_kwh": -16.0, "cpu_s": 2.7}') == (-16.0, 2.7)


@pytest.mark.parametrize("out, message", [("", "printed nothing"), ("EXIT: Infeasible\n", "not JSON"),
                                          ('{"energy_kwh": 1.0}', "not JSON"),
                                          ('{"energy_kwh": NaN, "cpu_s": 2.0}', "must be finite"),
                                          ('{"energy_kwh": 1.0, "cpu_s": 0.0}', "cpu_s > 0")])
def test_bad_output_names_what_is_wrong(out, message):
    with pytest.raises(ValueError, match=message):
        _script().parse_mseetc_output(out)


def test_speed_ratios():
    peers = _script()
    ours = pd.DataFrame([{"case": "a", "at_request_kwh": 101.0, "cpu_s": 2.0}])
    theirs = pd.DataFrame([{"case": "a", "solver": "x", "energy_kwh": 100.0, "cpu_s": 8.0, "source": "run here"}])
    r = peers.speed_ratios(ours, theirs).iloc[0]
    assert r["cpu_ratio"] == pytest.approx(4.0) and r["energy_diff_pct"] == pytest.approx(1.0)
    published = theirs.assign(source="published")
    assert peers.speed_ratios(ours, published)["cpu_ratio"].isna().all()  # another machine's time


def test_cpu_breakdown_finds_the_solvers_kernels():
    """Every part is measured (a renamed kernel would read as 0 s) and the parts add up to the whole."""
    b = _script().cpu_breakdown("yizhuang", 150.0)
    assert b["tables_s"] > 0.0 and b["sweeps_s"] > 0.0 and b["forward_runs_s"] > 0.0
    # a forward run per solve (the search's, the half grid's, the untied run's); a sweep per solve but the
    # untied run's where it reuses the chosen run's (same price)
    assert b["forward_runs"] >= 3 and b["forward_runs"] - 1 <= b["sweeps"] <= b["forward_runs"]
    assert 0.0 <= b["rest_s"] < b["cpu_s"]


@pytest.mark.slow
@pytest.mark.skipif(not (MSEETC / "mseetc").is_dir() or not Path(MSEETC_PYTHON).exists(),
                    reason="no ms-eetc checkout (MSEETC_CHECKOUT) or interpreter (MSEETC_PYTHON)")
def test_mseetc_live_on_the_level_case():
    """ms-eetc at N = 100 on the level 10 km case: the energy recorded for it on this machine (88.55 kWh)."""
    energy, cpu = _script().run_mseetc(MSEETC, MSEETC_PYTHON, "level_10km", 400.0, 100)
    assert energy == pytest.approx(88.5501, abs=0.01) and cpu > 0.0
