"""Simple driving strategies that run in a given time: the baselines a saving is measured against.

Two one-parameter strategies, each found by bisection on its parameter so that the run takes the
requested time (the planned time by default):

- :func:`constant_cruise`: one speed code for every section of a speed-profile problem (capped by
  each section's upper bound), the analogue of a driver who keeps one target speed;
- :func:`coast_point`: maximum traction (held at the limits), coasting from one point on, latest
  braking: the traction-coast-brake practice of Liu (2019), 4.3.1.

:func:`strategy_baselines` gives both plus the flat-out run, as a saving table needs them.
The best strategies of a richer family, as a check of the exact solver, are in
:mod:`pymoo_rail.optimal.strategies`.
"""

from __future__ import annotations

import numpy as np

from pymoo_rail.sim import Simulator, Trajectory
from pymoo_rail.sim.kernel import MODE_COAST, MODE_TRACTION


def constant_cruise(problem, target_s: float | None = None, tol_s: float = 1e-3) -> tuple[float, Trajectory]:
    """One speed code for every section, found by bisection so that the run takes ``target_s``.

    Parameters
    ----------
    problem : pymoo_rail.problems.SpeedProfileProblem
        A problem with the speed-code encoding; the code of a section is capped by its upper
        bound (``problem.xu``).
    target_s : float, optional
        Running time to hit (s); default the case's planned time.
    tol_s : float
        How close to ``target_s`` the run must be (s).

    Returns
    -------
    (float, Trajectory)
        The code (km/h) and its run. The running time falls monotonically as the code rises.

    Raises
    ------
    ValueError
        When no single code between the bounds gives ``target_s``.
    """
    target = problem.case.planned_time_s if target_s is None else float(target_s)

    def run(code):
        return problem.trajectory(np.minimum(np.full(problem.n_var, code), problem.xu))

    lo, hi = float(problem.xl.max()), float(problem.xu.max())
    if not (run(hi).running_time_s <= target <= run(lo).running_time_s):
        raise ValueError(f"target_s = {target}: no single code in [{lo}, {hi}] km/h gives that running time")
    while True:
        mid = 0.5 * (lo + hi)
        t = run(mid)
        if abs(t.running_time_s - target) <= tol_s or hi - lo < 1e-9:
            return mid, t
        if t.running_time_s > target:
            lo = mid
        else:
            hi = mid


def coast_point(simulator: Simulator, target_s: float, tol_s: float = 1e-3) -> tuple[float, Trajectory]:
    """Maximum traction, coasting from one point on, latest braking, in ``target_s``.

    Parameters
    ----------
    simulator : Simulator
        The simulator of the case.
    target_s : float
        Running time to hit (s).
    tol_s : float
        How close to ``target_s`` the run must be (s).

    Returns
    -------
    (float, Trajectory)
        The coasting point (m from the start) and its run.

    Raises
    ------
    ValueError
        When ``target_s`` is shorter than the flat-out run.
    """
    length = simulator.case.line.length_m

    def run(x_m):
        return simulator.run(np.array([[x_m, MODE_TRACTION, 0.0], [length, MODE_COAST, 0.0]]))

    lo, hi = 0.0, float(length)
    if not (run(hi).running_time_s <= target_s):
        raise ValueError(f"target_s = {target_s}: faster than the flat-out run")
    while True:
        mid = 0.5 * (lo + hi)
        t = run(mid)
        if (t.reached and abs(t.running_time_s - target_s) <= tol_s) or hi - lo < 1e-6:
            return mid, t
        if t.running_time_s > target_s or not t.reached:
            lo = mid
        else:
            hi = mid


def strategy_baselines(problem) -> dict[str, dict[str, float]]:
    """The flat-out run and both strategies at the planned time, for a saving table.

    Parameters
    ----------
    problem : pymoo_rail.problems.SpeedProfileProblem
        A speed-code problem of the case.

    Returns
    -------
    dict
        ``{"flat_out": {...}, "cruise": {..., "code_kmh"}, "coast": {..., "coast_m"}}``, each with
        ``energy_kwh`` (net) and ``running_time_s``.
    """
    flat = problem.simulator.flat_out()
    code, cruise = constant_cruise(problem)
    x_c, coast = coast_point(problem.simulator, problem.case.planned_time_s)
    return {"flat_out": {"energy_kwh": flat.energy.net_kwh, "running_time_s": flat.running_time_s},
            "cruise": {"energy_kwh": cruise.energy.net_kwh, "running_time_s": cruise.running_time_s,
                       "code_kmh": code},
            "coast": {"energy_kwh": coast.energy.net_kwh, "running_time_s": coast.running_time_s,
                      "coast_m": x_c}}


__all__ = ["constant_cruise", "coast_point", "strategy_baselines"]
