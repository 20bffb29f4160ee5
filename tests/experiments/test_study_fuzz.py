"""Property-based tests (hypothesis): generated bad study files and results folders get a named error
(``StudyError``, ``RecordError``, ``StoreError``) or run as written; never a raw exception from
inside, never code the file names (issue 30).

A package on ``sys.path`` writes a marker file when imported; the generated files name it (and
``os:system`` with a command that would write the same marker) among their values, and every
example checks that the marker was never written.
"""

from __future__ import annotations

import copy
import datetime
import json
import tempfile
import warnings
from pathlib import Path

import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from pymoo_rail.experiments import Study, StudyError, load_results, run_study, study_to_toml
from pymoo_rail.experiments.store import RecordError, StoreError, record_checksum

STUDY_EXAMPLES = 600
FOLDER_EXAMPLES = 60
NAMED = (StudyError, RecordError, StoreError)

BASE = {"name": "fuzz", "seeds": [1], "budget": {"n_gen": 1}, "history": True, "baseline": "nsga2",
        "problems": [{"problem": "zdt1", "n_var": 3}],
        "algorithms": [{"algorithm": "nsga2", "pop_size": 4, "crossover": {"operator": "sbx", "eta": 15}}]}

# where a mutation lands: a path of keys and indices into BASE (the last key may be new)
PATHS = [("name",), ("seeds",), ("budget",), ("budget", "n_gen"), ("history",), ("baseline",), ("problems",),
         ("algorithms",), ("problems", 0), ("problems", 0, "problem"), ("problems", 0, "n_var"),
         ("problems", 0, "label"), ("algorithms", 0, "algorithm"), ("algorithms", 0, "pop_size"),
         ("algorithms", 0, "crossover"), ("algorithms", 0, "crossover", "operator"),
         ("algorithms", 0, "crossover", "eta"), ("algorithms", 0, "mutation"), ("algorithms", 0, "sampling"),
         ("unknown_key",), ("problems", 0, "n_vars"), ("algorithms", 0, "pop_sise"), ("problems", 0, "command")]


@pytest.fixture(scope="module")
def marker(tmp_path_factory):
    """A package that writes ``marker`` when imported, importable by every example."""
    import sys

    root = tmp_path_factory.mktemp("evil")
    flag = root / "imported"
    package = root / "fuzz_evil_pkg"
    package.mkdir()
    (package / "__init__.py").write_text(f"open({str(flag)!r}, 'w').close()\ndef run(**kw):\n    return None\n")
    sys.path.insert(0, str(root))
    yield flag
    sys.path.remove(str(root))


def _values(flag_text: str):
    code = st.sampled_from(["os:system", "subprocess:getoutput", "fuzz_evil_pkg:run", "fuzz_evil_pkg.sub:run",
                            "builtins:exec", "zdt9", "", " ", "/abs/dir", "../../x", "a/b", "nsga2", "de", "zdt1",
                            f"touch {flag_text}"])
    # integers stay small: a valid study with pop_size = 10**9 runs as written, for ever
    scalar = st.one_of(st.booleans(), st.integers(-5, 40), st.floats(allow_nan=True, allow_infinity=True),
                       st.text(max_size=12), code, st.datetimes(min_value=datetime.datetime(1, 1, 1)))
    return st.one_of(scalar, st.lists(scalar, max_size=3), st.dictionaries(st.sampled_from(["operator", "eta", "x"]),
                                                                           scalar, max_size=2))


def _set(data: dict, path: tuple, value) -> None:
    node = data
    for key in path[:-1]:
        if isinstance(key, int):
            if not isinstance(node, list) or len(node) <= key:
                return
        elif not isinstance(node, dict) or key not in node:
            return
        node = node[key]
    if isinstance(node, dict) and not isinstance(path[-1], int):
        node[path[-1]] = value
    elif isinstance(node, list) and isinstance(path[-1], int) and len(node) > path[-1]:
        node[path[-1]] = value


def _study_mutations(flag_text: str):
    return st.lists(st.tuples(st.sampled_from(PATHS), _values(flag_text)), min_size=1, max_size=3)


FLAG_TEXT = "/tmp/pymoo-rail-fuzz-never"


@settings(max_examples=STUDY_EXAMPLES, deadline=None,
          suppress_health_check=[HealthCheck.too_slow, HealthCheck.function_scoped_fixture])
