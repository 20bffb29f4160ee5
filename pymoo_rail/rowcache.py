"""A CSV file of computed rows, each stamped with the key of what computed it.

The on-disk caches of expensive runs outside the study store (the exact solver's points,
:func:`pymoo_rail.optimal.reference.exact_points`; the section fronts of a journey,
:func:`pymoo_rail.journeys.section_fronts`) keep their rows in one CSV file. A row is served
only to a caller asking with the same key: the fields of the key (the case's content hash, the
version of the code that computed it, the settings) are written as columns, followed by a last
column ``cache_key``, the hash of all of them (:func:`row_key`). Rows of another key are never
served.

Guarantees:

- **Atomic.** Every change rewrites the whole file through
  :func:`pymoo_rail.atomic.atomic_write_text`: a reader (or a process killed mid-write) sees the
  previous complete file or the new one, never a part.
- **Concurrent writers.** :meth:`RowCache.add` re-reads the file and rewrites it while holding an
  OS file lock (``filelock``, ``<file>.lock``, released by the system when its holder dies), so two
  processes adding rows to one file lose none of each other's rows. The lock file is deleted as the
  lock is released (:func:`pymoo_rail.lockfiles.release_removing`): none is left beside the CSV.
- **Corrupt files.** A file that does not parse, whose last line is cut off, or whose rows lack
  their key or a value is moved aside to ``<file>.corrupt-<UTC time>`` with a
  :class:`CorruptCacheWarning` naming both files; its rows are then computed again. A file
  written before rows carried keys (no ``cache_key`` column) serves nothing, and its rows are
  dropped by the first :meth:`RowCache.add`.
"""

from __future__ import annotations

import datetime as dt
import hashlib
import io
import json
import os
import warnings
from contextlib import contextmanager
from pathlib import Path
from typing import Callable, Iterator, Mapping, Sequence

import numpy as np
import pandas as pd
from filelock import FileLock

from pymoo_rail.atomic import atomic_write_text
from pymoo_rail.lockfiles import release_removing

KEY_COLUMN = "cache_key"
"""Last column of every row: :func:`row_key` of the row's key fields."""


class CorruptCacheWarning(RuntimeWarning):
    """A cache file could not be trusted and was moved aside; its rows will be computed again."""


def row_key(fields: Mapping[str, object]) -> str:
    """The key of a row: 16 hex digits of the SHA-256 of its key fields (JSON, keys sorted).

    Floats are written with ``repr``, so ``1.5`` and ``1.50`` give one key and ``1.5`` and
    ``1.5000001`` two.
    """
    text = json.dumps({str(k): fields[k] for k in fields}, sort_keys=True, default=repr)
    return hashlib.sha256(text.encode("utf-8")).hexdigest()[:16]


def _stamp() -> str:
    return dt.datetime.now(dt.timezone.utc).strftime("%Y%m%dT%H%M%S.%fZ")


def set_aside(path: str | Path, reason: str, consequence: str, stacklevel: int = 2) -> Path | None:
    """Move an untrustworthy cache file to ``<file>.corrupt-<UTC time>`` and warn, naming both.

    Parameters
    ----------
    path : str or Path
        The cache file.
    reason : str
        What is wrong with it (goes into the :class:`CorruptCacheWarning`).
    consequence : str
        What the caller does instead, e.g. "its rows will be computed again".
    stacklevel : int
        Frames above the caller of this function that the warning points at (2: the caller's caller).

    Returns
    -------
    Path or None
        Where the file went; None when it had already gone (another process moved it).
    """
    path = Path(path)
    target = path.with_name(f"{path.name}.corrupt-{_stamp()}")
    try:
        os.replace(path, target)
    except FileNotFoundError:
        return None
    warnings.warn(f"{path}: {reason}; moved to {target.name}, {consequence}", CorruptCacheWarning,
                  stacklevel=stacklevel + 1)
    return target


