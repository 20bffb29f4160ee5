"""TTOBench efficiency maps: the loss tables of TTOBench's dynamic locomotive (``00_Loco_Dyn``) read
into EfficiencyMap, exact at the file's nodes; read-write-read round trips; bad tables name the field;
``load_train`` on every train format."""

from __future__ import annotations

import copy
import json
from dataclasses import replace
from pathlib import Path

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from pymoo_rail.cases import generate_case, load_train, write_case
from pymoo_rail.cases.ttobench import from_ttobench, read_train
from pymoo_rail.cases.ttobench_efficiency import loss_table_rows, map_from_loss_table, max_force_kn
from pymoo_rail.cases.ttobench_writer import to_ttobench, train_to_json
from pymoo_rail.model import CaseError, EfficiencyMap
from pymoo_rail.optimal import optimal_profile
from pymoo_rail.sim import Simulator
from pymoo_rail.sim.checks import check_run

DATA = Path(__file__).resolve().parents[1] / "data"
LOCO = DATA / "ttobench" / "superseded" / "00_Loco_Dyn.json"
TRACK = DATA / "ttobench" / "tracks" / "00_reference.json"
FIELDS = {"traction": "efficiency traction", "regen": "efficiency reg brake"}


def _raw() -> dict:
    return json.loads(LOCO.read_text())


def _file_efficiency(direction: str, load_pct: float, speed_kmh: float, loss_kw: float, aux_kw: float) -> float:
    """ms-eetc's reading of one node: force = load x min(F_max, P_max / v); losses include the auxiliaries."""
    force_kn = load_pct / 100.0 * min(380.0, 5500.0 * 3.6 / speed_kmh)
    wheel_kw = force_kn * speed_kmh / 3.6
    lost = loss_kw - aux_kw
    return wheel_kw / (wheel_kw + lost) if direction == "traction" else (wheel_kw - lost) / wheel_kw


def _assert_same_map(a: EfficiencyMap, b: EfficiencyMap) -> None:
    assert a.speeds_kmh == b.speeds_kmh
    assert np.asarray(b.forces_kn) == pytest.approx(np.asarray(a.forces_kn), rel=1e-12)
    assert np.asarray(b.values) == pytest.approx(np.asarray(a.values), rel=1e-12, abs=0.0)


def test_the_dynamic_locomotive_is_licensed_and_its_maps_are_exact_at_every_node():
    raw = _raw()
    assert raw["metadata"]["license"] == "BSD 2-Clause License"
    assert "BSD 2-Clause" in (DATA / "ttobench" / "LICENSE").read_text()
    train = read_train(LOCO).train
    # the smallest zero-load loss (36.5 kW, both tables, 0-20 km/h) is drawn as auxiliary power
    assert train.aux_power_kw == 36.5
    for direction, field in FIELDS.items():
        efficiency_map = getattr(train, f"{direction}_efficiency_map")
        assert efficiency_map.speeds_kmh == (20.0, 40.0, 60.0, 80.0, 100.0, 120.0, 140.0, 160.0)
        assert getattr(train, f"{direction}_efficiency") == efficiency_map.peak
        nodes = [row for row in raw[field]["values"] if row[0] > 0 and row[1] > 0]
        assert len(nodes) == 32
        for load, speed, loss in nodes:
            force = load / 100.0 * min(380.0, 5500.0 * 3.6 / speed)
            assert float(efficiency_map.efficiency(speed, force)) == pytest.approx(
                _file_efficiency(direction, load, speed, loss, 36.5), rel=1e-12)
    # the losses rise with the load faster than the wheel power at low load: efficiency 0.82-0.88
    assert 0.81 < np.min(train.traction_efficiency_map.values) and train.traction_efficiency < 0.94


def test_read_write_read_gives_the_same_maps_and_the_same_energy(tmp_path):
    case = from_ttobench(TRACK, LOCO, 0, -1, 1500.0)
    track_path, train_path = to_ttobench(case, tmp_path)
    written = json.loads(train_path.read_text())
    assert written["efficiency traction"]["units"] == {"load": "%", "velocity": "km/h", "losses": "kW"}
    back = from_ttobench(track_path, train_path, 0, -1, 1500.0)
    for direction in FIELDS:
        _assert_same_map(getattr(case.train, f"{direction}_efficiency_map"),
                         getattr(back.train, f"{direction}_efficiency_map"))
    assert back.train.aux_power_kw == case.train.aux_power_kw
    # the same run costs the same energy, auxiliaries and map losses included
    first, second = Simulator(case).flat_out(), Simulator(back).flat_out()
    assert second.energy.net_kwh == pytest.approx(first.energy.net_kwh, rel=1e-9)
    assert first.energy.aux_kwh == pytest.approx(36.5 * first.running_time_s / 3600.0)
    # the map costs more than the constant peak efficiency would
    constant = replace(case, train=replace(case.train, traction_efficiency_map=None, regen_efficiency_map=None))
    assert Simulator(constant).flat_out().energy.net_kwh < first.energy.net_kwh


