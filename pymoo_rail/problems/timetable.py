"""Several trains on a line sharing braking energy within one power-supply section: ``TimetableProblem``.

The pair of Chen et al. (2017) grown to a timetable. ``n_trains`` trains run the case one after
another (every leg in turn, dwelling ``dwell_s`` at each intermediate stop), nominally
``headway_s`` apart. With ``directions=2`` every second train runs the line the other way
(:func:`opposite_direction`: the same track from its far end, each gradient's sign reversed), on
its own track but in the same power-supply section, so an up train braking into a station can feed
a down train leaving it. Decision vector: each train's departure shift within ``+-window_s`` of its
nominal time (train 0 keeps its slot, which fixes the clock), then each train's driving shape per
leg (:mod:`pymoo_rail.sim.pacing`: paced to the leg's planned time, so every vector is on time).
All trains lie in one power-supply section: any train's regenerated power feeds the others'
traction through the supply with ``transmission_efficiency``
(:func:`pymoo_rail.sim.cooperation.shared_energy_bins`).

Objectives (minimised, any subset in any order):

- ``"energy"``: net substation energy, traction of all trains minus what they share (kWh);
- ``"waiting_time"``: mean passenger waiting time at the first station (s) for passengers arriving
  uniformly, with the timetable repeating every ``n_trains * headway_s``: ``sum h_i^2 / (2 sum h_i)``
  over the departure gaps ``h_i`` (``headway_s / 2`` for a regular timetable).

Constraints (``G <= 0``): separation of each train from the one ahead in its direction (eq. 9 of the paper, by
braking distance at ``separation_decel_ms2`` plus the train length and a safety margin; a train
clears the terminus ``dwell_s`` after arriving), and the
pace solve's running-time guard. The reference line is ``n_trains`` times the exact single-train
optimum of every leg without sharing (:func:`pymoo_rail.problems.cooperative_baseline.exact_baseline`).
"""

from __future__ import annotations

from dataclasses import replace

import numpy as np
from pymoo.core.problem import Problem

from pymoo_rail.constants import J_PER_KWH
from pymoo_rail.model import Case, Leg
from pymoo_rail.problems.cooperative import PacedTrain, finite_number
from pymoo_rail.problems.speed_profile import check_decisions
from pymoo_rail.sim import cooperation as coop
from pymoo_rail.sim.kernel import OUT_TRACTION_KWH
from pymoo_rail.sim.pacing import DEFAULT_TIME_TOL_S

TIMETABLE_OBJECTIVES = ("energy", "waiting_time")


def opposite_direction(case: Case) -> Case:
    """The case run the other way: the same track from its far end.

    Positions are mirrored (``x -> L - x``), gradients change sign, curves, tunnels and neutral
    sections keep their places on the track, legs run in reverse order with their planned times
    and dwells. Speed limits are taken to be the same in both directions (a case describes one
    direction only; where the real down-direction limits differ, give them as a case of their own).
    """
    if not isinstance(case, Case):
        raise TypeError(f"case = {case!r}: must be a pymoo_rail Case")
    line = case.line
    length = line.length_m

    def flip(rows, sign=1.0):
        return tuple((length - r[1], length - r[0], *(sign * v for v in r[2:])) for r in reversed(rows))

    mirrored = replace(line, gradients=flip(line.gradients, -1.0), speed_limits=flip(line.speed_limits),
                       curves=flip(line.curves), tunnels=flip(line.tunnels),
                       neutral_sections=flip(line.neutral_sections))
    legs = tuple(Leg(start_m=length - leg.end_m, end_m=length - leg.start_m, planned_time_s=leg.planned_time_s,
                     dwell_s=leg.dwell_s) for leg in reversed(case.legs))
    return replace(case, name=f"{case.name} (opposite direction)", line=mirrored, legs=legs,
                   initial_speed_ms=case.final_speed_ms, final_speed_ms=case.initial_speed_ms)


def mean_waiting_time_s(departures_s: np.ndarray, period_s: float) -> np.ndarray:
    """Mean wait (s) of uniformly arriving passengers for departures (N, n) repeating every ``period_s``."""
    d = np.sort(np.atleast_2d(departures_s), axis=1)
    gaps = np.diff(np.concatenate([d, d[:, :1] + period_s], axis=1), axis=1)
    return (gaps ** 2).sum(axis=1) / (2.0 * period_s)


