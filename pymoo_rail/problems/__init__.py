"""pymoo problems: the single-train speed profile, two cooperating trains (Chen et al. 2017), a timetable.

Names load on first use, so reading the objective table (:mod:`pymoo_rail.problems.objectives`)
or the encoding names (:mod:`pymoo_rail.problems.encodings`) costs neither Numba nor pymoo.
"""

from __future__ import annotations

from pymoo_rail.problems.lazy import lazy_names

# public name -> module of this package that defines it
_MODULE_OF = {
    "CooperativeTrainsProblem": "cooperative",
    "SpeedCodes": "encodings", "SwitchingPoints": "encodings", "BrakingOnset": "encodings", "PacedCodes": "encodings",
    "overrun_case": "encodings",
    "KinematicPhasesProblem": "phases", "phase_runs": "phases",
    "Objective": "objectives", "OBJECTIVE_TABLE": "objectives", "canonical_objective": "objectives",
    "objective_names": "objectives", "get_objective": "objectives",
    "OBJECTIVES": "speed_profile", "OBJECTIVE_ALIASES": "speed_profile", "SEED_002_WEIGHTS": "speed_profile",
    "ConstantObjectiveWarning": "speed_profile", "DecisionError": "speed_profile",
    "SpeedProfileProblem": "speed_profile", "check_decisions": "speed_profile", "objective_values": "speed_profile",
    "TimetableProblem": "timetable",
    "ControllerTuningProblem": "controller_tuning",
    "Trajectory": "speed_profile",
}

__all__ = list(_MODULE_OF)


__getattr__, __dir__ = lazy_names(__name__, _MODULE_OF, __all__)
