"""Paced speed codes: a driving shape and a running time, punctual by construction.

The speed-code encoding (:class:`~pymoo_rail.problems.encodings.SpeedCodes`) under a narrow
running-time constraint leaves an optimiser a thin slab of feasible vectors around the surface
``T(x) = T_plan``: most changes of one code move the running time out of the window. NSGA-II on
the suite's single-objective forms (1 % window) reaches the slab within five generations and then
collapses onto one run on its slow edge, from where every offspring is late or dearer
(``docs/suite.md``).

Here the decision vector is a *shape*, one value in [0, 1] per section (its speed code as a
fraction of the section's limit), and the *running time* itself (s), bounded by the problem's
window. Each shape is paced (:func:`pymoo_rail.sim.pacing.solve_pace`: every code raised or
lowered together) until the run takes the chosen time, so every vector of the box is on time up to
the pace solve's tolerance, with no repair. The shapes at pace 0 are exactly the speed codes
``shape * limit``, so the runs the encoding can reach are those of speed codes on the same
sections: the certified optimum is the same.
"""

from __future__ import annotations

from dataclasses import dataclass, replace

import numpy as np

from pymoo_rail.problems.encodings.base import EncodingSetup, ProgramEncoding, bound_field
from pymoo_rail.problems.encodings.speed_codes import SpeedCodes
from pymoo_rail.sim import Simulator
from pymoo_rail.sim.pacing import DEFAULT_TIME_TOL_S, PacedRuns, PacedSpeedCodes, section_limits_ms, solve_pace


@dataclass(frozen=True, eq=False)
class PacedCodes(ProgramEncoding):
    """Speed-code shapes (fractions of each section's limit) and a running time (s), paced.

    Parameters
    ----------
    partition, n_sections, max_section_m, floor_kmh
        The sections, as for :class:`~pymoo_rail.problems.encodings.SpeedCodes` (whose
        partition this encoding uses).
    time_tol_s : float
        Tolerance of the pace solve (s).

    Attributes
    ----------
    codes : PacedSpeedCodes
        Set by :meth:`bind`: sections, their limits, and the pacing of a shape.
    simulator : Simulator
        Set by :meth:`bind`: the problem's simulator (the pace solve runs on it).
    xl, xu : numpy.ndarray
        Set by :meth:`bind`: 0 and 1 for the shape, then the problem's running-time window (s)
        shrunk by the pace solve's tolerance at both ends, so a converged solve lands inside it.
    """

    partition: str = "gradient_limit"
    n_sections: int | None = None
    max_section_m: float | None = None
    floor_kmh: float = 10.0
    time_tol_s: float = DEFAULT_TIME_TOL_S
    codes: PacedSpeedCodes | None = bound_field()
    simulator: Simulator | None = bound_field()
    xl: np.ndarray | None = bound_field()
    xu: np.ndarray | None = bound_field()

    name = "paced_speed_codes"
    # every run lands on the platform through the braking envelope
    constant_objectives = ("stop_error",)

    def bind(self, setup: EncodingSetup) -> PacedCodes:
        """The paced encoding of the setup's case, its running times in the setup's ``time_range_s``.

        Raises
        ------
        ValueError
            When the problem tracks its runs, when its constraints leave the running time open
            (no ``time_tolerance_s`` nor ``time_window_s``), or naming the window when it holds no
            running time the train can run within the solve's tolerance (it must reach above the
            flat-out time).
        """
        self.refuse_tracking(setup, "the pace solve moves every code together to meet a running time; "
                                    "use speed_codes")
        lo, hi = setup.time_range_s
        if not (np.isfinite(lo) and np.isfinite(hi)):
            raise ValueError("encoding = 'paced_speed_codes' needs time_tolerance_s or time_window_s: "
                             "the running times its runs are paced to")
        sections = SpeedCodes(self.partition, self.n_sections, self.max_section_m, self.floor_kmh).bind(setup)
        case, simulator, time_tol_s = setup.case, setup.simulator, self.time_tol_s
        bounds = sections.boundaries_m
        window_s = setup.time_range_s
        t_min = simulator.flat_out().running_time_s
        lo = max(lo, t_min) + time_tol_s
        hi = hi - time_tol_s
        if not (np.isfinite(lo) and np.isfinite(hi) and lo < hi):
            raise ValueError(f"time window {tuple(window_s)!r} s: no running time between the flat-out run "
                             f"({t_min:.2f} s) and its end, {time_tol_s} s inside both ends, for paced speed codes")
        codes = PacedSpeedCodes(boundaries_m=bounds, limits_ms=section_limits_ms(case, bounds),
                                planned_time_s=float(case.planned_time_s))
        n = codes.n_var
        return replace(self, n_sections=n, time_tol_s=float(time_tol_s), codes=codes, simulator=simulator,
                       xl=np.concatenate([np.zeros(n), [lo]]), xu=np.concatenate([np.ones(n), [hi]]))

    @property
    def boundaries_m(self) -> np.ndarray:
        """Section boundaries (m)."""
        return self.codes.boundaries_m

    @property
    def units(self) -> list[str]:
        """Unit of each decision variable (the shape is a fraction of the section's limit)."""
        return ["1"] * self.n_sections + ["s"]

    def paced(self, X: np.ndarray) -> PacedRuns:
        """The runs of ``X``: each shape paced to the running time in its last column (pace, program, summary)."""
        self.bound()
        X = np.atleast_2d(np.asarray(X, dtype=float))
        if X.shape[1] != self.n_var:
            raise ValueError(f"paced speed codes need {self.n_var} values per run, got {X.shape[1]}")
        return solve_pace(self.simulator, self.codes, X[:, :-1], self.time_tol_s, target_s=X[:, -1])

    def programs(self, X: np.ndarray) -> np.ndarray:
        """Kernel programs of ``X`` (see :meth:`paced`)."""
        return self.paced(X).programs

    def summaries(self, X: np.ndarray, runner=None) -> np.ndarray:
        """Summaries of the paced runs of ``X`` (the pace solve has run every program already).

        ``runner`` is not used: the pace solve runs on this encoding's simulator (the problem's).
        """
        return self.paced(np.ascontiguousarray(X)).summaries
