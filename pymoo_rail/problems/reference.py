"""Certified energy / running-time fronts of a case, from the exact solver, cached on disk.

A rail problem whose objectives are net energy and running time (or time error) has a known
Pareto front: the minimum energy at each running time, which :mod:`pymoo_rail.optimal` computes.
This module turns the solver's runs into a front with a certificate and keeps it:

- **Nodes.** The solver is asked for the minimum-energy run at ``n_times`` running times from just
  above the minimum running time to :data:`FRONT_SPAN` x the planned time (and at the planned time
  itself). Each node is a real run of the simulator: ``running_time_s``, ``energy_kwh`` (net) and
  the front's slope ``lambda_kwh_per_s`` there.
- **Certificate.** ``energy_bound_kwh`` bounds ``|energy_kwh - true optimum|`` at the node's
  running time. When the solver reports this bound (column ``energy_bound_kwh`` of
  :func:`~pymoo_rail.optimal.optimal_front`) it is used (``certificate = "solver"``).
  Otherwise it is the two-grid estimate (``certificate = "two-grid"``): the difference between
  the default grid and one with half the speed nodes at the same requested time. Each node is
  solved twice, in a warm-started sweep over the times and alone; the lower run is kept and the
  bound raised to at least their difference. Either is also raised to at least
  :data:`BOUND_FLOOR_REL` of the energy. The coarse grid errs more than the
  default one (``docs/optimal.md``), so the difference over-estimates the default grid's error;
  it is an estimate, not a proof.
- **Between nodes.** The front is convex and decreasing in time, so the chord between two nodes
  lies above it by at most ``h (lambda_left - lambda_right) / 4`` (the tangents at both ends
  bound it from below). :meth:`CertifiedFront.energy_at` interpolates and adds that to the bound.
- **Cache.** Fronts are keyed by the case's *content* (:func:`case_hash`: train, line, planned
  time; never the name), the simulation step and :data:`FRONT_VERSION`. They are looked up in the
  fronts shipped with the package (``pymoo_rail/suite/fronts``), then in the user cache
  directory (``platformdirs.user_cache_dir("pymoo-rail")/fronts``, or ``$PYMOO_RAIL_CACHE_DIR``),
  and computed and written there (atomically) otherwise.
- **Gaps.** :func:`certified_gap` measures an optimiser's members against the front and counts
  those below it by more than the certificate (a defect of the reference). The gap to an optimum
  solved at a member's own running time is :func:`pymoo_rail.optimal.solved_energy_gap`.
"""

from __future__ import annotations

import hashlib
import json
import os
from dataclasses import dataclass
from pathlib import Path
from typing import Any, Callable, Sequence

import numpy as np
import pandas as pd

from pymoo_rail import __version__
from pymoo_rail.atomic import atomic_write_text
from pymoo_rail.constants import J_PER_KWH
from pymoo_rail.model import Case, case_to_dict
from pymoo_rail.rowcache import set_aside

FRONT_VERSION = "6"
"""Version of the front computation; bump it when the solver (with
:data:`pymoo_rail.optimal.solver.SOLVER_VERSION`) or the node choice changes
(4: every node solved in the sweep and alone, the lower kept, the bound at least their difference;
5: the solver keeps a run with its last switch moved only near the front, its certificate compares
the half grid at the run's price and has a floor of 1e-4 of the energy;
6: nodes also at the ends of the punctuality window, so that the optimum of a single-objective
form is a solved run, not a point on a chord)."""
PUNCTUAL_TOLERANCE_REL = 0.01
"""Default punctuality window: ``|T - T_plan| <= 1 %`` of the planned time (at least
:data:`PUNCTUAL_TOLERANCE_MIN_S`); fronts have nodes at both of its ends."""
PUNCTUAL_TOLERANCE_MIN_S = 1.0
FRONT_SPAN = 1.3
"""Fronts cover running times from the minimum to ``FRONT_SPAN`` x the planned time."""
DEFAULT_N_TIMES = 33
"""Nodes of a front on lines up to :data:`LONG_LINE_M`; longer lines get :data:`LONG_LINE_N_TIMES` (DP cost).
Each node's solve warm-starts the next one's: 33 nodes (not 17) keep the warm start close enough that the
yizhuang front no longer lies above members of the suite study by more than its bound."""
LONG_LINE_M = 10_000.0
LONG_LINE_N_TIMES = 9
BOUND_FLOOR_REL = 5.0e-4
"""Least two-grid bound, relative to the energy: the largest error of the default grid measured against
a direct strategy search and finer grids (``docs/optimal.md``); a small two-grid difference can be luck."""
COARSE_FACTOR = 2
"""The two-grid certificate compares the default grid with one of ``n_speeds / COARSE_FACTOR``."""
SHIPPED_DIR = Path(__file__).resolve().parent.parent / "suite" / "fronts"
CACHE_ENV = "PYMOO_RAIL_CACHE_DIR"
COLUMNS = ("requested_time_s", "running_time_s", "energy_kwh", "lambda_kwh_per_s", "energy_bound_kwh")


