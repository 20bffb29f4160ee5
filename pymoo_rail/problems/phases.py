"""The kinematic four-phase model of Meng et al. (2017), as a pymoo problem with a binary encoding.

The paper runs every station-to-station trip as traction, cruise, coast and brake, each phase at a
fixed acceleration (section 3.2: 1.0, 0, 0.033 and -1.1 m/s^2), and lets a genetic algorithm choose
the phase lengths, coded in binary (section 2.2). Everything follows in closed form from the
lengths ``s_i`` and accelerations ``a_i`` (eqs. 12, 13):

    v_i = sqrt(2 a_i s_i + v_(i-1)^2),     t_i = (v_i - v_(i-1)) / a_i     (t_i = s_i / v_i at a_i = 0)

and the four indices of section 1:

- energy index, eq. 4: ``K_N = sum_i m a_i s_i`` over the phases with a_i > 0 (the work of the
  fixed accelerations; summed over every phase it is the kinetic energy at the end, 0 for a stop,
  so only the driven phases can be meant). Reported in kWh (m in kg);
- comfort, eq. 5: ``K_S = sum |a_i - a_(i-1)|`` from rest to rest, m/s^2 (the ``accel_variation``
  objective, alias ``jerk``);
- stop error, eq. 6: ``K_J = |sum s_i - S|`` (m);
- punctuality, eq. 8: ``K_Z = |sum t_i - T|`` (s).

Reading of the model (the paper leaves it open; documented in ``docs/metro.md``):

- the braking phase runs to standstill (``v(X) = 0`` of eq. 1), so its length is
  ``v_3^2 / (2 |a_4|)``: the genes are the first three lengths and the stop error is a
  consequence, as the paper's 1000.18 m stop is;
- the printed coasting acceleration 0.033 m/s^2 carries no sign; coasting decelerates on the
  paper's line (resistance alone gives -0.074 m/s^2 at 75 km/h), so the default is -0.033;
- the minimum phase-duration rule (section 3.1, "each phase is held for a while") has no number
  in the paper: ``min_phase_s`` (default 2 s, reconstructed) is a constraint on every phase;
- speed limits hold at every head position (kinematic speeds are monotone within a phase, so
  phase ends and limit-zone ends are the only places to check).

With fixed accelerations and every phase held for ``min_phase_s > 0``, the comfort index cannot
change: it is the constant ``2 sum |a_i|`` of the sequence, and the problem warns about it.
"""

from __future__ import annotations

import warnings
from dataclasses import dataclass
from typing import Sequence

import numpy as np
from pymoo.core.problem import Problem

from pymoo_rail.constants import J_PER_KWH, KMH_PER_MS
from pymoo_rail.model import Case
from pymoo_rail.problems.objectives import canonical_objective, check_objectives
from pymoo_rail.problems.speed_profile import ConstantObjectiveWarning, weighted_sum_settings

PHASE_NAMES = ("traction", "cruise", "coast", "brake")
PHASE_OBJECTIVES = ("energy", "accel_variation", "stop_error", "time_error")  # "jerk": alias of accel_variation
MENG_ACCELERATIONS_MS2 = (1.0, 0.0, -0.033, -1.1)  # Meng et al. (2017) section 3.2, coasting signed


@dataclass(frozen=True)
class PhaseRuns:
    """Closed-form runs of many phase-length vectors (arrays of shape (N, 4) or (N,)).

    Attributes
    ----------
    length_m, speed_end_ms, duration_s : (N, 4)
        Length, end speed and duration of each phase (traction, cruise, coast, brake).
    stop_position_m, running_time_s, peak_speed_ms, energy_index_kwh, comfort_ms2 : (N,)
    """

    length_m: np.ndarray
    speed_end_ms: np.ndarray
    duration_s: np.ndarray
    stop_position_m: np.ndarray
    running_time_s: np.ndarray
    peak_speed_ms: np.ndarray
    energy_index_kwh: np.ndarray
    comfort_ms2: np.ndarray


