"""load_journey: one entry for journey files of every format, dispatched by suffix and content."""

from __future__ import annotations

import warnings
from pathlib import Path

import pytest

from pymoo_rail.cases import case_path, load_case
from pymoo_rail.cases.ttobench import BEIJING_SUBWAY_TRAIN, YIZHUANG_STOP_NAMES, YIZHUANG_TRACK, TTOBenchWarning
from pymoo_rail.journeys import Journey, TimedJourney, journey_from_ttobench, load_journey, timed_journey_from_ttobench
from pymoo_rail.model import CaseError

RELEASE = Path(__file__).resolve().parents[1] / "data" / "ttobench"
JOURNEY = RELEASE / "journeys" / "CH_StGallen_Wil_Journey_01.json"
TRACK = RELEASE / "tracks" / "CH_StGallen_Wil.json"
KISS = RELEASE / "trains" / "CH_Stadler_KISS_SBB.json"


def test_a_ttobench_track_gives_the_journey_of_its_stops():
    stops = ["Tongjinan Rd", "Jinghai Rd", -1]
    loaded = load_journey(YIZHUANG_TRACK, train=BEIJING_SUBWAY_TRAIN, stops=stops, stop_names=YIZHUANG_STOP_NAMES,
                          planned_times_s=[150.0, 900.0])
    direct = journey_from_ttobench(YIZHUANG_TRACK, BEIJING_SUBWAY_TRAIN, stops, stop_names=YIZHUANG_STOP_NAMES,
                                   planned_times_s=[150.0, 900.0])
    assert isinstance(loaded, Journey) and loaded == direct and loaded.n_sections == 2


def test_a_ttobench_journey_file_gives_a_timed_journey():
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", TTOBenchWarning)
        loaded = load_journey(JOURNEY, track=TRACK, train=KISS)
        direct = timed_journey_from_ttobench(JOURNEY, TRACK, KISS)
    assert isinstance(loaded, TimedJourney) and loaded.windows == direct.windows


def test_a_case_with_legs_gives_the_journey_of_its_legs():
    by_name = load_journey("cooperative-pair")
    by_path = load_journey(case_path("cooperative-pair"))
    assert by_name == by_path == Journey(case=load_case("cooperative-pair")) and by_name.n_sections == 2


def test_an_unknown_journey_is_named(tmp_path):
    with pytest.raises(CaseError, match="no such journey"):
        load_journey(tmp_path / "absent.json")
    odd = tmp_path / "odd.json"
    odd.write_text('{"metadata": {}}')
    with pytest.raises(CaseError, match="no known journey format"):
        load_journey(odd)


def test_a_journey_file_without_its_track_is_named():
    with pytest.raises(CaseError) as raised:
        load_journey(JOURNEY, train=KISS)
    assert raised.value.field == "options" and "track" in str(raised.value)
