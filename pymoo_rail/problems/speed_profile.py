"""The single-train speed-profile problem (Liu (2019) chapter 4, Meng et al. (2017) section 1, Tang et al. (2020) section 2)."""

from __future__ import annotations

import warnings
from typing import Sequence

import numpy as np
from pymoo.core.problem import Problem

from pymoo_rail.control import Tracker
from pymoo_rail.model import Case
from pymoo_rail.problems.encodings import resolve_encoding
from pymoo_rail.problems.encodings.base import Encoding, EncodingSetup, Runner
from pymoo_rail.problems.objectives import (
    OBJECTIVE_TABLE,
    canonical_objective,
    check_objectives,
    get_objective,
    objective_names,
)
from pymoo_rail.sim import Simulator, Trajectory
from pymoo_rail.sim import kernel as k
from pymoo_rail.sim.checks import end_speed_violation_ms

OBJECTIVES = objective_names()
"""Objective names (and aliases) of :class:`SpeedProfileProblem`: :data:`~pymoo_rail.problems.objectives.OBJECTIVE_TABLE`."""
OBJECTIVE_ALIASES = {alias: obj.name for obj in OBJECTIVE_TABLE for alias in obj.aliases}
"""Alias -> objective (``{"jerk": "accel_variation"}``)."""


def weighted_sum_settings(weights, scales, objectives: Sequence[str],
                          default_scales: dict[str, float]) -> tuple[np.ndarray, np.ndarray]:
    """Checked weights and scales of a weighted-sum form ``sum w_i f_i / s_i``.

    Parameters
    ----------
    weights : sequence of float
        One finite weight >= 0 per objective.
    scales : sequence of float or None
        One positive scale per objective; ``None`` takes ``default_scales`` of each objective.
    objectives : sequence of str
        The objective names (aliases allowed).
    default_scales : dict
        Scale of each canonical objective name (the typical size of its values).

    Returns
    -------
    (numpy.ndarray, numpy.ndarray)
        The weights and the scales.

    Raises
    ------
    ValueError
        Naming the weights or scales when their number or values do not fit.
    """
    w = np.asarray(weights, dtype=float)
    if w.shape != (len(objectives),) or not np.all(np.isfinite(w)) or np.any(w < 0):
        raise ValueError(f"weights = {w.tolist()!r}: need {len(objectives)} finite values >= 0, "
                         f"one per objective {tuple(objectives)}")
    if scales is None:
        scales = [default_scales[canonical_objective(name)] for name in objectives]
    sc = np.asarray(scales, dtype=float)
    if sc.shape != w.shape or not np.all(sc > 0):
        raise ValueError(f"scales = {sc.tolist()!r}: need {len(objectives)} positive values")
    return w, sc


# the problem's settings that belong to the encoding, at the values that mean "not given"
ENCODING_SETTINGS = {"partition": "gradient_limit", "n_sections": None, "max_section_m": None, "floor_kmh": 10.0,
                     "integer_codes": False, "regimes": None, "decel_range_ms2": None}


class TrackedRuns:
    """A :class:`~pymoo_rail.control.Tracker` as a runner: each program's ideal run, tracked by the controller."""

    def __init__(self, tracker: Tracker):
        self.tracker = tracker

    def run_batch(self, programs: np.ndarray) -> np.ndarray:
        """Summaries (N, N_OUT) of the tracked runs of programs."""
        return self.tracker.run_batch(programs)

    def run(self, program: np.ndarray) -> Trajectory:
        """The tracked trajectory of one program."""
        return self.tracker.run_program(program)


class DecisionError(ValueError):
    """Decision vectors a problem cannot evaluate; ``rows`` lists every bad row of the population."""

    def __init__(self, message: str, rows: list[int]):
        self.rows = rows
        super().__init__(message)


