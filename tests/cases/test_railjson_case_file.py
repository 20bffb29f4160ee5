"""railjson case files: a [railjson] table naming OSRD files, read by load_case and the CLI, written
back as complete case files."""

from __future__ import annotations

from pathlib import Path

import pytest

from pymoo_rail.cases import load_case, load_train, railjson_case, read_case
from pymoo_rail.cli import main
from pymoo_rail.model import CaseError

DATA = Path(__file__).resolve().parents[1] / "data" / "osrd"
EXAMPLE = DATA / "night-train-mid-west-to-mid-east.toml"


def test_load_case_reads_a_railjson_case_file():
    case = load_case(EXAMPLE)
    direct = railjson_case(DATA / "infras" / "small_infra.json", DATA / "rolling_stocks" / "night-train.json",
                           from_point="Mid_West_station", to_point="Mid_East_station", mode="25000V",
                           comfort="AIR_CONDITIONING", planned_time_s=700.0, name="osrd-night-train")
    assert case.line == direct.line and case.train == direct.train
    assert case.name == "osrd-night-train" and case.planned_time_s == 700.0
    assert case.description.startswith("OSRD's night train")
    assert load_train(EXAMPLE) == case.train  # the train of a railjson case file, mode and comfort as it says


def test_the_cli_writes_it_back_as_a_complete_case_file(tmp_path, capsys):
    out = tmp_path / "night.toml"
    assert main(["cases", str(EXAMPLE), "--write", str(out)]) == 0
    assert "written" in capsys.readouterr().out
    assert read_case(out) == load_case(EXAMPLE)
    assert "[railjson]" not in out.read_text()  # a plain case file: train and line in full


def _case_file(tmp_path, railjson: str, run: str = "planned_time_s = 700.0") -> Path:
    path = tmp_path / "case.toml"
    path.write_text(f'name = "x"\n[run]\n{run}\n[railjson]\n'
                    f'infra = "{DATA / "infras" / "tiny_infra.json"}"\n'
                    f'rolling_stock = "{DATA / "rolling_stocks" / "touristic-train.json"}"\n{railjson}\n')
    return path


@pytest.mark.parametrize("railjson, run, field", [
    ('from_point = "op.station_foo"\nto_point = "op.station_bar"\nspeed = 3', "planned_time_s = 700.0",
     "railjson.speed"),
    ('from_point = "op.station_foo"\nto_point = "op.station_bar"', "planned_time_s = -1.0", "run.planned_time_s"),
    ('from_point = "op.station_foo"\nto_point = "op.station_bar"', "dwell_s = 1.0", "run.planned_time_s"),
    ('from_point = "op.station_foo"', "planned_time_s = 700.0", "path"),
    ('path = [["ne.micro.foo_a", "START_TO_STOP"], ["ne.micro.bar_a", "START_TO_STOP"]]',
     "planned_time_s = 700.0", "path[1]"),
    ('from_point = "op.station_foo"\nto_point = "op.station_bar"\nmode = "25000V"', "planned_time_s = 700.0",
     "mode"),
])
def test_bad_railjson_case_files_name_the_field(tmp_path, railjson, run, field):
    with pytest.raises(CaseError) as err:
        load_case(_case_file(tmp_path, railjson, run))
    assert err.value.field == field


def test_a_missing_file_and_a_lone_railjson_file(tmp_path):
    path = tmp_path / "case.toml"
    path.write_text('name = "x"\n[run]\nplanned_time_s = 1.0\n[railjson]\ninfra = "nowhere.json"\n'
                    'rolling_stock = "also-nowhere.json"\n')
    with pytest.raises(CaseError, match="railjson.infra.*relative to the case file"):
        load_case(path)
    with pytest.raises(CaseError, match="is an OSRD railjson infrastructure, not a case"):
        load_case(DATA / "infras" / "small_infra.json")
    with pytest.raises(CaseError, match="is an OSRD railjson rolling stock, not a case.*load_train"):
        load_case(DATA / "rolling_stocks" / "night-train.json")


def test_railjson_files_are_told_apart_by_their_first_bytes():
    from pymoo_rail.cases.railjson import looks_like

    for path in [EXAMPLE, DATA / "infras" / "small_infra.json", *sorted((DATA / "rolling_stocks").glob("*.json"))]:
        assert looks_like(path.read_bytes()[:4096]), path
    others = [Path(__file__).resolve().parents[2] / "pymoo_rail" / "cases" / name
              for name in ("yizhuang.toml", "data/CN_Beijing_Subway.json", "data/CN_Songjiazhuang_Yizhuang.json")]
    for path in others:
        assert not looks_like(path.read_bytes()[:4096]), path


def test_the_registry_reader_takes_an_infrastructure_with_options():
    from pymoo_rail.cases.railjson import read_case

    case = read_case(DATA / "infras" / "small_infra.json", rolling_stock=DATA / "rolling_stocks" / "night-train.json",
                     from_point="Mid_West_station", to_point="Mid_East_station", planned_time_s=700.0,
                     mode="25000V", comfort="AIR_CONDITIONING", name="osrd-night-train")
    assert case.line == load_case(EXAMPLE).line and case.train == load_case(EXAMPLE).train
    with pytest.raises(CaseError, match="field 'planned_time_s'.*required"):
        read_case(DATA / "infras" / "small_infra.json", rolling_stock=DATA / "rolling_stocks" / "night-train.json",
                  from_point="Mid_West_station", to_point="Mid_East_station")
    with pytest.raises(CaseError, match="field 'mode'.*names its own"):
        read_case(EXAMPLE, mode="1500V")
    assert read_case(EXAMPLE) == load_case(EXAMPLE)
