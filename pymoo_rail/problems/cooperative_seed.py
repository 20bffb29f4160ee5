"""The paper's own encoding of two trains sharing braking energy (Chen et al. 2017), for reproduction.

``CooperativeSeedProblem`` is :class:`~pymoo_rail.problems.CooperativeTrainsProblem` in the paper's
decision vector, with the paper's repair and nested GA; it needs them (random vectors are on time
only 2-4 % of the time), which the paced encoding of ``CooperativeTrainsProblem`` does not.

Train A runs leg 0 of a two-leg case (station 1 -> 2), train B leg 1 (station 2 -> 3); B leaves
station 2 ``offset_s`` seconds after A leaves station 1 (the paper's x; negative: B leaves first).
Both legs lie in one power-supply section, so while one train brakes the other can draw the
regenerated power (with utilisation eta, the case's ``regen_efficiency``). B runs ahead of A on
the line, so A is the following train of the separation rule (eq. 9).

Decision vector (Chen et al. 2017 section 3.1, one flat vector):

``[dS_A, dS_B, gamma_1, v_1, q_1, ..., gamma_m, v_m, q_m, gamma'_1, v'_1, q'_1, ...]``

- ``dS_A``, ``dS_B`` (m): braking distance before each train's next station (the outer chromosome);
- per subsection of the run (cut at every gradient and limit change, section 1.1): the traction
  coefficient ``gamma_k`` in [0, 1], the exit speed ``v_k`` and the time share ``q_k`` in [0, 1]
  (eq. 1). Subsections beyond the braking point are ignored; the one holding it ends there.
  ``v_k`` is, by default, the position of the exit speed in the range the operating sequence
  can reach from the entry speed (0: the lowest, 1: the highest); ``speed_genes="absolute"``
  makes it a speed in km/h, moved into that range when outside it (the paper's repair).

Decoding (:mod:`pymoo_rail.sim.subsections`) follows the operating sequences of table 1 and the
time allotment of eq. 1. Energies are per train: traction drawn ``F v / eta_traction``;
regeneration only counts where the other train uses it at the same time (eq. 5). Objective:
the total net energy (eq. 6). Constraints (``G <= 0``): each train's running time within
``time_tolerance_s`` of its plan, speed limits (eq. 7), comfort at gradient changes (eq. 8),
separation (eq. 9), and the physical feasibility of the decoded sequences.

:class:`SubsectionProblem` is the same model for one train alone (the paper's encoding of the
uncoordinated case); :class:`PunctualityRepair` is the paper's repair as a pymoo ``Repair``;
:func:`nested_minimize` is the nested GA of section 3.
"""

from __future__ import annotations

import copy
import math
from dataclasses import dataclass, replace
from typing import Sequence

import numpy as np
import pandas as pd
from pymoo.core.problem import Problem
from pymoo.core.repair import Repair

from pymoo_rail.constants import J_PER_KWH, KMH_PER_MS
from pymoo_rail.model import Case, CaseError
from pymoo_rail.problems.cooperative import (  # noqa: F401 (re-exported for reproduction scripts)
    SEED_001_OFFSETS_S,
    check_vectors,
    finite_number,
    scale_gradients,
)
from pymoo_rail.sim import Simulator, Trajectory
from pymoo_rail.sim import cooperation as coop
from pymoo_rail.sim import subsections as sub
from pymoo_rail.sim.physics import KernelModel, davis_force
from pymoo_rail.sim.trajectory import EnergyBreakdown

CONSTRAINTS = ("time_a", "time_b", "speed_limit", "comfort", "separation", "feasibility")
SOLO_CONSTRAINTS = ("time", "speed_limit", "comfort", "feasibility")
SPEED_GENES = ("relative", "absolute")
# eq. 8 compares the acceleration before and after a gradient change: each side's is the mean over
# this distance (about a second of running), so the measure does not depend on the grid step
COMFORT_WINDOW_M = 10.0


@dataclass(frozen=True, eq=False)
class TrainSetup:
    """One train's run on the grid: its subsections and the bounds of its genes."""

    case: Case
    model: KernelModel
    start_m: float             # where the run starts on the common line
    sub_start: np.ndarray      # node index of each subsection start
    sub_end: np.ndarray
    sub_kind: np.ndarray       # 2 or 3 (table 1)
    sub_cap_ms: np.ndarray
    sub_grade_change: np.ndarray
    brake_bounds_m: tuple[float, float]

    @property
    def n_sub(self) -> int:
        """Number of subsections."""
        return self.sub_start.shape[0]

    @property
    def planned_time_s(self) -> float:
        """Planned running time (s)."""
        return self.case.planned_time_s