def check_decisions(X: np.ndarray, xl: np.ndarray, xu: np.ndarray, units: str | Sequence[str] = "") -> np.ndarray:
    """``X`` (N, n_var) as floats after checking it is finite and within ``[xl, xu]``; else :class:`DecisionError`."""
    X = np.atleast_2d(np.asarray(X, dtype=float))
    if X.ndim != 2 or X.shape[1] != xl.shape[0]:
        raise ValueError(f"decision vectors have shape {X.shape}: this problem has n_var = {xl.shape[0]}")
    with np.errstate(invalid="ignore"):
        bad = ~np.isfinite(X) | (X < xl) | (X > xu)
    rows = np.flatnonzero(bad.any(axis=1))
    if rows.size:
        r = int(rows[0])
        j = int(np.flatnonzero(bad[r])[0])
        what = "is not a finite number" if not np.isfinite(X[r, j]) else "is outside its bounds"
        unit = units if isinstance(units, str) else units[j]
        unit = f" {unit}" if unit else ""
        listed = ", ".join(str(int(i)) for i in rows[:10]) + (", ..." if rows.size > 10 else "")
        raise DecisionError(
            f"decision row {r}, variable {j} = {float(X[r, j])!r}{unit} {what} ([{xl[j]:g}, {xu[j]:g}]{unit}); "
            f"{rows.size} of {X.shape[0]} rows are bad (rows {listed}). Nothing was evaluated: decisions must "
            "be finite and inside [xl, xu] (clip or repair them first)", [int(i) for i in rows])
    return X


SEED_002_WEIGHTS = {"energy": 0.1, "jerk": 0.2, "stop_error": 0.4, "time_error": 0.3}


def objective_values(summaries: np.ndarray, names: Sequence[str], planned_time_s: float) -> np.ndarray:
    """Objective columns (N, len(names)) from kernel summaries (N, N_OUT), as the objective table says."""
    columns = []
    for name in names:
        obj = get_objective(name)
        values = summaries[:, k.OUT_NAMES.index(obj.kernel_column)]
        columns.append(np.abs(values - planned_time_s) if obj.off_plan else values)
    return np.column_stack(columns)


def weighted_sum_scales(flat_out_summary: np.ndarray, names: Sequence[str], planned_time_s: float) -> dict[str, float]:
    """Weighted-sum scale of each objective (canonical name) from the flat-out run's summary (N_OUT,)."""
    values = objective_values(np.atleast_2d(flat_out_summary), names, planned_time_s)[0]
    return {canonical_objective(name): get_objective(name).default_scale(float(v), planned_time_s)
            for name, v in zip(names, values)}


class ConstantObjectiveWarning(UserWarning):
    """An objective cannot vary under the problem's encoding: its front axis is dead."""


def warn_constant_objectives(objectives: Sequence[str], encoding) -> None:
    """Warn, naming them, about objectives the encoding holds constant."""
    dead = [name for name in objectives if name in encoding.constant_objectives]
    if dead:
        warnings.warn(f"objective(s) {', '.join(dead)} are constant under encoding '{encoding.name}' "
                      "(every run stops exactly at the platform): use encoding='braking_onset' for a "
                      "live stop error", ConstantObjectiveWarning, stacklevel=3)


