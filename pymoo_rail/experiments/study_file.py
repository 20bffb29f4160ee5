"""Study files: a :class:`Study` as TOML (read with the standard library, written by hand).

Example (``examples/study_zdt.toml``)::

    name = "zdt"
    seeds = [1, 2, 3, 4, 5]
    baseline = "nsga2"

    [budget]
    n_gen = 100

    [[problems]]
    problem = "zdt1"

    [[algorithms]]
    algorithm = "nsga2"
    pop_size = 100
"""

from __future__ import annotations

import json
import sys
from pathlib import Path
from typing import Any

if sys.version_info >= (3, 11):
    import tomllib
else:  # pragma: no cover - Python 3.10
    import tomli as tomllib

from pymoo_rail.experiments.spec import Study, StudyError


def read_study(path: str | Path) -> Study:
    """Load a study from a TOML file; errors name the file, the field and the value."""
    path = Path(path)
    if not path.is_file():
        raise StudyError("path", str(path), "no such study file")
    try:
        data = tomllib.loads(path.read_text(encoding="utf-8"))
    except UnicodeDecodeError as err:
        raise StudyError("toml", str(path), f"not UTF-8 text ({err.reason} at byte {err.start})", str(path)) from None
    except tomllib.TOMLDecodeError as err:
        raise StudyError("toml", str(path), f"not valid TOML: {err}", str(path)) from None
    except RecursionError:
        raise StudyError("toml", str(path), "nested too deeply to be a study file", str(path)) from None
    return Study.from_dict(data, source=str(path))


def _value(value: Any) -> str:
    if isinstance(value, bool):
        return "true" if value else "false"
    if isinstance(value, int):
        return str(value)
    if isinstance(value, float):
        return repr(value)
    if isinstance(value, str):
        return json.dumps(value)  # JSON string escapes are valid TOML basic-string escapes
    if isinstance(value, list):
        return "[" + ", ".join(_value(v) for v in value) + "]"
    if isinstance(value, dict):
        return "{" + ", ".join(f"{_key(k)} = {_value(v)}" for k, v in value.items()) + "}"
    raise TypeError(f"cannot write {type(value).__name__} to TOML: {value!r}")


def _key(key: str) -> str:
    bare = key and all(c.isalnum() or c in "-_" for c in key) and key.isascii()
    return key if bare else json.dumps(key)


def study_to_toml(study: Study) -> str:
    """The TOML text of a study (round-trips through :func:`read_study`)."""
    data = study.to_dict()
    lines = [f"{_key(k)} = {_value(data[k])}" for k in ("name", "seeds", "history", "baseline") if k in data]
    lines += ["", "[budget]"] + [f"{_key(k)} = {_value(v)}" for k, v in data["budget"].items()]
    for section in ("problems", "algorithms"):
        for table in data[section]:
            lines += ["", f"[[{section}]]"] + [f"{_key(k)} = {_value(v)}" for k, v in table.items()]
    return "\n".join(lines) + "\n"


def write_study(study: Study, path: str | Path) -> Path:
    """Write a study file atomically (temp file + rename)."""
    from pymoo_rail.atomic import atomic_write_text

    return atomic_write_text(Path(path), study_to_toml(study))
