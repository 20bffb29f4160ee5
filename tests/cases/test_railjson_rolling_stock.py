"""OSRD railjson rolling stock: the 11 realistic trains of OSRD's test data, modes, comfort, bad input;
``load_train`` on every train format."""

from __future__ import annotations

import copy
import json
import math
from pathlib import Path

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from pymoo_rail.cases import load_case, load_train, write_case
from pymoo_rail.cases.railjson_rolling_stock import RailjsonWarning, read_rolling_stock
from pymoo_rail.model import CaseError

DATA = Path(__file__).resolve().parents[1] / "data" / "osrd"
STOCKS = sorted((DATA / "rolling_stocks").glob("*.json"))
NAMES = [p.stem for p in STOCKS]


def _raw(name: str) -> dict:
    return json.loads((DATA / "rolling_stocks" / f"{name}.json").read_text())


def test_the_eleven_realistic_trains_are_there():
    assert NAMES == ["commuter-train", "d-tram-train", "dmu-regional-train", "e-tram-train", "emu-regional-train",
                     "freight-train", "high-speed-train", "intercity-train", "light-freight-train", "night-train",
                     "touristic-train"]


@pytest.mark.parametrize("path", STOCKS, ids=NAMES)
def test_every_field_maps_to_the_train(path):
    raw = json.loads(path.read_text())
    stock = read_rolling_stock(path)
    for mode in stock.modes:
        for comfort in (None,) + stock.comforts(mode):
            train = load_train(path, mode=mode, comfort=comfort)
            curve = raw["effort_curves"]["modes"][mode]
            points = curve["default_curve"] if comfort is None else \
                next(c["curve"] for c in curve["curves"] if c["cond"]["comfort"] == comfort)
            # the effort curve, point by point, in kN at km/h, and linear between points as in OSRD
            speeds_kmh = np.array(points["speeds"]) * 3.6
            assert train.traction.force_kn(speeds_kmh) == pytest.approx(np.array(points["max_efforts"]) / 1000.0)
            mid = 0.5 * (speeds_kmh[:-1] + speeds_kmh[1:])
            assert train.traction.force_kn(mid) == pytest.approx(
                0.5 * (np.array(points["max_efforts"][:-1]) + np.array(points["max_efforts"][1:])) / 1000.0)
    train = load_train(path)
    assert train.mass_kg == pytest.approx(raw["mass"])
    assert train.length_m == raw["length"]
    assert train.max_speed_ms == pytest.approx(raw["max_speed"])
    # OSRD accelerates mass x inertia_coefficient
    assert train.effective_mass_kg == pytest.approx(raw["mass"] * raw["inertia_coefficient"])
    assert train.max_accel_ms2 == raw["comfort_acceleration"]
    assert train.max_decel_ms2 == raw["const_gamma"]
    # braking at const_gamma on level track: force = gamma x inertia
    assert train.braking.force_kn(50.0)[0] * 1000.0 == pytest.approx(
        raw["const_gamma"] * raw["mass"] * raw["inertia_coefficient"])
    # Davis in N with v in m/s, as OSRD's RollingStock.getRollingResistance
    r = raw["rolling_resistance"]
    for v in (0.0, 10.0, 30.0):
        assert train.resistance.force_kn(v * 3.6, train.mass_t) * 1000.0 == pytest.approx(
            r["A"] + r["B"] * v + r["C"] * v * v, abs=1e-9)
    # OSRD's energy is mechanical: no efficiency, no regeneration
    assert (train.traction_efficiency, train.regen_efficiency, train.aux_power_kw) == (1.0, 0.0, 0.0)


def test_times_and_category_are_kept_on_the_rolling_stock():
    stock = read_rolling_stock(DATA / "rolling_stocks" / "commuter-train.json")
    assert (stock.startup_time_s, stock.startup_accel_ms2) == (25.0, 0.05)
    assert (stock.raise_pantograph_time_s, stock.electrical_power_startup_time_s) == (25.0, 5.0)
    assert stock.primary_category == "COMMUTER_TRAIN"
    diesel = read_rolling_stock(DATA / "rolling_stocks" / "dmu-regional-train.json")
    assert diesel.raise_pantograph_time_s is None and not diesel.is_electric()


def test_default_mode_and_the_mode_that_differs():
    # the high-speed train has a weaker 1500 V curve; its file's default mode is 1500V
    low = load_train(DATA / "rolling_stocks" / "high-speed-train.json")
    high = load_train(DATA / "rolling_stocks" / "high-speed-train.json", mode="25000V")
    assert "1500V" in low.name and "25000V" in high.name
    assert low.traction.force_kn(200.0)[0] < high.traction.force_kn(200.0)[0]
    assert low.traction.force_kn(200.0)[0] == pytest.approx(68.0)
    assert low.traction.force_kn(250.0)[0] == pytest.approx(62.0)  # the last point holds beyond 220 km/h


def test_unknown_mode_and_comfort_list_the_available_ones():
    path = DATA / "rolling_stocks" / "d-tram-train.json"
    with pytest.raises(CaseError, match=r"field 'mode' = '25000V'.*available: 750V, thermal; default thermal"):
        load_train(path, mode="25000V")
    with pytest.raises(CaseError, match=r"field 'comfort' = 'HEATING'.*available: STANDARD, AIR_CONDITIONING"):
        load_train(path, comfort="HEATING")


