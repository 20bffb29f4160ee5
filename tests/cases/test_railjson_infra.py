"""OSRD railjson infrastructure: paths over the track graph to a Line, checked against OSRD's own
data (its pathfinding result and path-property tests on small_infra), and written back as case files
that reload to the same Line on four OSRD test infrastructures."""

from __future__ import annotations

import json
from dataclasses import replace
from pathlib import Path

import pytest

from pymoo_rail.cases import load_train, railjson_case, read_case, write_case
from pymoo_rail.cases.railjson_infra import PathStep, path_line, read_infra
from pymoo_rail.model import Case, CaseError
from pymoo_rail.model.grid import curve_resistance_n_per_kn

DATA = Path(__file__).resolve().parents[1] / "data" / "osrd"
INFRAS = DATA / "infras"
S2S, S2T = "START_TO_STOP", "STOP_TO_START"


@pytest.fixture(scope="module")
def small():
    return read_infra(INFRAS / "small_infra.json")


def test_osrd_pathfinding_result_length_and_slopes(small):
    # OSRD's own pathfinding result on small_infra: its track ranges give its length and slope profile
    core = json.loads((DATA / "small_infra_pathfinding_core_response.json").read_text())
    steps = small.path_from_track_ranges([t for route in core["route_paths"] for t in route["track_sections"]])
    line = path_line(small, steps, default_limit_kmh=300.0)
    assert line.length_m == pytest.approx(core["length"], abs=1e-6)
    # OSRD lists the profile as (position, gradient) pairs, two per change
    points = core["slopes"]
    expected = [(points[k]["position"], points[k + 1]["position"], points[k]["gradient"])
                for k in range(0, len(points), 2)]
    expected = [row for row in expected if row[1] > row[0]]
    assert len(line.gradients) == len(expected)
    for ours, theirs in zip(line.gradients, expected):
        assert ours == pytest.approx(theirs, abs=1e-6)
    assert all(p["radius"] == 0.0 for p in core["curves"]) and line.curves == ()


def _with_slopes(path: Path, slopes: dict) -> dict:
    data = json.loads(path.read_text())
    for track in data["track_sections"]:
        if track["id"] in slopes:
            track["slopes"] = [{"begin": b, "end": e, "gradient": g} for b, e, g in slopes[track["id"]]]
    return data


def test_osrd_path_properties_slopes_forward_and_backward():
    # OSRD core's PathPropertiesTests.testSmallInfraSlopes: the same slopes, paths and expected profiles
    infra = read_infra(_with_slopes(INFRAS / "small_infra.json",
                                    {"TA0": [(0.0, 1000.0, 10.0), (1000.0, 2000.0, 15.0)],
                                     "TA1": [(1000.0, 1950.0, -5.0)]}))
    # TA0 and TA1 are not joined directly in small_infra: OSRD's test builds its path from track
    # offsets; here each track is read on its own and the two profiles are joined
    forward = [path_line(infra, infra.path([("TA0", S2S)], 500.0, 2000.0), default_limit_kmh=100.0),
               path_line(infra, infra.path([("TA1", S2S)], 0.0, 1500.0), default_limit_kmh=100.0)]
    assert forward[0].gradients == ((0.0, 500.0, 10.0), (500.0, 1500.0, 15.0))
    assert forward[1].gradients == ((0.0, 1000.0, 0.0), (1000.0, 1500.0, -5.0))
    backward = [path_line(infra, infra.path([("TA1", S2T)], 1000.0, 0.0), default_limit_kmh=100.0),
                path_line(infra, infra.path([("TA0", S2T)], 2000.0, 1000.0), default_limit_kmh=100.0)]
    assert backward[0].gradients == ((0.0, 1000.0, 0.0),)
    assert backward[1].gradients == ((0.0, 1000.0, -15.0),)  # uphill run backwards is downhill


def test_shortest_path_between_operational_points(small):
    steps = small.shortest_path("Mid_East_station", "South_East_station")
    assert [(s.track, s.direction) for s in steps] == [("TD1", S2S), ("TD3", S2S), ("TH0", S2S), ("TH1", S2S)]
    assert (steps[0].begin_m, steps[-1].end_m) == (14000.0, 4400.0)
    assert sum(s.length_m for s in steps) == 19400.0
    # the way back runs every track STOP_TO_START
    back = small.shortest_path("South_East_station", "Mid_East_station")
    assert [(s.track, s.direction) for s in back] == [("TH1", S2T), ("TH0", S2T), ("TD3", S2T), ("TD1", S2T)]
    with pytest.raises(CaseError, match="no path over the track graph"):
        small.shortest_path("North_station", "North_East_station")  # only by reversing
    with pytest.raises(CaseError, match="known: Mid_East_station"):
        small.shortest_path("Nowhere", "Mid_East_station")


