"""docs/case-format.md against the loader: every key, its default and whether it is required."""

from __future__ import annotations

import copy
import re
import sys
from pathlib import Path

import pytest

if sys.version_info >= (3, 11):
    import tomllib
else:  # pragma: no cover - Python 3.10
    import tomli as tomllib

from pymoo_rail.model import CaseError, case_from_dict, case_keys

DOC = Path(__file__).resolve().parents[2] / "docs" / "case-format.md"
ROW = re.compile(r"^\| `([^`]+)` \| [^|]* \| ([^|]+) \|")

MINIMAL = {
    "name": "m", "run": {"planned_time_s": 100.0},
    "train": {"mass_t": 200.0, "length_m": 100.0, "max_speed_kmh": 80.0,
              "resistance": {"a": 2.0, "b": 0.01, "c": 0.001, "unit": "kN", "speed_unit": "kmh"},
              "traction": {"max_force_kn": 200.0}, "braking": {"max_force_kn": 200.0}},
    "line": {"length_m": 1000.0, "gradients": [[0.0, 1000.0, 0.0]], "speed_limits": [[0.0, 1000.0, 80.0]]},
}
LEG = {"start_m": 0.0, "end_m": 1000.0, "planned_time_s": 100.0}


def documented() -> dict[str, str]:
    rows = {}
    for line in DOC.read_text().splitlines():
        match = ROW.match(line)
        if match:
            rows[match[1]] = match[2].strip()
    return rows


def test_every_key_the_loader_accepts_is_documented_and_no_other():
    assert set(documented()) == set(case_keys())


def _attribute(case, key: str):
    """The loaded value a key sets."""
    parts = key.replace("[]", "").split(".")
    if parts[0] == "run" and parts[1].endswith("_speed_kmh"):  # stored in m/s
        return getattr(case, parts[1].replace("_kmh", "_ms")) * 3.6
    if parts[0] == "run":
        return getattr(case.legs[0], parts[2]) if parts[1] == "legs" and len(parts) > 2 else getattr(case, parts[1])
    if parts[:2] == ["train", "braking"] and parts[2].startswith("regen_"):
        return getattr(case.train, parts[2])
    obj = case
    for part in parts:
        obj = getattr(obj, part)
    return obj


def _curve_form(key: str) -> bool:
    """``train.traction.table`` and the like: one of the three forms is always given."""
    parts = key.split(".")
    return len(parts) == 3 and parts[1] in ("traction", "braking") and parts[2] in ("segments", "table", "max_force_kn")


def _map_part(key: str) -> bool:
    """``train.traction_efficiency_map.gear`` and the like: keys of an optional table, checked with
    a map in ``tests/model/test_efficiency_map.py``."""
    parts = key.split(".")
    return len(parts) == 3 and parts[1].endswith("_efficiency_map")


@pytest.mark.parametrize("key, default", [(k, d) for k, d in documented().items()
                                          if d != "required" and not _curve_form(k) and not _map_part(k)])
def test_documented_defaults_are_the_loaders(key, default):
    data = copy.deepcopy(MINIMAL)
    if key.startswith("run.legs[]"):
        data["run"]["legs"] = [dict(LEG)]
    value = _attribute(case_from_dict(data), key)
    expected = None if default.startswith("none") else tomllib.loads(f"v = {default.strip('`')}")["v"]  # a TOML literal
    if expected == []:
        expected = ()
    assert value == expected, key


@pytest.mark.parametrize("key", [k for k, d in documented().items() if d == "required"])
def test_documented_required_keys_are_required(key):
    data = copy.deepcopy(MINIMAL)
    data["run"]["legs"] = [dict(LEG)]
    data["train"]["traction"] = {"segments": [{"v_max_kmh": 80.0, "poly": [200.0]}]}
    data["train"]["braking"] = {"segments": [{"v_max_kmh": 80.0, "poly": [200.0]}]}
    for direction in ("traction", "regen"):
        data["train"][f"{direction}_efficiency_map"] = {"speeds_kmh": [0.0, 80.0], "forces_kn": [0.0, 200.0],
                                                       "values": [[0.8, 0.9], [0.85, 0.9]]}
    parts = key.split(".")
    table = data
    for part in parts[:-1]:
        table = table[part.rstrip("[]")]
        if isinstance(table, list):
            table = table[0]
    del table[parts[-1]]
    with pytest.raises(CaseError, match=re.escape(parts[-1])):
        case_from_dict(data)


def test_a_force_curve_has_exactly_one_form():
    data = copy.deepcopy(MINIMAL)
    data["train"]["traction"] = {"max_power_kw": 2000.0}
    with pytest.raises(CaseError, match="exactly one form"):
        case_from_dict(data)


def test_the_minimal_example_of_the_page_loads(tmp_path):
    from pymoo_rail.cases import load_case

    block = DOC.read_text().split("```toml\n", 1)[1].split("```", 1)[0]
    (tmp_path / "level.toml").write_text(block)
    case = load_case(tmp_path / "level.toml")
    assert case.line.length_m == 2000.0 and case.train.traction.max_power_kw == 2500.0
