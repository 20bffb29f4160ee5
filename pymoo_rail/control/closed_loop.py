"""Closed-loop runs: a disturbed "real" train driven by a controller that may re-plan on the way.

The real train is the simulator's model of the case with the disturbances of
:class:`~pymoo_rail.control.Disturbance` (mass, adhesion, speed-sensor noise, traction lag) and
those of :class:`LoopDisturbance`: a late departure, running-resistance and regeneration-efficiency
errors, and a temporary speed restriction that the signalling enforces from the start (the
braking envelope keeps it) but that the controller learns only when the train passes
``announce_m``.

A controller (:class:`LoopController`) is asked for a reference curve for the rest of the run at
departure, every ``decide_every_s`` seconds and when the restriction is announced; between two
decisions the low-level tracking controller (hysteresis, PID, fuzzy PID) follows that curve in the
tracking kernel (:func:`pymoo_rail.control.kernel.track_trace`, the simulator's integration and
accounting). Three controllers are given, and a user's own is any object with the same three
members:

- :class:`CurveTracking`: the offline optimal curve, never changed;
- :class:`Replanning`: :meth:`OptimalPolicy.replan` from the measured state;
- :class:`Recovery`: when late, maximum traction until the plan's clock is caught up, then coast
  down to the plan's curve and follow it (the time-optimal recovery of a driver without a planner);
- :class:`OptimalControls`: the policy's own controls applied directly (no tracking controller),
  the exact policy a driver's advice is measured against (:mod:`pymoo_rail.control.advice`).
"""

from __future__ import annotations

import math
import time as _time
from dataclasses import dataclass, field, replace
from typing import Protocol

import numpy as np

from pymoo_rail.constants import J_PER_KWH
from pymoo_rail.control import kernel as ck
from pymoo_rail.control.controllers import PID, Controller, SpeedFilter, check_controller, filter_params
from pymoo_rail.control.disturbances import Disturbance, adhesion_limited, disturbed_tracker
from pymoo_rail.control.estimation import ResistanceEstimator, RunMeasurements
from pymoo_rail.control.policy import (OptimalPolicy, SpeedRestriction, model_from, resistance_scaled, restricted_model,
                                      run_trace)
from pymoo_rail.control.tracking import DEFAULT_CONTROL_PERIOD_S
from pymoo_rail.model import Case
from pymoo_rail.model.errors import FieldError, check_number
from pymoo_rail.sim import Simulator, Trajectory
from pymoo_rail.sim import kernel as sk
from pymoo_rail.sim.drivers import flat_out_program
from pymoo_rail.sim.physics import KernelModel, braking_envelope, max_braking, max_traction
from pymoo_rail.sim.trajectory import EnergyBreakdown

DEFAULT_DECIDE_EVERY_S = 10.0


@dataclass(frozen=True)
class LoopDisturbance(Disturbance):
    """A :class:`Disturbance` plus what a closed loop meets on the way (defaults: none).

    ``departure_delay_s``: the train leaves this late on the plan's clock; ``resistance_factor``
    scales the real Davis resistance, ``regen_factor`` the real regeneration efficiency;
    ``restriction`` is enforced from the start and announced to the controller at ``announce_m``.
    """

    departure_delay_s: float = 0.0
    resistance_factor: float = 1.0
    regen_factor: float = 1.0
    restriction: SpeedRestriction | None = None
    announce_m: float = 0.0

    def __post_init__(self) -> None:
        super().__post_init__()
        check_number("departure_delay_s", self.departure_delay_s, nonneg=True, error=FieldError)
        check_number("resistance_factor", self.resistance_factor, positive=True, error=FieldError)
        check_number("regen_factor", self.regen_factor, positive=True, error=FieldError)
        check_number("announce_m", self.announce_m, nonneg=True, error=FieldError)
        if self.restriction is not None and not isinstance(self.restriction, SpeedRestriction):
            raise FieldError("restriction", self.restriction, "must be a SpeedRestriction or None")


def as_loop_disturbance(disturbance: Disturbance | None) -> LoopDisturbance:
    """A :class:`LoopDisturbance` with the fields of ``disturbance`` (None: the nominal train)."""
    if disturbance is None:
        return LoopDisturbance()
    if isinstance(disturbance, LoopDisturbance):
        return disturbance
    if not isinstance(disturbance, Disturbance):
        raise FieldError("disturbance", disturbance, "must be a Disturbance or LoopDisturbance")
    return LoopDisturbance(**{name: getattr(disturbance, name) for name in Disturbance.__dataclass_fields__})


