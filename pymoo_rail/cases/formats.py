"""The registry of case formats: which reader reads a file, by its suffix or its content.

Each format is one module of :mod:`pymoo_rail.cases` with ``read_case(path, *,
allow_implausible=None, **options)`` and ``looks_like(head: bytes)``; a new format (railML,
railjson) is that module plus one line of :data:`FORMATS`. :func:`~pymoo_rail.cases.load_case`
and :func:`~pymoo_rail.journeys.load_journey` dispatch through :func:`format_of`.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path

from pymoo_rail.cases import toml_case, ttobench
from pymoo_rail.model import Case, CaseError

HEAD_BYTES = 4096  # how much of a file the content sniffers see


@dataclass(frozen=True)
class CaseFormat:
    """One file format: its name, its suffixes, a sniffer of its content and its case reader."""

    name: str
    suffixes: tuple[str, ...]
    looks_like: Callable[[bytes], bool]
    read_case: Callable[..., Case]


FORMATS: tuple[CaseFormat, ...] = (
    CaseFormat("toml", (".toml",), toml_case.looks_like, toml_case.read_case),
    CaseFormat("ttobench", (".json",), ttobench.looks_like, ttobench.read_case),
)


def format_of(path: str | Path) -> CaseFormat:
    """The format of the file at ``path``: by suffix, else by its first bytes; a CaseError names
    the formats known when none fits."""
    path = Path(path)
    by_suffix = [f for f in FORMATS if path.suffix.lower() in f.suffixes]
    if len(by_suffix) == 1:
        return by_suffix[0]
    try:
        with path.open("rb") as fh:
            head = fh.read(HEAD_BYTES)
    except OSError as err:
        raise CaseError("path", str(path), f"cannot be read: {err.strerror or err}", str(path)) from None
    for fmt in by_suffix or FORMATS:
        if fmt.looks_like(head):
            return fmt
    known = ", ".join(f"{f.name} ({' '.join(f.suffixes)})" for f in FORMATS)
    raise CaseError("path", str(path), f"is in no known case format (known: {known})", str(path))