class TimetableProblem(Problem):
    """Trains sharing regenerative braking energy in one supply section, departures free in a window.

    Parameters
    ----------
    case : Case
        The line every train runs (all its legs in turn, or its single run).
    n_trains : int
        Number of trains (>= 2).
    headway_s : float
        Nominal time between departures.
    dwell_s : float, optional
        Dwell at intermediate stops (default: the case's ``dwell_s``).
    window_s : float
        Each departure (but the first) may move this far from its nominal time (30 s).
    transmission_efficiency : float
        Share of regenerated power the supply delivers to another train (0.9), in (0, 1].
    objectives : sequence of str
        Among ``"energy"``, ``"waiting_time"`` (default both).
    max_section_m : float or None
        Longest section of a shape (400 m: fewer genes per train than the pair's 200 m).
    safety_margin_m, separation_decel_ms2 : float
        L_s and b of the separation rule (40 m, 1.0 m/s^2).
    time_step_s, time_tol_s, max_time_error_s, dx_m
        As for :class:`~pymoo_rail.problems.CooperativeTrainsProblem`.
    directions : {1, 2}
        2: trains alternate between the case's direction and the opposite one
        (:func:`opposite_direction`); separation applies within a direction, sharing across both,
        and the waiting time is the mean over the two first stations.

    Notes
    -----
    Extra outputs: ``traction_kwh``, ``shared_kwh``, ``net_kwh``, ``waiting_time_s``.
    """

    def __init__(self, case: Case, n_trains: int, headway_s: float, dwell_s: float | None = None, *,
                 window_s: float = 30.0, transmission_efficiency: float = 0.9,
                 objectives=TIMETABLE_OBJECTIVES, max_section_m: float | None = 400.0, safety_margin_m: float = 40.0,
                 separation_decel_ms2: float = 1.0, time_step_s: float = 0.1,
                 time_tol_s: float = DEFAULT_TIME_TOL_S, max_time_error_s: float = 0.5, dx_m: float | None = None,
                 directions: int = 1, **kwargs):
        if not isinstance(case, Case):
            raise TypeError(f"case = {case!r}: must be a pymoo_rail Case")
        if isinstance(n_trains, bool) or not isinstance(n_trains, (int, np.integer)) or n_trains < 2:
            raise ValueError(f"n_trains = {n_trains!r}: must be an integer >= 2")
        self.case = case
        self.n_trains = int(n_trains)
        self.headway_s = finite_number("headway_s", headway_s, positive=True)
        self.dwell_s = finite_number("dwell_s", case.dwell_s if dwell_s is None else dwell_s, nonneg=True)
        self.window_s = finite_number("window_s", window_s, nonneg=True)
        self.transmission_efficiency = finite_number("transmission_efficiency", transmission_efficiency,
                                                     positive=True)
        if self.transmission_efficiency > 1.0:
            raise ValueError(f"transmission_efficiency = {transmission_efficiency!r}: must be in (0, 1]")
        objectives = tuple(objectives)
        unknown = [o for o in objectives if o not in TIMETABLE_OBJECTIVES]
        if not objectives or unknown or len(set(objectives)) != len(objectives):
            raise ValueError(f"objectives = {objectives!r}: choose distinct names among {TIMETABLE_OBJECTIVES}")
        self.objectives = objectives
        self.safety_margin_m = finite_number("safety_margin_m", safety_margin_m, nonneg=True)
        self.separation_decel_ms2 = finite_number("separation_decel_ms2", separation_decel_ms2, positive=True)
        self.time_step_s = finite_number("time_step_s", time_step_s, positive=True)
        self.time_tol_s = finite_number("time_tol_s", time_tol_s, positive=True)
        self.max_time_error_s = finite_number("max_time_error_s", max_time_error_s, positive=True)
        if isinstance(directions, bool) or directions not in (1, 2):
            raise ValueError(f"directions = {directions!r}: must be 1 or 2")
        self.directions = int(directions)
        self.cases = (case, opposite_direction(case))[:self.directions]
        self.dx_m = dx_m
        self.routes = tuple(self._route(c, max_section_m, dx_m) for c in self.cases)
        self.legs = self.routes[0]
        self.direction_of = np.arange(self.n_trains) % self.directions
        sizes = [sum(leg.n_var for leg in self.routes[d]) for d in self.direction_of]
        self.n_shape = sizes[0]
        n_shift = self.n_trains - 1
        self.block_start = n_shift + np.concatenate([[0], np.cumsum(sizes)[:-1]]).astype(int)
        n_var = n_shift + int(sum(sizes))
        xl = np.concatenate([np.full(n_shift, -self.window_s), np.zeros(n_var - n_shift)])
        xu = np.concatenate([np.full(n_shift, self.window_s), np.ones(n_var - n_shift)])
        super().__init__(n_var=n_var, n_obj=len(objectives), n_ieq_constr=2, xl=xl, xu=xu, vtype=float, **kwargs)

    @staticmethod
    def _route(case: Case, max_section_m, dx_m) -> tuple[PacedTrain, ...]:
        """The paced legs of one direction."""
        if case.legs:
            legs = [(case.leg(k), leg.start_m) for k, leg in enumerate(case.legs)]
        else:
            legs = [(case, 0.0)]
        return tuple(PacedTrain.build(leg, start, max_section_m, dx_m) for leg, start in legs)

    def references_per_train_kwh(self) -> list[float]:
        """Per direction, one train's exact optimum alone over all legs, nothing shared (kWh).

        Solves each direction's legs with the exact solver on the problem's grid (about a CPU
        second per direction once compiled)."""
        from pymoo_rail.problems.cooperative_baseline import exact_baseline

        settings = {} if self.dx_m is None else {"dx_m": self.dx_m}
        return [exact_baseline(c, **settings).energy_kwh for c in self.cases]

    def reference_kwh(self) -> float:
        """The reference line (kWh): every train exactly optimal alone in its direction, nothing shared."""
        per_train = self.references_per_train_kwh()
        return float(sum(per_train[d] for d in self.direction_of))

    @property
    def period_s(self) -> float:
        """Period of the timetable: trains x headway (s)."""
        return self.n_trains * self.headway_s

    def departures_s(self, X: np.ndarray) -> np.ndarray:
        """Departure times (N, n_trains) from each train's first station."""
        X = check_decisions(X, self.xl, self.xu)
        nominal = self.headway_s * np.arange(self.n_trains)
        shifts = np.concatenate([np.zeros((X.shape[0], 1)), X[:, :self.n_trains - 1]], axis=1)
        return nominal + shifts

    def trains_of(self, direction: int) -> np.ndarray:
        """Indices of the trains running ``direction`` (0: the case's, 1: the opposite one)."""
        return np.flatnonzero(self.direction_of == direction)

    def shapes(self, X: np.ndarray, leg: int, direction: int = 0) -> np.ndarray:
        """Shapes of every train of ``direction`` on one of its legs, (N * n_d, n_sections), train-major."""
        X = check_decisions(X, self.xl, self.xu)
        route = self.routes[direction]
        offset = sum(tr.n_var for tr in route[:leg])
        blocks = [X[:, self.block_start[i] + offset: self.block_start[i] + offset + route[leg].n_var]
                  for i in self.trains_of(direction)]
        return np.stack(blocks, axis=1).reshape(-1, route[leg].n_var)

    def simulate(self, X: np.ndarray) -> dict:
        """Journeys of every train on the common clock, energies, separation and waiting time."""
        X = check_decisions(X, self.xl, self.xu)
        n = X.shape[0]
        departures = self.departures_s(X)
        traction = np.zeros(n)
        time_err = np.zeros(n)
        paced = []
        for d, route in enumerate(self.routes):
            n_d = self.trains_of(d).shape[0]
            runs = [tr.paced(self.shapes(X, k, d), self.time_tol_s) for k, tr in enumerate(route)]
            for p, tr in zip(runs, route):
                traction += p.summaries[:, OUT_TRACTION_KWH].reshape(n, n_d).sum(axis=1)
                time_err = np.maximum(time_err, np.abs(p.running_time_s - tr.case.planned_time_s).reshape(n, n_d)
                                      .max(axis=1))
            paced.append(runs)
        shared = np.zeros(n)
        separation = np.full(n, -np.inf)
        gap_m = self.case.train.length_m + self.safety_margin_m
        journeys_all = []
        for r in range(n):
            journeys = [None] * self.n_trains
            for d, route in enumerate(self.routes):
                trains = self.trains_of(d)
                for j, i in enumerate(trains):
                    t = departures[r, i]
                    runs = []
                    for tr, p in zip(route, paced[d]):
                        run = tr.clocked(p.programs[r * trains.shape[0] + j], t)
                        runs.append(run)
                        t = run.arrival_s + self.dwell_s
                    journeys[i] = coop.chain_runs(runs)
                order = trains[np.argsort(departures[r, trains], kind="stable")]
                for lead, follow in zip(order[:-1], order[1:]):
                    # the leader clears the terminus after a dwell there (turning back or to the depot)
                    excess = coop.separation_m(journeys[follow], journeys[lead], gap_m, self.separation_decel_ms2,
                                               self.time_step_s, journeys[lead].arrival_s + self.dwell_s)
                    separation[r] = max(separation[r], excess)
            t0, n_bins = coop.clock_span(journeys, self.time_step_s)
            trac, regen = coop.power_bins(journeys, t0, self.time_step_s, n_bins)
            shared[r] = coop.shared_energy_bins(trac, regen, self.transmission_efficiency).sum() / J_PER_KWH
            journeys_all.append(journeys)
        waiting = np.mean([mean_waiting_time_s(departures[:, self.trains_of(d)], self.period_s)
                           for d in range(self.directions)], axis=0)
        return {"departures_s": departures, "journeys": journeys_all, "traction_kwh": traction, "shared_kwh": shared,
                "net_kwh": traction - shared, "separation_m": separation, "time_error_s": time_err,
                "waiting_time_s": waiting}

    def _evaluate(self, x, out, *args, **kwargs):
        sim = self.simulate(x)
        values = {"energy": sim["net_kwh"], "waiting_time": sim["waiting_time_s"]}
        out["F"] = np.column_stack([values[o] for o in self.objectives])
        out["G"] = np.column_stack([sim["separation_m"], sim["time_error_s"] - self.max_time_error_s])
        for key in ("traction_kwh", "shared_kwh", "net_kwh", "waiting_time_s"):
            out[key] = sim[key]

    def describe(self) -> str:
        """One line naming the case, the trains, the headway and the legs."""
        return (f"TimetableProblem({self.case.name}: {self.n_trains} trains every {self.headway_s:g} s "
                f"+- {self.window_s:g} s, {self.directions} direction(s), {len(self.legs)} legs, {self.n_var} variables, objectives "
                f"{', '.join(self.objectives)})")
