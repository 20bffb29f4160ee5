"""pymoo problems: the single-train speed profile (and, later, two cooperating trains)."""

from pymoo_rail.problems.encodings import SpeedCodes, SwitchingPoints
from pymoo_rail.problems.speed_profile import OBJECTIVES, SEED_002_WEIGHTS, SpeedProfileProblem, objective_values
from pymoo_rail.sim import Trajectory

__all__ = ["SpeedProfileProblem", "SpeedCodes", "SwitchingPoints", "OBJECTIVES", "SEED_002_WEIGHTS",
           "objective_values", "Trajectory"]