class NoExactFrontError(NotImplementedError):
    """The problem has no exact front (e.g. three or more objectives); the message says what exists."""


def case_hash(case: Case) -> str:
    """SHA-256 of the case's content (train, line, planned time, dwell, legs): not of its names or prose."""
    data = case_to_dict(case)
    for key in ("name", "source", "description"):
        data.pop(key, None)
    if isinstance(data.get("train"), dict):
        data["train"].pop("name", None)  # the train's name is prose too
    text = json.dumps(data, sort_keys=True, default=repr)
    return hashlib.sha256(text.encode("utf-8")).hexdigest()


def cache_dir() -> Path:
    """The user cache directory of computed fronts (``$PYMOO_RAIL_CACHE_DIR`` overrides it)."""
    override = os.environ.get(CACHE_ENV)
    if override:
        return Path(override) / "fronts"
    import platformdirs

    return Path(platformdirs.user_cache_dir("pymoo-rail")) / "fronts"


def front_key(case: Case, dx_m: float, n_times: int) -> str:
    """The cache key of a case's front: content hash, step, number of nodes and front version."""
    return f"{case_hash(case)[:16]}-dx{dx_m:g}-n{n_times}-v{FRONT_VERSION}"


def read_commented_csv(path: str | Path) -> tuple[dict[str, str], pd.DataFrame]:
    """A CSV file whose leading ``# key: value`` lines describe it: (those fields, the table).

    The format of the shipped and cached fronts (certified and best-known).
    """
    meta = {}
    with open(path, encoding="utf-8") as handle:
        for line in handle:
            if not line.startswith("#"):
                break
            key, _, value = line[1:].partition(":")
            meta[key.strip()] = value.strip()
    return meta, pd.read_csv(path, comment="#")