def phase_runs(lengths_m: np.ndarray, accelerations_ms2: Sequence[float], mass_kg: float) -> PhaseRuns:
    """Run the kinematic model (eqs. 4, 5, 8, 12, 13) for the first three phase lengths (N, 3).

    The last phase brakes at ``accelerations_ms2[3]`` to standstill. A coasting phase whose speed
    would fall to zero ends at standstill (its remaining length is lost, the train stops there).
    """
    s = np.atleast_2d(np.asarray(lengths_m, dtype=float))
    a = np.asarray(accelerations_ms2, dtype=float)
    if s.shape[1] != 3:
        raise ValueError(f"lengths_m has {s.shape[1]} values per run: give the traction, cruise and coast lengths")
    if a.shape != (4,) or not np.all(np.isfinite(a)) or a[0] <= 0 or a[3] >= 0:
        raise ValueError(f"accelerations_ms2 = {list(a)!r}: need 4 finite values, traction > 0 and braking < 0")
    if not np.all(np.isfinite(s)) or np.any(s < 0):
        idx = tuple(int(i) for i in np.argwhere(~(np.isfinite(s) & (s >= 0)))[0])
        raise ValueError(f"lengths_m{list(idx)} = {float(s[idx])}: phase lengths must be finite and >= 0")
    n = s.shape[0]
    length = np.zeros((n, 4))
    speed = np.zeros((n, 4))
    duration = np.zeros((n, 4))
    v = np.zeros(n)
    for i in range(3):
        ai = a[i]
        si = s[:, i].copy()
        if ai == 0.0:
            v1 = v
            with np.errstate(divide="ignore", invalid="ignore"):
                t = np.where(si > 0, si / np.where(v > 0, v, np.inf), 0.0)
        else:
            u = v * v + 2.0 * ai * si
            stops = u < 0.0
            si = np.where(stops, -v * v / (2.0 * ai), si)  # decelerating to rest before the phase ends
            v1 = np.sqrt(np.maximum(u, 0.0))
            t = (v1 - v) / ai
        length[:, i], speed[:, i], duration[:, i] = si, v1, t
        v = v1
    length[:, 3] = v * v / (2.0 * -a[3])
    speed[:, 3] = 0.0
    duration[:, 3] = v / -a[3]
    used = length > 0
    # comfort from rest to rest over the phases actually run (eq. 5)
    comfort = np.zeros(n)
    previous = np.zeros(n)
    for i in range(4):
        comfort += np.where(used[:, i], np.abs(a[i] - previous), 0.0)
        previous = np.where(used[:, i], a[i], previous)
    comfort += np.abs(previous)
    driven = np.clip(a, 0.0, None)
    return PhaseRuns(length_m=length, speed_end_ms=speed, duration_s=duration,
                     stop_position_m=length.sum(axis=1), running_time_s=duration.sum(axis=1),
                     peak_speed_ms=speed.max(axis=1), energy_index_kwh=mass_kg * (length @ driven) / J_PER_KWH,
                     comfort_ms2=comfort)