def _train_setup(case: Case, start_m: float, model: KernelModel, decel_ms2: float, range_factor: float) -> TrainSetup:
    line = case.line
    pos = model.position_m
    dx = model.dx_m
    nodes = sorted({int(round(p / dx)) for p in line.breakpoints_m()})
    sub_start = np.asarray(nodes[:-1], dtype=np.int64)
    sub_end = np.asarray(nodes[1:], dtype=np.int64)
    caps = np.array([model.limit_ms[s:e + 1].min() for s, e in zip(sub_start, sub_end)])
    kinds = np.empty(sub_start.shape[0], dtype=np.int64)
    for j, (s, e) in enumerate(zip(sub_start, sub_end)):
        # type 3 when coasting accelerates the train on this subsection even at its highest speed
        # (the line force is the one the train feels: averaged over its length, curves included)
        line_force = float(np.mean(model.line_force_n[s:e]))
        kinds[j] = 3 if davis_force(model, caps[j]) + line_force < 0.0 else 2

    def grade_at(x: float) -> float:
        for s, e, g in line.gradients:
            if s <= x < e:
                return g
        return line.gradients[-1][2]

    change = np.zeros(sub_start.shape[0], dtype=np.bool_)
    for j in range(1, sub_start.shape[0]):
        change[j] = grade_at(pos[sub_start[j]] - 0.5 * dx) != grade_at(pos[sub_start[j]] + 0.5 * dx)
    # the paper's range: braking at b from the approach limit, times r (section 3.2)
    v_end = caps[-1]
    upper = min(range_factor * v_end * v_end / (2.0 * decel_ms2), 0.9 * line.length_m)
    return TrainSetup(case=case, model=model, start_m=start_m, sub_start=sub_start, sub_end=sub_end,
                      sub_kind=kinds, sub_cap_ms=caps, sub_grade_change=change,
                      brake_bounds_m=(0.02 * upper, upper))


@dataclass(frozen=True, eq=False)
class TrainRun:
    """One train of a decoded solution: its trajectory, its subsections as decoded, its figures."""

    trajectory: Trajectory
    subsections: pd.DataFrame
    summary: dict
    traction_kwh: float
    regen_kwh: float


@dataclass(frozen=True, eq=False)
class CooperativeSolution:
    """A decoded decision vector: both runs, the shared energy and the constraint values."""

    a: TrainRun
    b: TrainRun
    offset_s: float
    shared_a_from_b_kwh: float
    shared_b_from_a_kwh: float
    net_kwh: float
    constraints: dict

    @property
    def shared_kwh(self) -> float:
        """Regenerated energy used by the other train, both ways (kWh)."""
        return self.shared_a_from_b_kwh + self.shared_b_from_a_kwh

    @property
    def traction_kwh(self) -> float:
        """Traction energy of both trains (kWh)."""
        return self.a.traction_kwh + self.b.traction_kwh

    @property
    def feasible(self) -> bool:
        """True when every constraint is met."""
        return all(v <= 0.0 for v in self.constraints.values())


