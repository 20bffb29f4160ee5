"""The minimum-energy run for a given running time, and the energy / running-time front.

``optimal_profile`` prices time at ``lambda`` (W = J/s), solves the dynamic programme of
:mod:`pymoo_rail.optimal.dp` for ``net energy + lambda x time``, and searches ``lambda`` until the
run takes the requested time. Larger ``lambda`` means faster, costlier runs; the running time
falls monotonically as ``lambda`` grows, so the search (:mod:`pymoo_rail.optimal.price_search`) is a
safeguarded secant (Illinois) method on ``log lambda``. At the solution ``lambda`` is the slope of
the front: the energy one more second of running time would save. Every run carries an error bound
(:mod:`pymoo_rail.optimal.certificate`).

The returned :class:`~pymoo_rail.sim.Trajectory` is not the DP's estimate: it is the simulator's
run of the DP's control sequence (one program row per grid cell), so every figure in it comes from
the same physics and energy accounting as any optimiser's result.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import replace

import numpy as np
import pandas as pd

from pymoo_rail.constants import J_PER_KWH, KMH_PER_MS
from pymoo_rail.model import Case, InfeasibleCaseError
from pymoo_rail.model.errors import FieldError, check_number
from pymoo_rail.optimal import dp
from pymoo_rail.optimal.certificate import (
    CERTIFICATE_FACTOR,
    CERTIFICATE_FLOOR_REL,
    bound_from_parts_kwh,
    bound_parts_kwh,
    move_remainder_j,
    untied_excess_j,
)
from pymoo_rail.optimal.price_search import (
    ADJUST_WITHIN_S,
    JUMP_LOG_WIDTH,
    LAMBDA_MAX_W,
    LAMBDA_MIN_W,
    MAX_TIME_ERROR_S,
    Solve,
    search_price,
)
from pymoo_rail.sim import Simulator, Trajectory

SOLVER_VERSION = "5"
"""Version of the solver's answers: bump it whenever a run the solver returns for a case can change
(DP, search, certificate, or the simulator that replays the run), so on-disk caches of its runs
(:func:`pymoo_rail.optimal.reference.exact_points`, :func:`pymoo_rail.journeys.section_fronts`)
stop serving the old rows; bump ``pymoo_rail.optimal.reference.FRONT_VERSION`` with it.
1: the solver of front versions 5 and 6 (rows cached before carried no version); 2: the singular speeds
as states and the end speed an equality (the shipped fronts of version 6, rest to rest, move by at
most 0.0045 kWh, 0.005 %, within their certificates: not recomputed); 3: the certificate's floor at
least 5e-4 of the run's traction energy, runs unchanged (fronts recomputed as version 7 for their
certificates); 4: the coast curves into the braking envelope's corners and the end speed, and the
full-traction start, as states of the DP (``dp.coast_curves``; runs change where they coast into a
lower limit or a moving end, fronts recomputed as version 8); 5: the certificate compares a grid of
twice the speed nodes, not half (runs unchanged, fronts recomputed as version 9 for their certificates)."""
DEFAULT_N_SPEEDS = 200
DEFAULT_MAX_TARGETS = 16
DEFAULT_TIME_TOL_S = 0.05
DEFAULT_TOP_BIAS = 0.5
# ``profile`` refines the speed grid up to this many nodes when the discrete optimum jumps over the request
MAX_N_SPEEDS = 4 * DEFAULT_N_SPEEDS
DEFAULT_TIE_J = 100.0
# the constants of the search and the certificate, named here as before they had modules of their own
__all__ = ["SOLVER_VERSION", "DEFAULT_N_SPEEDS", "DEFAULT_MAX_TARGETS", "DEFAULT_TIME_TOL_S", "DEFAULT_TOP_BIAS",
           "DEFAULT_TIE_J", "MAX_N_SPEEDS", "MAX_TIME_ERROR_S", "ADJUST_WITHIN_S", "JUMP_LOG_WIDTH",
           "CERTIFICATE_FACTOR", "CERTIFICATE_FLOOR_REL", "LAMBDA_MIN_W", "LAMBDA_MAX_W", "Solve",
           "OptimalSolver", "min_running_time", "optimal_profile", "optimal_front"]


class OptimalSolver:
    """Exact minimum-energy runs of one case on one grid (reused across running times).

    Parameters
    ----------
    case : Case
    dx_m : float, optional
        Position step, the simulator's grid (default: the simulator's default, 1 m on metro lines).
    n_speeds : int
        Nodes of the cost-to-go in ``v^2`` at each position, from 0 to the braking envelope.
    max_targets : int
        Most partial-traction targets (speed nodes of the next position) tried per state.
    time_tol_s : float
        The ``lambda`` search stops once the run is this close to the requested time. The discrete
        optimum can jump over the request (switch points move by whole cells); the run returned is
        then the closest one, never more than 0.5 s off (the speed grid is refined if need be).
    top_bias : float
        In [0, 1): packs the speed nodes towards the braking envelope (node spacing there is
        ``1 - top_bias`` times the uniform one), where runs hold speed limits.
    tie_j : float
        Controls within this many joules of the best count as tied, and the forward run then keeps
        its regime: it removes chattering between coasting and partial traction, at a cost the
        certificate measures (0.07 % on a 1.7 km metro section on a 1 m grid, ``docs/optimal.md``).
    certify : bool
        Give every run an error bound (``summary["energy_bound_kwh"]``, see :meth:`energy_bound_kwh`);
        costs a second solve on a speed grid of twice the nodes.
    price_shape : array (n_cells,), optional
        Relative price of time per grid cell, scaled by the ``lambda`` search: a journey's timing
        points give each stretch between them its own price (:meth:`set_price_shape`).
    speed_floor_ms : array (n_nodes,), optional
        Lowest speed allowed at each grid node (0: none): a journey's minimum speeds at its timing
        points (:meth:`set_speed_floor`).
    singular : bool
        Add, for every price of time tried, the speeds at which holding is optimal (Pontryagin's
        singular arcs: ``V`` by partial traction, ``W`` by regenerative braking, see
        ``dp.singular_speeds``) as states of the DP at every position, so that it holds them exactly
        instead of at the nearest speed nodes (``docs/optimal.md``). False: the speed grid alone.
    """

    def __init__(self, case: Case, dx_m: float | None = None, n_speeds: int = DEFAULT_N_SPEEDS,
                 max_targets: int = DEFAULT_MAX_TARGETS, time_tol_s: float = DEFAULT_TIME_TOL_S,
                 top_bias: float = DEFAULT_TOP_BIAS, tie_j: float = DEFAULT_TIE_J, certify: bool = True,
                 price_shape: np.ndarray | None = None, speed_floor_ms: np.ndarray | None = None,
                 singular: bool = True):
        if isinstance(n_speeds, bool) or not isinstance(n_speeds, (int, np.integer)) or n_speeds < 3:
            raise ValueError(f"n_speeds = {n_speeds!r}: must be an integer >= 3")
        if isinstance(max_targets, bool) or not isinstance(max_targets, (int, np.integer)) or max_targets < 1:
            raise ValueError(f"max_targets = {max_targets!r}: must be an integer >= 1")
        if not (isinstance(top_bias, (int, float)) and 0.0 <= top_bias < 1.0):
            raise ValueError(f"top_bias = {top_bias!r}: must be a number in [0, 1)")
        self.top_bias = float(top_bias)
        if not (isinstance(tie_j, (int, float)) and math.isfinite(tie_j) and tie_j >= 0.0):
            raise ValueError(f"tie_j = {tie_j!r}: must be a finite number of joules >= 0")
        self.tie_j = float(tie_j)
        self.singular = bool(singular)
        self.case = case
        self.simulator = Simulator(case, dx_m)
        self.n_speeds = int(n_speeds)
        self.max_targets = int(max_targets)
        self.time_tol_s = check_number("time_tol_s", time_tol_s, positive=True, error=FieldError)
        self._value = np.empty((self.simulator.grid.n_nodes, self.n_speeds))
        self._tables = None  # transitions, built on the first solve (they do not depend on lambda)
        self._swept = None  # (price, shape, floor) of the cost-to-go in _value and _sing
        n_nodes = self.simulator.grid.n_nodes
        self._min_time_s: float | None = None
        self.n_solves = 0  # DP solves so far (for benchmarks)
        # the parts of the last certificate (kWh): grid, moved run, kept regimes, untied run (for benchmarks)
        self.last_bound_parts: dict[str, float] = {}
        self.certify = bool(certify)
        self._grid_check: OptimalSolver | None = None
        self._history: list[Solve] = []  # every solve so far: time depends on lambda alone
        self.price_shape: np.ndarray | None = None
        self.set_price_shape(price_shape)
        # the arrival speeds the case asks for: (lo, hi), lo = hi = the final speed unless it gives a window
        self.end_speed_ms = case.end_speed_window_ms()
        self._terminal_j = dp.terminal_cost(self.simulator.model, self.n_speeds, self.top_bias, self.end_speed_ms[0])
        # the coast curves into the envelope's corners and the end speed: kinks of the cost-to-go, held as states
        self._arrival = dp.coast_curves(self.simulator.model, float(self.end_speed_ms[0]), self.n_speeds,
                                        self.top_bias)
        self._sing = tuple(np.empty((n_nodes, dp.N_SINGULAR + self._arrival[0].shape[1])) for _ in range(3))
        self._curves = None  # the curves' price-independent controls (dp.curve_controls), built on the first sweep
        self.speed_floor_ms: np.ndarray | None = None
        self._floor_k: np.ndarray | None = None
        self.set_speed_floor(speed_floor_ms)

    def set_price_shape(self, price_shape: np.ndarray | None) -> None:
        """Price time per cell as ``lambda x price_shape`` (None: one price everywhere).

        Earlier solves were made at another shape, so they no longer guide the ``lambda`` search.
        """
        if price_shape is not None:
            shape = np.asarray(price_shape, dtype=float)
            n_cells = self.simulator.grid.n_nodes - 1
            if shape.shape != (n_cells,) or not np.all(np.isfinite(shape) & (shape > 0)):
                raise ValueError(f"price_shape: needs {n_cells} finite values > 0, one per cell")
            price_shape = shape
        self.price_shape = price_shape
        self._history = []
        self._swept = None
        if self._grid_check is not None:
            self._grid_check.set_price_shape(price_shape)

    def set_speed_floor(self, speed_floor_ms: np.ndarray | None) -> None:
        """Forbid runs slower than ``speed_floor_ms`` (n_nodes,) at each grid node (None: no floor).

        The DP rounds each floor up to its next speed node, so every run found holds it; a floor
        above the braking envelope leaves no run. Earlier solves no longer guide the search.
        """
        n_nodes = self.simulator.grid.n_nodes
        if speed_floor_ms is not None:
            floor = np.asarray(speed_floor_ms, dtype=float)
            if floor.shape != (n_nodes,) or not np.all(np.isfinite(floor) & (floor >= 0)):
                raise ValueError(f"speed_floor_ms: needs {n_nodes} finite values >= 0, one per grid node")
            speed_floor_ms = floor if np.any(floor > 0) else None
        floor_k = None
        if speed_floor_ms is not None:
            floor_k = dp.speed_floor_nodes(self.simulator.model, speed_floor_ms, self.n_speeds, self.top_bias)
        self.speed_floor_ms = speed_floor_ms
        self._floor_k = floor_k
        self._history = []
        self._swept = None
        if self._grid_check is not None:
            self._grid_check.set_speed_floor(speed_floor_ms)

    def holds_speed_floor(self, speed_ms: np.ndarray) -> bool:
        """Whether a run's node speeds hold the speed floor and it arrives at the end speed asked for."""
        if speed_ms.shape[0] < self.simulator.grid.n_nodes or speed_ms[-1] < self.end_speed_ms[0] - 1e-9:
            return False
        if self.speed_floor_ms is None:
            return True
        return bool(np.all(speed_ms[: self.speed_floor_ms.shape[0]] >= self.speed_floor_ms - 1e-9))

    @property
    def dx_m(self) -> float:
        """Step of the distance grid (m)."""
        return self.simulator.grid.dx_m

    def min_running_time_s(self) -> float:
        """The flat-out running time on this grid (raises if the train cannot reach the platform)."""
        if self._min_time_s is None:
            self._min_time_s = self.simulator.check_planned_time(math.inf)
        return self._min_time_s

    def solve_price(self, lambda_w: float) -> Solve:
        """The DP optimum of ``net energy + lambda_w x time`` (one backward sweep and forward run)."""
        self.transition_tables()
        self.n_solves += 1
        solution = self._record(lambda_w, self.run_dp(lambda_w, self.tie_j))
        self._history.append(solution)
        return solution

    def run_dp(self, lambda_w: float, tie_j: float) -> tuple:
        """:func:`pymoo_rail.optimal.dp.solve` at price ``lambda_w`` and tie rule ``tie_j`` on built tables.

        Returns the DP's raw forward run (modes, targets, speeds, cells done, energy, time, tie cost,
        value); :meth:`solve_price` records it as a :class:`Solve`.
        """
        prices = lambda_w if self.price_shape is None else lambda_w * self.price_shape
        # the cost-to-go of the last sweep still holds at its price and settings: only the forward run
        key = (lambda_w, id(self.price_shape), id(self._floor_k))
        if self._curves is None and self.singular:
            self._curves = dp.curve_controls(self.simulator.model, *self._arrival, self.n_speeds, self.max_targets,
                                             self.top_bias)
        run = dp.solve(self.simulator.model, self._tables, prices, self.max_targets, self.top_bias, tie_j,
                       self._value, self._floor_k, self._terminal_j, self.singular, self._sing, self._swept == key,
                       self._arrival, self._curves)
        self._swept = key
        return run

    def at_finest_speed_grid(self) -> bool:
        """Whether ``profile`` may not refine the speed grid any further (``MAX_N_SPEEDS`` nodes)."""
        return self.n_speeds >= MAX_N_SPEEDS

    def _record(self, lambda_w: float, run: tuple) -> Solve:
        modes, targets, speeds, done, energy, time, tie_cost, value_j = run
        if done < modes.shape[0]:
            x = self.simulator.grid.position_m[done]
            raise InfeasibleCaseError("line", self.case.name,
                                      f"the solver finds no way to the platform beyond {x:.1f} m", self.case.name)
        if speeds[-1] < self.end_speed_ms[0] - 1e-9:
            raise InfeasibleCaseError("run.final_speed_kmh", self.end_speed_ms[0] * KMH_PER_MS,
                                      f"the solver's run arrives at {speeds[-1] * KMH_PER_MS:.3f} km/h: the end speed "
                                      "asked for is out of reach", self.case.name)
        program = np.column_stack([self.simulator.model.position_m[1:], modes.astype(float), targets])
        return Solve(lambda_w, program, speeds, energy, time, float(value_j), tie_cost_j=tie_cost)

    def energy_bound_kwh(self, solution: Solve, traction_kwh: float = 0.0) -> float:
        """Estimated bound on the run's energy above the optimum at its running time (kWh, >= 0).

        The sum of three parts (``docs/optimal.md``, "Certificate"):

        - the grid: the optimum at the same price ``lambda`` on a speed grid of twice the nodes
          (same position grid, same controls; half the nodes at ``MAX_N_SPEEDS``), moved to this
          run's time along the front's slope ``lambda`` (that grid's supporting line there),
          differs from this run by ``delta``; if the DP's error falls like ``spacing^p``, this
          run's error is ``|delta| 2^p / (2^p - 1)``, and ``2 |delta|`` covers any ``p >= 1``
          (with half the nodes: ``|delta| / (2^p - 1)``, any ``p >= 0.58``);
        - a floor of ``1e-4`` of the run's net energy or ``5e-4`` of its traction energy
          ``traction_kwh`` (the larger), for where the two grids agree by coincidence or err alike;
        - the run above the supporting line at ``lambda``: for a moved run, its weak-duality gap to
          the bracketing runs (``dual_gap_j``); for any run, how much better the forward run
          without the tie rule is at the same price; the larger of the two.

        An estimate, not a proven bound: ``benchmarks/certificate_shifted.py`` checks it against
        ms-eetc on generated lines at running times off the benchmark's, ``benchmarks/reference_check.py``
        against every optimiser result the project's studies committed. The optimum meant is that of
        the simulator's model on this position grid, the model every optimiser's run is evaluated with.
        """
        # the two grids compared through their dual functions at the run's price, min E + lambda T
        other = self.grid_check_solver().solve_price(solution.lambda_w)
        self.last_bound_parts = bound_parts_kwh(solution, other, untied_excess_j(self, solution), traction_kwh)
        return bound_from_parts_kwh(self.last_bound_parts)

    def grid_check_solver(self) -> OptimalSolver:
        """The solver the certificate compares with: twice the speed nodes (half at ``MAX_N_SPEEDS``), same positions.

        Twice, not half: a grid of half the nodes can agree with this one by coincidence where both
        miss the optimum alike (generated lines 5 at 1.5 x its minimum time + 0.2 s and 7 at 1.4 x: the
        half grid's certificates 0.088 and 0.087 kWh, ms-eetc 0.160 and 0.283 kWh below the runs;
        ``benchmarks/certificate_shifted.py``, ``docs/optimal.md``).
        """
        if self._grid_check is None:
            n_speeds = 2 * self.n_speeds if 2 * self.n_speeds <= MAX_N_SPEEDS else max(self.n_speeds // 2, 3)
            self._grid_check = OptimalSolver(self.case, self.dx_m, n_speeds, self.max_targets,
                                             self.time_tol_s, self.top_bias, self.tie_j, certify=False,
                                             price_shape=self.price_shape, speed_floor_ms=self.speed_floor_ms,
                                             singular=self.singular)
            self._grid_check.simulator = self.simulator  # same grid and model: share them
            self._grid_check._min_time_s = self._min_time_s
        return self._grid_check

    def transition_tables(self) -> tuple:
        """The DP's transitions of this solver's model (:func:`pymoo_rail.optimal.dp.transitions`), built once.

        They do not depend on the price of time: a caller sweeping its own prices
        (``dp.backward_sweep``, e.g. :class:`pymoo_rail.control.OptimalPolicy`) reuses them.
        """
        if self._tables is None:
            self._tables = dp.transitions(self.simulator.model, self.n_speeds, self.max_targets, self.top_bias)
        return self._tables

    def solves(self) -> list[Solve]:
        """Every run this solver found at a price of time so far (``lambda_w``, ``time_s``, ``energy_j`` ...)."""
        return list(self._history)

    def move_remainder_j(self, time_s: float, lambda_w: float, target_s: float) -> float:
        """Bound on the error of moving a run at ``time_s`` (price ``lambda_w``) to ``target_s`` along ``lambda_w`` (J).

        The moved energy ``E + lambda (time_s - target_s)`` is the supporting line of the front at
        ``target_s``: at or below the optimum there. Above it lies the chord between this solver's
        closest solves on either side of ``target_s`` (the front is convex); the chord minus the line
        bounds the error. With no solve on one side, or for a run that is not one of this solver's
        solves (a moved run, within ``time_tol_s``; a run of the finer grid ``profile`` fell back
        to): ``lambda |time_s - target_s|``, the first-order term itself
        (:func:`pymoo_rail.optimal.certificate.move_remainder_j`).
        """
        return move_remainder_j(self._history, time_s, lambda_w, target_s)

    def trajectory(self, solution: Solve) -> Trajectory:
        """Replay a solution's controls in the simulator: the returned run is the simulator's own."""
        tr = self.simulator.run(solution.program)
        speeds = tr.speed_ms if solution.speeds is None else solution.speeds
        mismatch = float(np.max(np.abs(tr.speed_ms - speeds[: tr.speed_ms.shape[0]])))
        energy_j = tr.energy.net_kwh * J_PER_KWH
        if (not tr.reached or tr.speed_ms.shape[0] != speeds.shape[0] or mismatch > 1e-9
                or abs(energy_j - solution.energy_j) > 1e-9 * max(abs(energy_j), 1.0)):
            raise RuntimeError(f"the simulator's replay of the optimal controls departs from the solver's run "
                               f"(max speed difference {mismatch:.3g} m/s, energy {tr.energy.net_kwh:.6f} against "
                               f"{solution.energy_j / J_PER_KWH:.6f} kWh): solver and simulator disagree")
        summary = dict(tr.summary, lambda_w=solution.lambda_w, dp_value_j=solution.value_j,
                       n_speeds=float(self.n_speeds), dx_m=float(self.dx_m),
                       adjusted=float(solution.speeds is None))
        return replace(tr, summary=summary)

    def profile(self, running_time_s: float, lambda_guess_w: float | None = None) -> Trajectory:
        """The minimum-energy run taking ``running_time_s`` (see :func:`optimal_profile`)."""
        running_time_s = check_number("running_time_s", running_time_s, positive=True, error=FieldError)
        fastest = self.min_running_time_s()
        if running_time_s < fastest - 1e-9:
            raise InfeasibleCaseError("running_time_s", running_time_s,
                                      f"is below the minimum running time {fastest:.2f} s of the train on this line",
                                      self.case.name)
        solution = search_price(self, running_time_s, lambda_guess_w)
        if abs(solution.time_s - running_time_s) > MAX_TIME_ERROR_S:
            # the discrete optimum jumps over the requested time at this lambda: a finer speed grid
            # makes the jumps smaller
            if self.at_finest_speed_grid():
                raise RuntimeError(f"running_time_s = {running_time_s}: the closest optimum takes "
                                   f"{solution.time_s:.2f} s (lambda = {solution.lambda_w:.6g} W), more than "
                                   f"{MAX_TIME_ERROR_S} s off, at n_speeds = {self.n_speeds} (profile refines up to "
                                   f"{MAX_N_SPEEDS}): the discrete optimum jumps over this time; another n_speeds "
                                   "or dx_m moves the jumps")
            finer = OptimalSolver(self.case, self.dx_m, 2 * self.n_speeds, self.max_targets, self.time_tol_s,
                                  self.top_bias, self.tie_j, self.certify, self.price_shape, self.speed_floor_ms,
                                  self.singular)
            # where the finer grid's certificate compares it with this grid (at MAX_N_SPEEDS): its tables serve
            check = finer.grid_check_solver()
            if check.n_speeds == self.n_speeds:
                check._tables = self.transition_tables()
            tr = finer.profile(running_time_s, solution.lambda_w)
            self.last_bound_parts = finer.last_bound_parts
            return tr
        tr = self.trajectory(solution)
        if self.certify:
            tr = replace(tr, summary=dict(tr.summary, energy_bound_kwh=self.energy_bound_kwh(solution, tr.energy.traction_kwh)))
        return tr


def min_running_time(case: Case, dx_m: float | None = None) -> float:
    """The shortest running time of the case: the simulator's flat-out run (s).

    Raises :class:`~pymoo_rail.model.InfeasibleCaseError` if the train cannot reach the platform.
    """
    return Simulator(case, dx_m).check_planned_time(math.inf)


def optimal_profile(case: Case, running_time_s: float, **settings) -> Trajectory:
    """The minimum net-energy run that stops at the platform after ``running_time_s``.

    Dynamic programming over (position, speed) for ``net energy + lambda x running time`` with
    ``lambda`` found by a root search; the result is the simulator's replay of the optimal controls.

    Parameters
    ----------
    case : Case
    running_time_s : float
        Requested running time; at least :func:`min_running_time`.
    **settings
        Grid and search settings of :class:`OptimalSolver` (``dx_m``, ``n_speeds``, ``max_targets``,
        ``time_tol_s``, ``top_bias``, ``tie_j``, ``certify``); the accuracy the defaults reach is
        measured in ``docs/optimal.md``, and every run carries its own bound.

    Returns
    -------
    Trajectory
        With ``running_time_s`` within ``time_tol_s`` of the request when the discrete optimum allows
        it, never more than 0.5 s off; ``summary["lambda_w"]`` is the price of time (W) at which it
        is optimal; ``summary["energy_bound_kwh"]`` bounds its energy above the optimum at its
        running time (:meth:`OptimalSolver.energy_bound_kwh`; absent with ``certify=False``).

    Raises
    ------
    InfeasibleCaseError
        ``running_time_s`` below the minimum running time (the message gives the minimum).
    ValueError
        ``running_time_s`` not a finite positive number.
    """
    return OptimalSolver(case, **settings).profile(running_time_s)


def optimal_front(case: Case, running_times, *, progress: Callable[[int, int], None] | None = None,
                  **settings) -> pd.DataFrame:
    """Minimum net energy at each running time: the energy / running-time front of the case.

    Parameters
    ----------
    case : Case
    running_times : sequence of float
        Requested running times (s), each at least :func:`min_running_time`.
    progress : callable, optional
        Called as ``progress(done, total)`` after each running time is solved (for a progress bar).
    **settings
        As for :func:`optimal_profile`.

    Returns
    -------
    pandas.DataFrame
        One row per requested time, sorted by time: ``running_time_s`` (of the run found) and
        ``energy_kwh`` (net) of the simulated optimal run, ``requested_time_s``, ``traction_kwh``,
        ``regen_kwh``, ``aux_kwh``, ``lambda_kwh_per_s`` (the front's slope ``-dE/dT``: the energy
        one more second saves), ``energy_at_request_kwh`` (the energy moved along that slope to
        the requested time, to first order) and ``energy_bound_kwh``: a bound on ``energy_kwh``
        minus the optimum at ``running_time_s`` (kWh, >= 0; :meth:`OptimalSolver.energy_bound_kwh`;
        NaN with ``certify=False``).
    """
    times = np.atleast_1d(np.asarray(running_times, dtype=float))
    if times.ndim != 1 or times.size == 0:
        raise ValueError(f"running_times has shape {times.shape}: give one or more running times")
    for t in times:
        check_number("running_time_s", float(t), positive=True, error=FieldError)
    solver = OptimalSolver(case, **settings)
    rows = []
    guess = None
    for t in np.sort(times):
        tr = solver.profile(float(t), lambda_guess_w=guess)
        guess = tr.summary["lambda_w"]
        e = tr.energy
        slope = guess / J_PER_KWH
        rows.append({"running_time_s": tr.running_time_s, "energy_kwh": e.net_kwh, "requested_time_s": float(t),
                     "traction_kwh": e.traction_kwh, "regen_kwh": e.regen_kwh, "aux_kwh": e.aux_kwh,
                     "lambda_kwh_per_s": slope,
                     "energy_at_request_kwh": e.net_kwh + slope * (tr.running_time_s - float(t)),
                     "energy_bound_kwh": tr.summary.get("energy_bound_kwh", math.nan)})
        if progress is not None:
            progress(len(rows), len(times))
    return pd.DataFrame(rows)
