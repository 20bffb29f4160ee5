"""An optimal policy that re-plans the rest of the run from wherever the train is.

:class:`OptimalPolicy` is built once for a case and a planned arrival from the exact solver
(:mod:`pymoo_rail.optimal`). Its cost-to-go ``V_lambda(x, v)`` (the least ``net energy + lambda x
time`` from position ``x`` at speed ``v`` to the platform) answers "what is optimal from here" for
a whole grid of states at once, so a re-plan needs no new solve:

1. ``V_lambda`` is kept for a lattice of prices of time, ``lambda_k + P_aux = (lambda_plan + P_aux) r^k`` (computed
   lazily, each by one backward sweep over the line still ahead);
2. ``dV/dlambda`` is the running time of the optimal rest of the run (envelope theorem), so the
   slope of ``V`` between two neighbouring prices, read at the train's state, says which price
   arrives on time: no forward run is needed to choose it;
3. one forward run of the DP from the state at that price, then the last switch into the final
   coast is moved (a few simulator runs) until the run arrives at the planned time (where that
   is not enough, the cost-to-go between the two neighbouring prices is interpolated, by bisection);
4. the energy's lower bound comes from weak duality, ``E*(T) >= V_lambda(x, v) - lambda T`` for
   every price computed: the re-plan's certificate costs nothing more.

A temporary speed restriction changes the braking envelope only over a stretch before its end:
the transition tables are recomputed for the cells of that stretch alone and the cost-to-go of
the line behind the train is swept again. A measured mass changes every cell (new tables).
"""

from __future__ import annotations

import math
import time as _time
from dataclasses import dataclass, replace

import numpy as np

from pymoo_rail.constants import J_PER_KWH, KMH_PER_MS
from pymoo_rail.control.disturbances import adhesion_limited
from pymoo_rail.model import Case
from pymoo_rail.model.errors import FieldError, check_number
from pymoo_rail.optimal import OptimalSolver, dp
from pymoo_rail.sim import Trajectory
from pymoo_rail.sim import kernel as sk
from pymoo_rail.sim.drivers import flat_out_program, replaced_rows
from pymoo_rail.sim.physics import KernelModel, braking_envelope
from pymoo_rail.sim.trajectory import energy_from_summary, summary_dict

# Neighbouring prices of time of the lattice differ by this factor: on yizhuang one step moves the
# running time by about 3 s near the plan, which the moved last switch covers at second-order cost
PRICE_RATIO = 1.1
# Lattice entries kept per line variant (each is n_nodes x n_speeds doubles: 15 MB on 48 km)
MAX_PRICES_KEPT = 12
# Line variants (a measured mass, a restriction) kept with their tables and cost-to-go, the
# case's own included: a closed-loop study meets a new one in every world
MAX_LINES_KEPT = 4
# The re-planned run arrives within this of the plan when it can (the moved switch's resolution)
ARRIVAL_TOL_S = 0.25
# A re-planned run counts as on time within this of the plan (moving the switch by one cell
# changes the time by dx / v: 0.07 s at 50 km/h on a 1 m grid)
ON_TIME_TOL_S = 1.0
# Bounds of the total price of time (lambda plus the auxiliary power) the lattice spans
TIME_PRICE_MIN_W = 1.0e2
TIME_PRICE_MAX_W = 1.0e10


@dataclass(frozen=True)
class SpeedRestriction:
    """A temporary speed restriction: ``limit_kmh`` for the whole train between ``start_m`` and ``end_m``."""

    start_m: float
    end_m: float
    limit_kmh: float

    def __post_init__(self) -> None:
        for name in ("start_m", "end_m"):
            check_number(f"restriction.{name}", getattr(self, name), nonneg=True, error=FieldError)
        check_number("restriction.limit_kmh", self.limit_kmh, positive=True, error=FieldError)
        if self.end_m <= self.start_m:
            raise FieldError("restriction.end_m", self.end_m, f"must be above start_m = {self.start_m}")

    @classmethod
    def parse(cls, text: str) -> SpeedRestriction:
        """``"3000:3600:40"`` (start m, end m, limit km/h), the command line's form."""
        parts = str(text).split(":")
        if len(parts) != 3:
            raise FieldError("restriction", text, "must be START_M:END_M:LIMIT_KMH, e.g. 3000:3600:40")
        try:
            values = [float(p) for p in parts]
        except ValueError:
            raise FieldError("restriction", text, "must be three numbers START_M:END_M:LIMIT_KMH") from None
        return cls(*values)

    def check_on(self, case: Case) -> None:
        """Raise :class:`FieldError` unless the restriction lies on the case's line."""
        length = float(case.line.length_m)
        if self.end_m > length:
            raise FieldError("restriction.end_m", self.end_m, f"is beyond the end of the line ({length} m)")


