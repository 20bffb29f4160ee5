"""One optimisation of a speed profile, end to end: what ``pymoo-rail optimize`` does, for scripts too.

>>> from pymoo.algorithms.moo.nsga2 import NSGA2
>>> from pymoo_rail.cases import load_case
>>> from pymoo_rail.problems import SpeedProfileProblem
>>> from pymoo_rail.experiments.optimize import optimize_profile
>>> problem = SpeedProfileProblem(load_case("yizhuang"), time_window_s="default")   # doctest: +SKIP
>>> result = optimize_profile(problem, NSGA2(pop_size=40), ("n_gen", 50), seed=1)    # doctest: +SKIP
>>> result.front.head(), result.trajectory.energy.net_kwh, result.optimum.message     # doctest: +SKIP

The pipeline: run pymoo's ``minimize``; keep one member per objective vector
(:func:`~pymoo_rail.experiments.fronts.distinct_front`); simulate every member and sort the
front by running time, then energy; pick the member to show with the one rule
(:func:`~pymoo_rail.experiments.fronts.choose_member`); compare it with the certified optimum
at its own running time (the gap in kWh and the optimal run at that time).
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any, Callable, Sequence

import numpy as np
import pandas as pd
from pymoo.core.evaluator import Evaluator
from pymoo.core.population import Population
from pymoo.optimize import minimize

from pymoo_rail.experiments.fronts import choose_member, distinct_front
from pymoo_rail.experiments.penalty import PenalisedConstraints, handles_constraints
from pymoo_rail.optimal import optimal_profile
from pymoo_rail.optimal.reference import NoExactFrontError
from pymoo_rail.problems.encodings import decision_columns
from pymoo_rail.problems.objectives import time_objectives
from pymoo_rail.problems.reference import mirrored

DEFAULT_TIME_TOLERANCE_S = 1.0
"""How close to the planned time a member counts as punctual when the problem has no tolerance (s)."""


@dataclass(frozen=True)
class Optimum:
    """The exact reference at the chosen member's running time.

    Attributes
    ----------
    message : str
        One line for the user: the gap and the optimum, or why there is none.
    front_F : numpy.ndarray or None
        The certified front in the problem's objective space (two objectives only), to draw.
    energy_kwh, gap_kwh, bound_kwh : float or None
        The optimal energy at the chosen member's running time, the member's energy above it,
        and the certificate of the optimum there (kWh); None when no gap is reported.
    profile : Trajectory or None
        The optimal run at the chosen member's running time.
    """

    message: str
    front_F: np.ndarray | None = None
    energy_kwh: float | None = None
    gap_kwh: float | None = None
    bound_kwh: float | None = None
    profile: Any = None


@dataclass(frozen=True)
class OptimizeResult:
    """What :func:`optimize_profile` found.

    Attributes
    ----------
    problem : SpeedProfileProblem
        The problem that was optimised.
    front : pandas.DataFrame
        One row per distinct front member, sorted by running time then energy: ``chosen``, the
        objective columns ``f_<name>`` (``f_weighted_sum`` for a weighted sum), running time,
        net energy, stop error, acceleration variation, ``feasible``, ``cv`` and the decision
        variables ``x<j>_<unit>``.
    trajectories : tuple of Trajectory
        The simulated run of every row of ``front``.
    chosen : int
        Row of the member to show (:func:`~pymoo_rail.experiments.fronts.choose_member`).
    n_eval : int
        Evaluations the algorithm used.
    optimum : Optimum
        The exact reference at the chosen member's running time.
    """

    problem: Any
    front: pd.DataFrame
    trajectories: tuple
    chosen: int
    n_eval: int
    optimum: Optimum

    @property
    def trajectory(self):
        """The chosen member's run."""
        return self.trajectories[self.chosen]

    @property
    def F(self) -> np.ndarray:
        """Objective values of the front, in the rows' order."""
        return self.front[[c for c in self.front.columns if c.startswith("f_")]].to_numpy(float)

    @property
    def n_feasible(self) -> int:
        """How many front members meet every constraint."""
        return int(self.front["feasible"].sum())


def default_time_tolerance_s(objectives: Sequence[str], weights: Sequence[float] | None,
                             time_tolerance_s: float | None) -> float | None:
    """The running-time tolerance a run gets: the given one, else 1 s for one objective that ignores time.

    One objective without ``running_time`` or ``time_error`` (and no weighted sum) would let the
    run take any time; ``|T - T_plan| <= 1 s`` keeps it to the timetable (the form of Liu (2019)).
    """
    if time_tolerance_s is None and len(objectives) == 1 and weights is None \
            and objectives[0] not in time_objectives():
        return DEFAULT_TIME_TOLERANCE_S
    return time_tolerance_s