@dataclass(frozen=True)
class CertifiedFront:
    """The certified energy / running-time front of one case.

    Attributes
    ----------
    table : pandas.DataFrame
        One row per node, sorted by time, with :data:`COLUMNS`.
    case_hash : str
        :func:`case_hash` of the case it belongs to.
    case_name : str
    planned_time_s : float
    dx_m : float
        Simulation step of the solver's grid.
    certificate : str
        ``"solver"`` (the solver's own bound) or ``"two-grid"`` (see the module docstring).
    version : str
        Package and front version that computed it.
    """

    table: pd.DataFrame
    case_hash: str
    case_name: str
    planned_time_s: float
    dx_m: float
    certificate: str
    version: str

    @property
    def time_range_s(self) -> tuple[float, float]:
        """Shortest and longest running time of the front's nodes (s)."""
        t = self.table["running_time_s"].to_numpy()
        return float(t[0]), float(t[-1])

    def clip(self, window_s: tuple[float, float] | None) -> tuple[float, float]:
        """A running-time window cut to the front's range; ends within 0.5 s of the range are moved onto it.

        The nodes are the solver's runs, within 0.05 s of the requested times (never 0.5 s off), so a
        window built by :func:`default_window` may start a few hundredths of a second before the first node.
        """
        lo, hi = self.time_range_s
        if window_s is None:
            return lo, hi
        a, b = (float(v) for v in window_s)
        if a < lo - 0.5 or b > hi + 0.5 or not a < b:
            raise ValueError(f"time window {a:.2f}-{b:.2f} s: the front of '{self.case_name}' covers "
                             f"{lo:.2f}-{hi:.2f} s only")
        return max(a, lo), min(b, hi)

    def energy_at(self, running_time_s) -> tuple[np.ndarray, np.ndarray]:
        """Optimal energy (kWh) and its bound (kWh) at running times inside the front's range.

        Linear interpolation between nodes; the bound adds the chord's largest possible excess
        over the convex front, ``h (lambda_left - lambda_right) / 4``.
        """
        t = np.atleast_1d(np.asarray(running_time_s, dtype=float))
        lo, hi = self.time_range_s
        if np.any(~np.isfinite(t)) or np.any(t < lo - 1e-9) or np.any(t > hi + 1e-9):
            raise ValueError(f"running_time_s = {t.tolist()!r}: the front covers {lo:.2f}-{hi:.2f} s only")
        nodes_t = self.table["running_time_s"].to_numpy()
        nodes_e = self.table["energy_kwh"].to_numpy()
        slope = self.table["lambda_kwh_per_s"].to_numpy()
        bound = self.table["energy_bound_kwh"].to_numpy()
        energy = np.interp(t, nodes_t, nodes_e)
        k = np.clip(np.searchsorted(nodes_t, t, side="right") - 1, 0, len(nodes_t) - 2)
        h = nodes_t[k + 1] - nodes_t[k]
        chord = np.abs(slope[k] - slope[k + 1]) * h / 4.0
        total = np.maximum(bound[k], bound[k + 1]) + chord
        total = np.where(np.isclose(t, nodes_t[k]), bound[k], total)  # a node: its own bound only
        total = np.where(np.isclose(t, nodes_t[k + 1]), bound[k + 1], total)
        return energy, total

    def below_certificate(self, running_time_s, energy_kwh) -> tuple[np.ndarray, np.ndarray]:
        """Which runs lie below the front by more than its certificate, among those it covers.

        Returns ``(inside, below)``: boolean masks over the runs, ``inside`` where the running time
        is in the front's range (and the energy finite), ``below`` where ``E < E*(T) - bound(T)``,
        which a correct certificate never allows.
        """
        t = np.asarray(running_time_s, dtype=float).reshape(-1)
        e = np.asarray(energy_kwh, dtype=float).reshape(-1)
        lo, hi = self.time_range_s
        inside = (t >= lo) & (t <= hi) & np.isfinite(e)
        below = np.zeros_like(inside)
        if inside.any():
            optimum, bound = self.energy_at(t[inside])
            below[inside] = e[inside] < optimum - bound - 1e-9
        return inside, below

    def dense(self, n_points: int = 100, window_s: tuple[float, float] | None = None,
              with_nodes: bool = True) -> pd.DataFrame:
        """The front at ``n_points`` evenly spaced running times in ``window_s``, with each point's bound.

        ``with_nodes`` adds the front's nodes inside the window (its vertices: then there are more than
        ``n_points`` rows); without them there are exactly ``n_points`` (at least 2).
        """
        lo, hi = self.clip(window_s)
        t = np.linspace(lo, hi, max(int(n_points), 2))
        if with_nodes:
            t = np.union1d(t, self.table["running_time_s"].to_numpy())
            t = t[(t >= lo) & (t <= hi)]
        energy, bound = self.energy_at(t)
        return pd.DataFrame({"running_time_s": t, "energy_kwh": energy, "energy_bound_kwh": bound})

    # ------------------------------------------------------------------ file format
    def to_csv_text(self) -> str:
        """The front as a commented CSV (the format of the shipped and cached fronts)."""
        header = [f"# case_hash: {self.case_hash}", f"# case_name: {self.case_name}",
                  f"# planned_time_s: {self.planned_time_s!r}", f"# dx_m: {self.dx_m!r}",
                  f"# certificate: {self.certificate}", f"# version: {self.version}",
                  "# energy_bound_kwh: bound on |energy_kwh - optimum| at running_time_s (kWh)"]
        return "\n".join(header) + "\n" + self.table.loc[:, list(COLUMNS)].to_csv(index=False, float_format="%.9g")

    @classmethod
    def read_csv(cls, path: str | Path) -> CertifiedFront:
        """Read a front written by :meth:`to_csv_text` (raises ValueError naming the file if malformed)."""
        path = Path(path)
        if not path.read_bytes().endswith(b"\n"):
            raise ValueError(f"{path}: its last line is cut off (an interrupted write)")
        meta, table = read_commented_csv(path)
        missing = [c for c in COLUMNS if c not in table.columns]
        needed = ("case_hash", "case_name", "planned_time_s", "dx_m", "certificate", "version")
        if missing or any(k not in meta for k in needed) or len(table) < 2:
            raise ValueError(f"{path}: not a certified front file (missing columns {missing} or header fields)")
        for column in COLUMNS:
            values = pd.to_numeric(table[column], errors="coerce").to_numpy(dtype=float)
            if not np.isfinite(values).all():
                row = int(np.argmax(~np.isfinite(values)))
                raise ValueError(f"{path}: column '{column}' row {row}: {table[column].iloc[row]!r} is not a number")
        return cls(table, meta["case_hash"], meta["case_name"], float(meta["planned_time_s"]), float(meta["dx_m"]),
                   meta["certificate"], meta["version"])