class RowCache:
    """Rows of a CSV file served by key, added under a lock and written atomically.

    Parameters
    ----------
    path : str or Path
        The CSV file (created by the first :meth:`add`).
    value_columns : sequence of str
        Columns every row must hold as a finite number; a keyed file that lacks one, or a row
        whose value is missing or not a number, makes the file corrupt.
    text_columns : sequence of str
        Columns read back as text even when they look like numbers (e.g. a hash of digits only).
    """

    def __init__(self, path: str | Path, value_columns: Sequence[str], text_columns: Sequence[str] = ()):
        self.path = Path(path)
        self.value_columns = tuple(value_columns)
        self.text_columns = (*tuple(text_columns), KEY_COLUMN)
        self.lock_path = self.path.with_name(self.path.name + ".lock")

    # ------------------------------------------------------------------ reading
    def _parse(self) -> tuple[pd.DataFrame, str | None]:
        """(table, None) or (empty table, why the file is corrupt)."""
        try:
            raw = self.path.read_bytes()
        except FileNotFoundError:
            return pd.DataFrame(), None
        try:
            text = raw.decode("utf-8")
        except UnicodeDecodeError as err:
            return pd.DataFrame(), f"not UTF-8 text ({err.reason})"
        if not text.strip():
            return pd.DataFrame(), "the file is empty"
        if not text.endswith("\n"):
            return pd.DataFrame(), "its last line is cut off (an interrupted write)"
        try:
            with warnings.catch_warnings():  # a row longer than the header: pandas warns and drops data
                warnings.simplefilter("error", pd.errors.ParserWarning)
                table = pd.read_csv(io.StringIO(text), index_col=False, dtype={c: str for c in self.text_columns})
        except (pd.errors.ParserError, pd.errors.ParserWarning, pd.errors.EmptyDataError, ValueError) as err:
            detail = str(err).strip().splitlines()
            return pd.DataFrame(), f"not a CSV table ({detail[-1] if detail else type(err).__name__})"
        if KEY_COLUMN not in table.columns:
            return table, None  # written before rows carried keys: never served, dropped by the next add
        if table.columns[-1] != KEY_COLUMN or table[KEY_COLUMN].isna().any():
            return pd.DataFrame(), f"a row lacks its '{KEY_COLUMN}' (the last column)"
        for column in self.value_columns:
            if column not in table.columns:
                return pd.DataFrame(), f"column '{column}' is missing"
            values = pd.to_numeric(table[column], errors="coerce").to_numpy(dtype=float)
            if not np.isfinite(values).all():
                row = int(np.argmax(~np.isfinite(values)))
                return pd.DataFrame(), f"column '{column}' row {row}: {table[column].iloc[row]!r} is not a number"
        return table, None

    def _set_aside(self, reason: str) -> None:
        set_aside(self.path, reason, "its rows will be computed again", stacklevel=3)

    def _read_locked(self) -> pd.DataFrame:
        table, problem = self._parse()
        if problem is not None:
            self._set_aside(problem)
        return table

    def table(self) -> pd.DataFrame:
        """Every row of the file (an empty table when there is none; a corrupt file is moved aside)."""
        table, problem = self._parse()
        if problem is None:
            return table
        with self._lock():  # another process may be replacing it right now: decide under the lock
            return self._read_locked()

    def rows(self, fields: Mapping[str, object]) -> pd.DataFrame:
        """The rows stored with these key fields, in file order (index reset)."""
        table = self.table()
        if KEY_COLUMN not in table.columns:
            return table.iloc[0:0]
        return table[table[KEY_COLUMN] == row_key(fields)].reset_index(drop=True)

    # ------------------------------------------------------------------ writing
    @contextmanager
    def _lock(self) -> Iterator[None]:
        """Hold the file's lock; its lock file is gone once released."""
        self.path.parent.mkdir(parents=True, exist_ok=True)
        lock = FileLock(self.lock_path, thread_local=False)
        lock.acquire()
        try:
            yield
        finally:
            release_removing(lock)

    def add(self, rows: pd.DataFrame, fields: Mapping[str, object],
            replace: Callable[[pd.DataFrame], np.ndarray] | None = None) -> pd.DataFrame:
        """Add rows computed under these key fields; rewrite the file atomically, under its lock.

        Parameters
        ----------
        rows : pandas.DataFrame
            The new rows (without the key columns: they are added here).
        fields : mapping
            The key fields, written as columns and hashed into ``cache_key``.
        replace : callable, optional
            ``replace(table) -> bool mask`` over the file's rows as they are now: the rows to drop
            (e.g. the rows of the same section or running time, of any key: stale rows go when
            their successor comes). Rows of the same key are kept unless it marks them.

        Returns
        -------
        pandas.DataFrame
            The whole table as written.
        """
        new = rows.assign(**{name: [value] * len(rows) for name, value in fields.items()})
        new[KEY_COLUMN] = row_key(fields)
        with self._lock():
            old = self._read_locked()
            if KEY_COLUMN not in old.columns:
                old = old.iloc[0:0]  # rows written before rows carried keys: never served, not kept
            if replace is not None and len(old):
                old = old[~np.asarray(replace(old), dtype=bool)]
            table = pd.concat([old, new], ignore_index=True) if len(old) else new.reset_index(drop=True)
            table = table[[c for c in table.columns if c != KEY_COLUMN] + [KEY_COLUMN]]
            atomic_write_text(self.path, table.to_csv(index=False))
        return table


__all__ = ["RowCache", "CorruptCacheWarning", "row_key", "set_aside", "KEY_COLUMN"]
