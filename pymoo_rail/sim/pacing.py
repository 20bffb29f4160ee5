"""Punctuality by construction: a driving shape plus one pace, the pace found for the planned time.

A *paced* program family maps a shape ``c`` (speed codes as fractions of each section's limit, in
[0, 1]) and a scalar pace ``p`` in [-1, 1] to targets ``limit_k * clip(c_k + p, 0, 1)``: at
``p = 1`` every section runs at its limit (the fastest run), at ``p = -1`` every target is zero (the
train never leaves). Raising the pace raises every target, so the train is nowhere slower and the
running time falls monotonically with ``p``. :func:`solve_pace` finds, for a whole population at
once, the pace at which each shape takes its planned time, by bracketing regula falsi (Illinois)
with bisection where a run does not reach the platform. The shape is what an optimiser varies; the
time is met by the solve, as the exact solver meets it by pricing time (:mod:`pymoo_rail.optimal`).

Nothing here knows pymoo.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from pymoo_rail.constants import KMH_PER_MS
from pymoo_rail.model import Case
from pymoo_rail.sim.drivers import gradient_limit_partition, speed_code_programs
from pymoo_rail.sim.kernel import (
    MODE_COAST,
    MODE_HOLD_BRAKE,
    MODE_STOP,
    MODE_TOWARD,
    OUT_REACHED,
    OUT_RUNNING_TIME_S,
)
from pymoo_rail.sim.physics import davis_force
from pymoo_rail.sim.simulator import Simulator

PACE_MIN, PACE_MAX = -1.0, 1.0
DEFAULT_TIME_TOL_S = 0.02
MAX_ITERATIONS = 40


def split_long_sections(boundaries_m: np.ndarray, max_section_m: float | None) -> np.ndarray:
    """Cut every section longer than ``max_section_m`` into equal pieces."""
    if max_section_m is None:
        return np.asarray(boundaries_m, dtype=float)
    if not (np.isfinite(max_section_m) and max_section_m > 0):
        raise ValueError(f"max_section_m = {max_section_m!r}: must be a positive number of metres")
    out = [float(boundaries_m[0])]
    for a, b in zip(boundaries_m[:-1], boundaries_m[1:]):
        pieces = int(np.ceil((b - a) / max_section_m - 1e-9))
        out.extend(np.linspace(a, b, pieces + 1)[1:])
    return np.asarray(out)


def section_limits_ms(case: Case, boundaries_m: np.ndarray) -> np.ndarray:
    """The highest speed over each section (m/s): its lowest limit, at most the train's maximum speed."""
    limits = np.empty(boundaries_m.shape[0] - 1)
    for k, (a, b) in enumerate(zip(boundaries_m[:-1], boundaries_m[1:])):
        limits[k] = min(v for s, e, v in case.line.speed_limits if s < b and e > a)
    return np.minimum(limits, case.train.max_speed_kmh) / KMH_PER_MS