class SpeedProfileProblem(Problem):
    """Recommended speed profile of one train between two stops, as a vectorised pymoo problem.

    Parameters
    ----------
    case : Case
        Train, line and planned time (``load_case("yizhuang")``).
    objectives : sequence of str
        Any of ``"energy"`` (net kWh), ``"running_time"`` (s), ``"time_error"`` (``|T - T_plan|`` s,
        Liu (2019) eq. 4-21), ``"accel_variation"`` (comfort: total variation of the
        acceleration, sum of ``|a_i - a_(i-1)|`` over the grid cells, m/s^2; Meng et al. (2017) eq. 5,
        where it is called jerk: ``"jerk"`` is an alias of it, not a rate in m/s^3),
        ``"stop_error"`` (m, Meng et al. (2017) eq. 6), ``"peak_power"`` (the highest electrical
        traction power drawn, kW: a cell's traction work over its duration, divided by the traction
        efficiency; :mod:`pymoo_rail.problems.objectives` lists them all). Several give the Pareto form; one with
        ``time_tolerance_s`` gives the constrained form of Liu (2019) 4.4; ``weights`` give the
        weighted sum of Meng et al. (2017) eq. 9.
    encoding : Encoding or {"speed_codes", "switching_points", "braking_onset", "paced_speed_codes"}
        An encoding object, as pymoo takes ``sampling=...`` (``SpeedCodes(partition="equal")``,
        ``SwitchingPoints(regimes=...)``, ``BrakingOnset(...)``, ``PacedCodes(...)``), or its name,
        resolved by :mod:`pymoo_rail.problems.encodings` with the settings below that it takes.
        Speed codes per section (km/h), regime switching positions (m), or the phases of
        Meng et al. (2017) with the braking onset (m) and deceleration (m/s^2) as decisions (the
        only one where the stop error varies without ``tracking``); ``"paced_speed_codes"``: a
        speed-code shape per section and the running time (s), each shape paced to its time, so
        every vector is on time (needs ``time_tolerance_s`` or ``time_window_s``). An objective that
        cannot vary under the chosen encoding (the stop error of speed codes) triggers a
        ``ConstantObjectiveWarning``. A setting below that the encoding does not take is an error
        unless it has its default value; beside an encoding object, every setting must keep its
        default.
    partition : {"gradient_limit", "equal"}
        Sections of the speed-code encoding (Liu (2019) figs. 4-4 and 4-3).
    n_sections : int, optional
        Number of equal sections (``partition="equal"``, default 10).
    max_section_m : float, optional
        Split ``gradient_limit`` sections longer than this (finer control on long sections).
    time_tolerance_s : float, optional
        Adds the constraint ``|T - T_plan| <= time_tolerance_s``.
    time_window_s : (float, float) or "default", optional
        Adds the constraint ``lo <= T <= hi`` on the running time: keeps a Pareto front on the
        times a timetable planner would use. ``"default"`` is
        :func:`pymoo_rail.optimal.reference.default_window` (0.5 % above the minimum running
        time to 1.3 x the planned time), the range the certified front covers.
    weights : sequence of float, optional
        One weight per objective: minimise ``sum w_i f_i / scale_i`` (a single objective).
    scales : sequence of float, optional
        Normalisation of the weighted sum; by default the flat-out run's energy, 5 % of the planned
        time (time error, Meng et al.'s (2017) punctuality tolerance), the planned time (running time), the
        flat-out run's jerk and peak power, and 0.25 m (stop error, Meng et al.'s (2017) tolerance)
        (:meth:`pymoo_rail.problems.objectives.Objective.default_scale`).
    stop_tolerance_m : float or None
        Constraint ``stop_error <= stop_tolerance_m`` (default 0.25 m); ``None`` drops it.
    regimes : sequence of str, optional
        Regime sequence of the switching-point encoding.
    floor_kmh : float
        Lowest speed code (default 10 km/h): a code below the current speed means coasting.
    dx_m : float, optional
        Simulation grid step.
    tracking : Hysteresis, PID or FuzzyPID, optional
        Score each decision by the run of this ATO controller tracking its ideal curve (Liu (2019)
        optimises the tracked curve, section 5.1.3) instead of the ideal run itself; see
        :mod:`pymoo_rail.control`. ``trajectory(x)`` then returns the tracked run.
    control_period_s : float
        Control period of ``tracking`` (default 0.2 s).
    integer_codes : bool
        Whole-km/h speed codes (``vtype=int``), for pymoo's integer operators (e.g.
        ``IntegerRandomSampling``, ``SBX(repair=RoundingRepair(), vtype=float)``).
    decel_range_ms2 : (float, float), optional
        Bounds of the braking deceleration of ``encoding="braking_onset"``.

    Notes
    -----
    Every form carries the constraints "stop at the platform" and "never above a limit" (the
    kernel already brakes onto the limits, so the latter is a guard), and on a case with a moving
    end "arrive at the end speed asked for" (``run.final_speed_kmh`` or its window, within
    ``END_SPEED_TOL_MS``: ``pymoo_rail.sim.checks.end_speed_violation_ms``). Infeasible decisions come
    back as constraint violation.

    Decision vectors must be finite and inside ``[xl, xu]``: ``evaluate`` raises a
    :class:`DecisionError` (a ``ValueError``) naming every bad row of the population, the first
    bad variable with its value, unit and bounds. pymoo's operators and ours repair offspring
    into the bounds, so such a row is a bug upstream; nothing is clipped or turned into NaN
    objectives behind the caller's back. Repair first (e.g. ``np.clip(X, problem.xl,
    problem.xu)``) if clipping is what you mean.
    """

    def __init__(self, case: Case, objectives: Sequence[str] = ("energy", "time_error"),
                 encoding: str | Encoding = "speed_codes", partition: str = "gradient_limit",
                 n_sections: int | None = None, max_section_m: float | None = None,
                 time_tolerance_s: float | None = None, weights: Sequence[float] | None = None,
                 scales: Sequence[float] | None = None, stop_tolerance_m: float | None = 0.25,
                 regimes: Sequence[str] | None = None, floor_kmh: float = 10.0, dx_m: float | None = None,
                 tracking=None, control_period_s: float = 0.2, time_window_s=None, integer_codes: bool = False,
                 decel_range_ms2: tuple[float, float] | None = None, **kwargs):
        case = case.require_single_run(type(self).__name__)
        objectives = check_objectives(objectives)
        encoding = resolve_encoding(encoding, ENCODING_SETTINGS, partition=partition, n_sections=n_sections,
                                    max_section_m=max_section_m, floor_kmh=floor_kmh, integer_codes=integer_codes,
                                    regimes=tuple(regimes) if regimes is not None else None,
                                    decel_range_ms2=decel_range_ms2)
        if time_tolerance_s is not None and not (np.isfinite(time_tolerance_s) and time_tolerance_s > 0):
            raise ValueError(f"time_tolerance_s = {time_tolerance_s!r} must be a positive number")
        if stop_tolerance_m is not None and not (np.isfinite(stop_tolerance_m) and stop_tolerance_m > 0):
            raise ValueError(f"stop_tolerance_m = {stop_tolerance_m!r} must be a positive number or None")

        self.case = case
        self.objectives = objectives
        self.time_tolerance_s = time_tolerance_s
        self.stop_tolerance_m = stop_tolerance_m
        self.simulator = Simulator(case, dx_m)
        self.tracker = None if tracking is None else Tracker(case, tracking, control_period_s, dx_m)
        fastest = self.simulator.flat_out()
        if any(get_objective(name).off_plan for name in objectives) or time_tolerance_s is not None:
            self.simulator.check_planned_time()  # raises, naming planned_time_s, when impossible
        self.min_running_time_s = fastest.running_time_s
        self.time_window_s = self._check_window(time_window_s, case)
        setup = EncodingSetup(case, self.simulator, dx_m, tracking is not None, self._time_range_s())
        self.encoding = encoding.bind(setup)
        if tracking is None:
            warn_constant_objectives(objectives, self.encoding)

        self.weights = None
        self.scales = None
        if weights is not None:
            default = weighted_sum_scales(np.array([fastest.summary[name] for name in k.OUT_NAMES]), objectives,
                                          case.planned_time_s)
            self.weights, self.scales = weighted_sum_settings(weights, scales, objectives, default)

        n_obj = 1 if self.weights is not None else len(objectives)
        # a moving end (run.final_speed_kmh > 0): the arrival speed is asked for, not a ceiling (a run
        # coasting in slower violates it); at rest the stop constraint already holds it
        self.end_speed_constraint = case.end_speed_window_ms()[1] > 0.0
        n_ieq = (1 + (stop_tolerance_m is not None) + (time_tolerance_s is not None) + (self.time_window_s is not None)
                 + self.end_speed_constraint)
        super().__init__(n_var=self.encoding.n_var, n_obj=n_obj, n_ieq_constr=n_ieq,
                         xl=self.encoding.xl.copy(), xu=self.encoding.xu.copy(), vtype=self.encoding.vtype, **kwargs)

    # ------------------------------------------------------------------ evaluation
    def summaries(self, X: np.ndarray) -> np.ndarray:
        """Kernel summaries (N, N_OUT) of decision vectors (N, n_var): see ``pymoo_rail.sim.OUT_NAMES``."""
        X = np.atleast_2d(np.asarray(X, dtype=float))
        if X.shape[1] != self.n_var:
            raise ValueError(f"decision vectors have {X.shape[1]} values: this problem has n_var = {self.n_var}")
        return self.encoding.summaries(np.ascontiguousarray(X), self.runner)

    def check_decisions(self, X: np.ndarray) -> np.ndarray:
        """``X`` as a float array (N, n_var) after checking it is finite and inside ``[xl, xu]``.

        Raises
        ------
        DecisionError
            Naming the bad rows, and the first bad variable, value and bounds in the encoding's unit.
        """
        return check_decisions(X, self.xl, self.xu, self.encoding.units)

    def _evaluate(self, x, out, *args, **kwargs):
        s = self.summaries(self.check_decisions(x))
        values = objective_values(s, self.objectives, self.case.planned_time_s)
        if self.weights is not None:
            values = (values / self.scales) @ self.weights
            values = values[:, None]
        constraints = [s[:, k.OUT_LIMIT_EXCESS_MS] - 1e-6]
        if self.stop_tolerance_m is not None:
            constraints.append(s[:, k.OUT_STOP_ERROR_M] - self.stop_tolerance_m)
        if self.end_speed_constraint:
            constraints.append(end_speed_violation_ms(s[:, k.OUT_FINAL_SPEED_MS], self.case))
        if self.time_tolerance_s is not None:
            constraints.append(np.abs(s[:, k.OUT_RUNNING_TIME_S] - self.case.planned_time_s) - self.time_tolerance_s)
        if self.time_window_s is not None:
            lo, hi = self.time_window_s
            t = s[:, k.OUT_RUNNING_TIME_S]
            constraints.append(np.maximum(lo - t, t - hi))
        out["F"] = values
        out["G"] = np.column_stack(constraints)
        out["energy_kwh"] = s[:, k.OUT_NET_KWH]
        out["running_time_s"] = s[:, k.OUT_RUNNING_TIME_S]
        out["stop_error_m"] = s[:, k.OUT_STOP_ERROR_M]

    def _time_range_s(self) -> tuple[float, float]:
        """Running times the constraints accept: the tolerance window, inside the time window (infinite: open)."""
        lo, hi = -np.inf, np.inf
        if self.time_tolerance_s is not None:
            lo, hi = self.case.planned_time_s - self.time_tolerance_s, self.case.planned_time_s + self.time_tolerance_s
        if self.time_window_s is not None:
            lo, hi = max(lo, self.time_window_s[0]), min(hi, self.time_window_s[1])
        return lo, hi

    def _check_window(self, window, case: Case):
        if window is None:
            return None
        if isinstance(window, str):
            if window != "default":
                raise ValueError(f"time_window_s = {window!r}: give (lo, hi) in seconds or 'default'")
            from pymoo_rail.optimal.reference import default_window

            return default_window(self.min_running_time_s, case.planned_time_s)
        try:
            lo, hi = (float(v) for v in window)
        except (TypeError, ValueError):
            raise ValueError(f"time_window_s = {window!r}: give (lo, hi) in seconds or 'default'") from None
        if not (np.isfinite(lo) and np.isfinite(hi) and 0 <= lo < hi):
            raise ValueError(f"time_window_s = {window!r}: need finite 0 <= lo < hi seconds")
        if hi < self.min_running_time_s:
            raise ValueError(f"time_window_s = {window!r}: ends before the minimum running time "
                             f"{self.min_running_time_s:.2f} s")
        return lo, hi

    # ------------------------------------------------------------------ known front
    def certified_front(self):
        """The case's certified energy / running-time front (:mod:`pymoo_rail.optimal.reference`).

        Computed once per case content by the exact solver and cached on disk; raises
        :class:`~pymoo_rail.optimal.reference.NoExactFrontError` for forms that have none.
        """
        from pymoo_rail.optimal import reference as certified

        reason = self._no_exact_front_reason()
        if reason:
            raise certified.NoExactFrontError(f"{self.describe()}: no exact front: {reason}")
        return certified.certified_front(self.case, self.simulator.grid.dx_m)

    def _no_exact_front_reason(self) -> str:
        if self.tracker is not None:
            return "the objectives are those of a tracked run"
        if self.weights is not None:
            return "a weighted sum has no certified optimum"
        names = set(self.objectives)
        if len(self.objectives) == 1:
            if self.objectives != ("energy",) or self.time_tolerance_s is None:
                return "only energy under a running-time tolerance has an exact optimum"
            return ""
        if len(self.objectives) > 2 or not (names == {"energy", "running_time"} or names == {"energy", "time_error"}):
            return (f"objectives {self.objectives} (exact fronts exist for energy with running time or time error; "
                    "for three or more objectives pymoo_rail.suite offers a best-known front, labelled as such)")
        if self.time_window_s is None:
            return ("without a running-time window the front runs on to ever slower, cheaper runs; the certified "
                    "front covers the planner's times: pass time_window_s='default' (or a (lo, hi) inside it)")
        return ""

    def _calc_pareto_front(self, n_pareto_points: int | None = None, *args, **kwargs):
        """pymoo's hook: the certified front in this problem's objective space (or the constrained optimum).

        ``pareto_front()`` gives the front's nodes (its vertices) plus 100 evenly spaced points;
        ``pareto_front(n_pareto_points=n)`` at most ``n`` evenly spaced points (fewer where some are
        dominated). pymoo caches the first answer: pass ``use_cache=False`` to ask again with another ``n``.
        """
        from pymoo_rail.optimal import reference as certified
        from pymoo_rail.problems import reference

        front = self.certified_front()
        if len(self.objectives) == 1:
            energy, _, _ = certified.constrained_optimum(front, self.time_tolerance_s, window_s=self.time_window_s)
            return np.array([[energy]])
        if n_pareto_points is not None and (isinstance(n_pareto_points, bool)
                                            or not isinstance(n_pareto_points, (int, np.integer))
                                            or n_pareto_points < 2):
            raise ValueError(f"n_pareto_points must be an integer >= 2 or None, got {n_pareto_points!r}")
        F, _ = reference.mirrored(front, self.objectives, n_pareto_points, self.time_window_s)
        return F

    # ------------------------------------------------------------------ inspection
    def trajectory(self, x: np.ndarray) -> Trajectory:
        """The full trajectory of one decision vector."""
        x = np.asarray(x, dtype=float)
        if x.ndim != 1 or x.shape[0] != self.n_var:
            raise ValueError(f"x must be one decision vector of length n_var = {self.n_var}, got shape {x.shape}")
        return self.encoding.trajectory(self.check_decisions(x[None, :])[0], self.runner)

    @property
    def runner(self) -> Runner:
        """What runs the decoded programs: the simulator, or the ATO tracker (``tracking=``)."""
        return self.simulator if self.tracker is None else TrackedRuns(self.tracker)

    def describe(self) -> str:
        """One line naming the case, the form, the encoding and the objectives."""
        form = "weighted sum" if self.weights is not None else (
            "constrained single-objective" if len(self.objectives) == 1 else "Pareto")
        return (f"SpeedProfileProblem({self.case.name}, {form}: {', '.join(self.objectives)}; "
                f"{self.encoding.name} with {self.n_var} variables; {self.n_ieq_constr} constraints)")
