"""The single-train speed-profile problem (seed 000 chapter 4, seed 002 section 1, seed 003 section 2)."""

from __future__ import annotations

from typing import Sequence

import numpy as np
from pymoo.core.problem import Problem

from pymoo_rail.model import Case
from pymoo_rail.problems.encodings import ENCODINGS, SpeedCodes, SwitchingPoints
from pymoo_rail.sim import Simulator, Trajectory
from pymoo_rail.sim import kernel as k

OBJECTIVES = ("energy", "running_time", "time_error", "jerk", "stop_error")
DECISION_UNITS = {"speed_codes": "km/h", "switching_points": "m"}


class DecisionError(ValueError):
    """Decision vectors a problem cannot evaluate; ``rows`` lists every bad row of the population."""

    def __init__(self, message: str, rows: list[int]):
        self.rows = rows
        super().__init__(message)


def check_decisions(X: np.ndarray, xl: np.ndarray, xu: np.ndarray, unit: str = "") -> np.ndarray:
    """``X`` (N, n_var) as floats after checking it is finite and within ``[xl, xu]``; else :class:`DecisionError`."""
    X = np.atleast_2d(np.asarray(X, dtype=float))
    if X.ndim != 2 or X.shape[1] != xl.shape[0]:
        raise ValueError(f"decision vectors have shape {X.shape}: this problem has n_var = {xl.shape[0]}")
    unit = f" {unit}" if unit else ""
    for bad, what in ((~np.isfinite(X), "is not a finite number"), ((X < xl) | (X > xu), "is outside its bounds")):
        rows = np.flatnonzero(bad.any(axis=1))
        if rows.size:
            r = int(rows[0])
            j = int(np.flatnonzero(bad[r])[0])
            listed = ", ".join(str(int(i)) for i in rows[:10]) + (", ..." if rows.size > 10 else "")
            raise DecisionError(
                f"decision row {r}, variable {j} = {float(X[r, j])!r}{unit} {what} ([{xl[j]:g}, {xu[j]:g}]{unit}); "
                f"{rows.size} of {X.shape[0]} rows are bad (rows {listed}). Nothing was evaluated: decisions must "
                "be finite and inside [xl, xu] (clip or repair them first)", [int(i) for i in rows])
    return X
SEED_002_WEIGHTS = {"energy": 0.1, "jerk": 0.2, "stop_error": 0.4, "time_error": 0.3}


def objective_values(summaries: np.ndarray, names: Sequence[str], planned_time_s: float) -> np.ndarray:
    """Objective columns (N, len(names)) from kernel summaries (N, N_OUT)."""
    columns = []
    for name in names:
        if name == "energy":
            columns.append(summaries[:, k.OUT_NET_KWH])
        elif name == "running_time":
            columns.append(summaries[:, k.OUT_RUNNING_TIME_S])
        elif name == "time_error":
            columns.append(np.abs(summaries[:, k.OUT_RUNNING_TIME_S] - planned_time_s))
        elif name == "jerk":
            columns.append(summaries[:, k.OUT_JERK_MS2])
        elif name == "stop_error":
            columns.append(summaries[:, k.OUT_STOP_ERROR_M])
        else:
            raise ValueError(f"objective {name!r} is unknown (known: {', '.join(OBJECTIVES)})")
    return np.column_stack(columns)


