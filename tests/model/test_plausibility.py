"""Plausibility bounds: every real case passes them, each nonsense value of the audit is refused
with a CaseError naming the field, the value and (where one fits) the unit mistake, and
``allow_implausible`` waives them for research cases, from the file or from Python."""

from __future__ import annotations

import copy
from pathlib import Path

import pytest

from pymoo_rail.cases import KINDS, from_ttobench, generate_case, list_cases, load_case
from pymoo_rail.cases.ttobench import read_track
from pymoo_rail.cases.ttobench_release import release_pairs
from pymoo_rail.model import CaseError, build_grid, case_from_dict, case_to_dict
from pymoo_rail.model.plausibility import IMPLAUSIBLE_KINDS, check_plausible

ROOT = Path(__file__).resolve().parents[2]
TTOBENCH = ROOT / "tests" / "data" / "ttobench"


def _every_real_case():
    cases = [load_case(name) for name in list_cases()]
    cases += [load_case(p) for p in sorted((ROOT / "benchmarks" / "cases").glob("*.toml"))]
    cases += [load_case(p) for p in sorted((TTOBENCH / "trains").glob("*.toml"))]
    for track, train in release_pairs(TTOBENCH):
        n = len(read_track(track).stops_m)
        cases += [from_ttobench(track, train, i, i + 1, 100.0) for i in range(n - 1)]
        cases.append(from_ttobench(track, train, 0, n - 1, 100.0))
    cases += [generate_case(seed, kind=kind) for kind in KINDS for seed in range(8)]
    return cases + [case.leg(k) for case in cases for k in range(len(case.legs))]


def test_every_built_in_ttobench_benchmark_and_generated_case_is_plausible():
    cases = _every_real_case()
    assert len(cases) > 60
    for case in cases:
        check_plausible(case)  # raises on the first value outside the bounds


BASE = case_to_dict(load_case("yizhuang"))  # 2265 m, 194.295 t, 118 m, 80 km/h


def _set(data: dict, path: tuple, value) -> dict:
    node = data
    for key in path[:-1]:
        node = node[key]
    node[path[-1]] = value
    return data


def _line_of(length_m: float):
    def edit(data):
        data["line"].update(length_m=length_m, gradients=[[0.0, length_m, 0.0]],
                            speed_limits=[[0.0, length_m, 80.0]], curves=[], tunnels=[], neutral_sections=[])
        data["train"]["length_m"] = min(data["train"]["length_m"], length_m)
    return edit


# a wrong mass also puts the forces and powers per weight out of bounds
MASS_KINDS = ("mass", "force", "power")

