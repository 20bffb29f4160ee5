"""Built-in cases and case loading.

>>> from pymoo_rail.cases import load_case, list_cases
>>> case = load_case("yizhuang")
>>> case.line.length_m
2265.0
"""

from __future__ import annotations

from pathlib import Path

from pymoo_rail.model import Case, CaseError, read_case

_HERE = Path(__file__).resolve().parent


def list_cases() -> list[str]:
    """Names of the built-in cases."""
    return sorted(p.stem for p in _HERE.glob("*.toml"))


def case_path(name: str) -> Path:
    """The file of a built-in case."""
    path = _HERE / f"{name}.toml"
    if not path.is_file():
        raise CaseError("case", name, f"no such built-in case (built-in: {', '.join(list_cases())})")
    return path


def load_case(name_or_path: str | Path) -> Case:
    """Load a built-in case by name, or any case file by path.

    Parameters
    ----------
    name_or_path : str or Path
        A built-in name from :func:`list_cases` or the path of a TOML case file.
    """
    candidate = Path(name_or_path)
    if candidate.suffix == ".toml" or candidate.is_file():
        if not candidate.is_file():
            raise CaseError("path", str(candidate), "no such case file")
        return read_case(candidate)
    return read_case(case_path(str(name_or_path)))


def __getattr__(name: str):
    # TTOBench support imports json readers only when asked for
    if name in ("from_ttobench", "to_ttobench"):
        from pymoo_rail.cases import ttobench

        return getattr(ttobench, name)
    raise AttributeError(f"module 'pymoo_rail.cases' has no attribute {name!r}")


__all__ = ["load_case", "list_cases", "case_path", "from_ttobench", "to_ttobench"]