def real_model(case: Case, disturbance: LoopDisturbance, dx_m: float | None = None) -> KernelModel:
    """The kernels' model of the real train: disturbed mass, adhesion, resistance, regeneration, restriction."""
    model = disturbed_tracker(case, PID(), disturbance, dx_m=dx_m).simulator.model
    model = resistance_scaled(model, float(disturbance.resistance_factor))
    model = model._replace(regen_efficiency=min(model.regen_efficiency * disturbance.regen_factor, 1.0),
                           regen_map_values=None if model.regen_map_values is None else
                           np.minimum(model.regen_map_values * disturbance.regen_factor, 1.0))
    if disturbance.restriction is not None:
        disturbance.restriction.check_on(case)
        return restricted_model(model, disturbance.restriction, float(case.train.length_m))
    return model._replace(envelope_ms=braking_envelope(model))


@dataclass(frozen=True)
class LoopState:
    """What a controller knows when it decides: the measured state and the line as announced.

    ``event`` is ``"departure"``, ``"period"`` or ``"announcement"``; ``mass_t`` is the train's
    measured mass (weighed at departure), ``adhesion_factor`` the rail's adhesion as the ATP knows it
    (its braking curves, and so the real train's braking envelope, use it); ``measured`` the run so
    far as the train's sensors saw it (for an estimator, :mod:`pymoo_rail.control.estimation`).
    """

    position_m: float
    speed_ms: float
    elapsed_s: float
    restriction: SpeedRestriction | None
    mass_t: float
    event: str
    adhesion_factor: float = 1.0
    measured: RunMeasurements | None = None


class LoopController(Protocol):
    """A controller of the closed loop: a reference for the rest of the run at each decision.

    Instead of ``reference`` (followed by ``tracker``), a controller may give ``program(state)``:
    a driving program (``end_m, mode, target_ms`` rows, absolute positions) that drives the real
    train itself until the next decision, as a driver following advice or the optimal controls do.
    An optional ``speed_filter`` (:class:`~pymoo_rail.control.controllers.SpeedFilter`) filters the
    speed the tracker sees (absent or None: the sensor's reading as it is).
    """

    name: str
    tracker: Controller
    decide_every_s: float

    def reference(self, state: LoopState) -> Trajectory:
        """The speed-distance curve to follow from ``state`` until the next decision."""


@dataclass
class CurveTracking:
    """Follow the offline curve ``plan`` with ``tracker`` (no re-planning)."""

    plan: Trajectory
    tracker: Controller
    name: str = "tracking"
    decide_every_s: float = math.inf
    speed_filter: SpeedFilter | None = field(default_factory=SpeedFilter)

    def reference(self, state: LoopState) -> Trajectory:
        """The offline curve, whatever happens."""
        return self.plan


@dataclass
class Replanning:
    """Re-plan the rest with ``policy`` every ``decide_every_s`` seconds and on announcements."""

    policy: OptimalPolicy
    tracker: Controller
    decide_every_s: float = DEFAULT_DECIDE_EVERY_S
    name: str = "replanning"
    cpu_s: list = field(default_factory=list)
    estimator: ResistanceEstimator | None = field(default_factory=ResistanceEstimator)
    speed_filter: SpeedFilter | None = field(default_factory=SpeedFilter)

    def reference(self, state: LoopState) -> Trajectory:
        """The policy's optimal rest of the run, or the fastest run once the plan's time is past."""
        started = _time.process_time()
        ref = plan_for(self.policy, state, self.estimator)
        self.cpu_s.append(_time.process_time() - started)
        return ref