def restricted_model(model: KernelModel, restriction: SpeedRestriction | None, train_length_m: float) -> KernelModel:
    """The kernels' model with a temporary restriction added to its limits, and its braking envelope rebuilt.

    The restriction binds the head wherever any part of the train is in it, the rule of the
    case's own limits (:func:`pymoo_rail.model.build_grid`).
    """
    if restriction is None:
        return model
    x = model.position_m
    covered = (restriction.start_m < x + model.dx_m) & (restriction.end_m > x - train_length_m)
    limit = model.limit_ms.copy()
    limit[covered] = np.minimum(limit[covered], restriction.limit_kmh / KMH_PER_MS)
    restricted = model._replace(limit_ms=limit)
    return restricted._replace(envelope_ms=braking_envelope(restricted))


def resistance_scaled(model: KernelModel, factor: float) -> KernelModel:
    """The kernels' model with its Davis running resistance multiplied by ``factor`` (1: unchanged).

    The braking envelope is rebuilt: the resistance helps the brakes.
    """
    if factor == 1.0:
        return model
    m = model._replace(davis_a_n=model.davis_a_n * factor, davis_b_nsm=model.davis_b_nsm * factor,
                       davis_c_ns2m2=model.davis_c_ns2m2 * factor)
    return m._replace(envelope_ms=braking_envelope(m))


def model_from(model: KernelModel, node: int, speed_ms: float) -> KernelModel:
    """The model of the line ahead of grid node ``node``, with the train at ``speed_ms`` there.

    Positions stay absolute; the kernels read a model cell by cell, so a run of this model is the
    rest of a run of the whole one.
    """
    return model._replace(position_m=model.position_m[node:], limit_ms=model.limit_ms[node:],
                          grade_force_n=model.grade_force_n[node:], line_force_n=model.line_force_n[node:],
                          neutral=model.neutral[node:], envelope_ms=model.envelope_ms[node:],
                          initial_speed_ms=float(speed_ms))


def run_trace(model: KernelModel, program: np.ndarray, start_s: float = 0.0) -> Trajectory:
    """The simulator's run of ``program`` on ``model`` (e.g. :func:`model_from`), clock starting at ``start_s``."""
    out, x, v, t, a, f, r = sk.simulate_trace(model, np.ascontiguousarray(program, dtype=float))
    x = x.copy()
    x[0] = model.position_m[0]  # the kernel writes the start of the line as 0
    return Trajectory(position_m=x, speed_ms=v, time_s=t + start_s, accel_ms2=a, force_n=f, regime=r,
                      limit_ms=model.limit_ms[: x.shape[0]], energy=energy_from_summary(out),
                      running_time_s=float(out[sk.OUT_RUNNING_TIME_S]),
                      stop_error_m=float(out[sk.OUT_STOP_ERROR_M]), summary=summary_dict(out))