def certified_gap(front: CertifiedFront, running_time_s, energy_kwh) -> dict[str, float]:
    """Energy gaps of an optimiser's runs to the optimum at their own running times.

    Parameters
    ----------
    front : CertifiedFront
        The certified front of the case the members ran on.
    running_time_s, energy_kwh : array-like
        Running time and net energy of each feasible member.

    Returns
    -------
    dict
        ``gap_median_kwh`` and ``gap_min_kwh`` (``E - E*(T)`` over the members whose running time
        the front covers; in kWh, since on lines with strong regeneration ``E*`` can be near zero or
        negative and a relative gap means nothing), ``gap_median_pct`` (the median gap in % of the
        front's largest energy, its fastest run), ``n_in_range``, and ``n_below_certificate``:
        members below the optimum by more than its certificate (``E < E*(T) - bound(T)``), which a
        correct certificate never allows. Gaps are NaN when no member lies in the front's range.
    """
    t = np.asarray(running_time_s, dtype=float).reshape(-1)
    e = np.asarray(energy_kwh, dtype=float).reshape(-1)
    inside, below = front.below_certificate(t, e)
    out = {"n_in_range": float(inside.sum()), "n_below_certificate": float(below.sum()),
           "gap_median_kwh": float("nan"), "gap_min_kwh": float("nan"), "gap_median_pct": float("nan")}
    if not inside.any():
        return out
    optimum, _ = front.energy_at(t[inside])
    gap = e[inside] - optimum
    scale = float(front.table["energy_kwh"].abs().max())
    out.update(gap_median_kwh=float(np.median(gap)), gap_min_kwh=float(np.min(gap)),
               gap_median_pct=100.0 * float(np.median(gap)) / scale)
    return out


def default_window(min_time_s: float, planned_time_s: float) -> tuple[float, float]:
    """The running times a front covers and a problem's default window: planner's times around the plan.

    From 0.5 % above the minimum running time (the flat-out run is a single point, not a front) to
    ``FRONT_SPAN`` x the planned time (at least 1.2 x the minimum).
    """
    return min_time_s * 1.005, max(FRONT_SPAN * planned_time_s, 1.2 * min_time_s)


def punctual_tolerance_s(planned_time_s: float) -> float:
    """Half-width of the default punctuality window: 1 % of the planned time, at least 1 s."""
    return max(PUNCTUAL_TOLERANCE_MIN_S, PUNCTUAL_TOLERANCE_REL * float(planned_time_s))


def front_times(min_time_s: float, planned_time_s: float, n_times: int = DEFAULT_N_TIMES) -> np.ndarray:
    """Requested running times of the nodes: across :func:`default_window`, with the planned time
    and both ends of its punctuality window (:func:`punctual_tolerance_s`).

    Spaced quadratically (denser near the minimum time, where the front is steepest). The ends of
    the punctuality window are nodes because the optimum under ``|T - T_plan| <= tolerance`` lies on
    one of them (the slow end, energy falling with time): a node there is a solved run with its own
    bound, where a chord between nodes lies above the convex front (by 0.0045 kWh on the
    xiaohongmen-jiugong section, more than optimisers then end below it).
    """
    lo, hi = default_window(min_time_s, planned_time_s)
    u = np.linspace(0.0, 1.0, max(int(n_times) - 1, 2))
    times = lo + (hi - lo) * u ** 2
    tolerance = punctual_tolerance_s(planned_time_s)
    extra = [t for t in (planned_time_s - tolerance, planned_time_s, planned_time_s + tolerance) if lo < t < hi]
    return np.union1d(times, extra)


def n_times_for(case: Case) -> int:
    """Default number of front nodes of a case (fewer on long lines, where each DP solve costs more)."""
    return DEFAULT_N_TIMES if case.line.length_m <= LONG_LINE_M else LONG_LINE_N_TIMES


Progress = Callable[[int, int], None]
"""A progress callback: ``progress(done, total)`` in solves of the exact solver (``total`` may grow)."""
PROGRESS_DELAY_S = 2.0
"""A front computed in a terminal shows a progress bar once it has taken this long."""


