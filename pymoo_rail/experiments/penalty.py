"""Constraints as a penalty, for pymoo algorithms that refuse constrained problems (MOEA/D).

pymoo's MOEA/D asserts that the problem has no constraints, and every rail problem has some
(speed limits, the stop at the platform, a running-time window or tolerance). Wrapped in
:class:`PenalisedConstraints`, the problem has none: each objective gets ``penalty`` times the
total constraint violation added. The algorithm then searches the penalised objectives; what is
reported of its result must be evaluated again on the problem itself (its true objectives and
violations), as :func:`pymoo_rail.experiments.optimize.optimize_profile` does.
"""

from __future__ import annotations

import sys

import numpy as np
from pymoo.constraints.as_penalty import ConstraintsAsPenalty
from pymoo.core.individual import calc_cv

DEFAULT_PENALTY = 100.0
"""Added to every objective per unit of total constraint violation (m/s, m and s of the rail constraints)."""


class PenalisedConstraints(ConstraintsAsPenalty):
    """pymoo's ``ConstraintsAsPenalty`` for any number of objectives: the violation is added to each.

    pymoo 0.6.2's class reshapes the violation (one value per row) to the shape of ``F`` and so
    works for one objective only; here it is broadcast over the objectives.

    Parameters
    ----------
    problem : pymoo Problem
        The constrained problem (not modified).
    penalty : float
        What one unit of total constraint violation adds to every objective.
    """

    def __init__(self, problem, penalty: float = DEFAULT_PENALTY):
        if not (np.isfinite(penalty) and penalty > 0):
            raise ValueError(f"penalty = {penalty!r} must be a positive finite number")
        super().__init__(problem, penalty)

    def do(self, X, return_values_of, *args, **kwargs):
        """Evaluate the wrapped problem and add the penalty to every objective; no constraints remain."""
        out = self.__object__.do(X, return_values_of, *args, **kwargs)
        F, G, H = out["F"], out.get("G"), out.get("H")
        out["__F__"], out["__G__"], out["__H__"] = F, G, H  # as pymoo's class keeps them
        violation = np.reshape(calc_cv(G=G, H=H), (len(F), 1))
        out["F"] = F + self.penalty * violation
        out.pop("G", None)
        out.pop("H", None)
        return out


def handles_constraints(algorithm) -> bool:
    """False for an algorithm that refuses constrained problems: pymoo's MOEA/D (it asserts on them)."""
    # not imported, no instance of it exists: the main job does not pay for importing MOEA/D
    moead = sys.modules.get("pymoo.algorithms.moo.moead")
    return moead is None or not isinstance(algorithm, moead.MOEAD)
