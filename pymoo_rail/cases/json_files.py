"""Reading the JSON object of a data file (TTOBench, OSRD railjson) with errors that name the file."""

from __future__ import annotations

import json
from collections.abc import Mapping
from pathlib import Path
from typing import Union

from pymoo_rail.model import CaseError

Source = Union[str, Path, Mapping]


def load_json_object(source: Source, label: str) -> tuple[dict, str]:
    """The parsed JSON object of a file (or a mapping, as is) and a label for error messages.

    Parameters
    ----------
    source : str, Path or Mapping
        The file, or its already parsed content.
    label : str
        What the file is, for messages (``"TTOBench train"``, ``"railjson infrastructure"``).

    Raises
    ------
    CaseError
        The file cannot be read, is not JSON or does not hold a JSON object.
    """
    if isinstance(source, Mapping):
        return dict(source), f"<{label} dict>"
    path = Path(source)
    try:
        text = path.read_text(encoding="utf-8")
    except OSError as err:
        raise CaseError("<file>", str(path), f"cannot read the {label} file: {err.strerror}", str(path)) from None
    try:
        data = json.loads(text)
    except json.JSONDecodeError as err:
        raise CaseError("<file>", str(path), f"is not valid JSON: {err}", str(path)) from None
    if not isinstance(data, dict):
        raise CaseError("<file>", str(path), f"a {label} file must hold a JSON object", str(path))
    return data, str(path)


__all__ = ["load_json_object", "Source"]
