"""pymoo problems: the single-train speed profile, two cooperating trains (Chen et al. 2017), a timetable."""

from pymoo_rail.problems.cooperative import CooperativeTrainsProblem
from pymoo_rail.problems.encodings import SpeedCodes, SwitchingPoints
from pymoo_rail.problems.speed_profile import (
    OBJECTIVES,
    SEED_002_WEIGHTS,
    DecisionError,
    SpeedProfileProblem,
    check_decisions,
    objective_values,
)
from pymoo_rail.problems.timetable import TimetableProblem
from pymoo_rail.sim import Trajectory

__all__ = ["SpeedProfileProblem", "CooperativeTrainsProblem", "TimetableProblem", "SpeedCodes", "SwitchingPoints",
           "OBJECTIVES", "SEED_002_WEIGHTS", "objective_values", "Trajectory", "DecisionError", "check_decisions"]