class _SubsectionModel(Problem):
    """What the single-train and the two-train forms share: settings, genes, decoding, constraints."""

    def _setup(self, legs: Sequence[tuple[Case, float, str]], *, separation_decel_ms2: float,
               max_accel_change_ms2: float | None, brake_range_factor: float, time_tolerance_s: float,
               min_exit_speed_kmh: float, speed_genes: str, dx_m: float | None) -> tuple[list, list, list]:
        self.separation_decel_ms2 = finite_number("separation_decel_ms2", separation_decel_ms2, positive=True)
        self.max_accel_change_ms2 = (None if max_accel_change_ms2 is None
                                     else finite_number("max_accel_change_ms2", max_accel_change_ms2, positive=True))
        self.brake_range_factor = finite_number("brake_range_factor", brake_range_factor, positive=True)
        self.time_tolerance_s = finite_number("time_tolerance_s", time_tolerance_s, positive=True)
        self.min_exit_speed_ms = finite_number("min_exit_speed_kmh", min_exit_speed_kmh, positive=True) / KMH_PER_MS
        self.comfort_window_m = COMFORT_WINDOW_M
        if speed_genes not in SPEED_GENES:
            raise ValueError(f"speed_genes = {speed_genes!r} is unknown (known: {', '.join(SPEED_GENES)})")
        self.speed_genes = speed_genes
        self.relative_speeds = speed_genes == "relative"
        trains = []
        for leg_case, start_m, _ in legs:
            simulator = Simulator(leg_case, dx_m)
            simulator.check_planned_time()  # raises, naming planned_time_s, when the leg cannot be run on time
            trains.append(_train_setup(leg_case, start_m, simulator.model, self.separation_decel_ms2,
                                       self.brake_range_factor))
        self.trains = tuple(trains)
        xl = [tr.brake_bounds_m[0] for tr in trains]
        xu = [tr.brake_bounds_m[1] for tr in trains]
        names = [f"brake{label}_m" for _, _, label in legs]
        self.blocks = []
        for k, (tr, (_, _, label)) in enumerate(zip(trains, legs)):
            self.blocks.append((k, len(xl)))
            for j in range(tr.n_sub):
                xl += [0.0, 0.0, 0.0]
                xu += [1.0, 1.0 if self.relative_speeds else tr.sub_cap_ms[j] * KMH_PER_MS, 1.0]
                speed = f"v{label}{j + 1}" + ("_rel" if self.relative_speeds else "_kmh")
                names += [f"gamma{label}{j + 1}", speed, f"q{label}{j + 1}"]
        self.variable_names = tuple(names)
        return xl, xu, names

    # ------------------------------------------------------------------ decision vectors
    def check_x(self, X: np.ndarray) -> np.ndarray:
        return check_vectors(X, self.n_var, self.variable_names)

    def split(self, X: np.ndarray) -> list[tuple]:
        """Per train, (brake_m, gamma, v_exit, q) from decision vectors (N, n_var); v_exit in m/s or relative."""
        X = self.check_x(X)
        out = []
        for (brake_col, first), tr in zip(self.blocks, self.trains):
            genes = X[:, first:first + 3 * tr.n_sub].reshape(X.shape[0], tr.n_sub, 3)
            speed = genes[:, :, 1] if self.relative_speeds else genes[:, :, 1] / KMH_PER_MS
            out.append((np.ascontiguousarray(X[:, brake_col]), np.ascontiguousarray(genes[:, :, 0]),
                        np.ascontiguousarray(speed), np.ascontiguousarray(genes[:, :, 2])))
        return out

    def with_genes(self, X: np.ndarray, k: int, gamma: np.ndarray, v_exit: np.ndarray) -> np.ndarray:
        """A copy of X with train k's traction coefficients and exit-speed genes replaced."""
        X = np.array(X, dtype=float, copy=True)
        _, first = self.blocks[k]
        n_sub = self.trains[k].n_sub
        block = X[:, first:first + 3 * n_sub].reshape(X.shape[0], n_sub, 3)
        block[:, :, 0] = gamma
        block[:, :, 1] = v_exit if self.relative_speeds else v_exit * KMH_PER_MS
        X[:, first:first + 3 * n_sub] = block.reshape(X.shape[0], -1)
        return X

    def _drive(self, tr: TrainSetup, genes: tuple):
        brake, gamma, v_exit, q = genes
        return sub.drive_batch(tr.model, tr.sub_start, tr.sub_end, tr.sub_kind, tr.sub_cap_ms, tr.sub_grade_change,
                               brake, gamma, v_exit, q, tr.planned_time_s, self.separation_decel_ms2,
                               self.min_exit_speed_ms, self.relative_speeds, self.comfort_window_m)

    def _train_constraints(self, s: np.ndarray, tr: TrainSetup) -> tuple[np.ndarray, ...]:
        """(time, limit, comfort, feasibility) of one train's summaries."""
        g_time = np.abs(s[:, sub.RUN_RUNNING_TIME_S] - tr.planned_time_s) - self.time_tolerance_s
        g_limit = s[:, sub.RUN_LIMIT_EXCESS_MS] - 1e-6
        if self.max_accel_change_ms2 is None:
            g_comfort = np.full(s.shape[0], -1.0)
        else:
            g_comfort = s[:, sub.RUN_ACCEL_CHANGE_MS2] - self.max_accel_change_ms2
        # forces beyond the train's limits (m/s^2; 1e-3 absorbs the two integration schemes) and
        # exit speeds no repair could place (m/s)
        g_feasible = np.maximum(s[:, sub.RUN_FORCE_EXCESS_MS2] - 1e-3, s[:, sub.RUN_DECODE_EXCESS_MS] - 1e-9)
        return g_time, g_limit, g_comfort, g_feasible

    def _train_run(self, tr: TrainSetup, run: tuple) -> TrainRun:
        """The first run of a batch as a :class:`TrainRun`."""
        v, t, f, _, _, regime, subs, summ = (r[0] for r in run)
        n_active = int(summ[sub.RUN_N_ACTIVE])
        table = pd.DataFrame(subs[:n_active], columns=sub.SUB_NAMES).drop(columns="active")
        table["type"] = table["type"].astype(int)
        summary = {name: float(summ[i]) for i, name in enumerate(sub.RUN_NAMES)}
        accel = np.append((v[1:] ** 2 - v[:-1] ** 2) / (2.0 * tr.model.dx_m), 0.0)
        energy = EnergyBreakdown(traction_kwh=summary["traction_kwh"], regen_kwh=0.0, aux_kwh=0.0,
                                 net_kwh=summary["traction_kwh"])
        traj = Trajectory(position_m=tr.model.position_m.copy(), speed_ms=v.copy(), time_s=t.copy(), accel_ms2=accel,
                          force_n=np.append(f, 0.0), regime=np.append(regime, np.int8(3)),
                          limit_ms=tr.model.limit_ms.copy(), energy=energy, running_time_s=summary["running_time_s"],
                          stop_error_m=0.0, summary=dict(summary, reached=1.0))
        return TrainRun(trajectory=traj, subsections=table, summary=summary, traction_kwh=summary["traction_kwh"],
                        regen_kwh=summary["regen_kwh"])

    def _one(self, x: np.ndarray) -> np.ndarray:
        x = np.asarray(x, dtype=float)
        if x.ndim != 1 or x.shape[0] != self.n_var:
            raise ValueError(f"x must be one decision vector of length n_var = {self.n_var}, got shape {x.shape}")
        return x[None, :]


