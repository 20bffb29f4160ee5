"""The closed-loop study: seeded disturbed runs of every controller on a case, scored fairly.

Each run draws one world (:func:`draw_loop_disturbances`) and drives it with every controller, so
the controllers meet the same trains, delays and restrictions (paired samples). The energy is
compared at equal arrival in two ways: against the real train's exact optimum at the run's own
running time (``gap_pct``: the exact solver on the world's own model, restriction known from the
start), and through the plan's price of time, ``cost_kwh = net energy + lambda x lateness``, with
``lambda`` the exact plan's price of time (the slope of the energy / running-time front at the
planned time), lateness signed (an early arrival is credited at the same price). ``can_be_on_time`` says whether the real
train, flat out from its late departure with the restriction known, could still arrive on time.
"""

from __future__ import annotations

import math
import time as _time
from dataclasses import dataclass, field
from typing import Mapping, Sequence

import numpy as np
import pandas as pd

from pymoo_rail.constants import J_PER_KWH, KMH_PER_MS
from pymoo_rail.control.advice import AdvisedDriving
from pymoo_rail.control.closed_loop import (
    CurveTracking,
    LoopDisturbance,
    LoopState,
    OptimalControls,
    Recovery,
    Replanning,
    closed_loop,
    plan_for,
    real_model,
)
from pymoo_rail.control.controllers import PID, Controller, FuzzyPID, Hysteresis
from pymoo_rail.control.policy import OptimalPolicy, SpeedRestriction, run_trace
from pymoo_rail.model import Case
from pymoo_rail.model.errors import FieldError
from pymoo_rail.optimal import OptimalSolver
from pymoo_rail.sim import Simulator, Trajectory
from pymoo_rail.sim.drivers import flat_out_program

STUDY_CONTROLLERS = ("tracking_pid", "tracking_fuzzy_pid", "tracking_hysteresis", "recovery", "replanning",
                     "replanning_hysteresis", "optimal_controls", "advice")
# Curve tracking by the gains tuned on the case's plan (given to the study, tuned by the problems layer)
TUNED_CONTROLLERS = ("tracking_tuned_pid", "tracking_tuned_fuzzy_pid")
DECIDE_EVERY_S = 10.0
# Ranges of a world (uniform), shares of the line length or of the planned time where so named
WORLD_RANGES = {"mass_factor": (0.9, 1.15), "adhesion_factor": (0.85, 1.0), "speed_noise_kmh": (0.0, 0.5),
                "traction_lag_s": (0.0, 0.5), "resistance_factor": (0.9, 1.2), "regen_factor": (0.85, 1.0),
                "delay_share": (0.0, 0.06), "restriction_start_share": (0.3, 0.7),
                "restriction_length_share": (0.04, 0.08), "announce_before_share": (0.1, 0.25)}
P_DELAY = 0.5  # share of worlds with a late departure
PLAN_MARGIN = 1.08  # the study plans at least this far above the minimum running time
P_RESTRICTION = 0.5  # share of worlds with a temporary speed restriction
RESTRICTION_FACTOR = 0.7  # the restriction's limit against the lowest line limit over its stretch


def study_planned_time(case: Case) -> float:
    """The case's planned time, or :data:`PLAN_MARGIN` above its minimum running time where the case leaves less.

    metro-a's own 70 s is 0.4 % above its flat-out run: no disturbed train could be on time.
    """
    fastest = Simulator(case).min_running_time_s()
    return float(max(case.planned_time_s, round(PLAN_MARGIN * fastest)))