@given(mutations=_study_mutations(FLAG_TEXT))
def test_a_generated_bad_study_gets_a_named_error_or_runs_as_written(marker, mutations):
    data = copy.deepcopy(BASE)
    for path, value in mutations:
        _set(data, path, value)
    with tempfile.TemporaryDirectory() as folder:
        try:
            study = Study.from_dict(data, source="fuzz.toml")
            with warnings.catch_warnings():
                warnings.simplefilter("ignore")
                report = run_study(study, Path(folder) / "out", workers=1, progress=False)
        except NAMED as err:
            assert str(err) and "Traceback" not in str(err)
        else:
            assert report.n_runs == len(study.runs())
            assert not report.failures, report.failures[0]["error"]  # the pre-flight check catches what fails
            assert Path(folder, "out").resolve().is_relative_to(Path(folder).resolve())
            # a TOML file of the accepted study reads back as the same study
            assert study_to_toml(study)
    assert not marker.exists() and not Path(FLAG_TEXT).exists()


# ----------------------------------------------------------------------------- results folders

@pytest.fixture(scope="module")
def stored(tmp_path_factory):
    """The files of a small finished study: {relative path: text}."""
    folder = tmp_path_factory.mktemp("stored")
    study = Study("stored", problems=[{"problem": "zdt1", "n_var": 3}],
                  algorithms=[{"algorithm": "nsga2", "pop_size": 4}], seeds=2, budget={"n_gen": 2})
    run_study(study, folder, workers=1, progress=False)
    return {str(p.relative_to(folder)): p.read_text() for p in folder.rglob("*")
            if p.is_file() and "locks" not in p.parts}


RECORD_FIELDS = ["format", "run_id", "problem", "algorithm", "seed", "budget", "n_var", "n_obj", "front",
                 "indicators", "history", "counters", "inputs", "unavailable", "problem_label", "feasible",
                 "n_eval", "wall_time_s"]


def _folder_mutations():
    record_field = st.tuples(st.just("record"), st.sampled_from(RECORD_FIELDS), _values(FLAG_TEXT), st.booleans())
    front_field = st.tuples(st.just("front"), st.sampled_from(["F", "X", "CV", "extras"]), _values(FLAG_TEXT),
                            st.booleans())
    raw = st.tuples(st.just("bytes"), st.sampled_from(["record", "study"]), st.binary(max_size=64), st.just(False))
    study = st.tuples(st.just("study"), st.sampled_from(PATHS), _values(FLAG_TEXT), st.just(False))
    return st.lists(st.one_of(record_field, front_field, raw, study), min_size=1, max_size=3)


def _toml_or_none(data: dict) -> str | None:
    try:
        return study_to_toml(Study.from_dict(data))
    except (StudyError, TypeError):
        return None


@settings(max_examples=FOLDER_EXAMPLES, deadline=None,
          suppress_health_check=[HealthCheck.too_slow, HealthCheck.function_scoped_fixture])
@given(mutations=_folder_mutations())
def test_a_generated_bad_results_folder_gets_a_named_error_and_runs_nothing(marker, stored, mutations):
    files = dict(stored)
    record_name = sorted(k for k in files if k.startswith("runs/"))[0]
    with tempfile.TemporaryDirectory() as folder:
        folder = Path(folder)
        for name, text in files.items():
            (folder / name).parent.mkdir(parents=True, exist_ok=True)
            (folder / name).write_text(text)
        for kind, key, value, resign in mutations:
            record_path = folder / record_name
            if kind in ("record", "front"):
                try:
                    record = json.loads(record_path.read_text())
                except (ValueError, UnicodeDecodeError):
                    continue
                if not isinstance(record, dict):
                    continue
                value = json.loads(json.dumps(value, default=str))  # what a JSON file can hold
                if kind == "record":
                    record[key] = value
                elif isinstance(record.get("front"), dict):
                    record["front"][key] = value
                if resign:  # whoever sent the folder can compute a checksum
                    record.pop("checksum", None)
                    record["checksum"] = record_checksum(record)
                record_path.write_text(json.dumps(record))
            elif kind == "bytes":
                (record_path if key == "record" else folder / "study.toml").write_bytes(value)
            else:
                data = copy.deepcopy(BASE)
                _set(data, key, value)
                text = _toml_or_none(data)
                if text is not None:
                    (folder / "study.toml").write_text(text)
        for all_runs in (False, True):
            try:
                with warnings.catch_warnings():
                    warnings.simplefilter("ignore")
                    load_results(folder, all_runs=all_runs)
            except NAMED as err:
                assert str(err)
    assert not marker.exists() and not Path(FLAG_TEXT).exists()
