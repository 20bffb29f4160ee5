"""Case-loader validation: no bad physics and no coerced value gets through; every error names
the field path and the value."""

from __future__ import annotations

import math

import pytest

from pymoo_rail.cases import load_case
from pymoo_rail.model import CaseError, case_from_dict, case_to_dict


def _edited(edit, name: str = "yizhuang") -> dict:
    data = case_to_dict(load_case(name))
    edit(data)
    return data


def _error(edit, name: str = "yizhuang") -> CaseError:
    with pytest.raises(CaseError) as raised:
        case_from_dict(_edited(edit, name), source="edited.toml")
    assert "<entry>" not in str(raised.value) and "edited.toml" in str(raised.value)
    return raised.value


def test_traction_polynomial_negative_above_66_kmh_is_rejected_naming_segment_and_speed():
    # 300 - 4.5 v kN crosses zero at 66.7 km/h; the train runs to 80 km/h
    def edit(d):
        d["train"]["traction"] = {"segments": [{"v_max_kmh": 80.0, "poly": [300.0, -4.5]}]}

    err = _error(edit)
    assert err.field == "train.traction.segments[0].poly" and err.value == [300.0, -4.5]
    assert "-60 kN at 80 km/h" in str(err)


def test_braking_polynomial_negative_inside_a_middle_segment_is_rejected_at_its_minimum():
    # (v - 50)^2 - 25 = v^2 - 100 v + 2475 is -25 kN at 50 km/h, inside the segment [40, 60]
    def edit(d):
        d["train"]["braking"]["segments"] = [{"v_max_kmh": 40.0, "poly": [200.0]},
                                             {"v_max_kmh": 60.0, "poly": [2475.0, -100.0, 1.0]},
                                             {"v_max_kmh": 80.0, "poly": [150.0]}]

    err = _error(edit)
    assert err.field == "train.braking.segments[1].poly" and "-25 kN at 50 km/h" in str(err)


def test_the_last_segment_is_checked_up_to_the_trains_top_speed():
    def edit(d):  # positive up to its v_max 60, negative at 80 (where it still applies)
        d["train"]["traction"] = {"segments": [{"v_max_kmh": 60.0, "poly": [140.0, -2.0]}]}

    assert "at 80 km/h" in str(_error(edit))


@pytest.mark.parametrize("path, bad", [
    (("line", "speed_limits", 0, 2), True),
    (("line", "speed_limits", 0, 2), "55"),
    (("line", "gradients", 1, 2), False),
    (("train", "mass_t"), True),
    (("train", "resistance", "a"), True),
    (("train", "traction", "segments", 0, "v_max_kmh"), "51.5"),
    (("train", "traction", "segments", 1, "poly", 0), True),
    (("run", "planned_time_s"), "150"),
    (("train", "braking", "segments", 0, "v_max_kmh"), math.nan),
])
def test_booleans_strings_and_nan_are_refused_not_coerced(path, bad):
    def edit(d):
        target = d
        for key in path[:-1]:
            target = target[key]
        target[path[-1]] = bad

    err = _error(edit)
    dotted = ".".join(f"[{p}]" if isinstance(p, int) else p for p in path).replace(".[", "[")
    assert err.field == dotted and (err.value is bad or (err.value != err.value and bad != bad))
    assert repr(bad) in str(err)


@pytest.mark.parametrize("path, field", [
    (("train", "traction", "segments"), "train.traction.segments"),
    (("train", "braking", "segments"), "train.braking.segments"),
    (("line", "gradients"), "line.gradients"),
    (("line", "speed_limits"), "line.speed_limits"),
])
def test_empty_lists_name_their_field(path, field):
    def edit(d):
        target = d
        for key in path[:-1]:
            target = target[key]
        target[path[-1]] = []

    err = _error(edit)
    assert err.field == field


@pytest.mark.parametrize("path, value, field", [
    (("line", "gradients"), 5.0, "line.gradients"),
    (("line", "gradients", 0), "flat", "line.gradients[0]"),
    (("train", "traction", "segments", 0, "poly"), 203.0, "train.traction.segments[0].poly"),
    (("train", "traction", "segments"), {"v_max_kmh": 80}, "train.traction.segments"),
])
def test_wrong_shapes_name_their_field(path, value, field):
    def edit(d):
        target = d
        for key in path[:-1]:
            target = target[key]
        target[path[-1]] = value

    err = _error(edit)
    assert (err.field, err.value) == (field, value) and "must be an array" in str(err)


@pytest.mark.parametrize("key, value", [("dwell_s", -5.0), ("dwell_s", math.inf), ("planned_time_s", math.nan),
                                        ("start_m", math.nan), ("planned_time_s", True)])
def test_leg_fields_are_checked_under_their_own_name(key, value):
    def edit(d):
        d["run"]["legs"] = [{"start_m": 0.0, "end_m": 1300.0, "planned_time_s": 100.0, "dwell_s": 30.0},
                            {"start_m": 1300.0, "end_m": d["line"]["length_m"], "planned_time_s": 90.0}]
        d["run"]["legs"][0][key] = value

    err = _error(edit)
    assert err.field == f"run.legs[0].{key}"
