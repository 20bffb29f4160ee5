"""pymoo_rail.experiments.peers (benchmarks/peers.py's library): the parsing of ms-eetc's output (fast) and a live run when a checkout exists (slow)."""

from __future__ import annotations

import os
from pathlib import Path

import pandas as pd
import pytest

MSEETC = Path(os.environ.get("MSEETC_CHECKOUT", "/tmp/mseetc"))
MSEETC_PYTHON = os.environ.get("MSEETC_PYTHON", "/work/venv-mseetc/bin/python")


def _script():
    from pymoo_rail.experiments import peers

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


def test_mseetc_answers_are_read_from_the_caches_by_seed_n_time_and_boundary_speeds(tmp_path):
    """A cached answer is found in any of the CSVs; another time, N or end speed is not (NaN without a checkout)."""
    peers = _script()
    case = peers.comparable_case(3)  # 20 m/s ends
    cache = tmp_path / "a.csv"
    pd.DataFrame([{"seed": 3, "n": 2000, "time_s": 271.876, "v0_ms": 20.0, "v_end_ms": 20.0, "energy_kwh": 46.2,
                   "cpu_s": 9.0, "end_ms": 20.0, "load": 1.0}]).to_csv(cache, index=False)
    missing = tmp_path / "none.csv"
    assert peers.mseetc_cached([missing, cache], 3, case, 271.87612, 2000, None, "", 1) == (46.2, 9.0, 20.0)
    for seed, t, n in ((3, 271.9, 2000), (3, 271.876, 300), (4, 271.876, 2000)):
        got = peers.mseetc_cached([cache], seed, case, t, n, None, "", 1)
        assert all(x != x for x in got), (seed, t, n)  # NaN: not run, not found
    table = pd.DataFrame([{"seed": 3, "time_s": 271.87612, "ms2000_kwh": float("nan"), "ms2000_cpu_s": 0.0,
                           "ms2000_end_ms": 0.0}])
    assert peers.refresh_cached(table, {2000: [cache]}).loc[0, "ms2000_kwh"] == 46.2