class SubsectionProblem(_SubsectionModel):
    """One train alone in the paper's subsection model: least traction energy, on time.

    The uncoordinated case of Chen et al. (2017) in its own encoding. Decision vector
    ``[dS, gamma_1, v_1, q_1, ..., gamma_m, v_m, q_m]``; parameters as in
    :class:`CooperativeSeedProblem`. ``case`` is a single-run case (e.g. ``pair.leg(0)``).
    """

    def __init__(self, case: Case, *, separation_decel_ms2: float = 1.0, max_accel_change_ms2: float | None = 0.8,
                 brake_range_factor: float = 1.5, time_tolerance_s: float = 1.0, min_exit_speed_kmh: float = 3.6,
                 speed_genes: str = "relative", dx_m: float | None = None, **kwargs):
        if not isinstance(case, Case):
            raise TypeError(f"case = {case!r}: must be a pymoo_rail Case")
        if case.legs:
            raise CaseError("run.legs", f"{len(case.legs)} legs", "SubsectionProblem needs a single-run case "
                            "(use case.leg(k))", case.name)
        self.case = case
        xl, xu, names = self._setup([(case, 0.0, "")], separation_decel_ms2=separation_decel_ms2,
                                    max_accel_change_ms2=max_accel_change_ms2, brake_range_factor=brake_range_factor,
                                    time_tolerance_s=time_tolerance_s, min_exit_speed_kmh=min_exit_speed_kmh,
                                    speed_genes=speed_genes, dx_m=dx_m)
        super().__init__(n_var=len(names), n_obj=1, n_ieq_constr=len(SOLO_CONSTRAINTS), xl=np.asarray(xl, dtype=float),
                         xu=np.asarray(xu, dtype=float), vtype=float, **kwargs)

    def _evaluate(self, x, out, *args, **kwargs):
        (genes,) = self.split(x)
        run = self._drive(self.trains[0], genes)
        s = run[-1]
        out["F"] = s[:, sub.RUN_TRACTION_KWH][:, None]
        out["G"] = np.column_stack(self._train_constraints(s, self.trains[0]))
        out["running_time_s"] = s[:, sub.RUN_RUNNING_TIME_S]
        out["regen_kwh"] = s[:, sub.RUN_REGEN_KWH]

    def decode(self, x: np.ndarray) -> TrainRun:
        """The trajectory, the subsections as decoded and the figures of one decision vector."""
        (genes,) = self.split(self._one(x))
        return self._train_run(self.trains[0], self._drive(self.trains[0], genes))


