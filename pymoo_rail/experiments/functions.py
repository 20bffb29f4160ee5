"""Single-objective test functions on the domains of Liu (2019) section 3.5 (eqs. 3-6 to 3-8).

pymoo's ``Griewank`` ([-600, 600]) and ``Rosenbrock`` ([-2.048, 2.048]) already use the seed's
domains; pymoo's ``Sphere`` is ``sum (x - 0.5)^2`` on [0, 1], so the seed's sphere
``sum x^2`` on [-100, 100] is defined here. Every class knows its optimum (0).
"""

from __future__ import annotations

import numpy as np
from pymoo.core.problem import Problem
from pymoo.problems.single.griewank import Griewank
from pymoo.problems.single.rosenbrock import Rosenbrock


class Sphere(Problem):
    """``f(x) = sum x_i^2`` on [-100, 100]^n (Liu (2019) eq. 3-6); minimum 0 at the origin."""

    def __init__(self, n_var: int = 10) -> None:
        super().__init__(n_var=n_var, n_obj=1, xl=-100.0, xu=100.0, vtype=float)

    def _evaluate(self, x, out, *args, **kwargs):
        out["F"] = np.sum(x * x, axis=1)

    def _calc_pareto_front(self, *args, **kwargs):
        return np.zeros((1, 1))

    def _calc_pareto_set(self, *args, **kwargs):
        return np.zeros(self.n_var)


__all__ = ["Sphere", "Griewank", "Rosenbrock"]
