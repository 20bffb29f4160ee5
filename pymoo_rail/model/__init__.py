"""Train, line and case data (railway units in the files, SI inside the kernels)."""

from pymoo_rail.model.case import END_SPEED_TOL_MS, Case, Leg
from pymoo_rail.model.curves import DavisResistance, ForceCurve
from pymoo_rail.model.efficiency import EfficiencyMap
from pymoo_rail.model.errors import CaseError, InfeasibleCaseError
from pymoo_rail.model.grid import TrackGrid, build_grid
from pymoo_rail.model.line import Line
from pymoo_rail.model.schema import case_from_dict, case_keys, case_to_dict, train_from_dict
from pymoo_rail.model.train import GRAVITY_MS2, Train

__all__ = ["Case", "Leg", "Train", "Line", "ForceCurve", "DavisResistance", "EfficiencyMap", "CaseError", "InfeasibleCaseError",
           "TrackGrid", "build_grid", "case_from_dict", "case_to_dict", "case_keys", "train_from_dict",
           "GRAVITY_MS2", "END_SPEED_TOL_MS"]