# (what, edit, kind(s) of bound it breaks, field named first, words of the message)
AUDIT = [
    ("a 5000 m train on a 2265 m line", lambda d: _set(d, ("train", "length_m"), 5000.0), ("length", "mass"),
     "train.length_m", "longer than the line"),
    ("+80 permille", lambda d: _set(d, ("line", "gradients", 0, 2), 80.0), "gradient", "line.gradients[0]", "80"),
    ("-120 permille", lambda d: _set(d, ("line", "gradients", 0, 2), -120.0), "gradient", "line.gradients[0]",
     "-120"),
    ("a limit of 1e6 km/h", lambda d: _set(d, ("line", "speed_limits", 0, 2), 1e6), "speed",
     "line.speed_limits[0]", "above"),
    ("a top speed of 1e6 km/h", lambda d: d["train"].update(max_speed_kmh=1e6, traction={"max_force_kn": 310.0},
                                                            braking={"max_force_kn": 260.0}), ("speed", "force"),
     "train.max_speed_kmh", "above"),
    ("a limit of 1e-300 km/h", lambda d: _set(d, ("line", "speed_limits", 0, 2), 1e-300), "speed",
     "line.speed_limits[0]", "below"),
    ("0.194 t", lambda d: _set(d, ("train", "mass_t"), 0.194), MASS_KINDS, "train.mass_t", "tonnes"),
    ("5e-324 t", lambda d: _set(d, ("train", "mass_t"), 5e-324), MASS_KINDS, "train.mass_t", "below"),
    ("kg for t", lambda d: _set(d, ("train", "mass_t"), 194295.0), MASS_KINDS, "train.mass_t", "kg where t"),
    ("a 1e-9 m train", lambda d: _set(d, ("train", "length_m"), 1e-9), "length", "train.length_m", "below"),
    ("a 0.001 m line", _line_of(0.001), "length", "line.length_m", "below"),
    ("a 1e12 m line", _line_of(1e12), "length", "line.length_m", "above"),
    ("traction in N", lambda d: _set(d, ("train", "traction"),
                                     {"max_force_kn": 310_000.0, "max_power_kw": 3000.0}), "force",
     "train.traction.max_force_kn", "N where kN"),
    ("braking in N", lambda d: _set(d, ("train", "braking"), {"max_force_kn": 260_000.0}), "force",
     "train.braking.max_force_kn", "N where kN"),
    ("resistance in N", lambda d: d["train"]["resistance"].update(a=2000.0, unit="kN"), "force",
     "train.resistance", "N where kN"),
    ("an acceleration cap of 1e30 m/s^2", lambda d: _set(d, ("train", "max_accel_ms2"), 10 ** 30), "force",
     "train.max_accel_ms2", "above"),
    ("a deceleration cap of 0.001 m/s^2", lambda d: _set(d, ("train", "max_decel_ms2"), 0.001), "force",
     "train.max_decel_ms2", "below"),
    ("aux power 1e30 kW", lambda d: _set(d, ("train", "aux_power_kw"), 1e30), "power", "train.aux_power_kw",
     "above"),
    ("aux power in W", lambda d: _set(d, ("train", "aux_power_kw"), 150_000.0), "power", "train.aux_power_kw",
     "W where kW"),
    ("traction power in W", lambda d: _set(d, ("train", "traction"),
                                           {"max_force_kn": 310.0, "max_power_kw": 3.0e6}), "power",
     "train.traction.max_power_kw", "W where kW"),
    ("a power cap of 1e-6 kW", lambda d: _set(d, ("train", "traction"),
                                              {"max_force_kn": 310.0, "max_power_kw": 1e-6}), "power",
     "train.traction.max_power_kw", "below"),
    ("planned time 1e9 s", lambda d: _set(d, ("run", "planned_time_s"), 1e9), "time", "run.planned_time_s",
     "above"),
    ("planned time in ms", lambda d: _set(d, ("run", "planned_time_s"), 150_000.0), "time", "run.planned_time_s",
     "ms where s"),
    ("margin 1e300 s", lambda d: _set(d, ("run", "time_margin_s"), 1e300), "time", "run.time_margin_s", "above"),
    ("margin longer than the run", lambda d: _set(d, ("run", "time_margin_s"), 200.0), "time",
     "run.time_margin_s", "longer than the planned"),
    ("dwell 1e9 s", lambda d: _set(d, ("run", "dwell_s"), 1e9), "time", "run.dwell_s", "above"),
]


@pytest.mark.parametrize("what, edit, kind, field, words", AUDIT, ids=[a[0] for a in AUDIT])
def test_each_nonsense_value_of_the_audit_is_refused_by_name(what, edit, kind, field, words):
    data = copy.deepcopy(BASE)
    edit(data)
    with pytest.raises(CaseError) as raised:
        case_from_dict(data, source="audit.toml")
    err = raised.value
    message = str(err)
    assert err.field == field, message
    assert "audit.toml" in message and words in message and "allow_implausible" in message, message


@pytest.mark.parametrize("what, edit, kind, field, words", AUDIT, ids=[a[0] for a in AUDIT])
def test_a_research_case_waives_the_kind_it_names(what, edit, kind, field, words):
    data = copy.deepcopy(BASE)
    edit(data)
    kinds = (kind,) if isinstance(kind, str) else kind  # e.g. a 5000 m train of 194 t is also 39 kg/m
    others = [k for k in IMPLAUSIBLE_KINDS if k not in kinds]
    with pytest.raises(CaseError):  # waiving the other kinds is not enough
        case_from_dict(data, allow_implausible=others)
    case = case_from_dict(data, allow_implausible=kinds)
    assert case.allow_implausible == tuple(sorted(kinds))
    assert case_from_dict(data, allow_implausible=True).allow_implausible is True