def front_progress_bar(case_name: str):
    """A tqdm bar on standard error for a front's solves, shown after :data:`PROGRESS_DELAY_S` s.

    Returns ``(bar, progress)``: close ``bar`` when done; pass ``progress`` to :func:`compute_front`.
    """
    import sys
    import time

    from tqdm import tqdm

    delay_s = PROGRESS_DELAY_S
    bar = tqdm(total=1, desc=f"certified front of {case_name} (exact solver)", unit="solve",
               delay=delay_s, file=sys.stderr, dynamic_ncols=True, leave=False)
    started_s = time.monotonic()

    def progress(done: int, total: int) -> None:
        bar.total = total
        bar.update(done - bar.n)
        # tqdm throttles its refreshes: show the last count before the bar closes (once it is shown)
        if done == total and time.monotonic() - started_s >= delay_s:
            bar.refresh()

    return bar, progress


def _wants_progress(progress: bool | Progress | None) -> bool:
    import sys

    if progress is None:  # a terminal sees the bar; a test, a pipe or a notebook does not
        return bool(getattr(sys.stderr, "isatty", lambda: False)())
    return bool(progress) and not callable(progress)


def compute_front(case: Case, dx_m: float | None = None, n_times: int | None = None,
                  progress: Progress | None = None) -> CertifiedFront:
    """Compute a case's certified front with the exact solver (no cache; see :func:`certified_front`).

    ``progress(done, total)`` is called after every solve (``total``: the sweep, the solves alone
    and, for a two-grid certificate, the coarse sweep).

    Every node is solved twice: in one sweep over the running times (each solve warm-started from
    the last) and alone. The lower run at the requested time is kept, and the node's bound is raised
    to at least the difference of the two: a warm-started sweep can settle on a worse run than a
    solve started elsewhere (yizhuang, 17 nodes: 9.115 kWh at 171.6 s with a solver bound of 0.011
    kWh, while the solver alone at 171.1 s reached 9.034 kWh), so where they disagree the solver's
    own bound is not trusted.
    """
    from pymoo_rail.optimal import OptimalSolver, min_running_time, optimal_front
    from pymoo_rail.optimal.solver import DEFAULT_N_SPEEDS

    t_min = min_running_time(case, dx_m)
    times = front_times(t_min, case.planned_time_s, n_times or n_times_for(case))
    n = len(times)
    total = [2 * n]  # the sweep and the solves alone; a two-grid certificate adds a coarse sweep

    def stage(first: int):
        if progress is None:
            return None
        return lambda done, _: progress(first + done, total[0])

    sweep = optimal_front(case, times, dx_m=dx_m, progress=stage(0))
    alone = pd.concat([optimal_front(case, [t], dx_m=dx_m, progress=stage(n + k))
                       for k, t in enumerate(sweep["requested_time_s"])], ignore_index=True)
    use_alone = (alone["energy_at_request_kwh"] < sweep["energy_at_request_kwh"]).to_numpy()
    fine = sweep.copy()
    fine.loc[use_alone] = alone.loc[use_alone]
    spread = np.abs(sweep["energy_at_request_kwh"] - alone["energy_at_request_kwh"]).to_numpy()
    if "energy_bound_kwh" in fine.columns and fine["energy_bound_kwh"].notna().all():
        bound = fine["energy_bound_kwh"].to_numpy(dtype=float)
        certificate = "solver"
    else:
        total[0] = 3 * n
        coarse = optimal_front(case, times, dx_m=dx_m, n_speeds=DEFAULT_N_SPEEDS // COARSE_FACTOR,
                               progress=stage(2 * n))
        bound = np.abs(fine["energy_at_request_kwh"].to_numpy() - coarse["energy_at_request_kwh"].to_numpy())
        certificate = "two-grid"
    bound = np.maximum.reduce([bound, spread, BOUND_FLOOR_REL * np.abs(fine["energy_kwh"].to_numpy())])
    table = pd.DataFrame({"requested_time_s": fine["requested_time_s"], "running_time_s": fine["running_time_s"],
                          "energy_kwh": fine["energy_kwh"], "lambda_kwh_per_s": fine["lambda_kwh_per_s"],
                          "energy_bound_kwh": bound})
    # two requested times close to the minimum can land on the same run: keep it once
    table = table.sort_values("running_time_s", kind="stable").drop_duplicates("running_time_s").reset_index(drop=True)
    step = OptimalSolver(case, dx_m).dx_m if dx_m is None else float(dx_m)
    return CertifiedFront(table, case_hash(case), case.name, float(case.planned_time_s), float(step), certificate,
                          f"pymoo_rail {__version__} / front {FRONT_VERSION}")


