"""pymoo_rail.rowcache: rows served by key only, atomic rewrites, a lock for two writers, corrupt files set aside."""

from __future__ import annotations

import multiprocessing

import numpy as np
import pandas as pd
import pytest

from pymoo_rail.rowcache import KEY_COLUMN, CorruptCacheWarning, RowCache, row_key

KEY = {"case_hash": "0123456789012345", "version": "1", "n": 4}


def test_rows_are_served_by_their_whole_key():
    cache_key = row_key(KEY)
    assert row_key(dict(reversed(list(KEY.items())))) == cache_key  # order does not matter
    assert row_key({**KEY, "version": "2"}) != cache_key and row_key({**KEY, "n": 4.0}) != cache_key


def test_add_replaces_marked_rows_and_keeps_the_others(tmp_path):
    cache = RowCache(tmp_path / "rows.csv", value_columns=("t", "e"), text_columns=("case_hash",))
    cache.add(pd.DataFrame({"t": [1.0, 2.0], "e": [5.0, 4.0]}), KEY)
    other = {**KEY, "version": "2"}
    cache.add(pd.DataFrame({"t": [2.0], "e": [3.0]}), other, replace=lambda table: table["t"] == 2.0)
    assert cache.rows(KEY)["t"].tolist() == [1.0] and cache.rows(other)["e"].tolist() == [3.0]
    assert cache.rows({**KEY, "n": 5}).empty
    table = pd.read_csv(cache.path, dtype={"case_hash": str})
    assert table.columns[-1] == KEY_COLUMN and (table["case_hash"] == KEY["case_hash"]).all()
    assert not list(tmp_path.glob(".tmp-*"))  # the atomic writer left no temporary file


def test_a_failed_rewrite_leaves_the_previous_file(tmp_path):
    cache = RowCache(tmp_path / "rows.csv", value_columns=("t",))
    cache.add(pd.DataFrame({"t": [1.0]}), KEY)
    before = cache.path.read_bytes()

    def broken(table):
        raise KeyboardInterrupt  # killed while choosing rows, before the new file exists

    with pytest.raises(KeyboardInterrupt):
        cache.add(pd.DataFrame({"t": [2.0]}), KEY, replace=broken)
    assert cache.path.read_bytes() == before


@pytest.mark.parametrize("text, reason", [
    ("t,cache_key\n1.0,abc\n2.0,ab", "last line is cut off"),
    ("t,cache_key\n1.0,abc\n2.0\n", "lacks its 'cache_key'"),
    ("t,cache_key\n1.0,abc\nnan,abc\n", "'t' row 1"),
    ("t,cache_key\n1.0,abc,7\n", "not a CSV table"),
    (b"t,cache_key\n\xff\xfe,abc\n", "not UTF-8"),
])
def test_a_corrupt_file_is_moved_aside_with_a_warning_naming_it(tmp_path, text, reason):
    path = tmp_path / "rows.csv"
    path.write_bytes(text if isinstance(text, bytes) else text.encode())
    cache = RowCache(path, value_columns=("t",))
    with pytest.warns(CorruptCacheWarning, match=f"rows.csv: .*{reason}.*moved to rows.csv.corrupt-"):
        assert cache.rows(KEY).empty
    assert not path.exists() and len(list(tmp_path.glob("rows.csv.corrupt-*"))) == 1
    cache.add(pd.DataFrame({"t": [3.0]}), KEY)
    assert cache.rows(KEY)["t"].tolist() == [3.0]


def _add_rows(path: str, first: int, n: int) -> None:
    cache = RowCache(path, value_columns=("t",))
    for i in range(first, first + n):
        cache.add(pd.DataFrame({"t": [float(i)]}), KEY)


def test_three_processes_adding_to_one_file_lose_no_row_and_leave_no_lock_file(tmp_path):
    # the lock file is deleted at every release while others wait on it: a waiter that locked the
    # deleted file must retry on the new one, or two writers overlap and rows are lost
    path = str(tmp_path / "rows.csv")
    context = multiprocessing.get_context("fork" if "fork" in multiprocessing.get_all_start_methods() else "spawn")
    workers = [context.Process(target=_add_rows, args=(path, first, 25)) for first in (0, 1000, 2000)]
    for w in workers:
        w.start()
    for w in workers:
        w.join(timeout=120)
    assert [w.exitcode for w in workers] == [0, 0, 0]
    t = np.sort(RowCache(path, value_columns=("t",)).rows(KEY)["t"].to_numpy())
    np.testing.assert_array_equal(t, np.r_[np.arange(25), np.arange(1000, 1025), np.arange(2000, 2025)])
    assert sorted(p.name for p in tmp_path.iterdir()) == ["rows.csv"]