def draw_loop_disturbances(case: Case, n: int, seed: int, planned_time_s: float | None = None) -> list[LoopDisturbance]:
    """``n`` worlds for ``case`` from :data:`WORLD_RANGES`, reproducible by ``seed``."""
    if isinstance(n, bool) or not isinstance(n, (int, np.integer)) or n < 1:
        raise FieldError("n", n, "must be a positive integer")
    planned = float(case.planned_time_s if planned_time_s is None else planned_time_s)
    length = float(case.line.length_m)
    rng = np.random.default_rng(seed)
    worlds = []
    for _ in range(n):
        u = {k: float(rng.uniform(lo, hi)) for k, (lo, hi) in WORLD_RANGES.items()}
        delay = u["delay_share"] * planned if rng.random() < P_DELAY else 0.0
        restriction, announce = None, 0.0
        if rng.random() < P_RESTRICTION:
            start = round(u["restriction_start_share"] * length)
            end = min(round(start + max(u["restriction_length_share"] * length, 200.0)), length)
            lowest = min(kmh for s, e, kmh in case.line.speed_limits if s < end and e > start)
            limit = max(5.0 * math.floor(RESTRICTION_FACTOR * lowest / 5.0), 20.0)
            restriction = SpeedRestriction(float(start), float(end), limit)
            announce = max(start - u["announce_before_share"] * length, 0.0)
        worlds.append(LoopDisturbance(mass_factor=u["mass_factor"], adhesion_factor=u["adhesion_factor"],
                                      speed_noise_kmh=u["speed_noise_kmh"], traction_lag_s=u["traction_lag_s"],
                                      noise_seed=int(rng.integers(2**31)), departure_delay_s=delay,
                                      resistance_factor=u["resistance_factor"], regen_factor=u["regen_factor"],
                                      restriction=restriction, announce_m=announce))
    return worlds


def make_loop_controller(name: str, case: Case, policy: OptimalPolicy, tuned: Mapping[str, Controller] | None = None):
    """A fresh controller of the study by name, around ``policy`` and its plan.

    Names: :data:`STUDY_CONTROLLERS`, and :data:`TUNED_CONTROLLERS` when ``tuned`` maps ``"pid"``
    and ``"fuzzy_pid"`` to tuned controllers (e.g. by
    :func:`pymoo_rail.problems.controller_tuning.tune_controller`), which then track the plan.
    """
    tuned = dict(tuned or {})
    known = STUDY_CONTROLLERS + tuple(n for n in TUNED_CONTROLLERS if n.removeprefix("tracking_tuned_") in tuned)
    if name not in known:
        raise FieldError("controller", name, f"is unknown (known: {', '.join(known)})")
    plan = policy.plan
    if name in TUNED_CONTROLLERS:
        return CurveTracking(plan, tuned[name.removeprefix("tracking_tuned_")], name=name)
    makers = {
        "tracking_pid": lambda: CurveTracking(plan, PID(), name=name),
        "tracking_fuzzy_pid": lambda: CurveTracking(plan, FuzzyPID(), name=name),
        "tracking_hysteresis": lambda: CurveTracking(plan, Hysteresis(2.0, 4.0), name=name),
        "recovery": lambda: Recovery(plan, case, PID(), DECIDE_EVERY_S, name=name),
        "replanning": lambda: Replanning(policy, PID(), DECIDE_EVERY_S, name=name),
        "replanning_hysteresis": lambda: Replanning(policy, Hysteresis(2.0, 4.0), DECIDE_EVERY_S, name=name),
        "optimal_controls": lambda: OptimalControls(policy, DECIDE_EVERY_S, name=name),
        "advice": lambda: AdvisedDriving(policy, DECIDE_EVERY_S, name=name),
    }
    return makers[name]()


def can_be_on_time(case: Case, disturbance: LoopDisturbance, planned_time_s: float) -> bool:
    """Whether the real train, flat out from its late departure (the restriction known), arrives by the plan."""
    model = real_model(case, disturbance)
    run = run_trace(model, flat_out_program(float(case.line.length_m)))
    return bool(run.reached and disturbance.departure_delay_s + run.running_time_s <= planned_time_s)


def exact_energies_kwh(case: Case, disturbance: LoopDisturbance, running_times_s) -> list[float]:
    """The real train's exact minimum energy at each running time (kWh; NaN where there is none).

    The exact solver on the disturbed world's own model (mass, adhesion, resistance, regeneration,
    the restriction known from the start: what a clairvoyant planner could do), each run moved to
    the time asked along its price of time (it is within 0.5 s of it).
    """
    solver = OptimalSolver(case, certify=False)
    solver.simulator.model = real_model(case, disturbance)  # before any solve: tables from this model
    fastest = solver.min_running_time_s()
    out = []
    for t in running_times_s:
        if not np.isfinite(t) or t < fastest - 1e-6:
            out.append(math.nan)
            continue
        try:
            run = solver.profile(max(float(t), fastest))
        except (ValueError, RuntimeError):  # beyond the slowest run the grid represents
            out.append(math.nan)
            continue
        out.append(run.energy.net_kwh + run.summary["lambda_w"] / J_PER_KWH * (run.running_time_s - float(t)))
    return out