def default_dx_m(case: Case) -> float:
    """The simulator's default step for a case (the step the solver uses when none is given)."""
    from pymoo_rail.sim import Simulator

    return float(Simulator(case).grid.dx_m)


def find_front(case: Case, dx_m: float | None = None, n_times: int | None = None) -> Path | None:
    """The shipped or cached front file of a case, if any (shipped fronts first)."""
    step = default_dx_m(case) if dx_m is None else float(dx_m)
    name = f"{front_key(case, step, n_times or n_times_for(case))}.csv"
    for directory in (SHIPPED_DIR, cache_dir()):
        hits = sorted(directory.glob(f"*{name}")) if directory.is_dir() else []
        if hits:
            return hits[0]
    return None


_MEMORY: dict[str, CertifiedFront] = {}


def forget_fronts() -> None:
    """Drop the fronts held in memory (the disk cache stays): the next call reads or computes again."""
    _MEMORY.clear()


def certified_front(case: Case, dx_m: float | None = None, n_times: int | None = None,
                    use_cache: bool = True, progress: bool | Progress | None = None) -> CertifiedFront:
    """The certified front of a case: from memory, the shipped fronts, the user cache, or computed.

    Computing one takes from seconds to about a minute (33 nodes, each solved two or three times).
    ``progress``: ``None`` (default) shows a progress bar on standard error when it is a terminal
    and the computation lasts over :data:`PROGRESS_DELAY_S` s (so tests, pipes and notebooks stay
    quiet); ``True`` shows it whatever standard error is, ``False`` never; a callable is called as
    ``progress(done, total)`` after each solve instead (e.g. a GUI's own bar).

    A computed front is written to the user cache atomically (a reader never sees half a file),
    named ``<case name>-<key>.csv`` where the key is :func:`front_key` (content hash, step, nodes, version).
    A cached file that cannot be read (damaged, not a number, another case's content) is moved aside
    with a :class:`~pymoo_rail.rowcache.CorruptCacheWarning` naming it, and the front is computed
    again; a damaged shipped front raises ``ValueError`` naming the file.
    """
    step = default_dx_m(case) if dx_m is None else float(dx_m)
    n_times = n_times or n_times_for(case)
    key = front_key(case, step, n_times)
    if use_cache and key in _MEMORY:
        return _MEMORY[key]
    path = find_front(case, step, n_times) if use_cache else None
    front = None
    if path is not None:
        try:
            front = CertifiedFront.read_csv(path)
            if front.case_hash != case_hash(case):
                raise ValueError(f"{path}: front of case hash {front.case_hash[:16]}, not of this case's content")
        except ValueError as err:  # also pandas' parser errors and undecodable bytes
            if path.parent == SHIPPED_DIR:
                raise  # a damaged installation: recomputing would hide it
            set_aside(path, str(err).removeprefix(f"{path}: "), "the front will be computed again")
            front = None
    if front is None:
        if callable(progress):
            front = compute_front(case, step, n_times, progress)
        elif _wants_progress(progress):
            bar, tick = front_progress_bar(case.name)
            try:
                front = compute_front(case, step, n_times, tick)
            finally:
                bar.close()
        else:
            front = compute_front(case, step, n_times)
        safe = "".join(ch if ch.isalnum() or ch in "-_." else "_" for ch in case.name)
        atomic_write_text(cache_dir() / f"{safe}-{key}.csv", front.to_csv_text())
    _MEMORY[key] = front
    return front


