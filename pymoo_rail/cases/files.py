"""Reading a case, train or journey file's bytes: an unreadable path is a CaseError naming it."""

from __future__ import annotations

from pathlib import Path

from pymoo_rail.model import CaseError


def file_bytes(path: str | Path, limit: int | None = None) -> bytes:
    """The bytes of the file at ``path`` (the first ``limit`` of them when given).

    A missing file, a folder or a file without read permission is a :class:`CaseError` naming
    the path and the reason, never an ``OSError``.
    """
    path = Path(path)
    try:
        with path.open("rb") as fh:
            return fh.read() if limit is None else fh.read(limit)
    except OSError as err:
        raise CaseError("path", str(path), f"cannot be read: {err.strerror or err}", str(path)) from None