def test_speed_limits_by_train_category(small):
    steps = small.shortest_path("Mid_East_station", "South_East_station")
    # speed_section.0 (300 km/h, HLP 250) everywhere; .1 on TH0 [500, 1000] and TH1 [0, 4000]
    # (142 km/h, E32C 100); .2 on TH1 [3500, 4400] (112 km/h, MA100 80); the lowest applies
    expected = {
        None: ((0.0, 14500.0, 300.0), (14500.0, 18500.0, 142.0), (18500.0, 19400.0, 112.0)),
        "E32C": ((0.0, 14500.0, 300.0), (14500.0, 19000.0, 100.0), (19000.0, 19400.0, 112.0)),
        "MA100": ((0.0, 14500.0, 300.0), (14500.0, 18500.0, 142.0), (18500.0, 19400.0, 80.0)),
        "HLP": ((0.0, 14500.0, 250.0), (14500.0, 18500.0, 142.0), (18500.0, 19400.0, 112.0)),
    }
    for category, rows in expected.items():
        assert path_line(small, steps, category=category).speed_limits == rows


def test_electrification_gaps_and_directional_neutral_sections(small):
    steps = small.shortest_path("Mid_East_station", "South_East_station")
    # TD1 is not electrified: an electric train has no traction over it, a thermal one ignores it
    assert path_line(small, steps, voltages=("25000V",)).neutral_sections == ((0.0, 11000.0),)
    assert path_line(small, steps, voltages=None, neutral_sections=False).neutral_sections == ()
    west_out = small.path([("TA0", S2S), ("TA6", S2S)], 700.0, 10000.0)
    # neutral_section.1 (TA0 [1960, 2000]) and .0 (TA6 [0, 10]) join; .2 on TA6 [8500, 8600]
    assert path_line(small, west_out).neutral_sections == ((1260.0, 1310.0), (9800.0, 9900.0))
    # TA0 carries 1500 V only: 25 kV stops there
    assert path_line(small, west_out, voltages=("25000V",)).neutral_sections == ((0.0, 1310.0), (9800.0, 9900.0))
    assert path_line(small, west_out, voltages=("1500V", "25000V")).neutral_sections == \
        ((1260.0, 1310.0), (9800.0, 9900.0))
    west_in = small.path([("TA6", S2T), ("TA0", S2T)], 10000.0, 700.0)
    # neutral_section.3 applies STOP_TO_START only: TA0 [1850, 1990] is [10010, 10150] of this path
    assert path_line(small, west_in).neutral_sections == ((10010.0, 10150.0),)
    # with the pantograph raised again in 25 s at the 300 km/h limit: 2083.3 m more without traction
    longer = path_line(small, west_in, power_recovery_s=(25.0, 5.0))
    assert longer.neutral_sections[0][1] == pytest.approx(10150.0 + 5.0 * 300.0 / 3.6)  # lower_pantograph false


def test_curves_keep_their_radius_with_osrd_resistance(small):
    steps = small.shortest_path("North_station", "South_station")
    line = path_line(small, steps, default_limit_kmh=160.0)
    # TE1 [1000, 2000]: its curve [1700, 2000] 6000 m; TE0 [0, 300] 6000 m and [500, 1000] 8000 m;
    # TF1 [3100, 4400] 9500 m, cut at the station (4300)
    assert line.curves == ((700.0, 1300.0, 6000.0), (1500.0, 2000.0, 8000.0), (5603.0, 6803.0, 9500.0))
    assert line.curve_model == "osrd" and curve_resistance_n_per_kn(8000.0, "osrd") == pytest.approx(0.1)


def _round_trip_line(line, tmp_path, name) -> None:
    train = load_train(DATA / "rolling_stocks" / "commuter-train.json")
    case = Case(name=name, train=train, line=line, planned_time_s=1000.0)
    again = read_case(write_case(case, tmp_path / f"{name}.toml"))
    assert again.line == line  # every position, gradient, limit and neutral section, exactly
    assert again.train == train