class CooperativeSeedProblem(_SubsectionModel):
    """The paper's decision vector for :class:`~pymoo_rail.problems.CooperativeTrainsProblem`.

    Parameters
    ----------
    case, offset_s
        As for :class:`~pymoo_rail.problems.CooperativeTrainsProblem`.
    safety_margin_m : float
        L_s of eq. 9 (Chen et al. 2017 table 3: 40 m).
    separation_decel_ms2 : float
        b of eq. 9 and the largest deceleration of the braking phase (table 3: 1.0 m/s^2).
    max_accel_change_ms2 : float or None
        delta of eq. 8 (table 3: 0.8 m/s^2); ``None`` drops the comfort constraint.
    brake_range_factor : float
        r of section 3.2 (1.5): the braking distance ranges up to r times the distance to brake at b
        from the approach limit (down to 2 % of that).
    time_tolerance_s : float
        Each train must arrive within this of its planned time (1 s).
    share_energy : bool
        False gives the uncoordinated objective (traction of both, nothing shared).
    time_step_s : float
        Bin width of the common clock for power profiles and separation (0.1 s).
    min_exit_speed_kmh : float
        Lowest exit speed of a subsection (the trains do not stop between stations).
    speed_genes : {"relative", "absolute"}
        How the exit speeds are encoded (see the module docstring).
    dx_m : float, optional
        Simulation grid step (default of :class:`~pymoo_rail.sim.Simulator`).

    Notes
    -----
    Extra outputs per solution: ``traction_a_kwh``, ``traction_b_kwh``, ``regen_a_kwh`` and
    ``regen_b_kwh`` (usable by the other train, whether it uses it or not), ``shared_kwh``,
    ``running_time_a_s``, ``running_time_b_s``. ``decode(x)`` gives both trajectories;
    ``power_profiles(x)`` the power on the common clock.
    """

    def __init__(self, case: Case, offset_s: float, *, safety_margin_m: float = 40.0,
                 separation_decel_ms2: float = 1.0, max_accel_change_ms2: float | None = 0.8,
                 brake_range_factor: float = 1.5, time_tolerance_s: float = 1.0, share_energy: bool = True,
                 time_step_s: float = 0.1, min_exit_speed_kmh: float = 3.6, speed_genes: str = "relative",
                 dx_m: float | None = None, **kwargs):
        if not isinstance(case, Case):
            raise TypeError(f"case = {case!r}: must be a pymoo_rail Case")
        if len(case.legs) != 2:
            raise CaseError("run.legs", f"{len(case.legs)} legs",
                            "CooperativeSeedProblem needs a case with exactly two legs (A on leg 0, B on leg 1)",
                            case.name)
        self.offset_s = finite_number("offset_s", offset_s)
        self.safety_margin_m = finite_number("safety_margin_m", safety_margin_m, nonneg=True)
        self.time_step_s = finite_number("time_step_s", time_step_s, positive=True)
        self.share_energy = bool(share_energy)
        self.case = case
        legs = [(case.leg(0), case.legs[0].start_m, "_a"), (case.leg(1), case.legs[1].start_m, "_b")]
        xl, xu, names = self._setup(legs, separation_decel_ms2=separation_decel_ms2,
                                    max_accel_change_ms2=max_accel_change_ms2, brake_range_factor=brake_range_factor,
                                    time_tolerance_s=time_tolerance_s, min_exit_speed_kmh=min_exit_speed_kmh,
                                    speed_genes=speed_genes, dx_m=dx_m)
        a, b = self.trains
        # the common clock: from the first departure to well after the later planned arrival
        self.t0_s = min(0.0, self.offset_s)
        t_end = max(a.planned_time_s, self.offset_s + b.planned_time_s) + max(a.planned_time_s, b.planned_time_s)
        self.n_bins = int(math.ceil((t_end - self.t0_s) / self.time_step_s))
        super().__init__(n_var=len(names), n_obj=1, n_ieq_constr=len(CONSTRAINTS), xl=np.asarray(xl, dtype=float),
                         xu=np.asarray(xu, dtype=float), vtype=float, **kwargs)

    def simulate(self, X: np.ndarray) -> dict:
        """Both runs and their interaction for decision vectors (N, n_var), as arrays by name."""
        genes_a, genes_b = self.split(X)
        a, b = self.trains
        run_a = self._drive(a, genes_a)
        run_b = self._drive(b, genes_b)
        v_a, t_a, _, tr_a, rg_a, _, _, s_a = run_a
        v_b, t_b, _, tr_b, rg_b, _, _, s_b = run_b
        n = t_a.shape[0]
        shared = np.empty((n, 2))
        separation = np.empty(n)
        gap_m = a.case.train.length_m + self.safety_margin_m
        for r in range(n):
            bins = np.zeros((4, self.n_bins))
            for row, (t, e, shift) in enumerate(((t_a[r], tr_a[r], 0.0), (t_a[r], rg_a[r], 0.0),
                                                 (t_b[r], tr_b[r], self.offset_s), (t_b[r], rg_b[r], self.offset_s))):
                coop.bin_energy(t, e, shift, self.t0_s, self.time_step_s, bins[row])
            # eq. 5 one way at a time: A drawing from B's braking, then B from A's
            none = np.zeros(self.n_bins)
            shared[r, 0] = coop.shared_energy_bins(np.vstack([bins[0], none]), np.vstack([none, bins[3]]),
                                                   1.0).sum() / J_PER_KWH
            shared[r, 1] = coop.shared_energy_bins(np.vstack([none, bins[2]]), np.vstack([bins[1], none]),
                                                   1.0).sum() / J_PER_KWH
            separation[r] = coop.separation_excess(t_a[r], a.model.position_m, v_a[r], 0.0, a.start_m, t_b[r],
                                                   b.model.position_m, self.offset_s, b.start_m, gap_m,
                                                   self.separation_decel_ms2, self.t0_s, self.time_step_s,
                                                   self.n_bins)
        return {"run_a": run_a, "run_b": run_b, "summary_a": s_a, "summary_b": s_b, "shared_kwh": shared,
                "separation_m": separation}

    def _evaluate(self, x, out, *args, **kwargs):
        sim = self.simulate(x)
        s_a, s_b, shared = sim["summary_a"], sim["summary_b"], sim["shared_kwh"]
        traction = s_a[:, sub.RUN_TRACTION_KWH] + s_b[:, sub.RUN_TRACTION_KWH]
        used = shared.sum(axis=1) if self.share_energy else np.zeros(traction.shape[0])
        out["F"] = (traction - used)[:, None]
        out["G"] = self._constraints(s_a, s_b, sim["separation_m"])
        out["traction_a_kwh"] = s_a[:, sub.RUN_TRACTION_KWH]
        out["traction_b_kwh"] = s_b[:, sub.RUN_TRACTION_KWH]
        out["regen_a_kwh"] = s_a[:, sub.RUN_REGEN_KWH]
        out["regen_b_kwh"] = s_b[:, sub.RUN_REGEN_KWH]
        out["shared_kwh"] = used
        out["running_time_a_s"] = s_a[:, sub.RUN_RUNNING_TIME_S]
        out["running_time_b_s"] = s_b[:, sub.RUN_RUNNING_TIME_S]

    def _constraints(self, s_a: np.ndarray, s_b: np.ndarray, separation_m: np.ndarray) -> np.ndarray:
        time_a, limit_a, comfort_a, feasible_a = self._train_constraints(s_a, self.trains[0])
        time_b, limit_b, comfort_b, feasible_b = self._train_constraints(s_b, self.trains[1])
        return np.column_stack([time_a, time_b, np.maximum(limit_a, limit_b), np.maximum(comfort_a, comfort_b),
                                separation_m, np.maximum(feasible_a, feasible_b)])

    # ------------------------------------------------------------------ inspection
    def decode(self, x: np.ndarray) -> CooperativeSolution:
        """Both trajectories, the subsections as decoded, the shared energy and the constraints of one vector."""
        sim = self.simulate(self._one(x))
        run_a = self._train_run(self.trains[0], sim["run_a"])
        run_b = self._train_run(self.trains[1], sim["run_b"])
        g = self._constraints(sim["summary_a"], sim["summary_b"], sim["separation_m"])[0]
        shared = sim["shared_kwh"][0] if self.share_energy else np.zeros(2)
        return CooperativeSolution(a=run_a, b=run_b, offset_s=self.offset_s, shared_a_from_b_kwh=float(shared[0]),
                                   shared_b_from_a_kwh=float(shared[1]),
                                   net_kwh=run_a.traction_kwh + run_b.traction_kwh - float(shared.sum()),
                                   constraints=dict(zip(CONSTRAINTS, (float(v) for v in g))))

    def power_profiles(self, x: np.ndarray) -> pd.DataFrame:
        """Power of both trains on the common clock (kW per bin): traction, usable regeneration, shared."""
        return coop.power_profiles(clocked_pair(self, self.decode(x)), ("a", "b"), 1.0, self.time_step_s)

    def describe(self) -> str:
        """One line naming the case, the offset and the subsections."""
        a, b = self.trains
        return (f"CooperativeSeedProblem({self.case.name}, offset {self.offset_s:g} s: A {a.n_sub} subsections, "
                f"B {b.n_sub} subsections, {self.n_var} variables, {self.n_ieq_constr} constraints)")