def merged_tables(old_model: KernelModel, old_tables: tuple, new_model: KernelModel, n_speeds: int,
                  max_targets: int, bias: float) -> tuple:
    """Transition tables of ``new_model`` from those of ``old_model``, recomputing only the cells whose envelope changed.

    A cell's transitions read its line force, neutral flag, the envelope at its two ends and
    whether it is the last cell (:func:`pymoo_rail.optimal.dp.cell_types`); a restriction changes
    the envelope over a stretch before its end only. The rows of the recomputed cells are appended.
    """
    changed = np.flatnonzero(new_model.envelope_ms != old_model.envelope_ms)
    if changed.size == 0:
        return old_tables
    n_cells = old_model.position_m.shape[0] - 1
    first = max(int(changed[0]) - 1, 0)
    last = min(int(changed[-1]), n_cells - 1)
    # one cell more than needed, so that the stretch's own last cell is not taken for the line's last
    end_node = min(last + 3, n_cells + 1)
    sub = new_model._replace(position_m=new_model.position_m[first:end_node],
                             limit_ms=new_model.limit_ms[first:end_node],
                             grade_force_n=new_model.grade_force_n[first:end_node],
                             line_force_n=new_model.line_force_n[first:end_node],
                             neutral=new_model.neutral[first:end_node], envelope_ms=new_model.envelope_ms[first:end_node])
    fixed_u1, fixed_e, fixed_dt, offsets, tgt_u1, tgt_e, tgt_dt, cell_type = old_tables
    s_u1, s_e, s_dt, s_off, s_tu1, s_te, s_tdt, s_type = dp.transitions(sub, n_speeds, max_targets, bias)
    n_old = fixed_u1.shape[0]
    new_type = cell_type.copy()
    new_type[first:last + 1] = n_old + s_type[: last + 1 - first]
    return (np.concatenate([fixed_u1, s_u1]), np.concatenate([fixed_e, s_e]), np.concatenate([fixed_dt, s_dt]),
            np.concatenate([offsets[:-1], s_off + offsets[-1]]), np.concatenate([tgt_u1, s_tu1]),
            np.concatenate([tgt_e, s_te]), np.concatenate([tgt_dt, s_tdt]), new_type)


class _Line:
    """What the policy knows of one variant of the line and train: model, tables, cost-to-go per price."""

    def __init__(self, model: KernelModel, tables: tuple, terminal_j: np.ndarray):
        self.model = model
        self.tables = tables
        self.terminal_j = terminal_j  # cost-to-go at the end of the line (the case's end speed)
        self.values: dict[int, tuple[int, np.ndarray]] = {}  # lattice index -> (first valid node, V)
        self.last_k = 0


