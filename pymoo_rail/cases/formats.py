"""The registry of case formats: which reader reads a file, by its suffix or its content.

Each format is one module of :mod:`pymoo_rail.cases` with ``read_case(path, *,
allow_implausible=None, **options)``, a train reader and ``looks_like(head: bytes)``; a new format (railML,
railjson) is that module plus one line of :data:`FORMATS`. :func:`~pymoo_rail.cases.load_case`,
:func:`~pymoo_rail.cases.load_train` and :func:`~pymoo_rail.journeys.load_journey` dispatch
through :func:`format_of`.
"""

from __future__ import annotations

import inspect
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path

from pymoo_rail.cases import railjson, toml_case, ttobench
from pymoo_rail.cases.files import file_bytes
from pymoo_rail.model import Case, CaseError, Train

HEAD_BYTES = 4096  # how much of a file the content sniffers see


@dataclass(frozen=True)
class CaseFormat:
    """One file format: its name, its suffixes, a sniffer of its content, its case and train readers."""

    name: str
    suffixes: tuple[str, ...]
    looks_like: Callable[[bytes], bool]
    read_case: Callable[..., Case]
    read_train: Callable[..., Train]


FORMATS: tuple[CaseFormat, ...] = (  # content is tried in this order: the narrowest format first
    CaseFormat("railjson", (".toml", ".json"), railjson.looks_like, railjson.read_case, railjson.read_train),
    CaseFormat("toml", (".toml",), toml_case.looks_like, toml_case.read_case, toml_case.read_train),
    CaseFormat("ttobench", (".json",), ttobench.looks_like, ttobench.read_case, ttobench.read_train_file),
)


def call_reader(reader: Callable, name: str, path: Path, **options):
    """``reader(path, **options)``; options the reader does not take, or a required one missing,
    are a :class:`CaseError` naming the format ``name`` and the reader's keywords."""
    try:
        inspect.signature(reader).bind(path, **options)
    except TypeError as err:
        keywords = [key for key, p in inspect.signature(reader).parameters.items()
                    if p.kind is inspect.Parameter.KEYWORD_ONLY]
        raise CaseError("options", sorted(options), f"{err} (the {name} reader takes: {', '.join(keywords)})",
                        str(path)) from None
    return reader(path, **options)


def format_of(path: str | Path) -> CaseFormat:
    """The format of the file at ``path``: by suffix, else by its first bytes; a CaseError names
    the formats known when none fits."""
    path = Path(path)
    by_suffix = [f for f in FORMATS if path.suffix.lower() in f.suffixes]
    if len(by_suffix) == 1:
        return by_suffix[0]
    head = file_bytes(path, HEAD_BYTES)
    for fmt in by_suffix or FORMATS:
        if fmt.looks_like(head):
            return fmt
    if by_suffix:  # the suffix's general reader (the last) names what is wrong with the file
        return by_suffix[-1]
    known = ", ".join(f"{f.name} ({' '.join(f.suffixes)})" for f in FORMATS)
    raise CaseError("path", str(path), f"is in no known case format (known: {known})", str(path))