# ---------------------------------------------------------------------- the paper's repair
class PunctualityRepair(Repair):
    """The repair of Chen et al. (2017) section 3.2, step 1, as a pymoo ``Repair`` (Lamarckian: genes are rewritten).

    When a train's planned time lies outside the window eq. 1 can reach (eq. 10), its exit-speed
    genes (and, to speed up, its traction coefficients) move together toward the fastest or the
    slowest sequence until the plan lies inside; see :func:`pymoo_rail.sim.subsections.repair_one`.
    Works with :class:`CooperativeSeedProblem`, :class:`SubsectionProblem` and the inner problem of
    the nested GA, with ``speed_genes="relative"``: ``DE(..., repair=PunctualityRepair())``.
    """

    def __init__(self, iterations: int = 10):
        super().__init__()
        if int(iterations) < 1:
            raise ValueError(f"iterations = {iterations!r}: must be >= 1")
        self.iterations = int(iterations)

    def apply(self, problem, X: np.ndarray) -> np.ndarray:
        """The repaired copy of decision vectors X (N, n_var)."""
        return self._do(problem, np.atleast_2d(np.asarray(X, dtype=float)))

    def _do(self, problem, X, **kwargs):
        if isinstance(problem, PartialProblem):
            return self._do(problem.problem, problem.full(X))[:, problem.free]
        if not isinstance(problem, _SubsectionModel) or not problem.relative_speeds:
            raise ValueError(f"PunctualityRepair needs a subsection problem with speed_genes='relative', "
                             f"got {type(problem).__name__}")
        X = np.asarray(X, dtype=float)
        for k, (tr, genes) in enumerate(zip(problem.trains, problem.split(X))):
            brake, gamma, v_rel, _ = genes
            g_new, v_new, _ = sub.repair_batch(tr.model, tr.sub_start, tr.sub_end, tr.sub_kind, tr.sub_cap_ms, brake,
                                               gamma, v_rel, tr.planned_time_s, problem.separation_decel_ms2,
                                               problem.min_exit_speed_ms, self.iterations)
            X = problem.with_genes(X, k, g_new, v_new)
        return np.clip(X, problem.xl, problem.xu)


