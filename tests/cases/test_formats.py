"""One reader per format behind load_case: dispatch by suffix, else by content; options reach the reader."""

from __future__ import annotations

import ast
import shutil
import warnings
from pathlib import Path

import pytest

from pymoo_rail.cases import FORMATS, case_path, format_of, from_ttobench, load_case, load_train
from pymoo_rail.cases.ttobench import (BEIJING_SUBWAY_TRAIN, YIZHUANG_STOP_NAMES, YIZHUANG_TRACK, TTOBenchWarning,
                                       read_train)
from pymoo_rail.model import CaseError


def test_each_format_is_found_by_suffix_and_by_content(tmp_path):
    assert format_of(case_path("metro-a")).name == "toml"
    assert format_of(YIZHUANG_TRACK).name == "ttobench"
    # without a known suffix the content decides
    toml_copy = shutil.copy(case_path("metro-a"), tmp_path / "metro-a.case")
    json_copy = shutil.copy(YIZHUANG_TRACK, tmp_path / "yizhuang.track")
    assert format_of(toml_copy).name == "toml" and load_case(toml_copy) == load_case("metro-a")
    assert format_of(json_copy).name == "ttobench"
    unknown = tmp_path / "notes.txt"
    unknown.write_text("nothing a reader knows\n")
    with pytest.raises(CaseError) as raised:
        format_of(unknown)
    assert all(f.name in str(raised.value) for f in FORMATS)


def test_a_ttobench_track_loads_through_load_case_with_the_readers_options():
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", TTOBenchWarning)
        direct = from_ttobench(YIZHUANG_TRACK, BEIJING_SUBWAY_TRAIN, "Tongjinan Rd", "Jinghai Rd", 150.0,
                               stop_names=YIZHUANG_STOP_NAMES)
        loaded = load_case(YIZHUANG_TRACK, train=BEIJING_SUBWAY_TRAIN, from_stop="Tongjinan Rd",
                           to_stop="Jinghai Rd", planned_time_s=150.0, stop_names=YIZHUANG_STOP_NAMES)
        whole = load_case(YIZHUANG_TRACK, train=BEIJING_SUBWAY_TRAIN, planned_time_s=2000.0)
    assert loaded == direct
    assert whole.line.length_m > 20_000  # first to last stop by default


def test_reader_options_on_a_built_in_name_are_refused():
    with pytest.raises(CaseError, match="options"):
        load_case("yizhuang", train=BEIJING_SUBWAY_TRAIN)


def test_missing_or_unknown_reader_options_are_named():
    with pytest.raises(CaseError) as raised:
        load_case(YIZHUANG_TRACK)  # a TTOBench track needs its train and planned time
    assert raised.value.field == "options" and "train" in str(raised.value)
    with pytest.raises(CaseError, match="toml reader"):
        load_case(case_path("metro-a"), train=BEIJING_SUBWAY_TRAIN)


def test_load_train_reads_a_case_file_a_train_alone_or_a_ttobench_train(tmp_path):
    assert load_train(case_path("metro-a")) == load_case("metro-a").train
    alone = tmp_path / "train.toml"
    text = case_path("metro-a").read_text(encoding="utf-8")
    alone.write_text("[train" + text.split("[train", 1)[1].split("[line]")[0], encoding="utf-8")
    assert load_train(alone) == load_case("metro-a").train
    assert load_train(BEIJING_SUBWAY_TRAIN) == read_train(BEIJING_SUBWAY_TRAIN).train
    no_train = tmp_path / "empty.toml"
    no_train.write_text('name = "x"\n')
    with pytest.raises(CaseError, match="train"):
        load_train(no_train)


def test_the_cli_reads_case_and_train_files_only_through_the_registry():
    # the CLI imports pymoo_rail.cases (load_case, load_train, ...), never one format's reader module,
    # so that every file a command takes goes through formats.FORMATS

    cli = Path(__file__).resolve().parents[2] / "pymoo_rail" / "cli"
    readers = {f"pymoo_rail.cases.{name}" for name in ("toml_case", "ttobench", "railjson", "railjson_infra",
                                                       "railjson_rolling_stock", "formats")}
    imported = set()
    for path in cli.rglob("*.py"):
        for node in ast.walk(ast.parse(path.read_text(encoding="utf-8"))):
            if isinstance(node, ast.ImportFrom) and node.module:
                imported.add(node.module)
            elif isinstance(node, ast.Import):
                imported.update(alias.name for alias in node.names)
    assert "pymoo_rail.cases" in imported
    assert not imported & readers, sorted(imported & readers)