def world_rows(case: Case, run: int, world: LoopDisturbance, policy: OptimalPolicy, planned_time_s: float,
               controllers: Sequence[str] = STUDY_CONTROLLERS, exact: bool = True,
               tuned: Mapping[str, Controller] | None = None) -> list[dict]:
    """The rows of one world (index ``run``) driven by every controller: see :func:`loop_runs`."""
    price_kwh_s = policy.lambda_w / J_PER_KWH
    feasible = can_be_on_time(case, world, planned_time_s)
    rows = []
    for name in controllers:
        controller = make_loop_controller(name, case, policy, tuned)
        started = _time.process_time()
        trace = closed_loop(case, controller, world, planned_time_s=planned_time_s)
        s = trace.summary
        cpu = getattr(controller, "cpu_s", [])
        advised = name == "advice"
        rows.append({"case": case.name, "run": run, "controller": name, "net_kwh": s["net_kwh"],
                     "cost_kwh": s["net_kwh"] + price_kwh_s * s["lateness_s"], "lateness_s": s["lateness_s"],
                     "stop_error_m": s["stop_error_m"], "jerk_ms2": s["jerk_ms2"],
                     "advice_changes": float(controller.changes(trace)) if advised else math.nan,
                     "seconds_per_change": (trace.running_time_s / max(controller.changes(trace), 1)
                                            if advised else math.nan),
                     "n_decisions": s["n_decisions"], "reached": s["reached"], "can_be_on_time": feasible,
                     "delay_s": world.departure_delay_s, "restricted": world.restriction is not None,
                     "max_speed_kmh": float(np.max(trace.speed_ms) * KMH_PER_MS),
                     "decision_cpu_ms": float(np.median(cpu) * 1000.0) if cpu else math.nan,
                     "running_time_s": trace.running_time_s, "cpu_s": _time.process_time() - started})
    if exact:
        for row, best in zip(rows, exact_energies_kwh(case, world, [r["running_time_s"] for r in rows])):
            row["exact_kwh"] = best
            row["gap_pct"] = 100.0 * (row["net_kwh"] / best - 1.0) if best > 0 else math.nan
    return rows


def loop_runs(case: Case, n_runs: int, seed: int, controllers=STUDY_CONTROLLERS, policy: OptimalPolicy | None = None,
              planned_time_s: float | None = None, first_run: int = 0, exact: bool = True,
              tuned: Mapping[str, Controller] | None = None) -> pd.DataFrame:
    """One row per (world, controller): the closed-loop study of one case.

    Columns: ``case``, ``run`` (world index), ``controller``, ``net_kwh``, ``cost_kwh`` (energy
    plus the plan's price of time times the lateness), ``lateness_s``, ``stop_error_m``,
    ``jerk_ms2``, ``advice_changes`` (advice only), ``n_decisions``, ``can_be_on_time``,
    ``delay_s``, ``restricted``, ``decision_cpu_ms`` (median per decision, re-planning only) and
    ``cpu_s``; with ``exact``, ``exact_kwh`` (the real train's exact optimum at the run's own
    running time, :func:`exact_energies_kwh`) and ``gap_pct`` (energy above it, %). Worlds
    ``first_run .. first_run + n_runs - 1`` of the seeded draw; ``tuned`` adds the tuned trackers
    (:func:`make_loop_controller`).
    """
    planned = float(case.planned_time_s if planned_time_s is None else planned_time_s)
    policy = OptimalPolicy(case, planned) if policy is None else policy
    worlds = draw_loop_disturbances(case, first_run + n_runs, seed, planned)[first_run:]
    rows = []
    for k, world in enumerate(worlds):
        rows += world_rows(case, first_run + k, world, policy, planned, controllers, exact, tuned)
    return pd.DataFrame(rows)


