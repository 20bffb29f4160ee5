"""Whole-trip instances: the running time of a many-stop trip split over its sections.

A trip of ``n_var`` stop-to-stop sections is drawn from ``seed``: a pool of :data:`POOL_SIZE`
seeded lines (:func:`pymoo_rail.cases.generate_case`, from and to rest) and, for each section, which
of them it runs. Each pool line's energy-time curve ``E_k(t)`` is the lower convex hull of
simulated traction - hold - coast - brake runs (:func:`pymoo_rail.journeys.strategy_front`, up to
:data:`MAX_TIME_FACTOR` x its minimum time). The problem is
:class:`pymoo_rail.journeys.RunningTimeAllocationProblem`: minimise ``sum_k E_k(t_k)`` subject to
``sum_k t_k = T``, ``T`` :data:`TIME_SUPPLEMENT` x the sum of the sections' minimum running times;
its optimum is exact,
:func:`pymoo_rail.journeys.allocate_on_fronts` (equal marginal energy on convex piecewise-linear
curves), at every dimension.
"""

from __future__ import annotations

import numpy as np
import pandas as pd

from pymoo_rail.cases import generate_case
from pymoo_rail.journeys import RunningTimeAllocationProblem, allocate_on_fronts, front_energy, strategy_front
from pymoo_rail.model import Case
from pymoo_rail.optimal.reference import case_hash
from pymoo_rail.suite.identity import HV_MARGIN, as_text

POOL_SIZE = 8
"""Distinct lines a trip's sections are drawn from (their curves are computed once each)."""
MAX_TIME_FACTOR = 1.5
"""Each curve covers running times up to this factor times the line's minimum."""
TIME_SUPPLEMENT = 1.15
"""The trip's running time: this factor times the sum of the sections' minimum running times (a
timetable's running-time supplement), handed out where it saves the most energy."""


def pool_cases(seed: int, kind: str) -> list[Case]:
    """The :data:`POOL_SIZE` lines of a trip: generated from seeds drawn from ``seed``, those from and to rest."""
    rng = np.random.default_rng(seed)
    pool: list[Case] = []
    while len(pool) < POOL_SIZE:
        case = generate_case(int(rng.integers(0, 2**31 - 1)), kind)
        if case.initial_speed_ms == 0.0 and case.final_speed_ms == 0.0:  # a stop at every station
            pool.append(case)
    return pool


class TripProblem(RunningTimeAllocationProblem):
    """A whole-trip instance: :class:`~pymoo_rail.journeys.RunningTimeAllocationProblem` with its identity.

    Attributes
    ----------
    pool : list of Case
        The distinct lines; ``sections[k]`` is the pool index of section ``k``.
    optimum : (numpy.ndarray, float)
        The exact split (s per section) and its energy (kWh).
    """

    objectives = ("energy",)

    def __init__(self, pool: list[Case], sections: np.ndarray, curves: list[pd.DataFrame]):
        self.pool, self.sections = pool, np.asarray(sections, dtype=int)
        fastest = np.array([c["running_time_s"].iloc[0] for c in curves])
        total = TIME_SUPPLEMENT * float(fastest[self.sections].sum())
        super().__init__([curves[i] for i in self.sections], total)
        times, energies, _ = allocate_on_fronts(self.fronts, total)
        self.optimum = (times, float(energies.sum()))

    def _calc_pareto_front(self, *args, **kwargs) -> np.ndarray:
        return np.array([[self.optimum[1]]])

    def hv_reference_point(self) -> np.ndarray:
        """Energy of every section at its shortest time (the most any split in the box costs) plus
        :data:`~pymoo_rail.suite.identity.HV_MARGIN` of its distance from the optimum: the fixed
        reference of the HV gap."""
        fastest = float(sum(front_energy(f, f["running_time_s"].iloc[0]) for f in self.fronts))
        return np.array([fastest + HV_MARGIN * (fastest - self.optimum[1])])

    def definition(self) -> dict:
        """What the checksum covers: the pool's content, the sections, the curves, the budget, the bounds."""
        return {"pool_case_hashes": [case_hash(c) for c in self.pool], "sections": self.sections.tolist(),
                "curves": [as_text(f[["running_time_s", "energy_kwh"]].to_numpy()) for f in self._pool_curves()],
                "total_time_s": as_text(self.total_time_s), "xl": as_text(self.xl), "xu": as_text(self.xu),
                "n_eq_constr": int(self.n_eq_constr)}

    def _pool_curves(self) -> list[pd.DataFrame]:
        first = {int(i): k for k, i in reversed(list(enumerate(self.sections)))}
        return [self.fronts[first[i]] for i in sorted(first)]


def trip_problem(kind: str, n_var: int, seed: int, max_sections: int = 1000) -> TripProblem:
    """The trip of ``n_var`` sections on ``kind`` lines drawn from ``seed`` (see the module docstring).

    The sections of a shorter trip are the first ones of a longer trip of the same seed.
    """
    pool = pool_cases(seed, kind)
    sections = np.random.default_rng([seed, 1]).integers(0, POOL_SIZE, max(max_sections, n_var))[:n_var]
    curves = [strategy_front(case, max_time_factor=MAX_TIME_FACTOR) for case in pool]
    return TripProblem(pool, sections, curves)
