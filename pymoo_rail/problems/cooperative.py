"""Two trains sharing regenerative braking energy (Chen et al. 2017): ``CooperativeTrainsProblem``.

Train A runs leg 0 of a two-leg case (station 1 -> 2), train B leg 1 (station 2 -> 3); B leaves
station 2 ``offset_s`` seconds after A leaves station 1 (the paper's x; negative: B leaves first).
Both legs lie in one power-supply section, so while one train brakes the other can draw the
regenerated power (with utilisation eta, the case's ``regen_efficiency``). B runs ahead of A on
the line, so A is the following train of the separation rule (eq. 9).

Decision vector: each train's driving *shape*, A's genes first. With ``encoding="speed_codes"``
(the default) a shape is speed codes as fractions of each section's limit (sections cut at every
gradient and limit change, at most ``max_section_m`` long); with ``encoding="subsections"`` it is
the paper's operating sequences (braking distance, then traction share, turning speed and last
phase per subsection, :class:`~pymoo_rail.sim.pacing.PacedSubsections`). The running time is not a
decision: each shape is paced (:mod:`pymoo_rail.sim.pacing`) so that the train runs exactly its
planned time, whatever the vector. Every vector in the box is punctual, so any pymoo algorithm
(GA, DE, PSO, NSGA2, ...) works on it without a repair.

Both runs are the main simulator's (:class:`~pymoo_rail.sim.Simulator`); their power on the common
clock and the shared energy come from its traces (:mod:`pymoo_rail.sim.cooperation`). Objective:
the total net energy of eq. 6, traction of both minus what one draws from the other's braking
(kWh). A train's own regeneration is never credited. Constraints (``G <= 0``): separation (eq. 9)
and, as a guard, the running-time error of the pace solve (never active on the built-in case).

The paper's constraints on its own encoding (comfort, braking deceleration) and its nested GA
are in :mod:`pymoo_rail.problems.cooperative_seed`; the exact uncoordinated baseline is in
:mod:`pymoo_rail.problems.cooperative_baseline`.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, replace

import numpy as np
import pandas as pd
from pymoo.core.problem import Problem

from pymoo_rail.model import Case, CaseError
from pymoo_rail.problems.speed_profile import check_decisions
from pymoo_rail.sim import Simulator, Trajectory
from pymoo_rail.sim import cooperation as coop
from pymoo_rail.sim.kernel import OUT_TRACTION_KWH
from pymoo_rail.sim.pacing import DEFAULT_TIME_TOL_S, PacedRuns, PacedSpeedCodes, PacedSubsections, solve_pace

# Chen et al. (2017) sections 4.2-4.4.
SEED_001_OFFSETS_S = (-45.0, 0.0, 45.0, 90.0, 135.0)
CONSTRAINTS = ("separation", "time")
SHAPE_ENCODINGS = ("speed_codes", "subsections")
"""Shape encodings of one train here, each paced to its planned time (:mod:`pymoo_rail.sim.pacing`); the
single-train encodings of ``SpeedProfileProblem`` are another family (:mod:`pymoo_rail.problems.encodings`)."""


def finite_number(name: str, value, *, positive: bool = False, nonneg: bool = False) -> float:
    """``value`` as a float, or a ``ValueError`` naming ``name`` and the value."""
    if isinstance(value, bool) or not isinstance(value, (int, float, np.integer, np.floating)) \
            or not math.isfinite(float(value)):
        raise ValueError(f"{name} = {value!r}: must be a finite number")
    value = float(value)
    if positive and value <= 0:
        raise ValueError(f"{name} = {value!r}: must be > 0")
    if nonneg and value < 0:
        raise ValueError(f"{name} = {value!r}: must be >= 0")
    return value


def scale_gradients(case: Case, phi: float) -> Case:
    """The same case with every gradient multiplied by ``phi`` (Chen et al. 2017, section 4.4, fig. 6)."""
    phi = finite_number("phi", phi)
    line = replace(case.line, gradients=tuple((s, e, g * phi) for s, e, g in case.line.gradients))
    return replace(case, line=line, name=f"{case.name} (gradients x {phi:g})")


@dataclass(frozen=True, eq=False)
class PacedTrain:
    """One train on one stop-to-stop run: simulator, shape encoding and place on the common line."""

    case: Case
    simulator: Simulator
    encoding: PacedSpeedCodes | PacedSubsections
    start_m: float

    @classmethod
    def build(cls, case: Case, start_m: float = 0.0, max_section_m: float | None = 200.0,
              dx_m: float | None = None, encoding: str = "speed_codes", service_decel_ms2: float = 1.0,
              brake_range_factor: float = 1.5) -> PacedTrain:
        """A train on ``case``; ``encoding`` is ``"speed_codes"`` (sections of at most ``max_section_m``)
        or ``"subsections"`` (the paper's, braking distances scaled by ``service_decel_ms2`` and
        ``brake_range_factor``)."""
        if encoding not in SHAPE_ENCODINGS:
            raise ValueError(f"encoding = {encoding!r} is unknown (known: {', '.join(SHAPE_ENCODINGS)})")
        simulator = Simulator(case, dx_m)
        simulator.check_planned_time()  # raises, naming planned_time_s, when the run cannot be on time
        if encoding == "speed_codes":
            enc = PacedSpeedCodes.build(case, max_section_m)
        else:
            enc = PacedSubsections.build(simulator, service_decel_ms2, brake_range_factor)
        return cls(case=case, simulator=simulator, encoding=enc, start_m=float(start_m))

    @property
    def n_var(self) -> int:
        """Number of shape variables."""
        return self.encoding.n_var

    def paced(self, shapes: np.ndarray, time_tol_s: float = DEFAULT_TIME_TOL_S) -> PacedRuns:
        """The runs of the speed-code shapes, each scaled to its running time (:func:`solve_pace`)."""
        return solve_pace(self.simulator, self.encoding, shapes, time_tol_s)

    def clocked(self, program: np.ndarray, departure_s: float) -> coop.ClockedRun:
        """The traced run of one program at ``departure_s``."""
        return coop.clocked_run(self.simulator.model, self.simulator.run(program), departure_s, self.start_m)


@dataclass(frozen=True, eq=False)
class CooperativeSolution:
    """A decoded decision vector: both runs, the shared energy and the constraint values."""

    a: Trajectory
    b: Trajectory
    offset_s: float
    pace: tuple[float, float]
    traction_a_kwh: float
    traction_b_kwh: float
    shared_kwh: float
    constraints: dict

    @property
    def traction_kwh(self) -> float:
        """Traction energy of both trains (kWh)."""
        return self.traction_a_kwh + self.traction_b_kwh

    @property
    def net_kwh(self) -> float:
        """Traction energy minus the shared regenerated energy (kWh)."""
        return self.traction_kwh - self.shared_kwh

    @property
    def feasible(self) -> bool:
        """True when every constraint is met."""
        return all(v <= 0.0 for v in self.constraints.values())


class CooperativeTrainsProblem(Problem):
    """Cooperative timed driving of two trains sharing regenerative energy (Chen et al. 2017).

    Parameters
    ----------
    case : Case
        A case with exactly two consecutive legs (``load_case("cooperative-pair")``): train A runs
        leg 0, train B leg 1.
    offset_s : float
        B's departure from the start of leg 1 minus A's departure from the start of leg 0 (the
        paper's x, sections 4.2-4.4: -45, 0, 45, 90, 135 s).
    max_section_m : float or None
        Longest section of a shape (200 m): sections are cut at gradient and limit changes and
        split further down to this length.
    safety_margin_m : float
        L_s of eq. 9 (table 3: 40 m).
    separation_decel_ms2 : float
        b of eq. 9 (table 3: 1.0 m/s^2).
    share_energy : bool
        False gives the uncoordinated objective (traction of both, nothing shared).
    time_step_s : float
        Bin width of the common clock for power profiles and separation (0.1 s).
    time_tol_s : float
        Tolerance of the pace solve (0.02 s).
    max_time_error_s : float
        The guard constraint: a run further than this from its plan is infeasible (0.5 s).
    dx_m : float, optional
        Simulation grid step (default of :class:`~pymoo_rail.sim.Simulator`).
    encoding : {"speed_codes", "subsections"}
        The shape of each train (see the module docstring).
    brake_range_factor : float
        With ``encoding="subsections"``: r of Chen et al. (2017) section 3.2 (1.5), the braking
        distance ranges up to r times the distance to brake at ``separation_decel_ms2`` from the
        approach limit (down to 2 % of that).

    Notes
    -----
    Extra outputs per solution: ``traction_a_kwh``, ``traction_b_kwh``, ``shared_kwh``,
    ``running_time_a_s``, ``running_time_b_s``, ``pace_a``, ``pace_b``. ``decode(x)`` gives both
    trajectories; ``power_profiles(x)`` the power on the common clock.
    """

    def __init__(self, case: Case, offset_s: float, *, max_section_m: float | None = 200.0,
                 safety_margin_m: float = 40.0, separation_decel_ms2: float = 1.0, share_energy: bool = True,
                 time_step_s: float = 0.1, time_tol_s: float = DEFAULT_TIME_TOL_S, max_time_error_s: float = 0.5,
                 dx_m: float | None = None, encoding: str = "speed_codes", brake_range_factor: float = 1.5,
                 **kwargs):
        if not isinstance(case, Case):
            raise TypeError(f"case = {case!r}: must be a pymoo_rail Case")
        if len(case.legs) != 2:
            raise CaseError("run.legs", f"{len(case.legs)} legs",
                            "CooperativeTrainsProblem needs a case with exactly two legs (A on leg 0, B on leg 1)",
                            case.name)
        self.case = case
        self.offset_s = finite_number("offset_s", offset_s)
        self.safety_margin_m = finite_number("safety_margin_m", safety_margin_m, nonneg=True)
        self.separation_decel_ms2 = finite_number("separation_decel_ms2", separation_decel_ms2, positive=True)
        self.time_step_s = finite_number("time_step_s", time_step_s, positive=True)
        self.time_tol_s = finite_number("time_tol_s", time_tol_s, positive=True)
        self.max_time_error_s = finite_number("max_time_error_s", max_time_error_s, positive=True)
        self.share_energy = bool(share_energy)
        self.encoding = encoding
        self.trains = tuple(PacedTrain.build(case.leg(k), case.legs[k].start_m, max_section_m, dx_m, encoding,
                                             self.separation_decel_ms2, brake_range_factor) for k in (0, 1))
        n_a = self.trains[0].n_var
        self.slices = (slice(0, n_a), slice(n_a, n_a + self.trains[1].n_var))
        names = [name for tr, label in zip(self.trains, ("_a", "_b")) for name in tr.encoding.names(label)]
        self.variable_names = tuple(names)
        xl = np.concatenate([tr.encoding.xl for tr in self.trains])
        xu = np.concatenate([tr.encoding.xu for tr in self.trains])
        super().__init__(n_var=len(names), n_obj=1, n_ieq_constr=len(self.constraint_names), xl=xl, xu=xu,
                         vtype=float, **kwargs)

    constraint_names = CONSTRAINTS

    @property
    def departures_s(self) -> tuple[float, float]:
        """Departure times of the leading and the trailing train (s)."""
        return 0.0, self.offset_s

    def simulate(self, X: np.ndarray) -> dict:
        """Paced runs of both trains, their traces on the common clock and their interaction."""
        X = check_decisions(X, self.xl, self.xu)
        paced = [tr.paced(X[:, s], self.time_tol_s) for tr, s in zip(self.trains, self.slices)]
        n = X.shape[0]
        shared = np.zeros(n)
        separation = np.zeros(n)
        clocked = []
        a, b = self.trains
        gap_m = a.case.train.length_m + self.safety_margin_m
        for i in range(n):
            runs = [tr.clocked(p.programs[i], dep) for tr, p, dep in zip(self.trains, paced, self.departures_s)]
            if self.share_energy:
                shared[i] = coop.shared_energy_kwh(runs, 1.0, self.time_step_s)
            separation[i] = coop.separation_m(runs[0], runs[1], gap_m, self.separation_decel_ms2, self.time_step_s)
            clocked.append(runs)
        return {"X": X, "paced": paced, "clocked": clocked, "shared_kwh": shared, "separation_m": separation}

    def _constraints(self, sim: dict) -> np.ndarray:
        """``G`` (N, n_ieq_constr) of a :meth:`simulate` result, columns in ``constraint_names`` order."""
        err = np.max([np.abs(p.running_time_s - tr.case.planned_time_s)
                      for p, tr in zip(sim["paced"], self.trains)], axis=0)
        return np.column_stack([sim["separation_m"], err - self.max_time_error_s])

    def _evaluate(self, x, out, *args, **kwargs):
        sim = self.simulate(x)
        pa, pb = sim["paced"]
        trac_a, trac_b = pa.summaries[:, OUT_TRACTION_KWH], pb.summaries[:, OUT_TRACTION_KWH]
        out["F"] = (trac_a + trac_b - sim["shared_kwh"])[:, None]
        out["G"] = self._constraints(sim)
        out["traction_a_kwh"] = trac_a
        out["traction_b_kwh"] = trac_b
        out["shared_kwh"] = sim["shared_kwh"]
        out["running_time_a_s"] = pa.running_time_s
        out["running_time_b_s"] = pb.running_time_s
        out["pace_a"] = pa.pace
        out["pace_b"] = pb.pace

    # ------------------------------------------------------------------ inspection
    def decode(self, x: np.ndarray) -> CooperativeSolution:
        """Both trajectories, the shared energy and the constraints of one vector."""
        x = check_decisions(x, self.xl, self.xu)
        if x.shape[0] != 1:
            raise ValueError(f"decode takes one decision vector, got {x.shape[0]}")
        sim = self.simulate(x)
        pa, pb = sim["paced"]
        g = self._constraints(sim)[0]
        trajs = [tr.simulator.run(p.programs[0]) for tr, p in zip(self.trains, sim["paced"])]
        return CooperativeSolution(a=trajs[0], b=trajs[1], offset_s=self.offset_s,
                                   pace=(float(pa.pace[0]), float(pb.pace[0])),
                                   traction_a_kwh=trajs[0].energy.traction_kwh,
                                   traction_b_kwh=trajs[1].energy.traction_kwh,
                                   shared_kwh=float(sim["shared_kwh"][0]),
                                   constraints=dict(zip(self.constraint_names, (float(v) for v in g))))

    def power_profiles(self, x: np.ndarray) -> pd.DataFrame:
        """Power of both trains on the common clock (kW per bin): traction, usable regeneration, shared."""
        runs = self.simulate(x)["clocked"][0]
        return coop.power_profiles(runs, ("a", "b"), 1.0, self.time_step_s)

    def describe(self) -> str:
        """One line naming the case, the offset and the variables."""
        a, b = self.trains
        return (f"{type(self).__name__}({self.case.name}, offset {self.offset_s:g} s, {self.encoding}: {a.n_var} + "
                f"{b.n_var} genes, paced to {a.case.planned_time_s:g} s and {b.case.planned_time_s:g} s)")