# ---------------------------------------------------------------------- power on a common clock
def clocked_pair(problem: "CooperativeSeedProblem", solution: CooperativeSolution) -> list:
    """Both decoded runs on the common clock, their energies by the kernel's per-cell accounting."""
    return [coop.clocked_run(tr.model, run.trajectory, dep, tr.start_m)
            for tr, run, dep in zip(problem.trains, (solution.a, solution.b), (0.0, problem.offset_s))]


# ---------------------------------------------------------------------- the nested GA of section 3
class PartialProblem(Problem):
    """A subsection problem with some genes held at reference values: only the ``free`` ones vary.

    Evaluating a partial vector evaluates the full one; :class:`PunctualityRepair` repairs the full
    vector and keeps the free part. Used by the nested GA and by :func:`alternating_minimize`.
    """

    def __init__(self, problem: _SubsectionModel, free: np.ndarray, x_ref: np.ndarray):
        free = np.asarray(free, dtype=bool)
        x_ref = np.asarray(x_ref, dtype=float)
        if free.shape != (problem.n_var,) or x_ref.shape != (problem.n_var,) or not free.any():
            raise ValueError(f"free and x_ref must have n_var = {problem.n_var} entries, with at least one free gene")
        self.problem = problem
        self.free = free
        self.x_ref = x_ref
        super().__init__(n_var=int(free.sum()), n_obj=problem.n_obj, n_ieq_constr=problem.n_ieq_constr,
                         xl=problem.xl[free].copy(), xu=problem.xu[free].copy(), vtype=float)

    def full(self, x: np.ndarray) -> np.ndarray:
        """Full decision vectors: the reference vector with the free variables taken from ``x``."""
        x = np.atleast_2d(np.asarray(x, dtype=float))
        X = np.repeat(self.x_ref[None, :], x.shape[0], axis=0)
        X[:, self.free] = x
        return X

    def _evaluate(self, x, out, *args, **kwargs):
        res = self.problem.evaluate(self.full(x), return_as_dictionary=True)
        out["F"] = res["F"]
        out["G"] = res["G"]


class FixedBrakingProblem(PartialProblem):
    """The inner problem of the nested GA: the cooperative problem with both braking distances fixed."""

    def __init__(self, problem: CooperativeSeedProblem, brake_m: Sequence[float]):
        free = np.ones(problem.n_var, dtype=bool)
        free[:2] = False
        x_ref = np.concatenate([np.asarray(brake_m, dtype=float), problem.xl[2:]])
        super().__init__(problem, free, x_ref)
        self.brake_m = np.asarray(brake_m, dtype=float)


class BrakingDistanceProblem(Problem):
    """The outer problem of the nested GA: braking distances, each evaluated by an inner pymoo run.

    The value of a pair of braking distances is the best the inner algorithm finds for the rest of
    the vector (Chen et al. 2017 section 3.1); its constraint is that solution's violation. Inner runs are
    seeded from the outer algorithm's ``random_state``.
    """

    def __init__(self, problem: CooperativeSeedProblem, inner_algorithm, inner_termination):
        self.problem = problem
        self.inner_algorithm = inner_algorithm
        self.inner_termination = inner_termination
        super().__init__(n_var=2, n_obj=1, n_ieq_constr=1, xl=problem.xl[:2].copy(), xu=problem.xu[:2].copy(),
                         vtype=float)

    def _evaluate(self, x, out, *args, algorithm=None, **kwargs):
        from pymoo.optimize import minimize

        rng = algorithm.random_state if algorithm is not None else np.random.default_rng(0)
        f = np.empty(x.shape[0])
        g = np.empty(x.shape[0])
        inner = np.empty((x.shape[0], self.problem.n_var - 2))
        for i, brake in enumerate(x):
            res = minimize(FixedBrakingProblem(self.problem, brake), copy.deepcopy(self.inner_algorithm),
                           self.inner_termination, seed=int(rng.integers(2**31 - 1)))
            best = res.algorithm.opt[0]  # the best found, or the least infeasible
            f[i] = best.F[0]
            g[i] = best.CV[0]
            inner[i] = best.X
        out["F"] = f[:, None]
        out["G"] = g[:, None]
        out["inner_X"] = inner