def test_written_back_paths_reload_to_the_same_line_on_four_infrastructures(small, tmp_path):
    lines = {
        "small": path_line(small, small.shortest_path("West_station", "North_East_station"), category="E32C",
                           voltages=("25000V",)),
        "small-back": path_line(small, small.shortest_path("North_East_station", "Mid_West_station")),
        "tiny": path_line(read_infra(INFRAS / "tiny_infra.json"),
                          read_infra(INFRAS / "tiny_infra.json").shortest_path("op.station_foo", "op.station_bar"),
                          default_limit_kmh=140.0),
        "overlapping": path_line(read_infra(INFRAS / "overlapping_routes.json"),
                                 read_infra(INFRAS / "overlapping_routes.json").shortest_path("op.a1", "op.b1"),
                                 default_limit_kmh=100.0),
    }
    nested = read_infra(INFRAS / "nested_switches.json")
    tracks = [("T1", S2S), ("TD1", S2S), ("TD2", S2S), ("T3", S2S), ("TD3", S2S), ("T4", S2S)]
    lines["nested"] = path_line(nested, nested.path(tracks), routes=("1 -> 4",))
    assert lines["tiny"].gradients == ((0.0, 100.0, 0.0), (100.0, 5100.0, 10.0), (5100.0, 10100.0, -10.0),
                                       (10100.0, 10200.0, 0.0))
    assert lines["tiny"].speed_limits == ((0.0, 2100.0, 140.0), (2100.0, 6100.0, 60.0), (6100.0, 10200.0, 140.0))
    assert lines["overlapping"].length_m == 11000.0  # op.b1 is where t_center ends
    # route-bound speed sections: 80 m/s on route "1 -> 4" under the 50 and 40 m/s sections
    assert lines["nested"].speed_limits == ((0.0, 2015.0, 180.0), (2015.0, 4515.0, 144.0), (4515.0, 7515.0, 288.0))
    assert lines["small"].neutral_sections[0] == (0.0, 1310.0)
    for name, line in lines.items():
        _round_trip_line(line, tmp_path, name)


def test_railjson_case_writes_a_case_file_that_reloads(small, tmp_path):
    case = railjson_case(small, DATA / "rolling_stocks" / "night-train.json", from_point="Mid_West_station",
                         to_point="Mid_East_station", planned_time_s=700.0)
    assert case.line.length_m == 14450.0
    assert read_case(write_case(case, tmp_path / "night.toml")) == case
    # where no speed section applies OSRD limits the train to its maximum speed
    tiny = railjson_case(INFRAS / "tiny_infra.json", DATA / "rolling_stocks" / "touristic-train.json",
                         from_point="op.station_foo", to_point="op.station_bar", planned_time_s=900.0)
    assert tiny.line.speed_limits[0][2] == pytest.approx(100.0)
    # the brake keeps const_gamma on the 10 permille descent: gamma x inertia + m g 0.01
    assert tiny.train.braking.max_force_kn == pytest.approx(0.3 * 180.0 * 1.2 + 180.0 * 9.81 * 0.01)


def test_a_mode_without_traction_at_the_start_is_refused(small):
    with pytest.raises(CaseError, match=r"field 'mode' = '1500V'.*no traction where the path starts"
                                        r".*modes: 1500V, 25000V"):
        railjson_case(small, DATA / "rolling_stocks" / "high-speed-train.json", from_point="Mid_West_station",
                      to_point="Mid_East_station", planned_time_s=700.0)


def test_bad_paths_name_the_problem(small):
    with pytest.raises(CaseError, match=r"path\[1\].*not connected to the end of track 'TA0'"):
        small.path([("TA0", S2S), ("TD0", S2S)])
    with pytest.raises(CaseError, match=r"field 'path\[0\]' = 'T99'.*no such track section"):
        small.path([("T99", S2S)])
    with pytest.raises(CaseError, match=r"path\[0\].direction"):
        small.path([("TA0", "FORWARD")])
    with pytest.raises(CaseError, match="begin_m.*outside the track 'TA0'"):
        small.path([("TA0", S2S)], begin_m=2500.0)
    with pytest.raises(CaseError, match="no speed section applies here.*default_limit_kmh"):
        path_line(read_infra(INFRAS / "tiny_infra.json"), [PathStep("ne.micro.foo_to_bar", 0.0, 1000.0, S2S)])
    with pytest.raises(CaseError, match="does not continue the previous range"):
        small.path_from_track_ranges([{"track": "TA0", "begin": 0.0, "end": 100.0, "direction": S2S},
                                      {"track": "TA0", "begin": 200.0, "end": 300.0, "direction": S2S}])