@dataclass(frozen=True, eq=False)
class PacedSpeedCodes:
    """Speed-code shapes of one run, timed by a pace (see the module docstring).

    Attributes
    ----------
    boundaries_m : (n_sections + 1,)
        Section boundaries: every gradient and limit change, long sections split.
    limits_ms : (n_sections,)
        The highest target of each section (its lowest limit, at most the train's maximum speed).
    planned_time_s : float
        The running time every shape is paced to.
    """

    boundaries_m: np.ndarray
    limits_ms: np.ndarray
    planned_time_s: float
    pace_bounds = (PACE_MIN, PACE_MAX)

    @classmethod
    def build(cls, case: Case, max_section_m: float | None = 200.0,
              planned_time_s: float | None = None) -> PacedSpeedCodes:
        """The shape encoding of a single-run case, paced to ``planned_time_s`` (default: its plan)."""
        bounds = split_long_sections(gradient_limit_partition(case.line), max_section_m)
        limits = section_limits_ms(case, bounds)
        planned = case.planned_time_s if planned_time_s is None else float(planned_time_s)
        if not (np.isfinite(planned) and planned > 0):
            raise ValueError(f"planned_time_s = {planned_time_s!r}: must be a positive number of seconds")
        return cls(boundaries_m=bounds, limits_ms=limits, planned_time_s=planned)

    @property
    def n_var(self) -> int:
        """Number of shape variables (one per section)."""
        return self.limits_ms.shape[0]

    @property
    def xl(self) -> np.ndarray:
        """Lower bounds of the shape (0)."""
        return np.zeros(self.n_var)

    @property
    def xu(self) -> np.ndarray:
        """Upper bounds of the shape (1)."""
        return np.ones(self.n_var)

    def names(self, label: str = "") -> list[str]:
        """Variable names, ``label`` naming the train."""
        return [f"shape{label}{k + 1}" for k in range(self.n_var)]

    def programs(self, shapes: np.ndarray, pace: np.ndarray) -> np.ndarray:
        """Kernel programs of shapes (N, n_var) at paces (N,)."""
        shapes = np.atleast_2d(np.asarray(shapes, dtype=float))
        if shapes.shape[1] != self.n_var:
            raise ValueError(f"shapes have {shapes.shape[1]} values: this encoding has {self.n_var} sections")
        rel = np.clip(shapes + np.asarray(pace, dtype=float)[:, None], 0.0, 1.0)
        return speed_code_programs(self.boundaries_m, rel * self.limits_ms)


