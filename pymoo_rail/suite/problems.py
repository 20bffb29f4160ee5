"""The named problems of the benchmark suite: which case, which form, which encoding.

Every case gives two problems: ``<case>-bi``, energy and running time inside the planner's
running-time window (:func:`pymoo_rail.optimal.reference.default_window`), whose Pareto front is
the certified front of the exact solver; and ``<case>-single``, energy under
``|T - T_plan| <= 1 % of T_plan`` (at least 1 s), whose optimum is the front's least energy in that
window; its decisions are paced speed codes (a shape per section and the running time inside the
window, :mod:`pymoo_rail.problems.encodings.paced_codes`), so every decision vector is on time.
``metro-a-4obj`` is the four-objective metro form of Meng et al. (2017) (energy, time error, jerk,
stop error) with ``encoding="braking_onset"``, so that the stop error varies: no exact front
exists; a best-known front is offered, labelled as such. :data:`SUITE_VERSION` says which forms
changed when.
"""

from __future__ import annotations

from dataclasses import dataclass
from functools import lru_cache

from pymoo_rail.cases import load_case
from pymoo_rail.model import Case
from pymoo_rail.problems.encodings import encoding_settings
from pymoo_rail.optimal.reference import PUNCTUAL_TOLERANCE_REL, punctual_tolerance_s

TOLERANCE_REL = PUNCTUAL_TOLERANCE_REL
"""Running-time tolerance of the single-objective forms, relative to the planned time (the fronts'
punctuality window, :data:`pymoo_rail.optimal.reference.PUNCTUAL_TOLERANCE_REL`)."""
SECTIONS_PER_LINE = 12
"""Speed-code sections of a suite problem: gradient/limit sections split to at most length / 12."""


@dataclass(frozen=True)
class SuiteCase:
    """One case of the suite: a built-in case (a case file, or a section of the TTOBench Yizhuang line).

    Attributes
    ----------
    name : str
        Suite name of the case, a built-in case name (:func:`pymoo_rail.cases.load_case` loads it;
        the problems are ``<name>-bi`` and ``<name>-single``).
    summary : str
        One line on what the case is, for ``list_problems`` and the docs.
    """

    name: str
    summary: str

    def load(self) -> Case:
        """The case itself."""
        return load_case(self.name)


_TTOBENCH_PLAN = ("planned time reconstructed: 10 % above the minimum running time of this model, "
                  "rounded up to 5 s (TTOBench has no timetable)")

CASES: tuple[SuiteCase, ...] = (
    SuiteCase("yizhuang", "Beijing Yizhuang line, Tongjinan Rd -> Jinghai Rd, 2265 m, 150 s "
              "(Liu 2019, seed data of the ABC thesis)"),
    SuiteCase("yizhuang-ttobench", "the same run with TTOBench's line and Beijing subway train, 150 s"),
    SuiteCase("metro-a", "A-type metro, 1000 m, -5 / +10 permille, 70 s (Meng et al. 2017)"),
    SuiteCase("ttobench-songjiazhuang-xiaocun", "TTOBench Yizhuang line, Songjiazhuang -> Xiaocun, 2631 m, "
              "+10.4 / -8 permille, 170 s; " + _TTOBENCH_PLAN),
    SuiteCase("ttobench-xiaohongmen-jiugong", "TTOBench Yizhuang line, Xiaohongmen -> Jiugong, 2366 m, "
              "-20.4 / -24 permille descents, 145 s; " + _TTOBENCH_PLAN),
    SuiteCase("ttobench-wanyuan-rongjing", "TTOBench Yizhuang line, Wanyuan St -> Rongjing East St, 1280 m, 90 s; "
              + _TTOBENCH_PLAN),
    SuiteCase("ttobench-ref", "48.5 km TTOBench reference, level, 100 km/h on 25-35 km, 391 t intercity, 1541 s "
              "(reconstructed from the public TTOBench reference)"),
    SuiteCase("ttobench-ref-uphill", "the reference with a +5 permille climb on 25-35 km"),
    SuiteCase("ttobench-ref-downhill", "the reference with a -5 permille descent on 25-35 km"),
    SuiteCase("ttobench-ref-limit120", "the reference with 120 km/h (not 100) on 25-35 km"),
)