def mirrored(front: CertifiedFront, objectives: tuple[str, ...], n_points: int | None = None,
             window_s: tuple[float, float] | None = None) -> tuple[np.ndarray, np.ndarray]:
    """The front in a problem's objective space and the energy bound of each point.

    ``n_points=None`` gives the front's nodes (its vertices) plus 100 evenly spaced points; a number
    gives at most that many evenly spaced points (fewer where some are dominated or outside the front).

    ``objectives`` is ``("energy", "running_time")`` or ``("energy", "time_error")`` in any order.
    Time error ``e = |T - T_plan|`` mirrors the front about the planned time: the least energy at
    error ``e`` is the smaller of the optima at ``T_plan + e`` and ``T_plan - e`` (where the front
    covers them). Dominated points (e.g. energy rising with time under auxiliary power) drop out.
    ``window_s`` restricts the running times to the problem's window (see :meth:`CertifiedFront.clip`).
    """
    from pymoo.util.nds.non_dominated_sorting import find_non_dominated

    if "time_error" in objectives:
        lo, hi = front.clip(window_s)
        plan = front.planned_time_s
        e_max = max(hi - plan, plan - lo)
        e_min = max(lo - plan, 0.0)  # a plan faster than the front's first node: errors start there
        nodes = front.table["running_time_s"].to_numpy()
        nodes = nodes[(nodes >= lo) & (nodes <= hi)]
        err = np.linspace(e_min, e_max, max(int(n_points or 100), 2))
        if n_points is None:
            err = np.union1d(err, np.abs(nodes - plan))
        energy = np.full(err.shape, np.inf)
        bound = np.zeros(err.shape)
        for side in (plan + err, plan - err):
            inside = (side >= lo - 1e-9) & (side <= hi + 1e-9)
            e, b = front.energy_at(np.clip(side[inside], lo, hi))
            better = e < energy[inside]
            energy[np.flatnonzero(inside)[better]] = e[better]
            bound[np.flatnonzero(inside)[better]] = b[better]
        ok = np.isfinite(energy)
        columns = {"energy": energy[ok], "time_error": err[ok]}
        bound = bound[ok]
    else:
        dense = front.dense(n_points or 100, window_s, with_nodes=n_points is None)
        columns = {"energy": dense["energy_kwh"].to_numpy(), "running_time": dense["running_time_s"].to_numpy()}
        bound = dense["energy_bound_kwh"].to_numpy()
    F = np.column_stack([columns[name] for name in objectives])
    keep = find_non_dominated(F)
    keep = keep[np.argsort(F[keep, 0], kind="stable")]
    return F[keep], bound[keep]


def constrained_optimum(front: CertifiedFront, tolerance_s: float, n_points: int = 2001,
                        window_s: tuple[float, float] | None = None) -> tuple[float, float, float]:
    """Minimum energy with ``|T - T_plan| <= tolerance_s`` (and T in ``window_s``): (kWh, bound kWh, T s).

    Runs faster than the front's first node (0.5 % above the minimum time) are left out: the
    front falls steeply there, so they cost more than that node.
    """
    lo, hi = front.clip(window_s)
    a = max(front.planned_time_s - tolerance_s, lo)
    b = front.planned_time_s + tolerance_s
    if b > hi + 0.5:
        raise ValueError(f"time_tolerance_s = {tolerance_s}: the window around {front.planned_time_s} s "
                         f"reaches beyond the front's range {lo:.2f}-{hi:.2f} s")
    b = min(b, hi)
    if not a < b:
        raise ValueError(f"time_tolerance_s = {tolerance_s}: the window around {front.planned_time_s} s "
                         f"misses the front's range {lo:.2f}-{hi:.2f} s")
    t = np.union1d(np.linspace(a, b, n_points), front.table["running_time_s"].to_numpy())
    t = t[(t >= a) & (t <= b)]
    energy, bound = front.energy_at(t)
    k = int(np.argmin(energy))
    return float(energy[k]), float(bound[k]), float(t[k])


EXACT_POINT_COLUMNS = ("requested_time_s", "running_time_s", "energy_kwh", "traction_kwh", "regen_kwh",
                       "lambda_kwh_per_s", "neutral_traction_j", "limit_excess_ms", "stop_error_m", "n_speeds",
                       "solve_s")
"""Columns of :func:`exact_points` (then the key columns ``case_hash``, ``solver_version``, ``cache_key``)."""


def exact_points_key(case: Case, n_speeds: int) -> dict[str, object]:
    """The key of :func:`exact_points` rows: the case's content, the solver's version, the speed nodes.

    ``case_hash`` is :func:`case_hash` (names and prose left out, so a renamed case keeps its rows);
    ``solver_version`` is :data:`pymoo_rail.optimal.solver.SOLVER_VERSION`.
    """
    from pymoo_rail.optimal.solver import SOLVER_VERSION

    return {"case_hash": case_hash(case)[:16], "solver_version": SOLVER_VERSION, "n_speeds": int(n_speeds)}


