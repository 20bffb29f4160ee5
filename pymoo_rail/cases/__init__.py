"""Built-in cases and case loading.

>>> from pymoo_rail.cases import load_case, list_cases
>>> case = load_case("yizhuang")
>>> case.line.length_m
2265.0
"""

from __future__ import annotations

import re
from dataclasses import replace
from pathlib import Path

from pymoo_rail.cases.generate import KINDS, generate_case
from pymoo_rail.model import Case, CaseError, read_case

_HERE = Path(__file__).resolve().parent

# Passenger load states of the built-in cases: train mass in t per load name. Liu (2019) table 5-2
# gives the Yizhuang B-type 3M3T train empty (AW0), at the rated load (AW2) and crush-loaded (AW3);
# its traction and braking curves (eqs. 5-1, 5-2) are those of AW0 and are kept for every load.
LOADS_T: dict[str, dict[str, float]] = {
    "yizhuang": {"AW0": 194.295, "AW2": 282.375, "AW3": 307.095},
}


def with_load(case: Case, load: str) -> Case:
    """The case with the train mass of a named load state (``LOADS_T``), named ``"<case>-<load>"``."""
    table = LOADS_T.get(case.name)
    if table is None:
        raise CaseError("load", load, f"case '{case.name}' has no load states (cases with loads: "
                                      f"{', '.join(sorted(LOADS_T))})")
    if load not in table:
        raise CaseError("load", load, f"unknown load of case '{case.name}' (known: {', '.join(table)})")
    base = re.sub(r"\s*\((?:%s)\)$" % "|".join(table), "", case.train.name)  # drop the file's own load tag
    train = replace(case.train, mass_t=table[load], name=f"{base} ({load}, {table[load]} t)")
    return replace(case, name=f"{case.name}-{load}", train=train)


# Sections of the TTOBench Yizhuang line offered by name (the benchmark suite's cases, docs/suite.md):
# departure and arrival stop, planned time in s. TTOBench has no timetable: the planned times are 10 %
# above this model's minimum running time, rounded up to 5 s.
TTOBENCH_SECTIONS: dict[str, tuple[str, str, float]] = {
    "ttobench-songjiazhuang-xiaocun": ("Songjiazhuang", "Xiaocun", 170.0),
    "ttobench-xiaohongmen-jiugong": ("Xiaohongmen", "Jiugong", 145.0),
    "ttobench-wanyuan-rongjing": ("Wanyuan St", "Rongjing East St", 90.0),
}


def list_cases() -> list[str]:
    """Names of the built-in cases: the case files and the TTOBench sections (``TTOBENCH_SECTIONS``)."""
    return sorted([p.stem for p in _HERE.glob("*.toml")] + list(TTOBENCH_SECTIONS))


def case_path(name: str) -> Path:
    """The file of a built-in case (a TTOBench section is read from the shipped TTOBench files)."""
    path = _HERE / f"{name}.toml"
    if not path.is_file():
        raise CaseError("case", name, f"no such built-in case file (built-in: {', '.join(list_cases())})")
    return path


def _ttobench_section(name: str) -> Case:
    from pymoo_rail.cases.ttobench import BEIJING_SUBWAY_TRAIN, YIZHUANG_STOP_NAMES, YIZHUANG_TRACK, from_ttobench

    first, last, planned_time_s = TTOBENCH_SECTIONS[name]
    return from_ttobench(YIZHUANG_TRACK, BEIJING_SUBWAY_TRAIN, first, last, planned_time_s,
                         stop_names=YIZHUANG_STOP_NAMES, name=name)


def load_case(name_or_path: str | Path, load: str | None = None) -> Case:
    """Load a built-in case by name, or any case file by path.

    Parameters
    ----------
    name_or_path : str or Path
        A built-in name from :func:`list_cases` (a case file, or a section of the TTOBench Yizhuang
        line such as ``"ttobench-wanyuan-rongjing"``) or the path of a TOML case file.
    load : str, optional
        A passenger load state of the case (``LOADS_T``), e.g. ``load_case("yizhuang", load="AW3")``:
        the train mass of that load, the rest of the case unchanged.
    """
    candidate = Path(name_or_path)
    if candidate.suffix == ".toml" or candidate.is_file():
        if not candidate.is_file():
            raise CaseError("path", str(candidate), "no such case file")
        from pymoo_rail.cases.railjson import is_railjson_file, read_railjson_file  # OSRD railjson cases

        case = read_railjson_file(candidate) if is_railjson_file(candidate) else read_case(candidate)
    elif str(name_or_path) in TTOBENCH_SECTIONS:
        case = _ttobench_section(str(name_or_path))
    else:
        case = read_case(case_path(str(name_or_path)))
    return case if load is None else with_load(case, load)


def __getattr__(name: str):
    # TTOBench support imports json readers only when asked for
    if name in ("from_ttobench", "to_ttobench"):
        from pymoo_rail.cases import ttobench

        return getattr(ttobench, name)
    if name in ("load_train", "railjson_case"):  # OSRD railjson and any-format trains: cases/railjson.py
        from pymoo_rail.cases import railjson

        return getattr(railjson, name)
    raise AttributeError(f"module 'pymoo_rail.cases' has no attribute {name!r}")


__all__ = ["load_case", "generate_case", "KINDS", "list_cases", "case_path", "with_load", "LOADS_T",
           "TTOBENCH_SECTIONS", "from_ttobench", "to_ttobench", "load_train", "railjson_case"]