@dataclass
class Recovery:
    """Time-optimal recovery: when late, flat out until the plan's clock is caught up, then coast to the plan."""

    plan: Trajectory
    case: Case
    tracker: Controller
    decide_every_s: float = DEFAULT_DECIDE_EVERY_S
    name: str = "recovery"
    speed_filter: SpeedFilter | None = field(default_factory=SpeedFilter)

    def reference(self, state: LoopState) -> Trajectory:
        """The plan when on time; else flat out, coast down onto the plan's curve, then the plan."""
        plan = self.plan
        late_s = state.elapsed_s - float(np.interp(state.position_m, plan.position_m, plan.time_s))
        if late_s <= 0.0:
            return plan
        sim = Simulator(replace(self.case, train=replace(self.case.train, mass_t=state.mass_t)))
        model = restricted_model(adhesion_limited(sim.model, state.adhesion_factor), state.restriction,
                                 float(self.case.train.length_m))
        node = min(int(round(state.position_m / sim.grid.dx_m)), model.position_m.shape[0] - 2)
        ahead = model_from(model, node, min(state.speed_ms, float(model.envelope_ms[node])))
        length = float(model.position_m[-1])
        flat = run_trace(ahead, flat_out_program(length), state.elapsed_s)
        caught = np.flatnonzero(flat.time_s <= np.interp(flat.position_m, plan.position_m, plan.time_s))
        if caught.size == 0 or caught[0] >= flat.position_m.shape[0] - 2:
            return flat
        j = int(caught[0])
        coast = run_trace(model_from(model, node + j, flat.speed_ms[j]),
                          np.array([[length, sk.MODE_COAST, 0.0]]), float(flat.time_s[j]))
        below = np.flatnonzero(coast.speed_ms <= np.interp(coast.position_m, plan.position_m, plan.speed_ms))
        q = int(below[0]) if below.size else coast.position_m.shape[0] - 1
        x_join = coast.position_m[q]
        rest = plan.position_m > x_join
        x = np.concatenate([flat.position_m[:j], coast.position_m[: q + 1], plan.position_m[rest]])
        v = np.concatenate([flat.speed_ms[:j], coast.speed_ms[: q + 1], plan.speed_ms[rest]])
        r = np.concatenate([flat.regime[:j], coast.regime[: q + 1], plan.regime[rest]])
        f = np.concatenate([flat.force_n[:j], coast.force_n[: q + 1], plan.force_n[rest]])
        t = np.concatenate([flat.time_s[:j], coast.time_s[: q + 1], plan.time_s[rest]])
        return replace(plan, position_m=x, speed_ms=v, regime=r, time_s=t, accel_ms2=np.zeros_like(x), force_n=f,
                       limit_ms=np.zeros_like(x))


@dataclass
class OptimalControls:
    """Apply the policy's optimal controls directly, re-planned every ``decide_every_s`` s and on announcements."""

    policy: OptimalPolicy
    decide_every_s: float = DEFAULT_DECIDE_EVERY_S
    name: str = "optimal controls"
    tracker: Controller | None = None
    estimator: ResistanceEstimator | None = field(default_factory=ResistanceEstimator)

    def program(self, state: LoopState) -> np.ndarray:
        """The driving program of the policy's optimal rest of the run from ``state``."""
        plan_for(self.policy, state, self.estimator)
        return self.policy.last_program


def planner_train(policy: OptimalPolicy, state: LoopState, estimator: ResistanceEstimator | None = None) -> tuple:
    """The planner's train for ``state``: (restriction, mass, adhesion, resistance factor), the last
    updated by ``estimator`` from ``state.measured`` (None: the case's resistance)."""
    resistance = None
    if estimator is not None and state.measured is not None:
        resistance = estimator.update(policy.line_model(None, state.mass_t, state.adhesion_factor), state.measured)
    return state.restriction, state.mass_t, state.adhesion_factor, resistance


def plan_for(policy: OptimalPolicy, state: LoopState, estimator: ResistanceEstimator | None = None) -> Trajectory:
    """The policy's rest of the run from a loop state: :meth:`~OptimalPolicy.replan`, or the fastest run once the plan's time is past.

    With ``estimator``, the planner's running resistance is the one estimated from the run so far
    (:func:`planner_train`). The planner's train may be less able than the real one (a resistance
    error): a state above its braking envelope is taken at the envelope.
    """
    train = planner_train(policy, state, estimator)
    speed = min(state.speed_ms, policy.envelope_ms(state.position_m, *train))
    if state.elapsed_s >= policy.planned_time_s:
        return policy.fastest(state.position_m, speed, state.elapsed_s, *train)
    return policy.replan(state.position_m, speed, state.elapsed_s, *train)


def reference_command(model: KernelModel, reference: Trajectory) -> float:
    """The reference's own command at the model's first node, as a share of the maximum force in [-1, 1]."""
    x0 = float(model.position_m[0])
    k = min(int(np.searchsorted(reference.position_m, x0 + 1e-9, side="right")) - 1, reference.position_m.shape[0] - 1)
    force = float(reference.force_n[max(k, 0)])
    v = float(model.initial_speed_ms)
    if force > 0.0:
        top = max_traction(model, v, 0)
    elif force < 0.0:
        top = max_braking(model, v, 0)
    else:
        return 0.0
    return float(np.clip(force / top, -1.0, 1.0)) if top > 0.0 else math.copysign(1.0, force)


def _decision_period_s(controller) -> float:
    """The controller's ``decide_every_s``, checked (> 0; inf: it never decides again)."""
    every_s = float(controller.decide_every_s)
    if not every_s > 0.0:
        raise FieldError("controller.decide_every_s", controller.decide_every_s, "must be > 0 (inf: never)")
    return every_s