def phase_profile(lengths_m: np.ndarray, accelerations_ms2: Sequence[float], points_per_phase: int = 50
                  ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Position (m), speed (m/s) and time (s) along one kinematic run, for plots (fig. 3 and 5)."""
    r = phase_runs(np.asarray(lengths_m, dtype=float)[None, :3], accelerations_ms2, 1.0)
    a = np.asarray(accelerations_ms2, dtype=float)
    xs, vs, ts = [np.zeros(1)], [np.zeros(1)], [np.zeros(1)]
    x0 = v0 = t0 = 0.0
    for i in range(4):
        d = np.linspace(0.0, r.length_m[0, i], points_per_phase)[1:]
        v = np.sqrt(np.maximum(v0 * v0 + 2.0 * a[i] * d, 0.0))
        t = d / v0 if a[i] == 0.0 and v0 > 0 else (v - v0) / a[i] if a[i] != 0.0 else np.zeros_like(d)
        xs.append(x0 + d)
        vs.append(v)
        ts.append(t0 + t)
        x0, v0, t0 = x0 + r.length_m[0, i], r.speed_end_ms[0, i], t0 + r.duration_s[0, i]
    return np.concatenate(xs), np.concatenate(vs), np.concatenate(ts)


def decode_bits(bits: np.ndarray, n_genes: int, upper: float) -> np.ndarray:
    """Unsigned binary genes (most significant bit first) scaled to [0, upper]: (N, n_genes)."""
    bits = np.atleast_2d(np.asarray(bits))
    if bits.shape[1] % n_genes:
        raise ValueError(f"{bits.shape[1]} bits do not split into {n_genes} genes")
    n_bits = bits.shape[1] // n_genes
    if not np.all((bits == 0) | (bits == 1)):
        raise ValueError("bits must be 0/1 (or booleans)")
    weights = 2.0 ** np.arange(n_bits - 1, -1, -1)
    ints = bits.reshape(bits.shape[0], n_genes, n_bits).astype(float) @ weights
    return ints * (upper / (2.0 ** n_bits - 1.0))


def encode_bits(values: np.ndarray, n_bits: int, upper: float) -> np.ndarray:
    """The nearest binary genes of values in [0, upper] (inverse of :func:`decode_bits`)."""
    values = np.atleast_2d(np.asarray(values, dtype=float))
    ints = np.rint(np.clip(values, 0.0, upper) / upper * (2.0 ** n_bits - 1.0)).astype(np.int64)
    shifts = np.arange(n_bits - 1, -1, -1)
    bits = (ints[..., None] >> shifts) & 1
    return bits.reshape(values.shape[0], -1).astype(bool)


class KinematicPhasesProblem(Problem):
    """Meng et al. (2017): four phases at fixed accelerations, binary-coded lengths, four indices.

    Parameters
    ----------
    case : Case
        Line length, planned time, train mass and speed limits (``load_case("metro-a")``).
    objectives : sequence of str
        Among ``"energy"`` (index of eq. 4, kWh), ``"accel_variation"`` (alias ``"jerk"``, eq. 5),
        ``"stop_error"`` (eq. 6, m),
        ``"time_error"`` (eq. 8, s).
    weights : sequence of float, optional
        One per objective: minimise ``sum w_i f_i / scale_i`` (eqs. 9-11; the paper's GA maximises
        the reciprocal, eq. 14, which has the same optimum). The paper's are 0.1 / 0.2 / 0.4 / 0.3.
    scales : sequence of float, optional
        Default: the energy index of accelerating to the top speed limit, the comfort index of the
        sequence, 0.25 m (the paper's stop tolerance) and 5 % of the planned time (its
        punctuality tolerance).
    accelerations_ms2 : 4 floats
        Traction, cruise, coast and braking accelerations (default the paper's, coasting -0.033).
    n_bits : int
        Bits per phase length (the paper does not say; 16 gives 1000 m / 65535 = 0.015 m).
    min_phase_s : float
        Shortest duration of every phase (constraint; 0 drops it).
    binary : bool
        Binary genes (``vtype=bool``, the paper's encoding) or the three lengths as real numbers.

    Notes
    -----
    Constraints: every phase lasts ``min_phase_s``; the speed stays under every limit at every head
    position. Extra outputs: ``phase_lengths_m`` (N, 4), ``running_time_s``, ``peak_speed_kmh``,
    ``stop_position_m``, ``energy_index_kwh``.
    """

    def __init__(self, case: Case, objectives: Sequence[str] = PHASE_OBJECTIVES,
                 weights: Sequence[float] | None = None, scales: Sequence[float] | None = None,
                 accelerations_ms2: Sequence[float] = MENG_ACCELERATIONS_MS2, n_bits: int = 16,
                 min_phase_s: float = 2.0, binary: bool = True, **kwargs):
        objectives = check_objectives(objectives, known=PHASE_OBJECTIVES)
        if not isinstance(n_bits, (int, np.integer)) or not 2 <= n_bits <= 52:
            raise ValueError(f"n_bits = {n_bits!r} must be an integer in [2, 52]")
        if not (np.isfinite(min_phase_s) and min_phase_s >= 0):
            raise ValueError(f"min_phase_s = {min_phase_s!r} must be a number >= 0")
        self.case = case
        self.objectives = objectives
        self._keys = tuple(canonical_objective(name) for name in objectives)
        self.accelerations_ms2 = tuple(float(a) for a in accelerations_ms2)
        phase_runs(np.zeros((1, 3)), self.accelerations_ms2, 1.0)  # validates the accelerations
        self.n_bits = int(n_bits)
        self.min_phase_s = float(min_phase_s)
        self.binary = bool(binary)
        self.length_m = float(case.line.length_m)
        self.mass_kg = case.train.mass_kg
        self.limits = np.asarray(case.line.speed_limits, dtype=float)
        self.limits[:, 2] = np.minimum(self.limits[:, 2], case.train.max_speed_kmh)

        a = self.accelerations_ms2
        v_top = self.limits[:, 2].max() / KMH_PER_MS
        self.weights = self.scales = None
        if weights is not None:
            default = {"energy": self.mass_kg * 0.5 * v_top ** 2 / J_PER_KWH,
                       "accel_variation": sum(abs(np.diff([0.0, *a, 0.0]))),
                       "stop_error": 0.25, "time_error": 0.05 * case.planned_time_s}
            self.weights, self.scales = weighted_sum_settings(weights, scales, objectives, default)
        if "accel_variation" in self._keys and self.min_phase_s > 0:
            warnings.warn(f"objective {objectives[self._keys.index('accel_variation')]} (comfort, sum |a_i - a_(i-1)|) "
                          "is constant in the kinematic phase model: with fixed accelerations and "
                          "every phase held for min_phase_s it is the same sum |a_i - a_(i-1)| for every decision",
                          ConstantObjectiveWarning, stacklevel=2)

        n_var = 3 * self.n_bits if self.binary else 3
        n_ieq = 4 + self.limits.shape[0]
        if self.binary:
            xl, xu, vtype = np.zeros(n_var), np.ones(n_var), bool
        else:
            xl, xu, vtype = np.zeros(3), np.full(3, self.length_m), float
        super().__init__(n_var=n_var, n_obj=1 if self.weights is not None else len(objectives), n_ieq_constr=n_ieq,
                         xl=xl, xu=xu, vtype=vtype, **kwargs)

    # ------------------------------------------------------------------ decoding
    def lengths(self, X: np.ndarray) -> np.ndarray:
        """The traction, cruise and coast lengths (N, 3) of decision vectors."""
        X = np.atleast_2d(np.asarray(X))
        if X.shape[1] != self.n_var:
            raise ValueError(f"decision vectors have {X.shape[1]} values: this problem has n_var = {self.n_var}")
        if self.binary:
            return decode_bits(X.astype(float), 3, self.length_m)
        return X.astype(float)

    def encode(self, lengths_m: np.ndarray) -> np.ndarray:
        """Decision vectors of given traction, cruise and coast lengths (N, 3)."""
        lengths_m = np.atleast_2d(np.asarray(lengths_m, dtype=float))
        return encode_bits(lengths_m, self.n_bits, self.length_m) if self.binary else lengths_m

    def runs(self, X: np.ndarray) -> PhaseRuns:
        """Closed-form runs of decision vectors."""
        return phase_runs(self.lengths(X), self.accelerations_ms2, self.mass_kg)

    def indices(self, runs: PhaseRuns) -> dict[str, np.ndarray]:
        """The four indices of section 1 by objective name."""
        return {"energy": runs.energy_index_kwh, "accel_variation": runs.comfort_ms2,
                "stop_error": np.abs(runs.stop_position_m - self.length_m),
                "time_error": np.abs(runs.running_time_s - self.case.planned_time_s)}

    def limit_excess_ms(self, runs: PhaseRuns) -> np.ndarray:
        """Highest speed above each limit zone (N, n_zones), <= 0 when respected."""
        starts = np.concatenate([np.zeros((runs.length_m.shape[0], 1)), np.cumsum(runs.length_m, axis=1)[:, :-1]], 1)
        v0 = np.concatenate([np.zeros((runs.length_m.shape[0], 1)), runs.speed_end_ms[:, :-1]], 1)
        a = np.asarray(self.accelerations_ms2)
        out = np.empty((starts.shape[0], self.limits.shape[0]))
        for z, (lo, hi, kmh) in enumerate(self.limits):
            best = np.full(starts.shape[0], -np.inf)
            for i in range(4):  # speed is monotone in a phase: its extremes are at the clipped ends
                for x in (np.clip(starts[:, i], lo, hi), np.clip(starts[:, i] + runs.length_m[:, i], lo, hi)):
                    d = np.clip(x - starts[:, i], 0.0, runs.length_m[:, i])
                    inside = (x >= starts[:, i]) & (x <= starts[:, i] + runs.length_m[:, i]) & (runs.length_m[:, i] > 0)
                    v = np.sqrt(np.maximum(v0[:, i] ** 2 + 2.0 * a[i] * d, 0.0))
                    best = np.where(inside, np.maximum(best, v), best)
            out[:, z] = best - kmh / KMH_PER_MS
        return out

    def _evaluate(self, x, out, *args, **kwargs):
        runs = self.runs(x)
        idx = self.indices(runs)
        F = np.column_stack([idx[key] for key in self._keys])
        if self.weights is not None:
            F = ((F / self.scales) @ self.weights)[:, None]
        out["F"] = F
        out["G"] = np.column_stack([self.min_phase_s - runs.duration_s, self.limit_excess_ms(runs)])
        out["phase_lengths_m"] = runs.length_m
        out["running_time_s"] = runs.running_time_s
        out["stop_error_m"] = np.abs(runs.stop_position_m - self.length_m)
        out["peak_speed_kmh"] = runs.peak_speed_ms * KMH_PER_MS
        out["stop_position_m"] = runs.stop_position_m
        out["energy_index_kwh"] = runs.energy_index_kwh

    def describe(self) -> str:
        """One line naming the case, the form, the coding and the objectives."""
        form = "weighted sum" if self.weights is not None else "Pareto"
        coding = f"{self.n_bits}-bit binary" if self.binary else "real"
        return (f"KinematicPhasesProblem({self.case.name}, {form}: {', '.join(self.objectives)}; "
                f"3 phase lengths, {coding}; accelerations {self.accelerations_ms2} m/s^2)")


def exact_stop_coast_m(problem: KinematicPhasesProblem, traction_m: np.ndarray, cruise_m: np.ndarray) -> np.ndarray:
    """Coast lengths that put the stop exactly on the platform (bisection), NaN where none does."""
    traction_m, cruise_m = np.broadcast_arrays(np.asarray(traction_m, float), np.asarray(cruise_m, float))
    lo = np.zeros(traction_m.shape)
    hi = np.full(traction_m.shape, problem.length_m)
    a, m = problem.accelerations_ms2, problem.mass_kg

    def stop(coast):
        return phase_runs(np.column_stack([traction_m.ravel(), cruise_m.ravel(), coast.ravel()]), a, m
                          ).stop_position_m.reshape(traction_m.shape)

    ok = (stop(lo) <= problem.length_m) & (stop(hi) >= problem.length_m)
    for _ in range(50):
        mid = 0.5 * (lo + hi)
        past = stop(mid) > problem.length_m
        hi, lo = np.where(past, mid, hi), np.where(past, lo, mid)
    return np.where(ok, 0.5 * (lo + hi), np.nan)


def grid_optimum(problem: KinematicPhasesProblem, step_m: float = 1.0) -> tuple[np.ndarray, float]:
    """Reference for the weighted form: the best feasible run on a grid of traction and cruise
    lengths (``step_m``), the coast length chosen so that the train stops exactly at the platform.

    Returns ``(lengths_m (3,), f)``. Only the weighted single-objective form has one optimum.
    """
    if problem.weights is None:
        raise ValueError("grid_optimum needs the weighted form (weights=...)")
    if not (np.isfinite(step_m) and step_m > 0):
        raise ValueError(f"step_m = {step_m!r} must be a positive number")
    s1 = np.arange(step_m, problem.length_m, step_m)
    best_f, best_x = np.inf, None
    for chunk in np.array_split(s1, max(1, s1.size // 100)):
        t, c = np.meshgrid(chunk, np.arange(0.0, problem.length_m, step_m), indexing="ij")
        coast = exact_stop_coast_m(problem, t, c)
        keep = np.isfinite(coast)
        if not keep.any():
            continue
        L = np.column_stack([t[keep], c[keep], coast[keep]])
        runs = phase_runs(L, problem.accelerations_ms2, problem.mass_kg)
        idx = problem.indices(runs)
        F = np.column_stack([idx[canonical_objective(name)] for name in problem.objectives])
        f = (F / problem.scales) @ problem.weights
        G = np.column_stack([problem.min_phase_s - runs.duration_s, problem.limit_excess_ms(runs)])
        f[(G > 0).any(axis=1)] = np.inf
        j = int(np.argmin(f))
        if f[j] < best_f:
            best_f, best_x = float(f[j]), L[j]
    if best_x is None:
        raise ValueError("no feasible run on the grid: the limits or min_phase_s exclude every one")
    return best_x, best_f