SINGLE_ENCODING = "paced_speed_codes"
"""Encoding of the ``-single`` forms (:mod:`pymoo_rail.problems.encodings.paced_codes`)."""
SUITE_VERSION = "2"
"""Version of the suite's problem forms; bumped whenever a form changes what an optimiser searches.

1. First release: ``-single`` forms on speed codes with a 1 % running-time constraint.
2. ``-single`` forms on paced speed codes (a shape per section and the running time inside the
   tolerance window; every vector on time). ``metro-a-4obj``'s best-known front version 3 (runs
   of seeds 101-105). The ``-bi`` forms, ``metro-a-4obj``'s form and every certified front and
   optimum are unchanged.
"""

METRO_4OBJ = "metro-a-4obj"
METRO_4OBJ_OBJECTIVES = ("energy", "time_error", "jerk", "stop_error")
METRO_4OBJ_ENCODING = "braking_onset"


@lru_cache(maxsize=None)
def _cases() -> dict[str, SuiteCase]:
    return {c.name: c for c in CASES}


def list_problems() -> list[str]:
    """Names of the suite's problems (``<case>-bi``, ``<case>-single`` and ``metro-a-4obj``)."""
    names = []
    for c in CASES:
        names += [f"{c.name}-bi", f"{c.name}-single"]
    return names + [METRO_4OBJ]


def split(name: str) -> tuple[SuiteCase, str]:
    """The suite case and the form (``"bi"``, ``"single"`` or ``"4obj"``) of a problem name."""
    if not isinstance(name, str):
        raise ValueError(f"problem name {name!r}: must be a string (see list_problems())")
    if name == METRO_4OBJ:
        return _cases()["metro-a"], "4obj"
    base, _, form = name.rpartition("-")
    if form not in ("bi", "single") or base not in _cases():
        raise ValueError(f"problem name {name!r} is unknown (known: {', '.join(list_problems())})")
    return _cases()[base], form


def suite_case(name: str) -> Case:
    """The case behind a problem name (or a suite case name)."""
    if name in _cases():
        return _cases()[name].load()
    return split(name)[0].load()


def tolerance_s(case: Case) -> float:
    """Running-time tolerance of the single-objective form: 1 % of the planned time, at least 1 s."""
    return punctual_tolerance_s(case.planned_time_s)


def get_problem(name: str, **kwargs):
    """A suite problem by name, in pymoo's style (``pymoo.problems.get_problem``).

    Parameters
    ----------
    name : str
        One of :func:`list_problems`.
    **kwargs
        Passed on to :class:`~pymoo_rail.problems.SpeedProfileProblem` (e.g. ``encoding``);
        they override the suite's defaults, and the problem is then no longer the suite's.

    Returns
    -------
    SpeedProfileProblem
        With ``suite_name`` and ``suite_version`` (:data:`SUITE_VERSION`) set.
        ``problem.pareto_front()`` is the certified front (``-bi``), the certified optimum
        (``-single``); ``metro-a-4obj`` raises :class:`~pymoo_rail.optimal.reference.NoExactFrontError`
        and :func:`pymoo_rail.suite.best_known_front` gives its best-known front.
    """
    from pymoo_rail.problems import SpeedProfileProblem

    entry, form = split(name)
    case = entry.load()
    settings = dict(encoding="speed_codes", partition="gradient_limit",
                    max_section_m=case.line.length_m / SECTIONS_PER_LINE)
    if form == "bi":
        settings.update(objectives=("energy", "running_time"), time_window_s="default")
    elif form == "single":
        # paced: the running time is a decision inside the tolerance window, every vector on time (suite version 2)
        settings.update(objectives=("energy",), time_tolerance_s=tolerance_s(case), encoding=SINGLE_ENCODING)
    else:
        # the phases of Meng et al. (2017) with the braking onset as a decision: the only encoding
        # under which the stop error varies (speed codes always stop at the platform)
        settings.update(objectives=METRO_4OBJ_OBJECTIVES, encoding=METRO_4OBJ_ENCODING)
    settings.update(kwargs)
    if isinstance(settings["encoding"], str):  # the sections above are for the encodings that have sections
        taken = encoding_settings(settings["encoding"])
        settings = {k: v for k, v in settings.items() if k not in ("partition", "max_section_m") or k in taken
                    or k in kwargs}
    problem = SpeedProfileProblem(case, **settings)
    problem.suite_name = name
    problem.suite_version = SUITE_VERSION
    return problem