@dataclass(frozen=True, eq=False)
class PacedSubsections:
    """The operating sequences of Chen et al. (2017) (table 1) as kernel rows, timed by a pace.

    The run is cut into subsections at every gradient and limit change. The genes of one train are
    ``[dS, gamma_1, turn_1, last_1, ..., gamma_m, turn_m, last_m]``:

    - ``dS`` (m): the braking distance: from ``P = L - dS`` the train brakes at the constant
      deceleration that stops it at the platform, ``v_m^2 / (2 dS)`` (type 1, ``MODE_STOP``);
      subsections beyond P are dropped, the one holding P ends there;
    - ``gamma_k`` in [0, 1]: the traction share up to the turning speed (never below the force that
      holds the speed, as in the paper);
    - ``turn_k`` in [0, 1]: the turning speed ``v_a = cap_k clip(turn_k + p, 0, 1)`` at pace ``p``
      (the paper finds ``v_a`` from a time share ``q_k``; here one pace meets the plan for all);
    - ``last_k`` in [0, 1]: the share of the subsection run in its last phase: coasting (type 2)
      or, on a descent where coasting accelerates (type 3), holding the speed reached by
      regenerative braking. It sets the paper's exit speed ``v_k``.

    Rows per subsection: ``MODE_TOWARD`` to ``v_a`` with traction share ``gamma`` (traction, then
    hold, or on a descent coasting above ``v_a``), then ``MODE_COAST`` or ``MODE_HOLD_BRAKE``.
    Paces in [-1, 1] move the turning speeds; paces in (1, 2] move, beyond that, every ``gamma``
    toward 1 and every last phase toward zero length (the paper's repair toward the fastest
    sequence), so the running time falls monotonically over [-1, 2].
    """

    boundaries_m: np.ndarray
    caps_ms: np.ndarray
    descent: np.ndarray
    grade_change: np.ndarray
    brake_bounds_m: tuple[float, float]
    length_m: float
    planned_time_s: float
    pace_bounds = (PACE_MIN, PACE_MAX + 1.0)

    @classmethod
    def build(cls, simulator: Simulator, service_decel_ms2: float = 1.0,
              brake_range_factor: float = 1.5) -> PacedSubsections:
        """The subsections of the simulator's case; ``dS`` ranges over 2-100 % of ``brake_range_factor``
        times the distance to brake at ``service_decel_ms2`` from the approach limit (section 3.2)."""
        for name, value in (("service_decel_ms2", service_decel_ms2), ("brake_range_factor", brake_range_factor)):
            if not (np.isfinite(value) and value > 0):
                raise ValueError(f"{name} = {value!r}: must be a positive number")
        case, m = simulator.case, simulator.model
        line = case.line
        bounds = gradient_limit_partition(line)
        caps = section_limits_ms(case, bounds)
        descent = np.zeros(caps.shape[0], dtype=bool)
        change = np.zeros(caps.shape[0], dtype=bool)
        grades = [g for _, _, g in line.gradients]

        def grade_at(x: float) -> float:
            for (s, e, g) in line.gradients:
                if s <= x < e:
                    return g
            return grades[-1]

        for k, (a, b) in enumerate(zip(bounds[:-1], bounds[1:])):
            cells = (m.position_m[:-1] >= a) & (m.position_m[:-1] < b)
            # type 3 when coasting accelerates the train here even at its highest speed (the line force
            # is the one the train feels: averaged over its length, curves included)
            descent[k] = davis_force(m, caps[k]) + float(np.mean(m.line_force_n[cells])) < 0.0
            change[k] = k > 0 and grade_at(a - 1e-6) != grade_at(a + 1e-6)
        upper = min(brake_range_factor * caps[-1] ** 2 / (2.0 * service_decel_ms2), 0.9 * line.length_m)
        return cls(boundaries_m=bounds, caps_ms=caps, descent=descent, grade_change=change,
                   brake_bounds_m=(0.02 * upper, upper), length_m=float(line.length_m),
                   planned_time_s=float(case.planned_time_s))

    @property
    def n_sub(self) -> int:
        """Number of subsections."""
        return self.caps_ms.shape[0]

    @property
    def n_var(self) -> int:
        """Number of genes: the braking distance and three per subsection."""
        return 1 + 3 * self.n_sub

    @property
    def xl(self) -> np.ndarray:
        """Lower bounds: the shortest braking distance (m), then zeros."""
        return np.concatenate([[self.brake_bounds_m[0]], np.zeros(3 * self.n_sub)])

    @property
    def xu(self) -> np.ndarray:
        """Upper bounds: the longest braking distance (m), then ones."""
        return np.concatenate([[self.brake_bounds_m[1]], np.ones(3 * self.n_sub)])

    def names(self, label: str = "") -> list[str]:
        """Variable names, ``label`` naming the train."""
        return [f"brake{label}_m"] + [f"{g}{label}{k + 1}" for k in range(self.n_sub)
                                      for g in ("gamma", "turn", "last")]

    def programs(self, genes: np.ndarray, pace: np.ndarray) -> np.ndarray:
        """Kernel programs (N, 2 m + 1, 4) of genes (N, n_var) at paces (N,)."""
        genes = np.atleast_2d(np.asarray(genes, dtype=float))
        if genes.shape[1] != self.n_var:
            raise ValueError(f"genes have {genes.shape[1]} values: this encoding has {self.n_var}")
        pace = np.asarray(pace, dtype=float)[:, None]
        n, m = genes.shape[0], self.n_sub
        triples = genes[:, 1:].reshape(n, m, 3)
        extra = np.clip(pace - PACE_MAX, 0.0, 1.0)
        gamma = triples[:, :, 0] + extra * (1.0 - triples[:, :, 0])
        turn = self.caps_ms * np.clip(triples[:, :, 1] + pace, 0.0, 1.0)
        last = triples[:, :, 2] * (1.0 - extra)
        brake_point = self.length_m - genes[:, :1]
        a = np.minimum(self.boundaries_m[:-1], brake_point)
        b = np.minimum(self.boundaries_m[1:], brake_point)
        programs = np.zeros((n, 2 * m + 1, 4))
        programs[:, 0:2 * m:2, 0] = b - last * (b - a)
        programs[:, 0:2 * m:2, 1] = MODE_TOWARD
        programs[:, 0:2 * m:2, 2] = turn
        programs[:, 0:2 * m:2, 3] = gamma
        programs[:, 1:2 * m:2, 0] = b
        programs[:, 1:2 * m:2, 1] = np.where(self.descent, MODE_HOLD_BRAKE, MODE_COAST)
        programs[:, 1:2 * m:2, 3] = 1.0
        programs[:, -1] = (self.length_m, MODE_STOP, 0.0, 1.0)
        return programs