def loop_summary(runs: pd.DataFrame, on_time_s: float = 2.0) -> pd.DataFrame:
    """Per case and controller: medians, the share on time (within ``on_time_s``) among runs that can be."""
    rows = []
    for (case, name), g in runs.groupby(["case", "controller"], sort=False):
        can = g[g["can_be_on_time"]]
        rows.append({"case": case, "controller": name, "n": len(g),
                     "median_cost_kwh": g["cost_kwh"].median(), "median_net_kwh": g["net_kwh"].median(),
                     "median_gap_pct": g["gap_pct"].median() if "gap_pct" in g else math.nan,
                     "median_lateness_s": g["lateness_s"].median(),
                     "on_time_share": float((can["lateness_s"].abs() <= on_time_s).mean()) if len(can) else math.nan,
                     "late_share": float((can["lateness_s"] > on_time_s).mean()) if len(can) else math.nan,
                     "n_can_be_on_time": len(can), "median_stop_error_m": g["stop_error_m"].median(),
                     "median_jerk_ms2": g["jerk_ms2"].median(),
                     "median_seconds_per_change": g["seconds_per_change"].median(),
                     "median_decision_cpu_ms": g["decision_cpu_ms"].median()})
    return pd.DataFrame(rows)


@dataclass
class _RecordingReplanning(Replanning):
    """The re-planning controller, keeping the states it planned from."""

    states: list = field(default_factory=list)

    def reference(self, state: LoopState) -> Trajectory:
        self.states.append(state)
        return super().reference(state)


def replan_latency(case: Case, planned_time_s: float, n_worlds: int, seed: int) -> dict:
    """CPU time per re-plan of :class:`OptimalPolicy` against a fresh exact solve, in one process.

    The policy is built once. In each seeded world (:func:`draw_loop_disturbances`) the
    re-planning controller drives a closed-loop run; its re-plans are timed as the loop made them
    (``loop_*``: with the sweeps of prices and the tables of the world's train not yet computed),
    then again from the same states right after (``warm_*``: the train's own policy, its lattice
    and tables computed; also over the states in the first half of the line, and over the states
    that can still be on time, ``on_time_plans_ms``: the others get the flat-out run). Beside them, two
    fresh exact solves of the whole run at the planned time (new solver: tables, price search,
    certificate). Times in ms (re-plans) and s (solves and the policy's build).
    """
    started = _time.process_time()
    policy = OptimalPolicy(case, planned_time_s)
    build_s = _time.process_time() - started
    in_loop, warm, first_half, on_time_plans, fastest = [], [], [], [], 0
    for world in draw_loop_disturbances(case, n_worlds, seed, planned_time_s):
        controller = _RecordingReplanning(policy, PID(), DECIDE_EVERY_S)
        closed_loop(case, controller, world, planned_time_s=planned_time_s)
        in_loop += controller.cpu_s
        for state in controller.states:
            started = _time.process_time()
            rest = plan_for(policy, state)
            warm.append(_time.process_time() - started)
            if math.isfinite(rest.summary["lambda_w"]):
                on_time_plans.append(warm[-1])
            else:  # late beyond recovery: the flat-out run, one simulator run
                fastest += 1
            if state.position_m < 0.5 * float(case.line.length_m):
                first_half.append(warm[-1])
    fresh = []
    for _ in range(2):
        started = _time.process_time()
        OptimalSolver(case).profile(planned_time_s)
        fresh.append(_time.process_time() - started)
    ms = 1000.0
    return {"case": case.name, "length_km": float(case.line.length_m) / 1000.0, "replans": len(warm),
            "fastest": fastest, "build_s": build_s, "loop_median_ms": ms * float(np.median(in_loop)),
            "loop_p90_ms": ms * float(np.percentile(in_loop, 90)), "warm_median_ms": ms * float(np.median(warm)),
            "warm_p90_ms": ms * float(np.percentile(warm, 90)), "first_half_ms": ms * float(np.median(first_half)),
            "on_time_plans_ms": ms * float(np.median(on_time_plans)),
            "fresh_s": float(np.median(fresh))}