def front_table(problem, opt) -> tuple[pd.DataFrame, list]:
    """The distinct members of ``opt`` as a table sorted by running time then energy, and their runs.

    Returns
    -------
    (pandas.DataFrame, list of Trajectory)
        The columns of :attr:`OptimizeResult.front` except ``chosen``, and the run of every row.
    """
    opt = distinct_front(opt)  # one member per objective vector
    X = np.asarray(opt.get("X"), dtype=float)
    F = np.asarray(opt.get("F"), dtype=float)
    CV = np.asarray(opt.get("CV"), dtype=float).reshape(-1)
    trajectories = [problem.trajectory(x) for x in X]
    running = np.array([t.running_time_s for t in trajectories])
    energy = np.array([t.energy.net_kwh for t in trajectories])
    order = np.lexsort((energy, running))
    X, F, CV, running, energy = X[order], F[order], CV[order], running[order], energy[order]
    trajectories = [trajectories[i] for i in order]

    objective_cols = ([f"f_{name}" for name in problem.objectives] if problem.n_obj == len(problem.objectives)
                      else ["f_weighted_sum"])
    front = pd.DataFrame(F, columns=objective_cols)
    front["running_time_s"] = running
    front["energy_kwh"] = energy
    front["stop_error_m"] = [t.stop_error_m for t in trajectories]
    front["accel_variation_ms2"] = [t.accel_variation_ms2 for t in trajectories]
    front["feasible"] = CV <= 0
    front["cv"] = CV
    for j, column in enumerate(decision_columns(problem.encoding)):  # x0_kmh, x3_m, x4_ms2: the encoding's units
        front[column] = X[:, j]
    return front, trajectories


def _grid_hint(problem) -> str:
    dx_m = float(problem.simulator.grid.dx_m)
    return f"; a finer grid may meet it (dx_m, now {dx_m:.4g} m; --dx {dx_m / 2:.4g} on the command line)"


def _optimal_run(problem, running_time_s: float, front=None) -> tuple[Any, str]:
    """The optimal run at ``running_time_s``, else at the front's node nearest to it; and a note on any miss."""
    dx_m = problem.simulator.grid.dx_m
    try:
        return optimal_profile(problem.case, running_time_s, dx_m=dx_m), ""
    except (RuntimeError, ValueError) as err:  # a time the solver's grid jumps over
        note = f"; no optimal run at {running_time_s:.2f} s ({err})"
    if front is None:
        return None, note
    nodes = front.table["running_time_s"].to_numpy(float)
    nearest = float(nodes[np.argmin(np.abs(nodes - running_time_s))])
    try:
        run = optimal_profile(problem.case, nearest, dx_m=dx_m)
    except (RuntimeError, ValueError):
        return None, note + "; none drawn"
    return run, note + (f"; drawn instead: the optimal run at {run.running_time_s:.2f} s "
                        f"({run.running_time_s - running_time_s:+.2f} s), the front's nearest node")


def _without_front(problem, trajectory, err: Exception) -> Optimum:
    """The certified front failed: the optimum at the chosen run's own time, uncertified, if the solver meets it."""
    t = trajectory.running_time_s
    reason = f"optimum: the certified front could not be computed ({type(err).__name__}: {err})"
    run, note = _optimal_run(problem, t)
    if run is None:
        return Optimum(f"{reason}{note}; no gap reported{_grid_hint(problem)}")
    energy = run.energy.net_kwh
    gap = trajectory.energy.net_kwh - energy
    return Optimum(f"{reason}; the nearest optimum takes {run.running_time_s:.2f} s "
                   f"({run.running_time_s - t:+.2f} s from the chosen run) and {energy:.3f} kWh: the chosen run is "
                   f"{gap:+.3f} kWh above it (not certified){_grid_hint(problem)}",
                   None, float(energy), float(gap), None, run)


