"""Case files: the built-in cases, a user's own file, and every kind of bad input."""

import math

import pytest

from pymoo_rail.cases import list_cases, load_case
from pymoo_rail.cases import read_case, write_case
from pymoo_rail.model import CaseError, case_from_dict, case_to_dict
from tests.conftest import make_case_dict


def test_builtin_cases_listed():
    assert "yizhuang" in list_cases()


@pytest.mark.parametrize("name", list_cases())
def test_every_builtin_case_loads_and_has_a_source(name):
    case = load_case(name)
    assert case.name == name
    assert case.source, "every built-in case must say where its values come from"
    assert case.planned_time_s > 0


def test_yizhuang_values_from_seed_tables(yizhuang):
    # seed 000 tables 5-1 and 5-2
    assert yizhuang.line.length_m == 2265.0
    assert yizhuang.planned_time_s == 150.0 and yizhuang.dwell_s == 30.0
    assert yizhuang.train.mass_t == 194.295 and yizhuang.train.length_m == 140.0
    r = yizhuang.train.resistance
    assert (r.a, r.b, r.c, r.unit, r.speed_unit) == (2.031, 0.0622, 0.001807, "kN", "kmh")
    assert [g[2] for g in yizhuang.line.gradients] == [0, 0, -8, -3, 5, 1, 0, 0]
    assert yizhuang.line.speed_limits == ((0, 130, 55), (130, 2155, 80), (2155, 2265, 55))


def test_user_file_loads_like_a_builtin(tmp_path, yizhuang):
    path = write_case(yizhuang, tmp_path / "mine.toml")
    again = load_case(path)
    assert case_to_dict(again) == case_to_dict(yizhuang)
    assert load_case(str(path)).train == yizhuang.train


def test_handwritten_user_file(tmp_path):
    text = """
name = "my-line"
source = "made up"
[run]
planned_time_s = 90
[train]
mass_t = 200
length_m = 120
max_speed_kmh = 80
[train.resistance]
a = 1.0
b = 0.0
c = 0.0
unit = "N/kN"
speed_unit = "ms"
[train.traction]
max_force_kn = 250
max_power_kw = 3000
[train.braking]
table = [[0, 200], [80, 180]]
regen_max_power_kw = 2000
[line]
length_m = 1500
gradients = [[0, 700, 3], [700, 1500, -2]]
speed_limits = [[0, 1500, 80]]
tunnels = [[200, 900]]
curves = [[1000, 1200, 800]]
"""
    path = tmp_path / "my-line.toml"
    path.write_text(text)
    case = load_case(path)
    assert case.train.traction.max_power_kw == 3000
    assert case.train.regen_max_power_kw == 2000
    assert case.line.tunnels == ((200.0, 900.0),)


@pytest.mark.parametrize("mutate,field,value_text", [
    (lambda d: d["line"].update(gradients=[[0, 900, 0], [1000, 2000, 1]]), "line.gradients[1]", "gap"),
    (lambda d: d["line"].update(gradients=[[0, 1100, 0], [1000, 2000, 1]]), "line.gradients[1]", "overlap"),
    (lambda d: d["line"].update(speed_limits=[[0, 1500, 80]]), "line.speed_limits", "cover"),
    (lambda d: d["line"].update(gradients=[[0, 1000, 0], [1000, 900, 1], [900, 2000, 0]]), "line.gradients[1]",
     "negative or zero length"),
    (lambda d: d["line"].update(length_m=-5.0), "line.length_m", "-5.0"),
    (lambda d: d["train"].update(colour="red"), "train.colour", "unknown key"),
    (lambda d: d.update(extra=1), "extra", "unknown key"),
    (lambda d: d["train"]["resistance"].pop("unit"), "train.resistance.unit", "required"),
    (lambda d: d["train"].update(mass_t=0.0), "train.mass_t", "must be > 0"),
    (lambda d: d["train"].update(mass_t=math.nan), "train.mass_t", "finite"),
    (lambda d: d["train"]["traction"].update(max_force_kn=-1.0), "train.traction.max_force_kn", "positive"),
    (lambda d: d["run"].update(planned_time_s=0.0), "run.planned_time_s", "positive"),
    (lambda d: d["line"].update(curves=[[100, 200, 0.0]]), "line.curves[0]", "radius"),
    (lambda d: d["line"].update(neutral_sections=[[100, 300], [200, 400]]), "line.neutral_sections[1]", "overlaps"),
    (lambda d: d["line"].update(gradient_model="cubic"), "line.gradient_model", "cubic"),
])
def test_bad_input_names_field_and_value(mutate, field, value_text):
    data = make_case_dict()
    mutate(data)
    with pytest.raises(CaseError) as info:
        case_from_dict(data, source="bad.toml")
    message = str(info.value)
    assert field in message and value_text in message and "bad.toml" in message


def test_malformed_toml_file(tmp_path):
    path = tmp_path / "broken.toml"
    path.write_text("name = \n[run")
    with pytest.raises(CaseError, match="broken.toml.*not valid TOML"):
        read_case(path)


def test_unknown_builtin_name():
    with pytest.raises(CaseError, match="nosuchline"):
        load_case("nosuchline")


def test_missing_file(tmp_path):
    with pytest.raises(CaseError, match="no such case file"):
        load_case(tmp_path / "absent.toml")


def test_leg_slicing():
    data = make_case_dict(run={"planned_time_s": 200.0, "legs": [
        {"start_m": 0.0, "end_m": 1200.0, "planned_time_s": 110.0, "dwell_s": 30.0},
        {"start_m": 1200.0, "end_m": 2000.0, "planned_time_s": 80.0}]})
    data["line"]["gradients"] = [[0, 1000, 2.0], [1000, 2000, -4.0]]
    case = case_from_dict(data)
    second = case.leg(1)
    assert second.line.length_m == 800.0 and second.planned_time_s == 80.0
    assert second.line.gradients == ((0.0, 800.0, -4.0),)
    first = case.leg(0)
    assert first.line.gradients == ((0.0, 1000.0, 2.0), (1000.0, 1200.0, -4.0))
    with pytest.raises(CaseError, match="leg index"):
        case.leg(2)