def test_the_file_key_waives_and_the_keyword_replaces_it(tmp_path):
    data = _set(copy.deepcopy(BASE), ("line", "gradients", 0, 2), 90.0)
    path = tmp_path / "steep.toml"
    from pymoo_rail.cases import write_case

    with pytest.raises(CaseError, match="gradients"):
        write_case(case_from_dict(data), path)
    data["allow_implausible"] = ["gradient"]
    case = case_from_dict(data)
    write_case(case, path)
    assert 'allow_implausible = ["gradient"]' in path.read_text()
    assert load_case(path) == case
    with pytest.raises(CaseError, match="line.gradients"):
        load_case(path, allow_implausible=False)
    assert load_case(path, allow_implausible=True).allow_implausible is True


def test_a_case_without_the_key_writes_none():
    assert "allow_implausible" not in case_to_dict(load_case("yizhuang"))  # fingerprints unchanged


@pytest.mark.parametrize("bad", ["yes", 1, ["gradients"], [True]])
def test_a_bad_override_is_named(bad):
    data = dict(copy.deepcopy(BASE), allow_implausible=bad)
    with pytest.raises(CaseError, match="allow_implausible"):
        case_from_dict(data)


def test_description_source_and_train_name_must_be_text():
    for key in ("description", "source"):
        data = dict(copy.deepcopy(BASE), **{key: 5})
        with pytest.raises(CaseError) as raised:
            case_from_dict(data, source="typed.toml")
        assert raised.value.field == key and raised.value.value == 5
    data = _set(copy.deepcopy(BASE), ("train", "name"), 5)
    with pytest.raises(CaseError) as raised:
        case_from_dict(data, source="typed.toml")
    assert raised.value.field == "train.name" and raised.value.value == 5


def test_a_grid_too_large_for_memory_is_refused_before_allocating():
    data = copy.deepcopy(BASE)
    _line_of(1e12)(data)
    case = case_from_dict(data, allow_implausible=["length"])
    with pytest.raises(CaseError) as raised:
        build_grid(case)
    assert raised.value.field == "line.length_m" and "grid cells" in str(raised.value)
    with pytest.raises(CaseError) as raised:
        build_grid(load_case("yizhuang"), dx_m=1e-6)
    assert raised.value.field == "dx_m"


def test_the_documented_bounds_are_the_loaders():
    from pymoo_rail.model import plausibility as bounds

    doc = (ROOT / "docs" / "case-format.md").read_text(encoding="utf-8")
    rows = {}
    for line in doc.split("## Plausibility bounds")[1].split("\n## ")[0].splitlines():
        cells = [c.strip() for c in line.split("|")]
        if len(cells) > 3 and cells[1] in IMPLAUSIBLE_KINDS:
            rows.setdefault(cells[1], []).append(cells[2])
    assert set(rows) == set(IMPLAUSIBLE_KINDS)

    def shown(value: float) -> str:
        return f"{value:,.0f}".replace(",", " ") if value >= 10_000 else f"{value:g}"

    expected = {
        "length": [bounds.LINE_LENGTH_M[0], bounds.LINE_LENGTH_M[1] / 1000, *bounds.TRAIN_LENGTH_M],
        "speed": list(bounds.SPEED_KMH), "gradient": [bounds.MAX_GRADIENT_PERMILLE],
        "mass": [*bounds.MASS_T, *bounds.MASS_PER_METRE_T], "force": [*bounds.FORCE_PER_WEIGHT,
                                                                       bounds.RESISTANCE_PER_WEIGHT,
                                                                       *bounds.ACCEL_MS2],
        "power": [*bounds.POWER_KW_PER_T, bounds.AUX_POWER_KW_PER_T], "time": [bounds.MAX_TIME_S],
        "efficiency": [*bounds.PEAK_EFFICIENCY, *bounds.MAP_COVERAGE],
    }
    for kind, values in expected.items():
        text = " ".join(rows[kind])
        for value in values:
            assert shown(value) in text, f"{kind}: {shown(value)} is not in the documented bound {text!r}"