def nested_minimize(problem: CooperativeSeedProblem, *, outer_pop_size: int = 24, outer_n_gen: int = 20,
                    inner_pop_size: int = 100, inner_n_gen: int = 80, inner_algorithm=None, seed: int = 1,
                    verbose: bool = False):
    """The nested GA of Chen et al. (2017) section 3: an outer pymoo GA on the braking distances whose every
    evaluation runs an inner pymoo GA on the traction coefficients, exit speeds and time shares.

    Defaults are the paper's sizes (section 4.1: outer 24 x 20, inner 100 x 80); pymoo's GA
    operators (SBX, polynomial mutation, elitist survival) stand in for the paper's roulette wheel
    and one/two-point operators. Returns ``(x, F, outer_result)`` with ``x`` the full best vector.
    """
    from pymoo.algorithms.soo.nonconvex.ga import GA
    from pymoo.optimize import minimize

    if inner_algorithm is None:
        repair = PunctualityRepair() if problem.relative_speeds else None
        inner_algorithm = GA(pop_size=inner_pop_size, eliminate_duplicates=True, repair=repair)
    outer = BrakingDistanceProblem(problem, inner_algorithm, ("n_gen", inner_n_gen))
    res = minimize(outer, GA(pop_size=outer_pop_size, eliminate_duplicates=True), ("n_gen", outer_n_gen), seed=seed,
                   verbose=verbose)
    best = res.algorithm.opt[0]  # the best found, or the least infeasible
    x = np.concatenate([best.X, best.get("inner_X")])
    return x, float(best.F[0]), res


def train_genes(problem: CooperativeSeedProblem, k: int) -> np.ndarray:
    """Mask of train k's genes (its braking distance and its subsection triples)."""
    mask = np.zeros(problem.n_var, dtype=bool)
    brake_col, first = problem.blocks[k]
    mask[brake_col] = True
    mask[first:first + 3 * problem.trains[k].n_sub] = True
    return mask


def alternating_minimize(problem: CooperativeSeedProblem, x0: np.ndarray, *, rounds: int = 2,
                         n_evals: Sequence[int] = (4000, 3000), pop_size: int = 40, seed: int = 1,
                         algorithm=None):
    """Train-by-train optimisation: A and B take turns, each optimised with the other held fixed.

    Each turn is a pymoo run (by default DE/best/1/bin, CR 0.3, with :class:`PunctualityRepair`)
    on a :class:`PartialProblem` holding one train's genes free, started from the current vector
    plus random vectors. A turn keeps its result only when it is at least as good, so the objective
    never rises. The single-train searches are much easier than the joint one, and each turn can
    still move one train's traction onto the other's braking. Returns ``(x, F)``.
    """
    from pymoo.algorithms.soo.nonconvex.de import DE
    from pymoo.core.evaluator import Evaluator
    from pymoo.core.population import Population
    from pymoo.optimize import minimize

    x = np.asarray(x0, dtype=float).copy()

    def score(vec):
        pop = Population.new(X=np.atleast_2d(vec))
        Evaluator().eval(problem, pop)
        return float(pop.get("F")[0, 0]), float(pop.get("CV")[0, 0])

    best = score(x)
    rng = np.random.default_rng(seed)
    for r in range(rounds):
        for k in (0, 1):
            sub_problem = PartialProblem(problem, train_genes(problem, k), x)
            X = sub_problem.xl + rng.random((pop_size, sub_problem.n_var)) * (sub_problem.xu - sub_problem.xl)
            X[0] = x[sub_problem.free]
            algo = copy.deepcopy(algorithm) if algorithm is not None else DE(
                pop_size=pop_size, variant="DE/best/1/bin", CR=0.3, F=0.5, repair=PunctualityRepair())
            algo.initialization.sampling = X
            res = minimize(sub_problem, algo, ("n_evals", n_evals[k % len(n_evals)]),
                           seed=int(rng.integers(2**31 - 1)))
            cand = sub_problem.full(res.algorithm.opt[0].X)[0]
            cand_score = score(cand)
            if (cand_score[1], cand_score[0]) <= (best[1], best[0]):
                x, best = cand, cand_score
    return x, best[0]