class SpeedProfileProblem(Problem):
    """Recommended speed profile of one train between two stops, as a vectorised pymoo problem.

    Parameters
    ----------
    case : Case
        Train, line and planned time (``load_case("yizhuang")``).
    objectives : sequence of str
        Any of ``"energy"`` (net kWh), ``"running_time"`` (s), ``"time_error"`` (|T - T_plan| s,
        seed 000 eq. 4-21), ``"jerk"`` (comfort: sum of |a_i - a_(i-1)|, seed 002 eq. 5, in m/s^2),
        ``"stop_error"`` (m, seed 002 eq. 6). Several give the Pareto form; one with
        ``time_tolerance_s`` gives the constrained form of seed 000 4.4; ``weights`` give the
        weighted sum of seed 002 eq. 9.
    encoding : {"speed_codes", "switching_points"}
        Speed codes per section (km/h) or regime switching positions (m); see
        :mod:`pymoo_rail.problems.encodings`.
    partition : {"gradient_limit", "equal"}
        Sections of the speed-code encoding (seed 000 figs. 4-4 and 4-3).
    n_sections : int, optional
        Number of equal sections (``partition="equal"``, default 10).
    max_section_m : float, optional
        Split ``gradient_limit`` sections longer than this (finer control on long sections).
    time_tolerance_s : float, optional
        Adds the constraint ``|T - T_plan| <= time_tolerance_s``.
    weights : sequence of float, optional
        One weight per objective: minimise ``sum w_i f_i / scale_i`` (a single objective).
    scales : sequence of float, optional
        Normalisation of the weighted sum; by default the flat-out run's energy, 5 % of the planned
        time (time error, seed 002's punctuality tolerance), the planned time (running time), the
        flat-out run's jerk, and 0.25 m (stop error, seed 002's tolerance).
    stop_tolerance_m : float or None
        Constraint ``stop_error <= stop_tolerance_m`` (default 0.25 m); ``None`` drops it.
    regimes : sequence of str, optional
        Regime sequence of the switching-point encoding.
    floor_kmh : float
        Lowest speed code (default 10 km/h): a code below the current speed means coasting.
    dx_m : float, optional
        Simulation grid step.
    tracking : Hysteresis, PID or FuzzyPID, optional
        Score each decision by the run of this ATO controller tracking its ideal curve (seed 000
        optimises the tracked curve, section 5.1.3) instead of the ideal run itself; see
        :mod:`pymoo_rail.control`. ``trajectory(x)`` then returns the tracked run.
    control_period_s : float
        Control period of ``tracking`` (default 0.2 s).

    Notes
    -----
    Every form carries the constraints "stop at the platform" and "never above a limit" (the
    kernel already brakes onto the limits, so the latter is a guard). Infeasible decisions come
    back as constraint violation.

    Decision vectors must be finite and inside ``[xl, xu]``: ``evaluate`` raises a
    :class:`DecisionError` (a ``ValueError``) naming every bad row of the population, the first
    bad variable with its value, unit and bounds. pymoo's operators and ours repair offspring
    into the bounds, so such a row is a bug upstream; nothing is clipped or turned into NaN
    objectives behind the caller's back. Repair first (e.g. ``np.clip(X, problem.xl,
    problem.xu)``) if clipping is what you mean.
    """

    def __init__(self, case: Case, objectives: Sequence[str] = ("energy", "time_error"),
                 encoding: str = "speed_codes", partition: str = "gradient_limit", n_sections: int | None = None,
                 max_section_m: float | None = None, time_tolerance_s: float | None = None,
                 weights: Sequence[float] | None = None, scales: Sequence[float] | None = None,
                 stop_tolerance_m: float | None = 0.25, regimes: Sequence[str] | None = None,
                 floor_kmh: float = 10.0, dx_m: float | None = None, tracking=None,
                 control_period_s: float = 0.2, **kwargs):
        if isinstance(objectives, str):
            objectives = (objectives,)
        objectives = tuple(objectives)
        if not objectives:
            raise ValueError("objectives = (): give at least one objective")
        for name in objectives:
            if name not in OBJECTIVES:
                raise ValueError(f"objective {name!r} is unknown (known: {', '.join(OBJECTIVES)})")
        if len(set(objectives)) != len(objectives):
            raise ValueError(f"objectives = {objectives!r} repeats a name")
        if encoding == "speed_codes":
            self.encoding = SpeedCodes.build(case, partition, n_sections, max_section_m, floor_kmh)
        elif encoding == "switching_points":
            self.encoding = SwitchingPoints.build(case, tuple(regimes) if regimes is not None else None)
        else:
            raise ValueError(f"encoding = {encoding!r} is unknown (known: {', '.join(ENCODINGS)})")
        if time_tolerance_s is not None and not (np.isfinite(time_tolerance_s) and time_tolerance_s > 0):
            raise ValueError(f"time_tolerance_s = {time_tolerance_s!r} must be a positive number")
        if stop_tolerance_m is not None and not (np.isfinite(stop_tolerance_m) and stop_tolerance_m > 0):
            raise ValueError(f"stop_tolerance_m = {stop_tolerance_m!r} must be a positive number or None")

        self.case = case
        self.objectives = objectives
        self.time_tolerance_s = time_tolerance_s
        self.stop_tolerance_m = stop_tolerance_m
        self.simulator = Simulator(case, dx_m)
        self.tracker = None
        if tracking is not None:
            from pymoo_rail.control import Tracker  # the tracking layer is optional

            self.tracker = Tracker(case, tracking, control_period_s, dx_m)
        fastest = self.simulator.flat_out()
        if "time_error" in objectives or time_tolerance_s is not None:
            self.simulator.check_planned_time()  # raises, naming planned_time_s, when impossible
        self.min_running_time_s = fastest.running_time_s

        self.weights = None
        self.scales = None
        if weights is not None:
            weights = np.asarray(weights, dtype=float)
            if weights.shape != (len(objectives),) or not np.all(np.isfinite(weights)) or np.any(weights < 0):
                raise ValueError(f"weights = {weights.tolist()!r}: need {len(objectives)} finite values >= 0, "
                                 f"one per objective {objectives}")
            if scales is None:
                default = {"energy": fastest.energy.net_kwh, "time_error": 0.05 * case.planned_time_s,
                           "running_time": case.planned_time_s, "jerk": max(fastest.jerk_ms2, 1e-9),
                           "stop_error": 0.25}
                scales = [default[name] for name in objectives]
            scales = np.asarray(scales, dtype=float)
            if scales.shape != weights.shape or not np.all(scales > 0):
                raise ValueError(f"scales = {scales.tolist()!r}: need {len(objectives)} positive values")
            self.weights, self.scales = weights, scales

        n_obj = 1 if self.weights is not None else len(objectives)
        n_ieq = 1 + (stop_tolerance_m is not None) + (time_tolerance_s is not None)
        super().__init__(n_var=self.encoding.n_var, n_obj=n_obj, n_ieq_constr=n_ieq,
                         xl=self.encoding.xl.copy(), xu=self.encoding.xu.copy(), vtype=float, **kwargs)

    # ------------------------------------------------------------------ evaluation
    def summaries(self, X: np.ndarray) -> np.ndarray:
        """Kernel summaries (N, N_OUT) of decision vectors (N, n_var): see ``pymoo_rail.sim.OUT_NAMES``."""
        X = np.atleast_2d(np.asarray(X, dtype=float))
        if X.shape[1] != self.n_var:
            raise ValueError(f"decision vectors have {X.shape[1]} values: this problem has n_var = {self.n_var}")
        programs = self.encoding.programs(np.ascontiguousarray(X))
        if self.tracker is not None:
            return self.tracker.run_batch(programs)
        return self.simulator.run_batch(programs)

    def check_decisions(self, X: np.ndarray) -> np.ndarray:
        """``X`` as a float array (N, n_var) after checking it is finite and inside ``[xl, xu]``.

        Raises
        ------
        DecisionError
            Naming the bad rows, and the first bad variable, value and bounds in the encoding's unit.
        """
        return check_decisions(X, self.xl, self.xu, DECISION_UNITS.get(self.encoding.name, ""))

    def _evaluate(self, x, out, *args, **kwargs):
        s = self.summaries(self.check_decisions(x))
        values = objective_values(s, self.objectives, self.case.planned_time_s)
        if self.weights is not None:
            values = (values / self.scales) @ self.weights
            values = values[:, None]
        constraints = [s[:, k.OUT_LIMIT_EXCESS_MS] - 1e-6]
        if self.stop_tolerance_m is not None:
            constraints.append(s[:, k.OUT_STOP_ERROR_M] - self.stop_tolerance_m)
        if self.time_tolerance_s is not None:
            constraints.append(np.abs(s[:, k.OUT_RUNNING_TIME_S] - self.case.planned_time_s) - self.time_tolerance_s)
        out["F"] = values
        out["G"] = np.column_stack(constraints)
        out["energy_kwh"] = s[:, k.OUT_NET_KWH]
        out["running_time_s"] = s[:, k.OUT_RUNNING_TIME_S]
        out["stop_error_m"] = s[:, k.OUT_STOP_ERROR_M]

    # ------------------------------------------------------------------ inspection
    def trajectory(self, x: np.ndarray) -> Trajectory:
        """The full trajectory of one decision vector."""
        x = np.asarray(x, dtype=float)
        if x.ndim != 1 or x.shape[0] != self.n_var:
            raise ValueError(f"x must be one decision vector of length n_var = {self.n_var}, got shape {x.shape}")
        program = self.encoding.programs(self.check_decisions(x[None, :]))[0]
        if self.tracker is not None:
            return self.tracker.run_program(program)
        return self.simulator.run(program)

    def describe(self) -> str:
        form = "weighted sum" if self.weights is not None else (
            "constrained single-objective" if len(self.objectives) == 1 else "Pareto")
        return (f"SpeedProfileProblem({self.case.name}, {form}: {', '.join(self.objectives)}; "
                f"{self.encoding.name} with {self.n_var} variables; {self.n_ieq_constr} constraints)")
