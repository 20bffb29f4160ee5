"""The TOML case format (``docs/case-format.md``): read and write case files.

The file's tables are the plain-data form of :mod:`pymoo_rail.model.schema`; this module only
turns bytes into that structure and back. It is one entry of the format registry
(:mod:`pymoo_rail.cases.formats`).
"""

from __future__ import annotations

from collections.abc import Sequence
from pathlib import Path
from typing import Any

import rtoml

from pymoo_rail.cases.files import file_bytes
from pymoo_rail.model import Case, CaseError, Train, case_from_dict, case_to_dict, train_from_dict

SUFFIXES = (".toml",)


_UTF8_BOM = b"\xef\xbb\xbf"
_UTF16_BOMS = (b"\xff\xfe", b"\xfe\xff")


def parse_toml(raw: bytes, source: str) -> dict:
    """The TOML document in ``raw``; every way it can fail is a :class:`CaseError` naming ``source``.

    A UTF-8 byte-order mark (written by some Windows editors) is skipped; other encodings
    (UTF-16, Latin-1) and binary files are named as such instead of a decoding traceback.
    """
    if raw.startswith(_UTF8_BOM):
        raw = raw[len(_UTF8_BOM):]
    if raw.startswith(_UTF16_BOMS):
        raise CaseError("toml", source, "is UTF-16 text: save the file as UTF-8 (TOML files are UTF-8)", source)
    if b"\x00" in raw:
        raise CaseError("toml", source, "is a binary file (it holds NUL bytes), not a TOML text file", source)
    try:
        text = raw.decode("utf-8")
    except UnicodeDecodeError as err:
        raise CaseError("toml", source, f"is not UTF-8 text (byte {raw[err.start]:#04x} at offset {err.start}): "
                                        "save the file as UTF-8; Latin-1 or another legacy encoding?", source) from None
    try:  # rtoml (Rust) parses a million-row line ~3x faster than tomllib, and bounds the nesting depth
        return rtoml.loads(text)
    except rtoml.TomlParsingError as err:
        raise CaseError("toml", source, f"is not valid TOML: {err}", source) from None


def read_toml(path: str | Path) -> dict:
    """The TOML document in the file at ``path``; every failure a :class:`CaseError` naming it."""
    return parse_toml(file_bytes(path), str(path))


def read_case(path: str | Path, *, allow_implausible: bool | Sequence[str] | None = None) -> Case:
    """Read a TOML case file (``allow_implausible`` as in :func:`~pymoo_rail.model.case_from_dict`)."""
    return case_from_dict(read_toml(path), source=str(path), allow_implausible=allow_implausible)


def read_train(path: str | Path) -> Train:
    """The train of a TOML file with a ``[train]`` table: a case file, or a file with the train alone."""
    data = read_toml(path)
    if "train" not in data:
        raise CaseError("train", None, "is required: a train file holds a [train] table", str(path))
    return train_from_dict(data["train"], str(path))


def looks_like(head: bytes) -> bool:
    """True when the start of a file reads as a TOML case (a ``name =`` key or a ``[run]`` table)."""
    text = head.lstrip(b"\xef\xbb\xbf").decode("utf-8", errors="ignore")
    return any(line.strip().startswith(("name", "[run]", "[train]", "[line]")) for line in text.splitlines())


def _toml_value(value: Any) -> str:
    if isinstance(value, bool):
        return "true" if value else "false"
    if isinstance(value, str):
        return '"' + value.replace("\\", "\\\\").replace('"', '\\"').replace("\n", "\\n") + '"'
    if isinstance(value, (int, float)):
        return repr(float(value))
    if isinstance(value, dict):
        return "{" + ", ".join(f"{k} = {_toml_value(v)}" for k, v in value.items()) + "}"
    return "[" + ", ".join(_toml_value(v) for v in value) + "]"


def write_case(case: Case, path: str | Path) -> Path:
    """Write a case file that :func:`read_case` reads back to an equal case."""
    data = case_to_dict(case)
    lines: list[str] = []
    for key in ("name", "source", "description", "allow_implausible"):
        if key in data:
            lines.append(f"{key} = {_toml_value(data[key])}")

    def section(title: str, table: dict) -> None:
        lines.append(f"\n[{title}]")
        nested = []
        for k, v in table.items():
            if isinstance(v, dict):
                nested.append((k, v))
            else:
                lines.append(f"{k} = {_toml_value(v)}")
        for k, v in nested:
            section(f"{title}.{k}", v)

    section("run", data["run"])
    section("train", data["train"])
    section("line", data["line"])
    path = Path(path)
    path.write_text("\n".join(lines) + "\n", encoding="utf-8")
    return path
