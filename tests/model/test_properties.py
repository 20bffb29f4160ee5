"""Property-based tests (hypothesis): malformed cases and decisions get a named error or a
correct result; never a raw exception from inside, never a silent coercion.

Per run: 150 case mutations (pure Python, plus the flat-out run of each case that loads) and
60 populations of decisions on one compiled problem, so the suite stays cheap.
"""

from __future__ import annotations

import copy
import math
import tempfile
from pathlib import Path

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from pymoo_rail.cases import case_path, load_case
from pymoo_rail.model import CaseError, case_from_dict, case_to_dict
from pymoo_rail.sim import Simulator

CASE_EXAMPLES = 150
FILE_EXAMPLES = 100
DECISION_EXAMPLES = 60


def _base() -> dict:
    """metro-a with every optional part present, so every kind of field can be mutated."""
    data = case_to_dict(load_case("metro-a"))
    data["line"]["curves"] = [[100.0, 300.0, 800.0]]
    data["line"]["tunnels"] = [[400.0, 600.0]]
    data["line"]["neutral_sections"] = [[450.0, 520.0]]
    data["train"]["braking"] = {"segments": [{"v_max_kmh": 40.0, "poly": [390.0]},
                                             {"v_max_kmh": 80.0, "poly": [430.0, -1.0]}],
                                "regen_max_force_kn": 200.0}
    data["run"]["legs"] = [{"start_m": 0.0, "end_m": 500.0, "planned_time_s": 40.0, "dwell_s": 20.0},
                           {"start_m": 500.0, "end_m": 1000.0, "planned_time_s": 40.0}]
    return data


BASE = _base()


def _paths(node, prefix=()):
    """Every numeric leaf and every list of the case, as key paths."""
    if isinstance(node, dict):
        for key, value in node.items():
            yield from _paths(value, prefix + (key,))
    elif isinstance(node, list):
        yield prefix
        for i, value in enumerate(node):
            yield from _paths(value, prefix + (i,))
    elif isinstance(node, (int, float)) and not isinstance(node, bool):
        yield prefix


def _at(data, path):
    for key in path:
        data = data[key]
    return data


def _set(data, path, value):
    _at(data, path[:-1])[path[-1]] = value


def _dotted(path) -> str:
    text = ""
    for key in path:
        text += f"[{key}]" if isinstance(key, int) else (f".{key}" if text else key)
    return text


NUMBER_PATHS = [p for p in _paths(BASE) if not isinstance(_at(BASE, p), list)]
LIST_PATHS = [p for p in _paths(BASE) if isinstance(_at(BASE, p), list)]
NEVER_A_NUMBER = [True, False, "80", "1e3", "fast", [1.0], {"v": 1.0}, math.nan, math.inf, -math.inf]
# the audit's nonsense among them: 5e-324 t, 1e-300 km/h, 1e30 kW, 0.194 t, +-120 permille, 1e6 km/h
ODD_NUMBERS = [0, 0.0, -1.0, -1e-9, 1e-12, 1e9, 1e300, -1e300, 1, 7, 10**30, 5e-324, 1e-300, 1e-6, 1e30, 0.194,
               120.0, -120.0, 1e6, 1e12]

mutations = st.one_of(
    st.tuples(st.just("not a number"), st.sampled_from(NUMBER_PATHS), st.sampled_from(NEVER_A_NUMBER)),
    st.tuples(st.just("odd number"), st.sampled_from(NUMBER_PATHS),
              st.one_of(st.sampled_from(ODD_NUMBERS), st.floats(-1e4, 1e4, allow_nan=False))),
    st.tuples(st.just("odd list"), st.sampled_from(LIST_PATHS),
              st.sampled_from([[], 5.0, "abc", True, [[]], [["a", "b"]], {"x": 1}])),
    st.tuples(st.just("not text"), st.sampled_from([("name",), ("source",), ("description",), ("train", "name")]),
              st.sampled_from([5, 1.5, True, [], {"a": 1}])),
)


def _field_exists(field: str) -> bool:
    """True when ``field`` is a path into the case (a list index may point past the end)."""
    import re

    node = BASE
    for name, index in re.findall(r"([A-Za-z_]\w*)|\[(\d+)\]", field):
        if name:
            if not isinstance(node, dict) or name not in node:
                return name in ("segments", "table", "max_force_kn", "max_power_kw")  # curve forms
            node = node[name]
        else:
            if not isinstance(node, list):
                return False
            node = node[int(index)] if int(index) < len(node) else None
    return True