def test_load_train_reads_every_format(tmp_path):
    ttobench = load_train(LOCO)
    case_file = tmp_path / "loco.toml"
    write_case(from_ttobench(TRACK, LOCO, 0, -1, 1500.0), case_file)
    toml = load_train(case_file)
    for direction in FIELDS:  # the case file keeps the maps TTOBench gave
        _assert_same_map(getattr(ttobench, f"{direction}_efficiency_map"), getattr(toml, f"{direction}_efficiency_map"))
    assert toml.aux_power_kw == ttobench.aux_power_kw == 36.5
    railjson = load_train(DATA / "osrd" / "rolling_stocks" / "intercity-train.json")
    assert railjson.traction_efficiency_map is None and railjson.mass_t > 0


def test_a_map_that_losses_cannot_hold_is_refused_naming_the_field():
    case = from_ttobench(TRACK, LOCO, 0, -1, 1500.0)
    traction = case.train.traction_efficiency_map
    # a row at 0 km/h that differs from the next: a loss table has no efficiency at rest
    at_rest = EfficiencyMap((0.0,) + traction.speeds_kmh, traction.forces_kn,
                            ((0.5,) * len(traction.forces_kn),) + traction.values)
    with pytest.raises(CaseError) as err:
        train_to_json(replace(case.train, traction_efficiency_map=at_rest, traction_efficiency=at_rest.peak), "x")
    assert err.value.field == "train.traction_efficiency_map.values[0]"
    # the same row equal to its neighbour is what a reader holds: written and read back unchanged
    held = EfficiencyMap((0.0,) + traction.speeds_kmh, traction.forces_kn, traction.values[:1] + traction.values)
    back = read_train(train_to_json(replace(case.train, traction_efficiency_map=held), "x")).train
    _assert_same_map(traction, back.traction_efficiency_map)
    # auxiliary power without a map has no place in a TTOBench train
    with pytest.raises(CaseError) as err:
        train_to_json(replace(case.train, traction_efficiency_map=None, regen_efficiency_map=None), "x")
    assert err.value.field == "train.aux_power_kw"


@pytest.mark.parametrize("mutate, field, reason", [
    (lambda t: t["efficiency traction"].pop("units"), "efficiency traction", "units"),
    (lambda t: t["efficiency traction"]["units"].update(load="permille"), "efficiency traction.units.load",
     "unknown unit"),
    (lambda t: t["efficiency reg brake"]["units"].pop("losses"), "efficiency reg brake.units", "exactly the units"),
    (lambda t: t["efficiency traction"]["values"].__setitem__(7, [25.0, 20.0]), "efficiency traction.values[7]",
     "must be a row"),
    (lambda t: t["efficiency traction"]["values"].append([25.0, 20.0, 50.0]), "efficiency traction.values[45]",
     "a second loss"),
    (lambda t: t["efficiency traction"].update(values=[[50.0, 0.0, 100.0]]), "efficiency traction.values",
     "velocity above 0"),
    (lambda t: t["efficiency traction"].update(values=[[0.0, 20.0, 100.0]]), "efficiency traction.values",
     "load above 0"),
    # braking that loses more than it delivers (no efficiency in (0, 1] holds it)
    (lambda t: t["efficiency reg brake"]["values"].__setitem__(6, [25.0, 20.0, 900.0]), "efficiency reg brake",
     "loses more than the electric brake delivers"),
    # a loss below the auxiliaries (the zero-load loss) would be an efficiency above 1
    (lambda t: t["efficiency traction"]["values"].__setitem__(6, [25.0, 20.0, 10.0]), "efficiency traction",
     "loses less than the auxiliary power"),
    (lambda t: t.pop("efficiency reg brake"), "efficiency reg brake", "both efficiencies or neither"),
])
def test_bad_loss_tables_name_the_field(mutate, field, reason):
    raw = _raw()
    mutate(raw)
    with pytest.raises(CaseError, match=reason) as err:
        read_train(raw)
    assert err.value.field == field


_BAD_NUMBERS = st.sampled_from([-1.0, "20", None, True, float("nan"), float("inf")])


