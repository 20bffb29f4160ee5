"""TTOBench import/export: the shipped Yizhuang data against seed 000, units, round trips, bad input."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest

from pymoo_rail.cases import load_case
from pymoo_rail.cases.ttobench import (
    BEIJING_SUBWAY_TRAIN,
    POINT_MASS_LENGTH_M,
    TTOBENCH_LICENSE,
    YIZHUANG_STOP_NAMES,
    YIZHUANG_TRACK,
    from_ttobench,
    read_track,
    read_train,
)
from pymoo_rail.cases.ttobench_writer import to_ttobench
from pymoo_rail.model import CaseError
from pymoo_rail.sim import Simulator, gradient_limit_partition, speed_code_programs
from pymoo_rail.sim.physics import build_kernel_model, electric_braking_capped, max_braking
from tests.conftest import make_case

SHARED = Path("/work/shared/data/ttobench")

# Seed 000 table 5-1 (Tongjinan Rd -> Jinghai Rd): [start_m, end_m, permille]
SEED_000_GRADIENTS = [(0, 130, 0), (130, 248, 0), (248, 568, -8), (568, 938, -3), (938, 1378, 5),
                      (1378, 2058, 1), (2058, 2155, 0), (2155, 2265, 0)]


def track_dict() -> dict:
    return json.loads(YIZHUANG_TRACK.read_text())


def train_dict() -> dict:
    return json.loads(BEIJING_SUBWAY_TRAIN.read_text())


def section(**kwargs):
    return from_ttobench(YIZHUANG_TRACK, BEIJING_SUBWAY_TRAIN, 9, 10, 150.0, **kwargs)


def summaries(case, dx_m=1.0):
    """Flat-out run and a few speed-code runs: the physics a round trip must keep."""
    sim = Simulator(case, dx_m)
    bounds = gradient_limit_partition(case.line)
    codes = np.array([[55.0], [65.0], [75.0]]) / 3.6 * np.ones(bounds.shape[0] - 1)
    programs = np.concatenate([speed_code_programs(bounds, codes),
                               speed_code_programs(bounds, np.full((1, bounds.shape[0] - 1), 100.0))])
    return sim.run_batch(programs)


# ------------------------------------------------------------------------------------ the data


def test_shipped_copies_equal_the_shared_data_and_keep_the_license():
    assert "Dimitris Kouzoupis" in TTOBENCH_LICENSE.read_text()
    assert "Redistributions of source code must retain" in TTOBENCH_LICENSE.read_text()
    if not SHARED.is_dir():
        pytest.skip("shared TTOBench directory not present")
    for path in (YIZHUANG_TRACK, BEIJING_SUBWAY_TRAIN):
        assert json.loads(path.read_text()) == json.loads((SHARED / path.name).read_text())
    assert TTOBENCH_LICENSE.read_text() == (SHARED / "LICENSE").read_text()


def test_yizhuang_track_has_14_stops_over_22728_m():
    track = read_track(YIZHUANG_TRACK)
    assert len(track.stops_m) == 14 == len(YIZHUANG_STOP_NAMES)
    assert track.length_m == 22728.0
    assert track.stops_m[9:11] == (15757.0, 18022.0)


def test_section_15757_18022_has_the_gradients_of_seed_000_table_5_1():
    case = section()
    assert case.line.length_m == 2265.0  # seed 000 5.1.1: 2265 m
    line = case.line
    for start, end, permille in SEED_000_GRADIENTS:
        # TTOBench change points lie 1 m after the seed's; permille values are rounded to integers in the seed
        inside = np.linspace(start + 1.5, end - 1.5, 25)
        got = np.array([next(g for s, e, g in line.gradients if s <= x < e) for x in inside])
        assert np.all(np.abs(got - permille) <= 0.5), (start, end, permille, got)
    seed_points = {s for s, _, _ in SEED_000_GRADIENTS}
    for s, _, _ in line.gradients[1:]:
        assert min(abs(s - p) for p in seed_points) <= 1.0
    # overall rise: seed -0.790 m, TTOBench -0.518 m; the whole difference is 0.4 permille over 680 m
    rise_seed = sum((e - s) * g for s, e, g in SEED_000_GRADIENTS) / 1000
    assert line.altitude_m(2265.0) == pytest.approx(rise_seed + 0.4 * 680 / 1000, abs=1e-9)


def test_beijing_train_in_model_units():
    t = read_train(BEIJING_SUBWAY_TRAIN).train
    assert t.mass_t == 278.0 and t.rotary_factor == 0.0 and t.max_speed_kmh == 80.0
    assert t.traction.max_force_kn == 310.0 and t.traction.max_power_kw == 3100.0
    assert t.braking.max_force_kn == 260.0 and t.braking.max_power_kw == 4333.0
    assert (t.regen_max_force_kn, t.regen_max_power_kw) == (260.0, 4333.0)
    assert (t.traction_efficiency, t.regen_efficiency) == (0.7, 0.8)
    r = t.resistance
    assert (r.a, r.b, r.c, r.unit, r.speed_unit) == (3.9476, 0.0, 0.0022294, "kN", "kmh")
    assert t.length_m == POINT_MASS_LENGTH_M  # no length in the file: point mass
    # traction limit 310 kN up to P/F = 36 km/h, then 3100 kW / v
    assert t.traction.force_kn(20.0)[0] == 310.0
    assert t.traction.force_kn(72.0)[0] == pytest.approx(3100.0 * 3.6 / 72.0)


def test_other_units_give_the_same_train_and_physics():
    d = train_dict()
    d["mass"] = {"unit": "t", "value": 278.0}
    d["rho"] = {"unit": "-", "value": 0.0}
    d["max speed"] = {"unit": "m/s", "value": 80.0 / 3.6}
    d["max traction power"] = {"unit": "MW", "value": 3.1}
    d["max reg braking power"] = {"unit": "W", "value": 4333e3}
    d["max traction force"] = {"unit": "N", "value": 310e3}
    d["rolling resistance r0"] = {"unit": "N", "value": 3947.6}
    d["rolling resistance r1"] = {"unit": "N/(m/s)", "value": 0.0}
    d["rolling resistance r2"] = {"unit": "N/(m/s)^2", "value": 0.0022294 * 1000 * 3.6**2}
    d["efficiency traction"] = {"unit": "-", "value": 0.7}
    d["efficiency reg brake"] = {"unit": "-", "value": 0.8}
    tr = track_dict()
    tr["stops"] = {"unit": "km", "values": [x / 1000 for x in tr["stops"]["values"]]}
    a, b = section(), from_ttobench(tr, d, 9, 10, 150.0)
    for name in ("mass_t", "max_speed_kmh", "traction_efficiency", "regen_efficiency"):
        assert getattr(b.train, name) == pytest.approx(getattr(a.train, name), rel=1e-12)
    assert b.train.resistance.c == pytest.approx(0.0022294, rel=1e-12)
    assert b.line.length_m == pytest.approx(2265.0, rel=1e-12)
    np.testing.assert_allclose(summaries(b), summaries(a), rtol=1e-9, atol=1e-9)


@pytest.mark.parametrize("stop_from, stop_to", [(9, 10), ("Tongjinan Rd", "jinghai rd"), (15757.0, 18022.0),
                                                (-5, -4), (15757.3, 10)])
def test_stops_by_index_name_or_position(stop_from, stop_to):
    case = from_ttobench(YIZHUANG_TRACK, BEIJING_SUBWAY_TRAIN, stop_from, stop_to, 150.0,
                         stop_names=YIZHUANG_STOP_NAMES)
    assert case.line == section().line


@pytest.mark.parametrize("stop_from, stop_to, match", [
    (9, 14, "index out of range"), ("Tongjinan Rd", 10, "stop_names"), (15700.0, 10, "no stop at"),
    (10, 9, "to_stop"), (True, 10, "stop"), (9, 9, "to_stop"),
])
def test_bad_stop_references(stop_from, stop_to, match):
    with pytest.raises(CaseError, match=match):
        from_ttobench(YIZHUANG_TRACK, BEIJING_SUBWAY_TRAIN, stop_from, stop_to, 150.0)


def test_unknown_stop_name():
    with pytest.raises(CaseError, match="no such stop"):
        from_ttobench(YIZHUANG_TRACK, BEIJING_SUBWAY_TRAIN, "Wangfujing", 10, 150.0, stop_names=YIZHUANG_STOP_NAMES)


# ------------------------------------------------------------------------------- round trips


def _json_values(obj):
    """The numeric content of a TTOBench object, keyed by field."""
    out = {}
    for key, entry in obj.items():
        if key == "metadata":
            continue
        out[key] = entry.get("value", entry.get("values"))
    return out


def test_ttobench_to_case_to_ttobench_gives_the_same_train_values(tmp_path):
    case = section()
    _, train_path = to_ttobench(case, tmp_path)
    original, written = _json_values(train_dict()), _json_values(json.loads(train_path.read_text()))
    assert set(original) == set(written)
    for key, value in original.items():
        assert written[key] == pytest.approx(value, rel=1e-12, abs=1e-12), key
    units = json.loads(train_path.read_text())
    assert all(units[key]["unit"] == train_dict()[key]["unit"] for key in original)


def test_whole_line_round_trip_gives_the_same_change_points(tmp_path):
    case = from_ttobench(YIZHUANG_TRACK, BEIJING_SUBWAY_TRAIN, 0, -1, 1500.0)
    track_path, _ = to_ttobench(case, tmp_path, altitude_m=0.0)
    written, original = json.loads(track_path.read_text()), track_dict()
    for key in ("speed limits", "gradients"):
        assert np.allclose(written[key]["values"], original[key]["values"], rtol=0, atol=1e-9), key
        assert written[key]["units"] == original[key]["units"]
    assert written["stops"]["values"] == [0.0, 22728.0]  # one case = one run: the stops in between are passed
    assert written["altitude"] == original["altitude"]
    assert "Kouzoupis" in written["metadata"]["license"]


@pytest.mark.parametrize("train_length_m", [None, 140.0])
def test_case_to_ttobench_to_case_keeps_the_physics(tmp_path, train_length_m):
    case = section(train_length_m=train_length_m, dwell_s=30.0)
    track_path, train_path = to_ttobench(case, tmp_path)
    back = from_ttobench(track_path, train_path, 0, 1, 150.0, dwell_s=30.0)
    assert back.train == case.train and back.line == case.line
    np.testing.assert_array_equal(summaries(back), summaries(case))


def test_synthetic_case_round_trip_with_every_convertible_field(tmp_path):
    # Per-weight resistance with v in m/s, a force-only traction curve, braking with a force cap only,
    # rotating mass, acceleration caps, a whole-train model and an uneven line.
    case = make_case(
        train={"rotary_factor": 0.08, "max_accel_ms2": 0.9, "max_decel_ms2": 1.0, "traction_efficiency": 0.85,
               "regen_efficiency": 0.6, "resistance": {"a": 1.2, "b": 0.01, "c": 0.0003, "unit": "N/kN",
                                                       "speed_unit": "ms"},
               "traction": {"max_force_kn": 150.0}, "braking": {"max_force_kn": 140.0, "regen_max_force_kn": 90.0}},
        line={"gradients": [[0.0, 700.0, 4.0], [700.0, 1500.0, -6.0], [1500.0, 2000.0, 0.0]],
              "speed_limits": [[0.0, 300.0, 60.0], [300.0, 2000.0, 100.0]]},
    )
    track_path, train_path = to_ttobench(case, tmp_path)
    data = json.loads(train_path.read_text())
    assert data["max pn braking force"]["value"] == pytest.approx(50.0)  # 140 total - 90 electric
    assert data["length"] == {"unit": "m", "value": 100.0}
    back = from_ttobench(track_path, train_path, 0, 1, 100.0)
    assert back.train.rotary_factor == pytest.approx(0.08) and back.train.max_accel_ms2 == 0.9
    np.testing.assert_allclose(summaries(back), summaries(case), rtol=1e-9, atol=1e-6)


def test_pneumatic_braking_maps_to_total_braking_with_electric_regen_caps():
    d = train_dict()
    d["max pn braking force"] = {"unit": "kN", "value": 100.0}
    case = from_ttobench(YIZHUANG_TRACK, d, 9, 10, 150.0)
    model = build_kernel_model(case)
    for v_kmh in (0.0, 30.0, 59.0, 61.0, 70.0, 79.9):
        v = v_kmh / 3.6
        electric = min(260e3, 4333e3 / v) if v > 0 else 260e3
        total = max_braking(model, v, 0)  # level, no deceleration cap: the curve itself
        assert total == pytest.approx(100e3 + electric, rel=2e-5)
        assert electric_braking_capped(model, v, total) == pytest.approx(electric, rel=1e-12)
    # ... and it goes back to the same TTOBench values
    from pymoo_rail.cases.ttobench_writer import train_to_json
    out = train_to_json(case.train, "x")
    assert out["max pn braking force"]["value"] == pytest.approx(100.0, rel=1e-12)
    assert out["max reg braking force"]["value"] == 260.0 and out["max reg braking power"]["value"] == 4333.0


def test_builtin_case_file_is_the_ttobench_section():
    builtin, converted = load_case("yizhuang-ttobench"), section(dwell_s=30.0)
    assert builtin.train == converted.train and builtin.line == converted.line
    assert (builtin.planned_time_s, builtin.dwell_s) == (150.0, 30.0)
    assert "BSD 2-Clause" in builtin.source and "Kouzoupis" in builtin.source
    seed = load_case("yizhuang")
    assert seed.line.length_m == builtin.line.length_m == 2265.0


# ------------------------------------------------------------------------------------ bad input


def _set(path: str, value):
    def mutate(d):
        *keys, last = path.split("/")
        node = d
        for key in keys:
            node = node[int(key)] if isinstance(node, list) else node[key]
        if value is _DELETE:
            del node[last]
        else:
            node[int(last) if isinstance(node, list) else last] = value
    return mutate


_DELETE = object()

TRAIN_CASES = [
    (_set("mass/unit", _DELETE), "mass.unit", "is required"),
    (_set("mass/unit", "lb"), "mass.unit", "unknown unit"),
    (_set("max speed/unit", "mph"), "max speed.unit", "unknown unit"),
    (_set("rolling resistance r2/unit", "kN/(km/h)"), "rolling resistance r2.unit", "unknown unit"),
    (_set("rolling resistance r1", {"value": 0.0}), "rolling resistance r1.unit", "is required"),
    (_set("efficiency traction/value", 0.9), "efficiency traction.value", "fraction"),
    (_set("efficiency reg brake", _DELETE), "efficiency reg brake", "both efficiencies"),
    (_set("efficiency traction/value", 170.0), "efficiency traction", "<= 1"),
    (_set("max traction force/value", -1.0), "max traction force.value", "> 0"),
    (_set("mass/value", "heavy"), "mass.value", "finite number"),
    (_set("max pn braking force/value", -5.0), "max pn braking force.value", ">= 0"),
    (_set("max speed", _DELETE), "max speed", "is required"),
    (_set("top speed", {"unit": "km/h", "value": 80}), "top speed", "unknown field"),
    (_set("rho/value", 150.0), "rho", "<= 1"),
]


@pytest.mark.parametrize("mutate, field, reason", TRAIN_CASES, ids=[c[1] + ":" + c[2] for c in TRAIN_CASES])
def test_bad_train_input_names_the_field(mutate, field, reason):
    d = train_dict()
    mutate(d)
    with pytest.raises(CaseError, match=reason) as err:
        from_ttobench(YIZHUANG_TRACK, d, 9, 10, 150.0)
    assert err.value.field == field


_TUNNEL_UNITS = {"position": "m", "length": "m", "cross section": "m^2"}
_CURVE_UNITS = {"position": "m", "radius at start": "m", "radius at end": "m"}
TRACK_CASES = [
    (_set("gradients/values/5", [1000.0, 3.0]), "gradients.values[5]", "sorted"),
    (_set("speed limits/values/3", [480.0, 70]), "speed limits.values[3]", "sorted"),
    (_set("gradients/units/slope", "%"), "gradients.units.slope", "unknown unit"),
    (_set("gradients/units", {"position": "m"}), "gradients.units.slope", "is required"),
    (_set("speed limits/units/velocity", "mph"), "speed limits.units.velocity", "unknown unit"),
    (_set("stops/unit", _DELETE), "stops.unit", "is required"),
    (_set("stops/values/3", 1000.0), "stops.values[3]", "sorted"),
    (_set("stops/values/0", 5.0), "stops.values[0]", "position 0"),
    (_set("speed limits/values/0", [10.0, 50]), "speed limits.values[0]", "position 0"),
    (_set("gradients/values/55", [22728.0, 2.0]), "gradients.values[55]", "before the end"),
    (_set("speed limits/values/2", [480.0, -5]), "speed limits.values[2]", "> 0"),
    (_set("speed limits/values/2", [480.0]), "speed limits.values[2]", "pair"),
    (_set("altitude/unit", "ft"), "altitude.unit", "unknown unit"),
    (_set("tunnels", {"units": {}, "values": [[100.0, 200.0, 40.0]]}), "tunnels.units", "exactly the units"),
    (_set("tunnels", {"units": _TUNNEL_UNITS, "values": [[100.0, 200.0, 40.0], [250.0, 10.0, 40.0]]}),
     "tunnels.values[1]", "overlaps"),
    (_set("tunnels", {"units": _TUNNEL_UNITS, "values": [[22700.0, 200.0, 40.0]]}), "tunnels.values[0]",
     "beyond the end"),
    (_set("curvatures", {"units": {}, "values": [[0.0, "infinity", "infinity"], [500.0, 400.0, 400.0]]}),
     "curvatures.units", "exactly the units"),
    (_set("curvatures", {"units": _CURVE_UNITS, "values": [[0.0, "infinity", "infinity"], [500.0, 0, 400.0]]}),
     "curvatures.values[1][1]", "radius of 0"),
    (_set("curvatures", {"units": _CURVE_UNITS, "values": [[0.0, "infinity", "straight"]]}),
     "curvatures.values[0][2]", "infinity"),
    (_set("ETCS braking data", {"Kt_int": {"unit": "-", "value": 1.1}}), "ETCS braking data.M_NVAVADH",
     "exactly"),
    (_set("metadata", {}), "metadata.id", "is required"),
]


@pytest.mark.parametrize("mutate, field, reason", TRACK_CASES, ids=[c[1] + ":" + c[2] for c in TRACK_CASES])
def test_bad_track_input_names_the_field(mutate, field, reason):
    d = track_dict()
    mutate(d)
    with pytest.raises(CaseError, match=reason) as err:
        from_ttobench(d, BEIJING_SUBWAY_TRAIN, 9, 10, 150.0)
    assert err.value.field == field


def test_level_track_without_gradients_and_straight_curvatures_are_accepted():
    d = track_dict()
    del d["gradients"]
    d["curvatures"] = {"units": _CURVE_UNITS, "values": [[0.0, "infinity", "infinity"]]}
    case = from_ttobench(d, BEIJING_SUBWAY_TRAIN, 9, 10, 150.0)
    assert case.line.gradients == ((0.0, 2265.0, 0.0),)


def test_unreadable_and_invalid_files(tmp_path):
    with pytest.raises(CaseError, match="cannot read"):
        read_track(tmp_path / "missing.json")
    bad = tmp_path / "bad.json"
    bad.write_text("{not json")
    with pytest.raises(CaseError, match="not valid JSON"):
        read_train(bad)


@pytest.mark.parametrize("change, field", [
    ({"train": {"aux_power_kw": 5.0}}, "train.aux_power_kw"),
    ({"train": {"regen_min_speed_kmh": 5.0}}, "train.regen_min_speed_kmh"),
    ({"train": {"traction": {"table": [[0.0, 100.0], [50.0, 80.0]]}}}, "train.traction.table"),
    ({"train": {"braking": {"max_force_kn": 300.0, "max_power_kw": 3000.0, "regen_max_force_kn": 100.0}}},
     "train.braking"),
    ({"line": {"curves": [[100.0, 300.0, 400.0]]}}, "line.curves"),
    ({"line": {"neutral_sections": [[100.0, 300.0]]}}, "line.neutral_sections"),
    ({"line": {"gradient_model": "point_mass"}}, "line.gradient_model"),
])
def test_export_refuses_what_ttobench_cannot_hold(tmp_path, change, field):
    case = make_case(**change)
    with pytest.raises(CaseError) as err:
        to_ttobench(case, tmp_path)
    assert err.value.field == field


def test_seed_case_with_polynomial_curves_cannot_be_exported(tmp_path, yizhuang):
    with pytest.raises(CaseError) as err:
        to_ttobench(yizhuang, tmp_path)
    assert err.value.field == "train.traction.segments"
    assert not list(tmp_path.iterdir())  # nothing half-written
