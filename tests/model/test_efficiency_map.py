"""Efficiency maps in the model and the case format: interpolation, chain, round trip, bad input."""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from pymoo_rail.cases import load_case
from pymoo_rail.model import CaseError, EfficiencyMap, case_from_dict, case_to_dict

MAP = {"speeds_kmh": [0.0, 40.0, 80.0], "forces_kn": [0.0, 100.0, 300.0],
       "values": [[0.6, 0.8, 0.82], [0.7, 0.88, 0.9], [0.72, 0.9, 0.92]]}


def _case(**train) -> dict:
    data = case_to_dict(load_case("yizhuang"))
    for direction in ("traction", "regen"):  # a map sets its direction's constant (its peak)
        if f"{direction}_efficiency_map" in train:
            data["train"].pop(f"{direction}_efficiency")
    data["train"].update(train)
    return data


def test_bilinear_inside_and_held_at_the_edges():
    m = EfficiencyMap(tuple(MAP["speeds_kmh"]), tuple(MAP["forces_kn"]), tuple(tuple(r) for r in MAP["values"]))
    assert m.efficiency(20.0, 50.0) == pytest.approx(0.25 * (0.6 + 0.8 + 0.7 + 0.88))
    assert m.efficiency(40.0, -100.0) == pytest.approx(0.88)  # the magnitude of a braking force
    assert m.efficiency(200.0, 1000.0) == pytest.approx(0.92) and m.efficiency(0.0, 0.0) == pytest.approx(0.6)
    assert m.peak == 0.92


def test_chain_multiplies_motor_gear_and_converter_on_the_union_of_nodes():
    motor = EfficiencyMap((0.0, 100.0), (0.0, 200.0), ((0.8, 0.9), (0.85, 0.95)))
    other = EfficiencyMap((0.0, 50.0, 100.0), (0.0, 200.0), ((1.0, 1.0), (0.9, 0.9), (1.0, 1.0)))
    chained = EfficiencyMap.chain((motor, 0.97, other, 0.98))
    assert chained.speeds_kmh == (0.0, 50.0, 100.0)
    v, f = np.array([10.0, 50.0, 90.0]), np.array([20.0, 150.0, 190.0])
    expected = motor.efficiency(v, f) * 0.97 * 0.98 * other.efficiency(v, f)
    assert np.allclose(chained.efficiency(v, f), expected, rtol=0, atol=0.03)  # a product is not bilinear
    assert chained.efficiency(50.0, 200.0) == pytest.approx(0.925 * 0.97 * 0.98 * 0.9)  # exact on the nodes
    with pytest.raises(CaseError, match="at least one map"):
        EfficiencyMap.chain((0.9, 0.95))


def test_case_file_map_with_parts_round_trips_and_the_constant_is_its_peak():
    case = case_from_dict(_case(traction_efficiency_map={**MAP, "gear": 0.96, "converter": 0.98},
                                regen_efficiency_map=MAP))
    train = case.train
    assert train.traction_efficiency == pytest.approx(0.92 * 0.96 * 0.98)
    assert train.traction_efficiency_map.efficiency(40.0, 100.0) == pytest.approx(0.88 * 0.96 * 0.98)
    assert train.regen_efficiency == 0.92
    again = case_from_dict(case_to_dict(case))
    assert again.train == train


def test_gear_and_converter_default_to_one():
    plain = case_from_dict(_case(traction_efficiency_map=MAP)).train.traction_efficiency_map
    assert case_from_dict(_case(traction_efficiency_map={**MAP, "gear": 1.0, "converter": 1.0})).train \
        .traction_efficiency_map == plain


def test_cases_without_a_map_write_no_map_keys():
    assert "traction_efficiency_map" not in case_to_dict(load_case("yizhuang"))["train"]


@pytest.mark.parametrize("edit, field", [
    (lambda m: m.update(values=[[0.6, 0.8, 0.82], [0.7, 0.88, 0.9]]), "train.traction_efficiency_map.values"),
    (lambda m: m["values"][1].__setitem__(2, 88.0), "train.traction_efficiency_map.values[1][2]"),
    (lambda m: m["values"][0].__setitem__(0, 0.0), "train.traction_efficiency_map.values[0][0]"),
    (lambda m: m["speeds_kmh"].__setitem__(1, 0.0), "train.traction_efficiency_map.speeds_kmh[1]"),
    (lambda m: m["forces_kn"].__setitem__(0, -5.0), "train.traction_efficiency_map.forces_kn[0]"),
    (lambda m: m.update(gear=1.5), "train.traction_efficiency_map.gear"),
    (lambda m: m.update(motor=0.9), "train.traction_efficiency_map.motor"),
    (lambda m: m.update(values="0.9"), "train.traction_efficiency_map.values"),
    (lambda m: m.pop("forces_kn"), "train.traction_efficiency_map.forces_kn"),
])
def test_bad_map_names_the_field(edit, field):
    table = {k: [list(r) if isinstance(r, list) else r for r in v] for k, v in MAP.items()}
    edit(table)
    with pytest.raises(CaseError) as raised:
        case_from_dict(_case(traction_efficiency_map=table), source="edited.toml")
    assert raised.value.field == field and "edited.toml" in str(raised.value)


def test_a_constant_other_than_the_maps_peak_is_refused():
    with pytest.raises(CaseError) as raised:
        case_from_dict(_case(traction_efficiency_map=MAP, traction_efficiency=0.8))
    assert raised.value.field == "train.traction_efficiency" and "0.92" in str(raised.value)


@pytest.mark.parametrize("edit, field, words", [
    (lambda m: m.update(values=[[0.3, 0.4, 0.4]] * 3), "train.traction_efficiency_map.values", "peak"),
    (lambda m: m.update(speeds_kmh=[0.0, 5.0, 10.0]), "train.traction_efficiency_map.speeds_kmh", "top speed"),
    (lambda m: m.update(forces_kn=[0.0, 100_000.0, 300_000.0]), "train.traction_efficiency_map.forces_kn",
     "N where kN"),
])
def test_implausible_maps_are_refused_unless_waived(edit, field, words):
    table = {k: list(v) for k, v in MAP.items()}
    edit(table)
    with pytest.raises(CaseError) as raised:
        case_from_dict(_case(traction_efficiency_map=table))
    assert raised.value.field == field and words in str(raised.value)
    data = _case(traction_efficiency_map=table)
    data["allow_implausible"] = ["efficiency"]
    assert case_from_dict(data).train.traction_efficiency_map is not None


_junk = st.one_of(st.none(), st.booleans(), st.text(max_size=3), st.floats(allow_nan=True, allow_infinity=True),
                  st.lists(st.floats(allow_nan=True), max_size=3))


@settings(max_examples=60, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(key=st.sampled_from(["speeds_kmh", "forces_kn", "values"]), index=st.integers(0, 2), junk=_junk)
def test_generated_bad_entries_get_a_named_case_error(key, index, junk):
    table = {k: [list(r) if isinstance(r, list) else r for r in v] for k, v in MAP.items()}
    table[key][index] = junk
    try:
        case = case_from_dict(_case(regen_efficiency_map=table), source="gen.toml")
    except CaseError as err:
        assert err.field.startswith("train.regen_efficiency_map") and "gen.toml" in str(err)
        return
    # accepted: then every value is a valid efficiency on increasing nodes
    m = case.train.regen_efficiency_map
    assert all(0.0 < x <= 1.0 and math.isfinite(x) for row in m.values for x in row)
    assert all(b > a for a, b in zip(m.speeds_kmh, m.speeds_kmh[1:]))
