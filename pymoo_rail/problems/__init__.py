"""pymoo problems: the single-train speed profile, two cooperating trains (Chen et al. 2017), a timetable."""

from pymoo_rail.problems.cooperative import CooperativeTrainsProblem
from pymoo_rail.problems.encodings import BrakingOnset, SpeedCodes, SwitchingPoints, overrun_case
from pymoo_rail.problems.phases import KinematicPhasesProblem, phase_runs
from pymoo_rail.problems.speed_profile import (
    OBJECTIVE_ALIASES,
    OBJECTIVES,
    SEED_002_WEIGHTS,
    ConstantObjectiveWarning,
    DecisionError,
    SpeedProfileProblem,
    canonical_objective,
    check_decisions,
    objective_values,
)
from pymoo_rail.problems.timetable import TimetableProblem
from pymoo_rail.sim import Trajectory

__all__ = ["SpeedProfileProblem", "CooperativeTrainsProblem", "SpeedCodes", "SwitchingPoints", "BrakingOnset",
           "overrun_case", "ConstantObjectiveWarning", "KinematicPhasesProblem", "phase_runs", "OBJECTIVES",
           "OBJECTIVE_ALIASES", "canonical_objective", "SEED_002_WEIGHTS", "objective_values", "Trajectory",
           "DecisionError", "check_decisions", "TimetableProblem"]
