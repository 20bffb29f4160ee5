"""The certified fronts of cases: from memory, the fronts shipped with the package, the user cache, or computed.

Fronts are keyed by the case's *content* (:func:`~pymoo_rail.optimal.reference.front.case_hash`),
the simulation step, the number of nodes and :data:`~pymoo_rail.optimal.reference.front.FRONT_VERSION`
(:func:`front_key`). They are looked up in the fronts shipped with the package
(``pymoo_rail/suite/fronts``), then in the user cache directory
(``platformdirs.user_cache_dir("pymoo-rail")/fronts``, or ``$PYMOO_RAIL_CACHE_DIR``), and computed
and written there (atomically) otherwise.
"""

from __future__ import annotations

import os
from pathlib import Path

from pymoo_rail.atomic import atomic_write_text
from pymoo_rail.model import Case
from pymoo_rail.optimal.reference.compute import Progress, compute_front, default_dx_m, front_progress_bar
from pymoo_rail.optimal.reference.front import FRONT_VERSION, CertifiedFront, case_hash
from pymoo_rail.optimal.reference.nodes import n_times_for
from pymoo_rail.rowcache import set_aside

SHIPPED_DIR = Path(__file__).resolve().parents[2] / "suite" / "fronts"
CACHE_ENV = "PYMOO_RAIL_CACHE_DIR"


def cache_dir() -> Path:
    """The user cache directory of computed fronts (``$PYMOO_RAIL_CACHE_DIR`` overrides it)."""
    override = os.environ.get(CACHE_ENV)
    if override:
        return Path(override) / "fronts"
    import platformdirs

    return Path(platformdirs.user_cache_dir("pymoo-rail")) / "fronts"


def front_key(case: Case, dx_m: float, n_times: int) -> str:
    """The cache key of a case's front: content hash, step, number of nodes and front version."""
    return f"{case_hash(case)[:16]}-dx{dx_m:g}-n{n_times}-v{FRONT_VERSION}"


def find_front(case: Case, dx_m: float | None = None, n_times: int | None = None) -> Path | None:
    """The shipped or cached front file of a case, if any (shipped fronts first)."""
    step = default_dx_m(case) if dx_m is None else float(dx_m)
    name = f"{front_key(case, step, n_times or n_times_for(case))}.csv"
    for directory in (SHIPPED_DIR, cache_dir()):
        hits = sorted(directory.glob(f"*{name}")) if directory.is_dir() else []
        if hits:
            return hits[0]
    return None


_MEMORY: dict[str, CertifiedFront] = {}


def forget_fronts() -> None:
    """Drop the fronts held in memory (the disk cache stays): the next call reads or computes again."""
    _MEMORY.clear()


def _wants_progress(progress: bool | Progress | None) -> bool:
    import sys

    if progress is None:  # a terminal sees the bar; a test, a pipe or a notebook does not
        return bool(getattr(sys.stderr, "isatty", lambda: False)())
    return bool(progress) and not callable(progress)


def certified_front(case: Case, dx_m: float | None = None, n_times: int | None = None,
                    use_cache: bool = True, progress: bool | Progress | None = None) -> CertifiedFront:
    """The certified front of a case: from memory, the shipped fronts, the user cache, or computed.

    Computing one takes from seconds to about a minute (33 nodes, each solved two or three times).
    ``progress``: ``None`` (default) shows a progress bar on standard error when it is a terminal
    and the computation lasts over :data:`PROGRESS_DELAY_S` s (so tests, pipes and notebooks stay
    quiet); ``True`` shows it whatever standard error is, ``False`` never; a callable is called as
    ``progress(done, total)`` after each solve instead (e.g. a GUI's own bar).

    A computed front is written to the user cache atomically (a reader never sees half a file),
    named ``<case name>-<key>.csv`` where the key is :func:`front_key` (content hash, step, nodes, version).
    A cached file that cannot be read (damaged, not a number, another case's content) is moved aside
    with a :class:`~pymoo_rail.rowcache.CorruptCacheWarning` naming it, and the front is computed
    again; a damaged shipped front raises ``ValueError`` naming the file.
    """
    step = default_dx_m(case) if dx_m is None else float(dx_m)
    n_times = n_times or n_times_for(case)
    key = front_key(case, step, n_times)
    if use_cache and key in _MEMORY:
        return _MEMORY[key]
    path = find_front(case, step, n_times) if use_cache else None
    front = None
    if path is not None:
        try:
            front = CertifiedFront.read_csv(path)
            if front.case_hash != case_hash(case):
                raise ValueError(f"{path}: front of case hash {front.case_hash[:16]}, not of this case's content")
        except ValueError as err:  # also pandas' parser errors and undecodable bytes
            if path.parent == SHIPPED_DIR:
                raise  # a damaged installation: recomputing would hide it
            set_aside(path, str(err).removeprefix(f"{path}: "), "the front will be computed again")
            front = None
    if front is None:
        if callable(progress):
            front = compute_front(case, step, n_times, progress)
        elif _wants_progress(progress):
            bar, tick = front_progress_bar(case.name)
            try:
                front = compute_front(case, step, n_times, tick)
            finally:
                bar.close()
        else:
            front = compute_front(case, step, n_times)
        safe = "".join(ch if ch.isalnum() or ch in "-_." else "_" for ch in case.name)
        atomic_write_text(cache_dir() / f"{safe}-{key}.csv", front.to_csv_text())
    _MEMORY[key] = front
    return front