@dataclass(frozen=True, eq=False)
class PacedRuns:
    """Result of :func:`solve_pace`: per run the pace, its kernel program and its summary."""

    pace: np.ndarray
    programs: np.ndarray
    summaries: np.ndarray

    @property
    def running_time_s(self) -> np.ndarray:
        """Running time of each run (s)."""
        return self.summaries[:, OUT_RUNNING_TIME_S]


def _times(simulator: Simulator, encoding: PacedSpeedCodes, shapes: np.ndarray, pace: np.ndarray):
    out = simulator.run_batch(encoding.programs(shapes, pace))
    t = np.where(out[:, OUT_REACHED] > 0, out[:, OUT_RUNNING_TIME_S], np.inf)
    return t, out


def solve_pace(simulator: Simulator, encoding: PacedSpeedCodes, shapes: np.ndarray,
               time_tol_s: float = DEFAULT_TIME_TOL_S, target_s: np.ndarray | float | None = None) -> PacedRuns:
    """The pace at which each shape runs in ``encoding.planned_time_s`` (a population at once).

    Parameters
    ----------
    simulator : Simulator
        Of the case the encoding was built on.
    encoding : PacedSpeedCodes or PacedSubsections
        Anything with ``planned_time_s``, ``pace_bounds`` and ``programs(shapes, pace)`` whose
        running time falls with the pace.
    shapes : (N, n_var)
        The encoding's genes (speed-code shapes in [0, 1]).
    time_tol_s : float
        Stop once every run is this close to the plan (or its pace bracket has shrunk to 1e-9).
    target_s : float or (N,) array, optional
        Running time of each run (s), instead of ``encoding.planned_time_s``.

    Returns
    -------
    PacedRuns
        The runs found; a run whose time jumps over the plan (a discontinuity of the grid) is the
        closer side of its final bracket. The plan must be at least the flat-out time
        (:meth:`Simulator.check_planned_time`), or the fastest side is returned.
    """
    shapes = np.atleast_2d(np.asarray(shapes, dtype=float))
    n = shapes.shape[0]
    target = np.broadcast_to(np.asarray(encoding.planned_time_s if target_s is None else target_s, dtype=float), (n,))
    pace_min, pace_max = encoding.pace_bounds
    lo = np.full(n, pace_min)  # slow side: time >= target
    hi = np.full(n, pace_max)  # fast side: time <= target
    t_hi, out_hi = _times(simulator, encoding, shapes, hi)
    f_hi = t_hi - target
    f_lo = np.full(n, np.inf)
    pace = hi.copy()
    out = out_hi.copy()
    best_err = np.abs(f_hi)
    side = np.zeros(n)
    active = f_hi < -time_tol_s  # flat out is too fast: the pace must come down
    for _ in range(MAX_ITERATIONS):
        if not active.any():
            break
        idx = np.flatnonzero(active)
        a, b, fa, fb = lo[idx], hi[idx], f_lo[idx], f_hi[idx]
        finite = np.isfinite(fa)
        with np.errstate(invalid="ignore", divide="ignore"):
            secant = b - fb * (b - a) / (fb - fa)
        mid = 0.5 * (a + b)
        trial = np.where(finite & (secant > a) & (secant < b), secant, mid)
        t, o = _times(simulator, encoding, shapes[idx], trial)
        f = t - target[idx]
        err = np.abs(f)
        better = err < best_err[idx]
        pace[idx[better]] = trial[better]
        out[idx[better]] = o[better]
        best_err[idx[better]] = err[better]
        slow = f > 0
        # Illinois: halve the stale end's value when the same side moves twice
        fb_new = np.where(slow & (side[idx] == -1), 0.5 * fb, fb)
        fa_new = np.where(~slow & (side[idx] == 1), 0.5 * fa, fa)
        lo[idx] = np.where(slow, trial, a)
        f_lo[idx] = np.where(slow, f, fa_new)
        hi[idx] = np.where(slow, b, trial)
        f_hi[idx] = np.where(slow, fb_new, f)
        side[idx] = np.where(slow, -1, 1)
        done = (err <= time_tol_s) | (hi[idx] - lo[idx] < 1e-9)
        active[idx[done]] = False
    programs = encoding.programs(shapes, pace)
    return PacedRuns(pace=pace, programs=programs, summaries=out)