def _reference_on_grid(ref, ahead: KernelModel) -> tuple[float, float, np.ndarray]:
    """End of the reference's first traction phase, start of its final braking, its speed on the grid ahead."""
    x_ref = np.ascontiguousarray(ref.position_m, dtype=float)
    regime = np.ascontiguousarray(ref.regime, dtype=np.int8)
    x_start, x_stop = ck.reference_phases(x_ref, regime, x_ref.shape[0])
    v_ref = np.interp(ahead.position_m, x_ref, np.asarray(ref.speed_ms, dtype=float), right=0.0)
    return x_start, x_stop, v_ref


def _program_leg(ahead: KernelModel, program, every_s: float, x_end: float):
    """A controller's own program run on the real train up to the next decision.

    Returns the trace arrays (position, speed, time, acceleration, force, regime) up to the first
    node at ``every_s`` seconds or at ``x_end``, their length, and whether the run ended there.
    """
    run = run_trace(ahead, program)
    x, vs, ts, a, f, r = (run.position_m, run.speed_ms, run.time_s, run.accel_ms2, run.force_n, run.regime)
    cut = np.flatnonzero((ts[1:] >= every_s - 1e-9) | (x[1:] >= x_end))
    count = x.shape[0] if cut.size == 0 else int(cut[0]) + 2
    finished = count >= x.shape[0]
    return tuple(y[:count] for y in (x, vs, ts, a, f, r)), count, finished


def closed_loop(case: Case, controller: LoopController, disturbance: Disturbance | None = None,
                planned_time_s: float | None = None, control_period_s: float = DEFAULT_CONTROL_PERIOD_S,
                dx_m: float | None = None) -> Trajectory:
    """One closed-loop run of the disturbed real train under ``controller``.

    Parameters
    ----------
    case : Case
        The line and the nominal train the controller was built for.
    controller : LoopController
        :class:`CurveTracking`, :class:`Replanning`, :class:`Recovery` or a user's own.
    disturbance : Disturbance or LoopDisturbance, optional
        The real train and what happens on the way (None: nominal).
    planned_time_s : float, optional
        The plan's running time (default: the case's), for the lateness.
    control_period_s : float
        Period of the low-level tracking controller.
    dx_m : float, optional
        Grid step of the real train's simulator.

    Returns
    -------
    Trajectory
        The real train's run on the plan's clock (``time_s[0]`` is the departure delay). Summary:
        ``net_kwh`` and the energy terms, ``running_time_s`` (from departure), ``arrival_s``,
        ``lateness_s`` (arrival minus plan), ``stop_error_m``, ``jerk_ms2`` (acceleration
        variation), ``regime_changes``, ``reached``, ``n_decisions`` and ``decision_points_m``.
    """
    d = as_loop_disturbance(disturbance)
    direct = callable(getattr(controller, "program", None))
    tracker = check_controller(PID() if direct else controller.tracker)
    planned = float(case.planned_time_s if planned_time_s is None else planned_time_s)
    every_s = _decision_period_s(controller)
    model = real_model(case, d, dx_m)
    n = model.position_m.shape[0]
    noise = np.ascontiguousarray(d.noise_ms())
    code, params = int(tracker.code()), np.ascontiguousarray(tracker.params(), dtype=float)
    filter_ab = filter_params(getattr(controller, "speed_filter", None))
    carry = np.zeros(ck.N_CARRY)  # the low-level controller, carried from one reference to the next
    node, v, t = 0, float(model.initial_speed_ms), float(d.departure_delay_s)
    known, pending = None, d.restriction is not None  # the restriction as the controller knows it
    parts: list[tuple] = []
    decisions: list[float] = []
    event = "departure"
    previous = None
    while True:
        if pending and d.announce_m <= float(model.position_m[node]):  # announced before departure
            known, pending = d.restriction, False
        state = LoopState(float(model.position_m[node]), v, t, known, case.train.mass_t * d.mass_factor, event,
                          d.adhesion_factor, measurements(parts, float(model.position_m[node]), v, t, noise,
                                                          float(control_period_s)))
        decisions.append(state.position_m)
        ahead = model_from(model, node, v)
        x_end = float(d.announce_m) if pending and d.announce_m > state.position_m else math.inf
        if direct:  # the controller's program drives the real train itself
            (x, vs, ts, a, f, r), count, finished = _program_leg(ahead, controller.program(state), every_s, x_end)
        else:
            ref = controller.reference(state)
            x_start, x_stop, v_ref = _reference_on_grid(ref, ahead)
            if carry[ck.C_RESUME] > 0.0 and ref is not previous:
                # a new reference: the controller starts from the reference's own command
                ck.align_controller(code, params, carry, reference_command(ahead, ref))
            previous = ref
            out, x, vs, ts, a, f, r, _ = ck.track_trace(ahead, v_ref, float(x_start), float(x_stop), code, params,
                                                        float(control_period_s), noise, float(d.traction_lag_s),
                                                        filter_ab, carry, every_s, x_end)
            carry[ck.C_RESUME] = 1.0
            count = x.shape[0]
            finished = out[sk.OUT_REACHED] == 0.0 or count == ahead.position_m.shape[0]
        keep = slice(0, count) if finished else slice(0, count - 1)
        parts.append((x[keep], vs[keep], ts[keep] + t, a[keep], f[keep], r[keep]))
        if finished:
            break
        if pending and x[-1] >= d.announce_m:
            known, pending, event = d.restriction, False, "announcement"
        else:
            event = "period"
        node += count - 1
        v, t = float(vs[-1]), float(ts[-1] + t)
    return _assemble(model, parts, d, planned, decisions, n)


