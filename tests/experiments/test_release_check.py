"""The TTOBench release check: a whole track with its train, the optimum held, NSGA2 beside it."""

from __future__ import annotations

from pathlib import Path

import pytest

from pymoo_rail.experiments.release_check import release_case, release_row

TTOBENCH = Path(__file__).resolve().parents[1] / "data" / "ttobench"
TRACK, TRAIN = TTOBENCH / "tracks" / "CN_Songjiazhuang_Yizhuang.json", TTOBENCH / "trains" / "CN_Beijing_Subway.json"


def test_the_whole_track_runs_from_the_first_to_the_last_stop():
    assert release_case(TRACK, TRAIN).line.length_m == pytest.approx(22_700, abs=100)


@pytest.mark.slow
def test_the_optimum_holds_and_no_punctual_member_beats_it():
    row = release_row(release_case(TRACK, TRAIN), n_gen=2, pop_size=10)
    assert row["held"] and row["t_min_s"] > 0
    assert not row["gap_pct"] < 0  # nan (no punctual member) or above the optimum
    assert row["front_size"] >= 1 and row["n_var"] > 0