def exact_points(case: Case, running_times_s: Sequence[float], path: str | Path, *, n_speeds: int | None = None,
                 redo_s: Sequence[float] = (), on_run: Callable[[float, Any], None] | None = None) -> pd.DataFrame:
    """The exact solver's runs at chosen running times, cached row by row in a CSV file.

    The resumable form of :func:`~pymoo_rail.optimal.optimal_front` for long lines, where one
    running time costs minutes: each finished time is added to the file at once
    (:class:`pymoo_rail.rowcache.RowCache`: atomic rewrite under a file lock), so an interrupted
    computation resumes where it stopped and two processes on one file lose no row. A row is
    served only under the same key (:func:`exact_points_key`: the case's content hash, the
    solver's :data:`~pymoo_rail.optimal.solver.SOLVER_VERSION` and ``n_speeds``); rows of another
    key are never served, and a new row replaces every row of its requested time. A corrupt file
    is moved aside with a :class:`~pymoo_rail.rowcache.CorruptCacheWarning` and its times solved
    again. The times are solved in increasing order, each warm-started from the slope of the one
    before, as :func:`~pymoo_rail.optimal.optimal_front` does.

    Parameters
    ----------
    case : Case
        The case.
    running_times_s : sequence of float
        Requested running times (s).
    path : str or Path
        The CSV cache (created when missing).
    n_speeds : int, optional
        Speed nodes of the solver (default: the solver's).
    redo_s : sequence of float
        Times to solve again even when cached (and to solve when not requested), e.g. to get the
        run itself through ``on_run``.
    on_run : callable, optional
        Called as ``on_run(requested_time_s, trajectory)`` after each solve.

    Returns
    -------
    pandas.DataFrame
        The rows of ``running_times_s``, sorted by running time: :data:`EXACT_POINT_COLUMNS`
        (``energy_kwh`` is net; ``solve_s`` is the wall seconds of the solve).
    """
    import time

    from pymoo_rail.optimal import OptimalSolver
    from pymoo_rail.optimal.solver import DEFAULT_N_SPEEDS
    from pymoo_rail.rowcache import RowCache

    n_speeds = DEFAULT_N_SPEEDS if n_speeds is None else int(n_speeds)
    key = exact_points_key(case, n_speeds)
    cache = RowCache(path, value_columns=EXACT_POINT_COLUMNS, text_columns=("case_hash", "solver_version"))
    rows = {float(r["requested_time_s"]): r for r in cache.rows(key).to_dict("records")}
    done = set(rows) - {float(t) for t in redo_s}
    solver, guess = None, None
    for t in sorted({float(t) for t in running_times_s} | {float(t) for t in redo_s}):
        if t in done:
            continue
        if solver is None:  # built only when a time is missing: the grid and tables cost seconds
            solver = OptimalSolver(case, n_speeds=n_speeds)
        start = time.perf_counter()
        traj = solver.profile(t, lambda_guess_w=guess)
        guess = traj.summary["lambda_w"]
        row = {"requested_time_s": t, "running_time_s": traj.running_time_s, "energy_kwh": traj.energy.net_kwh,
               "traction_kwh": traj.energy.traction_kwh, "regen_kwh": traj.energy.regen_kwh,
               "lambda_kwh_per_s": guess / J_PER_KWH, "neutral_traction_j": traj.summary["neutral_traction_j"],
               "limit_excess_ms": traj.summary["limit_excess_ms"], "stop_error_m": traj.stop_error_m,
               "n_speeds": n_speeds, "solve_s": time.perf_counter() - start}
        cache.add(pd.DataFrame([row]), key, replace=lambda table, t=t: table["requested_time_s"] == t)
        rows[t] = row
        if on_run is not None:
            on_run(t, traj)
    wanted = sorted({float(t) for t in running_times_s})
    frame = pd.DataFrame([rows[t] for t in wanted], columns=list(EXACT_POINT_COLUMNS))
    return frame.sort_values("running_time_s", kind="stable").reset_index(drop=True)


__all__ = ["CertifiedFront", "NoExactFrontError", "case_hash", "cache_dir", "certified_front", "compute_front",
           "constrained_optimum", "default_window", "exact_points", "exact_points_key", "find_front", "forget_fronts",
           "front_key", "front_times", "mirrored", "punctual_tolerance_s", "EXACT_POINT_COLUMNS", "FRONT_VERSION",
           "PUNCTUAL_TOLERANCE_MIN_S", "PUNCTUAL_TOLERANCE_REL"]