class OptimalPolicy:
    """The energy-optimal rest of the run from any state, arriving at the planned time.

    Parameters
    ----------
    case : Case
        The line and the nominal train.
    planned_time_s : float
        Planned running time from departure (s), at least the minimum running time.
    **settings
        Grid settings of :class:`pymoo_rail.optimal.OptimalSolver` (``dx_m``, ``n_speeds``, ...).

    Attributes
    ----------
    plan : Trajectory
        The exact optimum for ``planned_time_s`` from departure (with its certificate).
    lambda_w : float
        Its price of time (W), the centre of the lattice of prices the policy keeps.
    n_sweeps : int
        Backward sweeps done so far (a re-plan that reuses the lattice does none).
    last_program : array (rows, 3 or 4)
        The driving program (``end_m, mode, target_ms`` and, where the train has a varying traction
        efficiency map, the traction share of part-power rows; absolute positions) of the last run
        returned: the optimal controls themselves, for a controller that applies them directly.

    Examples
    --------
    >>> from pymoo_rail.cases import load_case
    >>> policy = OptimalPolicy(load_case("metro-a"), 70.0)
    >>> rest = policy.replan(400.0, 15.0, 30.0)
    >>> abs(rest.running_time_s - 70.0) < 0.5
    True
    """

    def __init__(self, case: Case, planned_time_s: float, **settings):
        self.case = case
        self.planned_time_s = check_number("planned_time_s", planned_time_s, positive=True, error=FieldError)
        self.solver = OptimalSolver(case, **settings)
        self.plan = self.solver.profile(self.planned_time_s)
        self.lambda_w = float(self.plan.summary["lambda_w"])
        bound = float(self.plan.summary.get("energy_bound_kwh", 0.0))
        # the grid's share of the certificate, carried over to the re-planned runs (an estimate)
        self.grid_bound_rel = bound / max(abs(self.plan.energy.net_kwh), 1e-12)
        self.n_speeds = self.solver.n_speeds
        self.max_targets = self.solver.max_targets
        self.bias = self.solver.top_bias
        self.tie_j = self.solver.tie_j
        self.n_sweeps = 0
        self.last_program: np.ndarray | None = None
        self._lines: dict[tuple, _Line] = {}
        model = self.solver.simulator.model
        self.dx_m = float(self.solver.dx_m)
        self.aux_w = float(model.aux_power_w)
        self._lines[(self.case.train.mass_t, 1.0, 1.0, None)] = _Line(model, self.solver.transition_tables(),
                                                            self._terminal(model))

    def _terminal(self, model: KernelModel) -> np.ndarray:
        return dp.terminal_cost(model, self.n_speeds, self.bias, self.case.end_speed_window_ms()[0])

    def _forget_lines(self) -> None:
        """Keep the case's own line and the most recently used others (each holds tables and sweeps)."""
        nominal = (self.case.train.mass_t, 1.0, 1.0, None)
        others = [key for key in self._lines if key != nominal]
        for key in others[: max(len(others) - (MAX_LINES_KEPT - 1), 0)]:
            del self._lines[key]

    # ------------------------------------------------------------------ inputs
    def _check_state(self, model: KernelModel, position_m, speed_ms, elapsed_s,
                     before_plan: bool = True) -> tuple[int, float, float]:
        length = float(model.position_m[-1])
        x = check_number("position_m", position_m, nonneg=True, error=FieldError)
        if x > length:
            raise FieldError("position_m", position_m, f"is beyond the end of the line ({length} m)")
        v = check_number("speed_ms", speed_ms, nonneg=True, error=FieldError)
        t = check_number("elapsed_s", elapsed_s, nonneg=True, error=FieldError)
        if before_plan and t > self.planned_time_s:
            raise FieldError("elapsed_s", elapsed_s, f"is past the planned arrival ({self.planned_time_s} s); "
                                                     "use fastest() for the earliest arrival")
        node = min(int(round(x / self.dx_m)), model.position_m.shape[0] - 1)
        if node == model.position_m.shape[0] - 1:
            raise FieldError("position_m", position_m, "is at the platform: nothing is left to plan")
        top = float(model.envelope_ms[node])
        if v > top * (1.0 + 1e-9) + 1e-12:
            raise FieldError("speed_ms", speed_ms, f"is above the braking envelope at {model.position_m[node]:.1f} m "
                                                   f"({top:.4f} m/s, {top * KMH_PER_MS:.2f} km/h): the train cannot "
                                                   "keep the limits ahead")
        return node, min(v, top), t

    def _line(self, restriction: SpeedRestriction | None, mass_t: float | None,
              adhesion_factor: float | None = None, resistance_factor: float | None = None) -> _Line:
        if restriction is not None:
            if not isinstance(restriction, SpeedRestriction):
                raise FieldError("restriction", restriction, "must be a SpeedRestriction (start_m, end_m, limit_kmh)")
            restriction.check_on(self.case)
        mass = self.case.train.mass_t if mass_t is None else check_number("mass_t", mass_t, positive=True,
                                                                          error=FieldError)
        adhesion = 1.0 if adhesion_factor is None else check_number("adhesion_factor", adhesion_factor,
                                                                    positive=True, error=FieldError)
        if adhesion > 1.0:
            raise FieldError("adhesion_factor", adhesion_factor, "must be at most 1 (a share of the nominal forces)")
        resistance = 1.0 if resistance_factor is None else check_number("resistance_factor", resistance_factor,
                                                                        positive=True, error=FieldError)
        key = (mass, adhesion, resistance, restriction)
        if key in self._lines:
            self._lines[key] = self._lines.pop(key)  # most recently used last
            return self._lines[key]
        base_key = (mass, adhesion, resistance, None)
        if base_key not in self._lines:  # a measured mass, adhesion or resistance changes every cell: new tables
            case = replace(self.case, train=replace(self.case.train, mass_t=mass))
            solver = OptimalSolver(case, self.dx_m, self.n_speeds, self.max_targets, top_bias=self.bias,
                                   tie_j=self.tie_j, certify=False)
            # before any table
            solver.simulator.model = resistance_scaled(adhesion_limited(solver.simulator.model, adhesion), resistance)
            self._lines[base_key] = _Line(solver.simulator.model, solver.transition_tables(),
                                          self._terminal(solver.simulator.model))
        base = self._lines[base_key]
        if restriction is None:
            self._forget_lines()
            return base
        model = restricted_model(base.model, restriction, float(self.case.train.length_m))
        tables = merged_tables(base.model, base.tables, model, self.n_speeds, self.max_targets, self.bias)
        self._lines[key] = line = _Line(model, tables, base.terminal_j)
        line.last_k = base.last_k
        self._forget_lines()
        return line

    def line_model(self, restriction: SpeedRestriction | None = None, mass_t: float | None = None,
                   adhesion_factor: float | None = None, resistance_factor: float | None = None) -> KernelModel:
        """The planner's model of the whole line and train (the arguments as :meth:`replan`'s)."""
        return self._line(restriction, mass_t, adhesion_factor, resistance_factor).model

    def envelope_ms(self, position_m: float, restriction: SpeedRestriction | None = None,
                    mass_t: float | None = None, adhesion_factor: float | None = None,
                    resistance_factor: float | None = None) -> float:
        """The planner's braking envelope at the grid node nearest ``position_m`` (m/s): the highest speed it plans from."""
        model = self._line(restriction, mass_t, adhesion_factor, resistance_factor).model
        node = min(max(int(round(float(position_m) / self.dx_m)), 0), model.position_m.shape[0] - 1)
        return float(model.envelope_ms[node])

    def model_ahead(self, position_m: float, speed_ms: float, restriction: SpeedRestriction | None = None,
                    mass_t: float | None = None, adhesion_factor: float | None = None,
                    resistance_factor: float | None = None) -> KernelModel:
        """The planner's model of the line ahead of ``position_m`` (nearest node) with the train at ``speed_ms``."""
        model = self._line(restriction, mass_t, adhesion_factor, resistance_factor).model
        node = min(max(int(round(float(position_m) / self.dx_m)), 0), model.position_m.shape[0] - 2)
        return model_from(model, node, min(float(speed_ms), float(model.envelope_ms[node])))

    # ------------------------------------------------------------------ the lattice of prices
    def _price(self, k: int) -> float:
        # geometric in the total price of time: towards cheap prices time becomes free (lambda ->
        # -P_aux), so a train ahead of its plan is not driven faster to save auxiliary energy
        return (self.lambda_w + self.aux_w) * PRICE_RATIO ** k - self.aux_w

    def _entry(self, line: _Line, k: int, node: int) -> tuple:
        """Cost-to-go at lattice price ``k``, valid from ``node`` on (swept over the line ahead only).

        Returns ``(value, sing_v, sing_p, sing_val)``: the cost-to-go at the speed nodes and at the
        price's singular speeds (:func:`pymoo_rail.optimal.dp.singular_speeds`), as the solver keeps them.
        """
        entry = line.values.get(k)
        if entry is not None and entry[0] <= node:
            return entry[1]
        m = line.model
        n = m.position_m.shape[0]
        arrays = (np.zeros((n, self.n_speeds)), np.zeros((n, 2)), np.full((n, 2), -1.0), np.zeros((n, 2))) \
            if entry is None else entry[1]
        value, sing_v, sing_p, sing_val = arrays
        prices = np.full(n - 1 - node, self._price(k))
        ahead = model_from(m, node, 0.0)
        tables = line.tables[:-1] + (np.ascontiguousarray(line.tables[-1][node:]),)
        dp.singular_speeds(ahead, prices + m.aux_power_w, self.n_speeds, self.bias, sing_v[node:], sing_p[node:])
        dp.backward_sweep(ahead, prices, *tables, value[node:], np.zeros(n - node, dtype=np.int64), line.terminal_j,
                          sing_v[node:], sing_p[node:], sing_val[node:], self.max_targets, self.bias,
                          dp.curve_controls(ahead, sing_v[node:, dp.N_SINGULAR:], sing_p[node:, dp.N_SINGULAR:],
                                            self.n_speeds, self.max_targets, self.bias))
        self.n_sweeps += 1
        line.values[k] = (node, arrays)
        if len(line.values) > MAX_PRICES_KEPT:  # forget the price farthest from this one
            far = max(line.values, key=lambda j: abs(j - k))
            del line.values[far]
        return arrays

    def _cost_to_go(self, line: _Line, k: int, node: int, speed_ms: float) -> float:
        m = line.model
        value, _, sing_p, sing_val = self._entry(line, k, node)
        where = dp.value_position(m.envelope_ms[node] ** 2, speed_ms ** 2, self.n_speeds - 1, self.bias)
        return float(dp.interp_aug(value[node], where, sing_p[node], sing_val[node]))

    def _run_time_between(self, line: _Line, k: int, node: int, speed_ms: float) -> float:
        """Running time of the optimal rest of the run between prices k and k + 1: dV/dlambda."""
        d_value = self._cost_to_go(line, k + 1, node, speed_ms) - self._cost_to_go(line, k, node, speed_ms)
        return d_value / (self._price(k + 1) - self._price(k))

    def _choose_price(self, line: _Line, node: int, speed_ms: float, remaining_s: float) -> int:
        """The lattice price whose neighbouring slopes bracket the remaining time (V is concave in lambda).

        A galloping search from the last price chosen: a re-plan close to the last one tests one or
        two prices, already swept; a large change (a late departure) doubles its steps.
        """
        total = self.lambda_w + self.aux_w
        k_min = int(math.floor(math.log(TIME_PRICE_MIN_W / total) / math.log(PRICE_RATIO)))
        k_max = int(math.ceil(math.log(TIME_PRICE_MAX_W / total) / math.log(PRICE_RATIO)))

        def too_slow(k: int) -> bool:  # between prices k and k + 1 the rest still takes too long
            return k < k_max and self._run_time_between(line, k, node, speed_ms) > remaining_s + ARRIVAL_TOL_S

        def too_fast(k: int) -> bool:  # between prices k - 1 and k it is already too fast
            return k > k_min and self._run_time_between(line, k - 1, node, speed_ms) < remaining_s - ARRIVAL_TOL_S

        k = min(max(line.last_k, k_min), k_max)
        if too_slow(k):
            wrong, step = too_slow, 1
        elif too_fast(k):
            wrong, step = too_fast, -1
        else:
            return k
        right = k
        while wrong(right):  # gallop until the condition no longer holds (or a bound)
            k = right
            right = min(max(k + step, k_min), k_max)
            if right == k:
                break
            step *= 2
        while abs(right - k) > 1:
            mid = (k + right) // 2
            if wrong(mid):
                k = mid
            else:
                right = mid
        line.last_k = right
        return right

    # ------------------------------------------------------------------ the runs
    def _rollout(self, line: _Line, k: int, node: int, speed_ms: float, share: float = 0.0) -> np.ndarray:
        """The DP's forward run from the state at lattice price ``k`` (or ``share`` of the way to ``k + 1``).

        Between two lattice prices the cost-to-go is interpolated linearly in the price (the
        supporting lines of the front at both ends): the run in between when neither end, nor
        its moved last switch, meets the time.
        """
        model = model_from(line.model, node, speed_ms)
        value, sing_v, sing_p, sing_val = (a[node:] for a in self._entry(line, k, node))
        price_w = self._price(k)
        if share > 0.0:
            # the singular speeds differ between the prices: the mixed run keeps to the speed nodes
            value = (1.0 - share) * value + share * self._entry(line, k + 1, node)[0][node:]
            price_w = (1.0 - share) * price_w + share * self._price(k + 1)
            sing_v, sing_p, sing_val = np.zeros_like(sing_v), np.full_like(sing_p, -1.0), np.zeros_like(sing_val)
        n = model.position_m.shape[0]
        price = np.full(n - 1, price_w + model.aux_power_w)
        # part-power traction among the controls where the train has a varying traction efficiency map
        modes, targets, _, done, *_ = dp.forward_run(model, price, np.ascontiguousarray(value), self.max_targets,
                                                     self.bias, self.tie_j, np.ascontiguousarray(sing_v),
                                                     np.ascontiguousarray(sing_p), np.ascontiguousarray(sing_val))
        if done < n - 1:
            raise FieldError("speed_ms", speed_ms, f"leaves no way to the platform from {model.position_m[0]:.1f} m")
        return np.column_stack([model.position_m[1:], modes.astype(float), targets])

    def _on_time_program(self, line: _Line, k: int, node: int, speed_ms: float, model: KernelModel,
                         remaining_s: float) -> tuple[np.ndarray, float]:
        """The run at price ``k`` with its last switch moved to the time; if that misses, a price between
        ``k`` and its neighbour on the other side of the time, by bisection. Returns (program, price)."""
        program = self.meet_time(model, self._rollout(line, k, node, speed_ms), remaining_s)
        miss = self._times(model, program[None])[0] - remaining_s
        if abs(miss) <= ARRIVAL_TOL_S:
            return program, self._price(k)
        lo = k if miss > 0 else k - 1  # the time lies between prices lo and lo + 1
        # the share of the way from lo to lo + 1: 0 runs slower, 1 faster
        slow, fast = 0.0, 1.0
        best = (abs(miss), program, self._price(k))
        for _ in range(8):
            share = 0.5 * (slow + fast)
            trial = self.meet_time(model, self._rollout(line, lo, node, speed_ms, share), remaining_s)
            late = self._times(model, trial[None])[0] - remaining_s
            price = (1.0 - share) * self._price(lo) + share * self._price(lo + 1)
            if abs(late) < best[0]:
                best = (abs(late), trial, price)
            if abs(late) <= ARRIVAL_TOL_S:
                break
            if late > 0:
                slow = share
            else:
                fast = share
        return best[1], best[2]

    @staticmethod
    def _times(model: KernelModel, programs: np.ndarray) -> np.ndarray:
        out = sk.simulate_batch_serial(model, np.ascontiguousarray(programs))
        return np.where(out[:, sk.OUT_REACHED] > 0, out[:, sk.OUT_RUNNING_TIME_S], np.inf)

    @classmethod
    def meet_time(cls, model: KernelModel, program: np.ndarray, remaining_s: float) -> np.ndarray:
        """Move the program's last switch into its final coast until its run takes ``remaining_s``.

        An earlier coast point makes the run slower, a later one faster; at an optimum the coast
        point trades time for energy at the price of time, so a small move stays near the front.
        Returns the program whose run is closest to ``remaining_s`` (the input if no move helps).
        """
        modes = program[:, 1]
        coast = modes == sk.MODE_COAST
        braking = modes == sk.MODE_BRAKE
        powered = np.flatnonzero(~coast & ~braking)
        if powered.size == 0:
            return program
        last = int(powered[-1])
        base_time = cls._times(model, program[None])[0]
        if abs(base_time - remaining_s) <= ARRIVAL_TOL_S:
            return program
        too_slow = base_time > remaining_s
        keep = sk.MODE_TRACTION if modes[last] == sk.MODE_TRACTION else sk.MODE_HOLD_BRAKE

        def moved(j: int) -> np.ndarray:
            if too_slow:  # power j cells longer
                return replaced_rows(program, slice(last + 1, last + 1 + j), keep)
            return replaced_rows(program, slice(max(last + 1 - j, 0), last + 1), sk.MODE_COAST)  # coast j cells earlier

        lo, hi = 0, (program.shape[0] - 1 - last) if too_slow else last + 1
        if hi == 0:
            return program
        # lo: on the side of the base run, hi: past the request (or the farthest move possible)
        if (cls._times(model, moved(hi)[None])[0] > remaining_s) == too_slow:
            return moved(hi)
        while hi - lo > 1:
            mid = (lo + hi) // 2
            if (cls._times(model, moved(mid)[None])[0] > remaining_s) == too_slow:
                lo = mid
            else:
                hi = mid
        times = cls._times(model, np.stack([moved(lo), moved(hi)]))
        return moved(lo) if abs(times[0] - remaining_s) <= abs(times[1] - remaining_s) else moved(hi)

    def fastest(self, position_m: float, speed_ms: float, elapsed_s: float,
                restriction: SpeedRestriction | None = None, mass_t: float | None = None,
                adhesion_factor: float | None = None, resistance_factor: float | None = None) -> Trajectory:
        """The earliest arrival from a state: maximum traction, held at the limits, latest braking.

        Unlike :meth:`replan`, ``elapsed_s`` may be past the planned arrival.
        """
        line = self._line(restriction, mass_t, adhesion_factor, resistance_factor)
        node, v, elapsed = self._check_state(line.model, position_m, speed_ms, elapsed_s, before_plan=False)
        model = model_from(line.model, node, v)
        self.last_program = flat_out_program(float(model.position_m[-1]))
        tr = run_trace(model, self.last_program, elapsed)
        return self._finish(tr, elapsed, math.inf, math.nan,
                            on_time=abs(tr.time_s[-1] - self.planned_time_s) <= ON_TIME_TOL_S)

    def _finish(self, tr: Trajectory, elapsed_s: float, lambda_w: float, lower_j: float, on_time: bool,
                cpu_s: float = math.nan) -> Trajectory:
        arrival = float(tr.time_s[-1])
        energy_kwh = tr.energy.net_kwh
        gap_kwh = energy_kwh - lower_j / J_PER_KWH if math.isfinite(lower_j) else math.nan
        bound = max(gap_kwh, 0.0) + self.grid_bound_rel * abs(energy_kwh) if math.isfinite(gap_kwh) else math.nan
        summary = dict(tr.summary, lambda_w=lambda_w, elapsed_s=elapsed_s, remaining_time_s=tr.running_time_s,
                       arrival_s=arrival, planned_time_s=self.planned_time_s, lateness_s=arrival - self.planned_time_s,
                       on_time=float(on_time), energy_bound_kwh=bound, replan_cpu_s=cpu_s)
        return replace(tr, running_time_s=arrival, summary=summary)

    def replan(self, position_m: float, speed_ms: float, elapsed_s: float,
               restriction: SpeedRestriction | None = None, mass_t: float | None = None,
               adhesion_factor: float | None = None, resistance_factor: float | None = None) -> Trajectory:
        """The optimal rest of the run from a state, arriving at the planned time.

        Parameters
        ----------
        position_m : float
            Where the train is (m from the start; taken at the nearest grid node).
        speed_ms : float
            Its speed (m/s), at most the braking envelope there.
        elapsed_s : float
            Time since the planned departure (s), at most ``planned_time_s``: a late departure is
            a departure with ``elapsed_s`` > 0.
        restriction : SpeedRestriction, optional
            A temporary speed restriction on the line (known from now on).
        mass_t : float, optional
            The measured train mass (t), if it differs from the case's.
        adhesion_factor : float, optional
            The rail's adhesion as a share (<= 1) of the nominal traction and braking force peaks,
            as the ATP knows it (its braking curves use it): the planner's train gets the same caps.
        resistance_factor : float, optional
            The running resistance as a multiple of the case's Davis resistance, e.g. estimated on
            the way (:class:`pymoo_rail.control.estimation.ResistanceEstimator`).

        Returns
        -------
        Trajectory
            The simulator's run of the rest: positions from the train's node to the platform, the
            clock continuing from ``elapsed_s`` (``running_time_s`` is the arrival time on that
            clock, ``energy`` the energy from here). ``summary`` adds ``lambda_w`` (price of time
            of the run), ``lateness_s`` (arrival minus plan), ``on_time`` (1.0 when within
            ``ON_TIME_TOL_S`` of the plan; a train that even the fastest run brings in later
            than ``planned - ARRIVAL_TOL_S`` is planned ``ARRIVAL_TOL_S`` behind the fastest run,
            the earliest arrival but for a quarter of a second that costs the most energy; when even
            the cheapest run of the lattice arrives early, that run),
            ``energy_bound_kwh`` (estimated bound above the optimum at the run's time: the duality
            gap to the cost-to-go of every price computed plus the plan's grid share) and
            ``replan_cpu_s``.

        Raises
        ------
        FieldError
            A state off the line or at the platform, a speed above the braking envelope, a time
            past the plan, a restriction beyond the line, a mass or resistance factor that is not a positive
            number.
        """
        started = _time.process_time()
        line = self._line(restriction, mass_t, adhesion_factor, resistance_factor)
        node, v, elapsed = self._check_state(line.model, position_m, speed_ms, elapsed_s)
        remaining = self.planned_time_s - elapsed
        model = model_from(line.model, node, v)
        fastest = flat_out_program(float(model.position_m[-1]))
        t_min = self._times(model, fastest[None])[0]
        # A train that cannot be on time, or only just (metro-a's last coast), is planned
        # ARRIVAL_TOL_S behind the fastest run: the last fraction of a second of the front costs
        # the most energy (on metro-a's late worlds flat out paid 3.2 % above the exact optimum at
        # its own time, the run just behind it 0.5 %, arriving 0.6 s later at the median)
        target = max(remaining, t_min + ARRIVAL_TOL_S)
        k = self._choose_price(line, node, v, target)
        program, price_w = self._on_time_program(line, k, node, v, model, target)
        self.last_program = program
        tr = run_trace(model, program, elapsed)
        # weak duality: E*(T) >= V_lambda(state) - lambda T for every price swept so far
        lower = max(self._cost_to_go(line, j, node, v) - self._price(j) * target
                    for j, (first, _) in list(line.values.items()) if first <= node)
        on_time = abs(tr.time_s[-1] - self.planned_time_s) <= ON_TIME_TOL_S
        return self._finish(tr, elapsed, price_w, lower, on_time, _time.process_time() - started)
