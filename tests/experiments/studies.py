"""Study declarations shared by the experiment tests (importable from a subprocess)."""

from __future__ import annotations

import numpy as np
from numba import njit, prange

from pymoo_rail.experiments import Study, algorithm, problem


def small_study(n_gen: int = 8, name: str = "zdt-small") -> Study:
    """The done-when study of issue 5 (3 problems x 3 algorithms x 5 seeds) with tiny budgets."""
    return Study(
        name,
        problems=[problem("zdt1", n_var=8), problem("zdt2", n_var=8), problem("zdt3", n_var=8)],
        algorithms=[algorithm("nsga2", pop_size=12), algorithm("moead", pop_size=12),
                    algorithm("sms-emoa", pop_size=12)],
        seeds=[1, 2, 3, 4, 5],
        budget={"n_gen": n_gen},
        baseline="nsga2",
    )


def slow_zdt1(n_var: int = 4, delay_s: float = 0.0):
    """pymoo's ZDT1, built after ``delay_s`` seconds (so runs overlap in the concurrency tests).

    When the environment names a log file (``PYMOO_RAIL_TEST_LOG``), each build appends one line:
    the tests count computations with it.
    """
    import os
    import time

    from pymoo.problems import get_problem

    log = os.environ.get("PYMOO_RAIL_TEST_LOG")
    if log:
        with open(log, "a", encoding="utf-8") as handle:
            handle.write(f"{os.getpid()}\n")
    time.sleep(delay_s)
    return get_problem("zdt1", n_var=n_var)


def case_sphere(case: str, n_var: int = 3):
    """A cheap problem whose optimum depends on a case's content: the sphere centred at
    ``mass_t / 1000`` in every variable (its front moves when the case file is edited)."""
    import numpy as np
    from pymoo.core.problem import Problem

    from pymoo_rail.cases import load_case

    centre = load_case(case).train.mass_t / 1000.0

    class CaseSphere(Problem):
        def __init__(self):
            super().__init__(n_var=n_var, n_obj=2, xl=-1.0, xu=1.0)

        def _evaluate(self, x, out, *args, **kwargs):
            out["F"] = np.column_stack([np.sum((x - centre) ** 2, axis=1), np.sum((x + centre) ** 2, axis=1)])

    return CaseSphere()



@njit(parallel=True, cache=True)
def parallel_spheres(x):
    """The two sphere objectives of each row of ``x``, on Numba's threads (cached on disk)."""
    out = np.empty((x.shape[0], 2))
    for i in prange(x.shape[0]):
        out[i, 0] = np.sum((x[i] - 0.5) ** 2)
        out[i, 1] = np.sum((x[i] + 0.5) ** 2)
    return out


def jitted_sphere(n_var: int = 3):
    """A two-objective sphere as a study worker meets Numba: a kernel loaded from the disk cache runs
    on Numba's threads first, then a function is compiled in the worker (no cache)."""
    from pymoo.core.problem import Problem

    @njit(cache=False)
    def doubled(f):
        return 2.0 * f

    class JittedSphere(Problem):
        def __init__(self):
            super().__init__(n_var=n_var, n_obj=2, xl=-1.0, xu=1.0)

        def _evaluate(self, x, out, *args, **kwargs):
            out["F"] = 0.5 * doubled(parallel_spheres(x))

    return JittedSphere()