def measurements(parts: list, position_m: float, speed_ms: float, time_s: float, noise_ms: np.ndarray,
                 period_s: float) -> RunMeasurements | None:
    """The run so far (``parts`` of the closed loop, then the train at its current state) as its sensors saw it.

    Sampled every ``period_s`` from departure (the speed sensor's instants, with the run's own
    sensor noise ``noise_ms`` in turn), and at the current state; the work of the applied force
    sums each grid cell's force times its length. None before the first leg.
    """
    if not parts:
        return None
    x = np.concatenate([p[0] for p in parts] + [[position_m]])
    v = np.concatenate([p[1] for p in parts] + [[speed_ms]])
    t = np.concatenate([p[2] for p in parts] + [[time_s]])
    f = np.concatenate([p[4] for p in parts])
    work = np.concatenate([[0.0], np.cumsum(f * np.diff(x))])
    instants = np.append(np.arange(t[0], t[-1], period_s), t[-1])
    noise = (noise_ms[np.arange(instants.shape[0]) % noise_ms.shape[0]] if noise_ms.size
             else np.zeros(instants.shape[0]))
    noise[0] = 0.0  # standing at departure: the reading is exact
    return RunMeasurements(instants, np.interp(instants, t, x), np.interp(instants, t, v) + noise,
                           np.interp(instants, t, work))


def _assemble(model: KernelModel, parts: list, d: LoopDisturbance, planned: float, decisions: list,
              n_nodes: int) -> Trajectory:
    x, v, t, a, f, r = (np.concatenate([p[k] for p in parts]) for k in range(6))
    trac, regen = sk.trace_cell_energies(model, x, v, f)
    running = float(t[-1] - t[0])
    aux_kwh = model.aux_power_w * running / J_PER_KWH
    energy = EnergyBreakdown(traction_kwh=float(trac.sum() / J_PER_KWH), regen_kwh=float(regen.sum() / J_PER_KWH),
                             aux_kwh=aux_kwh, net_kwh=float((trac.sum() - regen.sum()) / J_PER_KWH + aux_kwh))
    length = float(model.position_m[-1])
    reached = bool(abs(x[-1] - length) <= 0.5 * model.dx_m and v[-1] <= 1e-6)
    cells = a[:-1]
    jerk = float(np.abs(np.diff(np.concatenate([[0.0], cells, [0.0]]))).sum())
    summary = {"traction_kwh": energy.traction_kwh, "regen_kwh": energy.regen_kwh, "aux_kwh": aux_kwh,
               "net_kwh": energy.net_kwh, "running_time_s": running, "arrival_s": float(t[-1]),
               "lateness_s": float(t[-1] - planned), "departure_delay_s": float(d.departure_delay_s),
               "stop_position_m": float(x[-1]), "stop_error_m": abs(length - float(x[-1])), "jerk_ms2": jerk,
               "regime_changes": float(np.count_nonzero(np.diff(r[:-1]))), "reached": float(reached),
               "limit_excess_ms": float(max(np.max(v - model.limit_ms[np.minimum(
                   np.round(x / model.dx_m).astype(int), n_nodes - 1)]), 0.0)),
               "n_decisions": float(len(decisions)), "decision_points_m": decisions}
    return Trajectory(position_m=x, speed_ms=v, time_s=t, accel_ms2=a, force_n=f, regime=r,
                      limit_ms=model.limit_ms[np.minimum(np.round(x / model.dx_m).astype(int), n_nodes - 1)],
                      energy=energy, running_time_s=running, stop_error_m=summary["stop_error_m"], summary=summary)
