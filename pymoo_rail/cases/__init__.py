"""Built-in cases and case loading: one reader module per file format behind :func:`load_case`.

The formats are registered in :mod:`pymoo_rail.cases.formats` (TOML: :mod:`~pymoo_rail.cases.toml_case`,
TTOBench: :mod:`~pymoo_rail.cases.ttobench`, written back by :mod:`~pymoo_rail.cases.ttobench_writer`);
:func:`load_case` picks one by the file's suffix or content.

>>> from pymoo_rail.cases import load_case, list_cases
>>> case = load_case("yizhuang")
>>> case.line.length_m
2265.0
"""

from __future__ import annotations

import re
from collections.abc import Sequence
from dataclasses import replace
from pathlib import Path

from pymoo_rail.cases.formats import FORMATS, call_reader, format_of
from pymoo_rail.cases.generate import KINDS, generate_case
from pymoo_rail.cases.railjson import railjson_case
from pymoo_rail.cases.toml_case import read_case, write_case
from pymoo_rail.cases.ttobench import BEIJING_SUBWAY_TRAIN, YIZHUANG_STOP_NAMES, YIZHUANG_TRACK, from_ttobench
from pymoo_rail.cases.ttobench_writer import to_ttobench
from pymoo_rail.model import Case, CaseError, Train

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
    first, last, planned_time_s = TTOBENCH_SECTIONS[name]
    return from_ttobench(YIZHUANG_TRACK, BEIJING_SUBWAY_TRAIN, first, last, planned_time_s,
                         stop_names=YIZHUANG_STOP_NAMES, name=name)


def load_case(name_or_path: str | Path, load: str | None = None, *,
              allow_implausible: bool | Sequence[str] | None = None, **options) -> Case:
    """Load a built-in case by name, or any case file by path.

    Parameters
    ----------
    name_or_path : str or Path
        A built-in name from :func:`list_cases` (a case file, or a section of the TTOBench Yizhuang
        line such as ``"ttobench-wanyuan-rongjing"``) or the path of a case file in any format of
        :data:`~pymoo_rail.cases.formats.FORMATS`, found by suffix or content: a TOML case file, or
        a TTOBench track with ``train=``, ``planned_time_s=`` and optionally ``from_stop=``,
        ``to_stop=`` (default: first to last stop) and the other keywords of :func:`from_ttobench`.
    load : str, optional
        A passenger load state of the case (``LOADS_T``), e.g. ``load_case("yizhuang", load="AW3")``:
        the train mass of that load, the rest of the case unchanged.
    allow_implausible : bool or sequence of str, optional
        Waive the plausibility bounds (``True``) or some kinds of them (``["gradient"]``) for a
        research case; replaces the file's own ``allow_implausible`` key when given
        (``docs/case-format.md``).
    **options
        Keywords of the format's reader (a TTOBench track's ``train=``, ``planned_time_s=``, ...).
    """
    candidate = Path(name_or_path)
    if candidate.suffix.lower() in {s for f in FORMATS for s in f.suffixes} or candidate.is_file():
        if not candidate.is_file():
            raise CaseError("path", str(candidate), "no such case file")
        fmt = format_of(candidate)
        case = call_reader(fmt.read_case, fmt.name, candidate, allow_implausible=allow_implausible, **options)
    elif options:
        raise CaseError("options", sorted(options), f"'{name_or_path}' is a built-in case: it takes no reader "
                                                    "options (they are for files of other formats)")
    elif str(name_or_path) in TTOBENCH_SECTIONS:
        case = _ttobench_section(str(name_or_path))
    else:
        case = read_case(case_path(str(name_or_path)), allow_implausible=allow_implausible)
    return case if load is None else with_load(case, load)


def load_train(path: str | Path, **options) -> Train:
    """The train of a file in any format of :data:`~pymoo_rail.cases.formats.FORMATS`: the
    ``[train]`` table of a TOML file (a case, or the train alone), a TTOBench train file
    (``train_length_m=`` as in :func:`from_ttobench`; efficiencies given as loss tables become
    efficiency maps and auxiliary power), or an OSRD railjson rolling stock (``mode=``,
    ``comfort=``; docs/railjson.md). A train meets the plausibility bounds when it joins a case."""
    path = Path(path)
    if not path.is_file():
        raise CaseError("path", str(path), "no such train file")
    fmt = format_of(path)
    return call_reader(fmt.read_train, fmt.name, path, **options)


__all__ = ["load_case", "generate_case", "KINDS", "list_cases", "case_path", "with_load", "LOADS_T",
           "TTOBENCH_SECTIONS", "from_ttobench", "to_ttobench", "read_case", "write_case", "FORMATS", "format_of",
           "load_train", "railjson_case"]
