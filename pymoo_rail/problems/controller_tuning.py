"""Tuning controller gains with pymoo on a training set of disturbed trains (a fair PID vs fuzzy PID study).

:class:`ControllerTuningProblem` scores a gain vector by the mean tracking error (rms of speed minus
reference over the controlled part, km/h) of the disturbed trains of a training set
(:func:`pymoo_rail.control.draw_disturbances`); every controller family gets the same objective, the
same training set and, in a study, the same search budget. The reference curve is any
:class:`~pymoo_rail.sim.Trajectory`; ``reference="table3"`` builds the physical run of table 3 of
Meng et al. (2017) (:func:`table3_reference`).
"""

from __future__ import annotations

from functools import lru_cache

import numpy as np
from pymoo.core.problem import Problem

from pymoo_rail.control.controllers import PID, FuzzyPID
from pymoo_rail.control.disturbances import draw_disturbances, track_disturbed
from pymoo_rail.model import Case
from pymoo_rail.problems.speed_profile import SpeedProfileProblem
from pymoo_rail.sim import Trajectory
from pymoo_rail.sim import kernel as k

# Gain bounds (PID units: 1/(km/h), 1/(km/h s), s/(km/h)); the fuzzy tuner adds its three increment scales.
PID_BOUNDS = {"kp": (0.01, 2.0), "ki": (0.0, 0.5), "kd": (0.0, 0.5)}
FUZZY_BOUNDS = {**PID_BOUNDS, "dkp": (0.0, 1.0), "dki": (0.0, 0.1), "dkd": (0.0, 0.2)}
FAMILIES = ("pid", "fuzzy_pid")
TABLE3 = {"running_time_s": 68.87, "peak_kmh": 75.89, "stop_m": 1000.18}  # Meng et al. (2017) table 3


def controller_from_gains(family: str, x: np.ndarray):
    """A :class:`PID` or :class:`FuzzyPID` from a gain vector of this module's bounds."""
    x = np.asarray(x, dtype=float)
    names = list(PID_BOUNDS if family == "pid" else FUZZY_BOUNDS)
    if family not in FAMILIES:
        raise ValueError(f"family = {family!r} is unknown (known: {', '.join(FAMILIES)})")
    if x.shape != (len(names),):
        raise ValueError(f"gains have {x.shape} values: {family} needs {len(names)} ({', '.join(names)})")
    gains = dict(zip(names, (float(v) for v in x)))
    return PID(**gains) if family == "pid" else FuzzyPID(**gains)


@lru_cache(maxsize=4)
def _table3_reference(case: Case) -> tuple[Trajectory, tuple[float, ...]]:
    from pymoo.algorithms.soo.nonconvex.de import DE
    from pymoo.optimize import minimize

    p = SpeedProfileProblem(case, objectives=("energy",), encoding="braking_onset", stop_tolerance_m=None)

    class _Fit(Problem):
        def __init__(self):
            super().__init__(n_var=p.n_var, n_obj=1, xl=p.xl, xu=p.xu)

        def _evaluate(self, x, out, *args, **kwargs):
            s = p.summaries(x)
            t_err = s[:, k.OUT_RUNNING_TIME_S] - TABLE3["running_time_s"]
            x_err = s[:, k.OUT_STOP_POSITION_M] - TABLE3["stop_m"]
            out["F"] = (t_err ** 2 + x_err ** 2 + 100.0 * s[:, k.OUT_LIMIT_EXCESS_MS])[:, None]

    res = minimize(_Fit(), DE(pop_size=40), ("n_gen", 100), seed=1)
    return p.trajectory(res.X), tuple(float(v) for v in res.X)


def table3_reference(case: Case) -> Trajectory:
    """The run of the metro case closest to table 3 of Meng et al. (2017) on the physical model.

    Traction, cruise, coast and braking at a chosen deceleration (``encoding="braking_onset"``),
    fitted by pymoo's DE (seed 1) to the table's running time (68.87 s) and stop position
    (1000.18 m). The paper's printed phase lengths do not fit its own accelerations
    (``benchmarks/reports/metro_table3.md``), so this run is the table's outcome, not its lengths.
    """
    return _table3_reference(case)[0]


class ControllerTuningProblem(Problem):
    """Gains of a controller family tuned for the mean tracking error over disturbed trains.

    Parameters
    ----------
    case : Case
    family : {"pid", "fuzzy_pid"}
    reference : Trajectory or "table3"
        The curve to track.
    n_train : int
        Training scenarios, drawn by :func:`draw_disturbances` with ``train_seed``.
    control_period_s : float
    """

    def __init__(self, case: Case, family: str = "pid", reference: Trajectory | str = "table3", n_train: int = 8,
                 train_seed: int = 0, control_period_s: float = 0.2, **kwargs):
        if family not in FAMILIES:
            raise ValueError(f"family = {family!r} is unknown (known: {', '.join(FAMILIES)})")
        if isinstance(reference, str):
            if reference != "table3":
                raise ValueError(f"reference = {reference!r}: give a Trajectory or 'table3'")
            reference = table3_reference(case)
        self.case = case
        self.family = family
        self.reference = reference
        self.control_period_s = float(control_period_s)
        self.training = draw_disturbances(n_train, train_seed)
        bounds = PID_BOUNDS if family == "pid" else FUZZY_BOUNDS
        xl = np.array([b[0] for b in bounds.values()])
        xu = np.array([b[1] for b in bounds.values()])
        super().__init__(n_var=xl.size, n_obj=1, xl=xl, xu=xu, **kwargs)

    def cost(self, x: np.ndarray) -> float:
        """Mean rms tracking error (km/h, controlled part) over the training set."""
        controller = controller_from_gains(self.family, x)
        errors = [track_disturbed(self.case, self.reference, controller, d, self.control_period_s)
                  .summary["control_error_rms_kmh"] for d in self.training]
        return float(np.mean(errors))

    def _evaluate(self, x, out, *args, **kwargs):
        out["F"] = np.array([[self.cost(xi)] for xi in np.atleast_2d(x)])


def tune_controller(case: Case, family: str, reference: Trajectory, n_train: int = 4, pop_size: int = 10,
                    n_gen: int = 10, seed: int = 1):
    """Gains of ``family`` tuned on ``reference`` by pymoo's DE (mean rms tracking error over disturbed trains).

    The same training set and budget for every family (:class:`ControllerTuningProblem`), so a
    study compares the families fairly. Returns the :class:`PID` or :class:`FuzzyPID` of the best gains.
    """
    from pymoo.algorithms.soo.nonconvex.de import DE
    from pymoo.optimize import minimize

    problem = ControllerTuningProblem(case, family, reference=reference, n_train=n_train)
    result = minimize(problem, DE(pop_size=pop_size), ("n_gen", n_gen), seed=seed)
    return controller_from_gains(family, np.asarray(result.X, dtype=float))