@settings(max_examples=CASE_EXAMPLES, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(mutations)
def test_a_malformed_case_gets_a_named_error_or_loads_exactly_what_was_written(mutation):
    kind, path, value = mutation
    data = copy.deepcopy(BASE)
    _set(data, path, value)
    try:
        case = case_from_dict(data, source="mutated.toml")
    except CaseError as err:
        message = str(err)
        assert err.field and "<" not in err.field and "mutated.toml" in message, message
        assert _field_exists(err.field), f"{err.field!r} is no field of a case: {message}"
        if kind == "not text":  # description = 5: refused under its own name
            assert err.field == _dotted(path) and err.value is value, message
        if kind == "not a number" and not isinstance(_at(BASE, path), list):
            # a value that is never a number must be refused under its own name, not coerced
            assert err.field == _dotted(path) or _dotted(path).startswith(err.field), message
            assert err.value is value or (isinstance(value, float) and math.isnan(value) and math.isnan(err.value))
        return
    assert kind not in ("not a number", "not text"), f"{_dotted(path)} = {value!r} was accepted"
    # it loaded: the case holds exactly the value written (nothing clipped or converted)
    reread = case_to_dict(case)
    if kind == "odd number":
        assert float(_at(reread, path)) == float(value) and not isinstance(_at(reread, path), bool)
    # and its fastest run either reaches the platform or the error names a field
    try:
        minimum = Simulator(case.legs and case.leg(0) or case, dx_m=5.0).check_reachable().running_time_s
    except CaseError as err:
        assert err.field and "<" not in err.field, str(err)
    else:
        assert math.isfinite(minimum) and minimum > 0


# ---------------------------------------------------------------------------- case files

TEXT = case_path("metro-a").read_text(encoding="utf-8")
LINES = TEXT.splitlines(keepends=True)

file_damage = st.one_of(
    st.tuples(st.just("encoding"), st.sampled_from(["latin-1", "utf-16", "utf-16-le", "utf-32", "cp1252"]),
              st.sampled_from(["ä", "Großräschen", "€", "\u00e9"])),
    st.tuples(st.just("bom"), st.sampled_from([b"\xef\xbb\xbf", b"\xff\xfe", b"\xfe\xff"]), st.none()),
    st.tuples(st.just("truncate"), st.integers(0, len(TEXT)), st.none()),
    st.tuples(st.just("insert bytes"), st.integers(0, len(TEXT)), st.binary(min_size=1, max_size=8)),
    st.tuples(st.just("nest"), st.integers(1, 200_000), st.sampled_from(["[", "{a = ", "[[", "[{b = "])),
    st.tuples(st.just("replace line"), st.integers(0, len(LINES) - 1),
              st.text(st.characters(codec="utf-8"), max_size=30)),
)


def _damaged(damage) -> bytes:
    kind, where, what = damage
    if kind == "encoding":
        return TEXT.replace('name = "metro-a"', f'name = "{what}"').encode(where, errors="replace")
    if kind == "bom":
        return where + TEXT.encode()
    if kind == "truncate":
        return TEXT.encode()[:where]
    if kind == "insert bytes":
        raw = TEXT.encode()
        return raw[:where] + what + raw[where:]
    if kind == "nest":
        closing = "]" if what.startswith("[") and "{" not in what else "}"
        return (TEXT + f"\nextra = {what * where}1{closing * where}\n").encode()
    return "".join(LINES[:where] + [what + "\n"] + LINES[where + 1:]).encode()


@settings(max_examples=FILE_EXAMPLES, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(file_damage)
def test_a_damaged_case_file_gives_a_case_error_naming_the_file_or_loads(damage):
    with tempfile.TemporaryDirectory() as folder:
        path = Path(folder) / "damaged.toml"
        path.write_bytes(_damaged(damage))
        try:
            case = load_case(path)
        except CaseError as err:
            assert "damaged.toml" in str(err) and err.field, str(err)
        else:  # loaded: e.g. a UTF-8 BOM, or a cut after the last line
            assert case.line.length_m > 0


# ---------------------------------------------------------------------------- decisions

_PROBLEM = []


def _problem():
    """One problem (and one compiled simulator) for every example."""
    if not _PROBLEM:
        from pymoo_rail.problems import SpeedProfileProblem

        _PROBLEM.append(SpeedProfileProblem(load_case("metro-a"), objectives=("energy", "time_error")))
    return _PROBLEM[0]


@pytest.fixture(scope="module")
def problem():
    return _problem()


def _populations():
    p = _problem()
    inside = st.floats(0.0, 1.0)
    bad = st.sampled_from([math.nan, math.inf, -math.inf, -1.0, -1e-9, 1e6, 81.0, 200.0])
    cell = st.one_of(inside.map(lambda u: ("in", u)), bad.map(lambda b: ("raw", b)))
    return st.lists(st.lists(cell, min_size=p.n_var, max_size=p.n_var), min_size=1, max_size=6)


@settings(max_examples=DECISION_EXAMPLES, deadline=None, suppress_health_check=[HealthCheck.function_scoped_fixture])
@given(data=st.data())
def test_a_population_with_bad_rows_is_refused_naming_them_or_evaluated_finitely(problem, data):
    from pymoo_rail.problems import DecisionError

    rows = data.draw(_populations())
    xl, xu = problem.xl, problem.xu
    X = np.array([[xl[j] + u * (xu[j] - xl[j]) if tag == "in" else u for j, (tag, u) in enumerate(row)]
                  for row in rows])
    bad_rows = [i for i, x in enumerate(X) if not (np.all(np.isfinite(x)) and np.all((x >= xl) & (x <= xu)))]
    if bad_rows:
        with pytest.raises(DecisionError) as raised:
            problem.evaluate(X)
        assert raised.value.rows == bad_rows
        first = bad_rows[0]
        j = int(np.flatnonzero(~np.isfinite(X[first]) | (X[first] < xl) | (X[first] > xu))[0])
        assert f"decision row {first}, " in str(raised.value)
        assert f"variable {j} = {float(X[first, j])!r} km/h" in str(raised.value)
    else:
        out = problem.evaluate(X, return_as_dictionary=True)
        assert np.all(np.isfinite(out["F"])) and np.all(np.isfinite(out["G"]))
        assert out["F"].shape == (len(X), 2)