@pytest.mark.parametrize("change, field", [
    (lambda d: d["track_sections"][0].update(length=-1.0), "track_sections[0].length"),
    (lambda d: d["track_sections"][6]["slopes"][0].update(end=20000.0), "track_sections[6].slopes[0]"),
    (lambda d: d["track_sections"][6]["slopes"][0].update(gradient="3"), "track_sections[6].slopes[0].gradient"),
    (lambda d: d["switches"][0].update(switch_type="turntable"), "switches[0].switch_type"),
    (lambda d: d["switches"][0]["ports"]["A"].update(track="nowhere"), "switches[0].ports.A"),
    (lambda d: d["speed_sections"][0]["track_ranges"][0].update(applicable_directions="UP"),
     "speed_sections[0].track_ranges[0].applicable_directions"),
    (lambda d: d["speed_sections"][0].update(speed_limit=0.0), "speed_sections[0].speed_limit"),
    (lambda d: d["neutral_sections"][0].update(lower_pantograph=None), "neutral_sections[0].lower_pantograph"),
    (lambda d: d["speed_sections"][0].update(on_routes="rt.a"), "speed_sections[0].on_routes"),
    (lambda d: d["operational_points"][0]["parts"][0].update(position=1e6), "operational_points[0].parts[0].position"),
])
def test_bad_infrastructures_name_the_field(change, field):
    data = json.loads((INFRAS / "small_infra.json").read_text())
    change(data)
    with pytest.raises(CaseError) as err:
        read_infra(data)
    assert err.value.field == field


def test_a_loop_is_read_once_per_pass():
    # a path that runs a track twice (a loop) gets its slopes on both passes, not doubled
    data = json.loads((INFRAS / "tiny_infra.json").read_text())
    infra = read_infra(data)
    steps = infra.path([("ne.micro.foo_to_bar", S2S)], 4000.0, 6000.0)
    twice = tuple(steps) + (replace(steps[0], begin_m=4000.0, end_m=6000.0),)
    line = path_line(infra, twice, default_limit_kmh=100.0)
    assert line.gradients == ((0.0, 1000.0, 10.0), (1000.0, 2000.0, -10.0), (2000.0, 3000.0, 10.0),
                              (3000.0, 4000.0, -10.0))


def _mirror(rows, length, negate=False):
    return tuple((length - b, length - a, -v if negate else v) for a, b, v in reversed(rows))


def test_every_station_pair_run_backwards_mirrors_the_profile(small):
    # on every path between two stations of small_infra, the same tracks run the other way give the
    # mirrored line: gradients mirrored and negated, limits and curves mirrored (its speed sections
    # apply both ways); the altitude at the end is the same climb with the opposite sign
    pairs = 0
    for a in small.operational_points:
        for b in small.operational_points:
            if a == b:
                continue
            try:
                steps = small.shortest_path(a, b)
            except CaseError:
                continue
            back = tuple(PathStep(s.track, s.begin_m, s.end_m, S2T if s.direction == S2S else S2S)
                         for s in reversed(steps))
            forward, backward = path_line(small, steps), path_line(small, back)
            length = forward.length_m
            assert backward.length_m == length == pytest.approx(sum(s.length_m for s in steps))
            assert backward.gradients == _mirror(forward.gradients, length, negate=True)
            assert backward.speed_limits == _mirror(forward.speed_limits, length)
            assert backward.curves == _mirror(forward.curves, length)
            assert backward.altitude_m(length) == pytest.approx(-forward.altitude_m(length))
            pairs += 1
    assert pairs == 40  # of the 56 ordered pairs, 16 need a reversal


def test_power_recovery_uses_the_rolling_stocks_times(small):
    # West_station -> Mid_East_station crosses neutral_section.1 (TA0 [1960, 2000], pantograph lowered)
    # and .0 (TA6 [0, 10], lowered) then .2 (TA6 [8500, 8600], not lowered) at 300 km/h
    stock = DATA / "rolling_stocks" / "commuter-train.json"  # raise_pantograph_time 25 s, power start-up 5 s
    plain = railjson_case(small, stock, path=[("TA0", S2S), ("TA6", S2S)], begin_m=700.0, end_m=10000.0,
                          mode="1500V", planned_time_s=600.0)
    slow = railjson_case(small, stock, path=[("TA0", S2S), ("TA6", S2S)], begin_m=700.0, end_m=10000.0,
                         mode="1500V", planned_time_s=600.0, power_recovery=True)
    assert plain.line.neutral_sections == ((1260.0, 1310.0), (9800.0, 9900.0))
    # 25 s after the lowered ones (they join), 5 s after the other, each at the 300 km/h limit
    assert [x for row in slow.line.neutral_sections for x in row] == pytest.approx(
        [1260.0, 1310.0 + 25.0 * 300.0 / 3.6, 9800.0, 9900.0 + 5.0 * 300.0 / 3.6])
