"""A benchmark suite of rail problems with certified exact fronts, in pymoo's style.

>>> from pymoo_rail.suite import get_problem, list_problems
>>> problem = get_problem("yizhuang-bi")        # energy and running time, the planner's window
>>> pf = problem.pareto_front()                 # the certified front (shipped, or cached on disk)
>>> problem = get_problem("generated-metro-bi", n_var=300, seed=7)   # a seeded, scalable family instance
>>> bounded = get_problem("generated-metro-3obj", n_var=30, seed=1).bounded_front()  # energy, time, comfort

See ``docs/suite.md`` for the problems, how their fronts were computed and how exact they are.
"""

from pymoo_rail.optimal.reference import CertifiedFront, NoExactFrontError
from pymoo_rail.suite.comfort import COMFORT_OBJECTIVES, BoundedFront, comfort_floor_ms2
from pymoo_rail.suite.families import (
    FAMILIES,
    FAMILY_VERSION,
    Family,
    FamilyProblem,
    get_problem,
    list_families,
)
from pymoo_rail.suite.fronts_io import best_known_front, compute_best_known_front, verify
from pymoo_rail.suite.coco_logger import COCOLogger
from pymoo_rail.suite.ioh_logger import IOHLogger
from pymoo_rail.suite.problems import (
    CASES,
    SUITE_VERSION,
    SuiteCase,
    list_problems,
    suite_case,
    tolerance_s,
)

__all__ = ["get_problem", "list_problems", "list_families", "Family", "FamilyProblem", "FAMILIES", "FAMILY_VERSION",
           "BoundedFront", "COMFORT_OBJECTIVES", "comfort_floor_ms2",
           "IOHLogger", "COCOLogger",
           "suite_case", "tolerance_s", "CASES", "SUITE_VERSION", "SuiteCase",
           "verify", "best_known_front", "compute_best_known_front", "CertifiedFront", "NoExactFrontError"]