def test_a_comfort_curve_is_used_when_it_differs(tmp_path):
    raw = _raw("commuter-train")
    ac = raw["effort_curves"]["modes"]["25000V"]["curves"][1]
    assert ac["cond"]["comfort"] == "AIR_CONDITIONING"
    ac["curve"]["max_efforts"] = [f - 10000.0 for f in ac["curve"]["max_efforts"]]
    path = tmp_path / "ac.json"
    path.write_text(json.dumps(raw))
    standard = load_train(path, comfort="STANDARD")
    cooled = load_train(path, comfort="AIR_CONDITIONING")
    assert standard.traction.force_kn(0.0)[0] - cooled.traction.force_kn(0.0)[0] == pytest.approx(10.0)


def test_load_train_reads_every_format(tmp_path):
    # a case file, a TTOBench train, a railjson rolling stock, through the format registry
    yizhuang = load_case("yizhuang")
    path = write_case(yizhuang, tmp_path / "y.toml")
    assert load_train(path) == yizhuang.train
    tto = Path(__file__).resolve().parents[2] / "pymoo_rail" / "cases" / "data" / "CN_Beijing_Subway.json"
    assert load_train(tto).mass_t == pytest.approx(278.0)
    assert load_train(STOCKS[0]).mass_t == pytest.approx(390.0)
    with pytest.raises(CaseError, match="field 'options'.*mode.*the toml reader takes"):
        load_train(path, mode="25000V")
    with pytest.raises(CaseError, match="field 'options'.*comfort.*the ttobench reader takes"):
        load_train(tto, comfort="STANDARD")


def test_load_train_names_what_it_cannot_read(tmp_path):
    with pytest.raises(CaseError, match="no such train file"):
        load_train(tmp_path / "missing.json")
    with pytest.raises(CaseError, match="railjson infrastructure, not a train"):
        load_train(DATA / "infras" / "tiny_infra.json")
    broken = tmp_path / "broken.json"
    broken.write_text("{")
    with pytest.raises(CaseError, match="not valid JSON"):
        load_train(broken)


def _write(tmp_path, raw) -> Path:
    path = tmp_path / "stock.json"
    path.write_text(json.dumps(raw))
    return path


@pytest.mark.parametrize("change, field", [
    (lambda r: r["rolling_resistance"].update(type="polynomial"), "rolling_resistance.type"),
    (lambda r: r["rolling_resistance"].update(B=-1.0), "rolling_resistance.B"),
    (lambda r: r.update(inertia_coefficient=0.9), "inertia_coefficient"),
    (lambda r: r.update(comfort_acceleration=0.0), "comfort_acceleration"),
    (lambda r: r.pop("mass"), "mass"),
    (lambda r: r.update(length="110"), "length"),
    (lambda r: r["effort_curves"].update(default_mode="3000V"), "effort_curves.default_mode"),
    (lambda r: r["effort_curves"]["modes"]["1500V"]["default_curve"]["speeds"].__setitem__(0, 1.0),
     "effort_curves.modes.1500V.default_curve.speeds[0]"),
    (lambda r: r["effort_curves"]["modes"]["1500V"]["default_curve"]["speeds"].__setitem__(3, 0.5),
     "effort_curves.modes.1500V.default_curve.speeds[3]"),
    (lambda r: r["effort_curves"]["modes"]["1500V"]["default_curve"]["max_efforts"].pop(),
     "effort_curves.modes.1500V.default_curve.max_efforts"),
    (lambda r: r["effort_curves"]["modes"]["25000V"].update(is_electric="yes"),
     "effort_curves.modes.25000V.is_electric"),
])
def test_what_cannot_be_represented_names_the_field(tmp_path, change, field):
    raw = _raw("commuter-train")
    change(raw)
    with pytest.raises(CaseError) as err:
        load_train(_write(tmp_path, raw))
    assert err.value.field == field
    assert str(_write(tmp_path, raw)) in str(err.value)


def test_fields_not_modelled_warn(tmp_path):
    raw = _raw("commuter-train")
    raw["energy_sources"] = [{"energy_source_type": "Battery"}]
    raw["etcs_brake_params"] = {"gamma_emergency": {}}
    raw["effort_curves"]["modes"]["25000V"]["curves"][0]["cond"]["power_restriction_code"] = "C1"
    with pytest.warns(RailjsonWarning) as record:
        train = load_train(_write(tmp_path, raw))
    fields = " ".join(str(w.message) for w in record)
    assert "'energy_sources'" in fields and "'etcs_brake_params'" in fields and "power_restriction_code" not in fields
    assert "curves[0].cond" in fields
    assert train.max_decel_ms2 == raw["const_gamma"]


_NUMERIC = ["mass", "length", "max_speed", "inertia_coefficient", "comfort_acceleration", "const_gamma"]


@settings(max_examples=40, deadline=None)
@given(key=st.sampled_from(_NUMERIC),
       value=st.one_of(st.floats(allow_nan=True, allow_infinity=True).filter(lambda v: not (v > 0 and
                                                                                             math.isfinite(v))),
                       st.text(max_size=3), st.booleans(), st.none()))
def test_generated_bad_numbers_name_the_field(key, value):
    raw = copy.deepcopy(_RAW_COMMUTER)
    raw[key] = value
    with pytest.raises(CaseError) as err:
        read_rolling_stock(raw).train()
    assert err.value.field == key


_RAW_COMMUTER = _raw("commuter-train")