def optimum_at(problem, trajectory, reference: bool = True) -> Optimum:
    """The certified optimum at ``trajectory``'s running time: the gap, the front to draw, the optimal run.

    A failure of the exact solver (a running time its grid cannot meet) never loses the run: the
    message then says why, gives the nearest optimum it found and the time difference, and how a
    finer grid may help.

    Parameters
    ----------
    problem : SpeedProfileProblem
    trajectory : Trajectory
        The run to compare (the chosen member's).
    reference : bool
        False skips the exact solver (``--no-reference``).
    """
    if not reference:
        return Optimum("optimum: skipped (--no-reference)")
    try:
        front = problem.certified_front()
    except NoExactFrontError as err:
        return Optimum(f"optimum: none certified for this form ({str(err).split('no exact front: ')[-1]})")
    except (RuntimeError, ValueError) as err:  # the solver could not meet one of the front's running times
        return _without_front(problem, trajectory, err)
    front_F = None
    if problem.n_obj == 2:
        front_F, _ = mirrored(front, problem.objectives, 200, problem.time_window_s)
    lo, hi = front.time_range_s
    t = trajectory.running_time_s
    if not lo <= t <= hi:
        return Optimum(f"optimum: the chosen run's {t:.2f} s lies outside the certified front's "
                       f"{lo:.2f}-{hi:.2f} s; no gap reported", front_F)
    (energy,), (bound,) = front.energy_at(t)
    gap = trajectory.energy.net_kwh - energy
    message = (f"gap to the optimum at {t:.2f} s: {gap:+.3f} kWh ({100 * gap / abs(energy):+.2f} %); "
               f"optimum {energy:.3f} kWh (certified within {bound:.3f} kWh, {front.certificate})")
    profile, note = _optimal_run(problem, t, front)
    return Optimum(message + note, front_F, float(energy), float(gap), float(bound), profile)


def _search(problem, algorithm, termination, seed, callback, penalty):
    """pymoo's ``minimize``; with a penalty, on the penalised problem, and its front evaluated again on ``problem``."""
    if penalty is None:
        if problem.has_constraints() and not handles_constraints(algorithm):
            raise ValueError(f"{type(algorithm).__name__} has no constraint handling and the problem has "
                             f"{problem.n_ieq_constr + problem.n_eq_constr} constraints: pass penalty=... "
                             "(constraints as a penalty) or use an algorithm that handles constraints (NSGA2)")
        res = minimize(problem, algorithm, termination, seed=seed, verbose=False, callback=callback)
        return res.algorithm.opt, int(res.algorithm.evaluator.n_eval)
    res = minimize(PenalisedConstraints(problem, penalty), algorithm, termination, seed=seed, verbose=False,
                   callback=callback)
    # the true objectives and violations, not the penalised ones
    opt = Evaluator().eval(problem, Population.new(X=res.algorithm.opt.get("X")))
    return opt, int(res.algorithm.evaluator.n_eval)


def optimize_profile(problem, algorithm, termination, seed: int | None = None, *,
                     callback: Callable | None = None, reference: bool = True,
                     penalty: float | None = None) -> OptimizeResult:
    """Optimise a speed-profile problem and return its front table, chosen member and gap to the optimum.

    Parameters
    ----------
    problem : SpeedProfileProblem
    algorithm : pymoo Algorithm
    termination : tuple or pymoo Termination
        As for :func:`pymoo.optimize.minimize`, e.g. ``("n_gen", 50)``.
    seed : int, optional
        Random seed: same seed, same result.
    callback : callable, optional
        pymoo callback, called with the algorithm after every generation (a progress bar).
    reference : bool
        Compare the chosen member with the certified optimum (see :func:`optimum_at`).
    penalty : float, optional
        Search with the constraints as a penalty (:class:`~pymoo_rail.experiments.penalty.PenalisedConstraints`),
        for an algorithm without constraint handling (MOEA/D); the front is then evaluated again on
        ``problem``, so its table holds the true objectives and violations. Without it such an
        algorithm on a constrained problem is a ``ValueError`` before any work.

    Returns
    -------
    OptimizeResult
    """
    opt, n_eval = _search(problem, algorithm, termination, seed, callback, penalty)
    front, trajectories = front_table(problem, opt)
    window_s = problem.time_tolerance_s if problem.time_tolerance_s is not None else DEFAULT_TIME_TOLERANCE_S
    chosen = choose_member(front[[c for c in front.columns if c.startswith("f_")]].to_numpy(float),
                           front["cv"].to_numpy(float), front["running_time_s"].to_numpy(float),
                           front["energy_kwh"].to_numpy(float), problem.case.planned_time_s, window_s)
    front.insert(0, "chosen", np.arange(len(front)) == chosen)
    return OptimizeResult(problem, front, tuple(trajectories), chosen, n_eval,
                          optimum_at(problem, trajectories[chosen], reference))
