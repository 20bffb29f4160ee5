"""The section-front cache of ``section_fronts(cache_path=...)``: keyed by content and version, atomic, never stale."""

from __future__ import annotations

import dataclasses
import warnings

import numpy as np
import pandas as pd
import pytest

from pymoo_rail.journeys import Journey, section_fronts
from pymoo_rail.rowcache import KEY_COLUMN, CorruptCacheWarning
from tests.conftest import make_case


def sections(n: int = 3, limit_kmh: float = 100.0):
    """Short synthetic sections (different lengths, so different contents) with one train."""
    return [make_case(line={"length_m": 1500.0 + 250.0 * k, "gradients": [[0.0, 1500.0 + 250.0 * k, 0.0]],
                            "speed_limits": [[0.0, 1500.0 + 250.0 * k, limit_kmh]]}) for k in range(n)]


class Source:
    """A front source with the signature of ``optimal_front`` that counts the sections it is asked for."""

    def __init__(self, fail_at_length_m: float | None = None):
        self.calls: list[float] = []
        self.fail_at_length_m = fail_at_length_m

    def __call__(self, case, running_times):
        if case.line.length_m == self.fail_at_length_m:
            raise KeyboardInterrupt("stopped during this section")
        self.calls.append(case.line.length_m)
        return pd.DataFrame({"running_time_s": running_times, "energy_kwh": 2.0 * case.line.length_m / running_times})


def journey(name: str = "line", parts=None) -> Journey:
    parts = sections() if parts is None else parts
    return Journey.from_sections(name=name, sections=parts, dwell_s=(30.0,) * (len(parts) - 1))


def test_a_renamed_section_is_served_and_a_changed_one_under_its_name_is_computed(tmp_path):
    cache = tmp_path / "fronts.csv"
    source = Source()
    first = section_fronts(journey("line"), source, n_times=4, cache_path=cache)
    assert len(source.calls) == 3
    # the same sections under other names (the journey's name is in each section's name): all read back
    renamed = journey("renamed line")
    assert renamed.sections[0].name != journey("line").sections[0].name
    seen = []
    again = section_fronts(renamed, source, n_times=4, cache_path=cache, on_front=lambda k, c: seen.append(c))
    assert len(source.calls) == 3 and seen == [False, False, False]
    for a, b in zip(first, again):
        np.testing.assert_array_equal(a.to_numpy(), b.to_numpy())
    # section 1 changed (a lower speed limit) under the same journey and section names: computed again
    parts = sections()
    slower = sections(limit_kmh=60.0)[1]
    changed = journey("line", [parts[0], slower, parts[2]])
    assert changed.sections[1].name == journey("line").sections[1].name
    section_fronts(changed, source, n_times=4, cache_path=cache, on_front=lambda k, c: seen.append(c))
    assert seen[3:] == [False, True, False] and len(source.calls) == 4
    # the stale rows of section 1 went when its new front came: one front per section in the file
    table = pd.read_csv(cache)
    assert table.groupby("section")[KEY_COLUMN].nunique().tolist() == [1, 1, 1]
    # a finished run leaves the cache and nothing else (no fronts.csv.lock)
    assert sorted(p.name for p in tmp_path.iterdir()) == ["fronts.csv"]


def test_a_front_of_another_strategy_version_is_not_served(tmp_path, monkeypatch):
    cache = tmp_path / "fronts.csv"
    one = journey("one", sections(1))
    seen = []
    section_fronts(one, "simulated", cache_path=cache, on_front=lambda k, c: seen.append(c))
    section_fronts(one, "simulated", cache_path=cache, on_front=lambda k, c: seen.append(c))
    monkeypatch.setattr("pymoo_rail.journeys.fronts.STRATEGY_VERSION", "test-next")
    section_fronts(one, "simulated", cache_path=cache, on_front=lambda k, c: seen.append(c))
    assert seen == [True, False, True]


def test_an_interrupted_run_keeps_the_finished_sections(tmp_path):
    cache = tmp_path / "fronts.csv"
    stopping = Source(fail_at_length_m=2000.0)  # section 2
    with pytest.raises(KeyboardInterrupt):
        section_fronts(journey(), stopping, n_times=4, cache_path=cache)
    assert stopping.calls == [1500.0, 1750.0]
    source = Source()
    seen = []
    section_fronts(journey(), source, n_times=4, cache_path=cache, on_front=lambda k, c: seen.append(c))
    assert seen == [False, False, True] and source.calls == [2000.0]


@pytest.mark.parametrize("damage", ["cut", "garbage"])
def test_a_damaged_cache_is_moved_aside_and_recomputed(tmp_path, damage):
    cache = tmp_path / "fronts.csv"
    source = Source()
    section_fronts(journey(), source, n_times=4, cache_path=cache)
    text = cache.read_text()
    # an append cut off mid-line (the old writer's failure), or a value overwritten
    cache.write_text(text[:-25] if damage == "cut" else text.replace(text.splitlines()[2].split(",")[1], "x#!", 1))
    with pytest.warns(CorruptCacheWarning, match="fronts.csv: .*moved to fronts.csv.corrupt-"):
        section_fronts(journey(), source, n_times=4, cache_path=cache)
    assert len(source.calls) == 6
    aside = list(tmp_path.glob("fronts.csv.corrupt-*"))
    assert len(aside) == 1 and aside[0].read_text() != cache.read_text()
    with warnings.catch_warnings():
        warnings.simplefilter("error")  # the rewritten file is sound
        section_fronts(journey(), source, n_times=4, cache_path=cache)
    assert len(source.calls) == 6


def test_a_file_without_keys_serves_nothing(tmp_path):
    # a cache written before rows carried keys (names and settings only): its fronts may be stale
    cache = tmp_path / "fronts.csv"
    one = journey("one", sections(1))
    pd.DataFrame({"running_time_s": [100.0, 200.0], "energy_kwh": [1.0, 0.5], "section": 0,
                  "case": one.sections[0].name, "source": "Source", "grid": "quadratic", "n_times": 4,
                  "max_time_factor": 1.5, "dx_m": 0.0}).to_csv(cache, index=False)
    source = Source()
    front = section_fronts(one, source, n_times=4, cache_path=cache)[0]
    assert source.calls == [1500.0] and front["energy_kwh"].iloc[-1] != 0.5
    assert KEY_COLUMN in pd.read_csv(cache).columns and len(pd.read_csv(cache)) == len(front)


def test_the_key_holds_the_content_not_prose(tmp_path):
    cache = tmp_path / "fronts.csv"
    case = sections(1)[0]
    source = Source()
    section_fronts(case, source, n_times=4, cache_path=cache)
    section_fronts(dataclasses.replace(case, name="other", source="elsewhere", description="prose"), source,
                   n_times=4, cache_path=cache)
    assert len(source.calls) == 1
    section_fronts(case.with_planned_time(case.planned_time_s + 1.0), source, n_times=4, cache_path=cache)
    assert len(source.calls) == 2