@settings(max_examples=40, deadline=None)
@given(direction=st.sampled_from(sorted(FIELDS)), row=st.integers(0, 44), column=st.integers(0, 2), bad=_BAD_NUMBERS)
def test_a_bad_number_anywhere_in_a_loss_table_names_its_row(direction, row, column, bad):
    raw = _raw()
    raw[FIELDS[direction]]["values"][row][column] = bad
    with pytest.raises(CaseError) as err:
        read_train(raw)
    assert err.value.field == f"{FIELDS[direction]}.values[{row}]"


@st.composite
def loss_tables(draw):
    """A loss table of both directions with the auxiliaries in every loss, efficiencies in (0.3, 1]."""
    speeds = sorted(draw(st.sets(st.integers(1, 40).map(lambda k: 5.0 * k), min_size=1, max_size=5)))
    loads = sorted(draw(st.sets(st.sampled_from([10.0, 25.0, 50.0, 75.0, 100.0, 120.0]), min_size=1, max_size=4)))
    aux_kw = draw(st.sampled_from([0.0, 27.0]))
    tables = {}
    for direction in FIELDS:
        rows = [(0.0, v, aux_kw) for v in speeds] if aux_kw else []
        for v in speeds:
            for load in loads:
                wheel = load / 100.0 * float(max_force_kn(v, 300.0, 4000.0)) * v / 3.6
                share = draw(st.floats(0.0, 0.7))  # loss beyond the auxiliaries, per unit of wheel power
                rows.append((load / 100.0, v, aux_kw + share * wheel))
        tables[direction] = rows
    return tables, aux_kw


@settings(max_examples=30, deadline=None)
@given(loss_tables())
def test_any_loss_table_reads_exactly_at_its_nodes_and_round_trips(tables_aux):
    tables, aux_kw = tables_aux
    for direction, rows in tables.items():
        efficiency_map = map_from_loss_table(direction, rows, 300.0, 4000.0, aux_kw, "test")
        for load, speed, loss in rows:
            if load > 0:
                force = load * float(max_force_kn(speed, 300.0, 4000.0))
                wheel = force * speed / 3.6
                expected = wheel / (wheel + loss - aux_kw) if direction == "traction" else (wheel - loss + aux_kw) / wheel
                assert float(efficiency_map.efficiency(speed, force)) == pytest.approx(expected, rel=1e-12)
        # written as rows (load in %) and read again: the same map
        written = [(load / 100.0, v, loss) for load, v, loss in
                   loss_table_rows(efficiency_map, direction, 300.0, 4000.0, aux_kw)]
        _assert_same_map(efficiency_map, map_from_loss_table(direction, written, 300.0, 4000.0, aux_kw, "test"))


def test_one_table_and_one_scalar_efficiency():
    raw = _raw()
    raw["efficiency reg brake"] = {"unit": "%", "value": 80.0}
    train = read_train(copy.deepcopy(raw)).train
    assert train.regen_efficiency_map is None and train.regen_efficiency == 0.8
    assert train.traction_efficiency_map is not None and train.aux_power_kw == 36.5
    back = read_train(train_to_json(train, "x")).train
    assert back.regen_efficiency == 0.8 and back.regen_efficiency_map is None
    _assert_same_map(train.traction_efficiency_map, back.traction_efficiency_map)


@pytest.mark.slow
def test_the_dynamic_locomotive_runs_optimally_and_its_map_costs_more_than_its_peak():
    train = load_train(LOCO)
    case = replace(generate_case(0, "suburban"), train=train, initial_speed_ms=0.0, final_speed_ms=0.0)
    fastest = Simulator(case).flat_out()
    optimal = optimal_profile(case, 1.15 * fastest.running_time_s)
    assert check_run(optimal, case).passes() and abs(optimal.running_time_s - 1.15 * fastest.running_time_s) <= 0.5
    assert optimal.energy.net_kwh < fastest.energy.net_kwh
    # the map is at most its peak everywhere: the same train at the constant peak needs less
    peak = replace(case, train=replace(train, traction_efficiency_map=None, regen_efficiency_map=None))
    assert optimal_profile(peak, 1.15 * fastest.running_time_s).energy.net_kwh < optimal.energy.net_kwh


def test_a_column_at_zero_force_must_be_the_held_edge():
    traction = load_train(LOCO).traction_efficiency_map
    zero = EfficiencyMap(traction.speeds_kmh, (0.0,) + traction.forces_kn,
                         tuple((0.5,) + row for row in traction.values))
    with pytest.raises(CaseError, match="no efficiency at 0 kN") as err:
        loss_table_rows(zero, "traction", 380.0, 5500.0, 36.5)
    assert err.value.field == "train.traction_efficiency_map.forces_kn[0]"
