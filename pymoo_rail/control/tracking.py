"""Tracking a reference speed-distance curve with an ATO controller (Liu (2019) 2.1 and 5.1.3)."""

from __future__ import annotations


import numpy as np

from pymoo_rail.constants import KMH_PER_MS
from pymoo_rail.control import kernel as ck
from pymoo_rail.control.controllers import Controller, check_controller
from pymoo_rail.model import Case
from pymoo_rail.model.errors import FieldError, check_number
from pymoo_rail.sim import Simulator, Trajectory
from pymoo_rail.sim import kernel as sk
from pymoo_rail.sim.trajectory import energy_from_summary, summary_dict

DEFAULT_CONTROL_PERIOD_S = 0.2  # a usual ATO control cycle (the seeds give none)


def _check_reference(reference: Trajectory) -> None:
    if not isinstance(reference, Trajectory):
        raise ValueError(f"reference = {type(reference).__name__}: must be a pymoo_rail.sim.Trajectory")
    for name in ("position_m", "speed_ms", "regime"):
        values = np.asarray(getattr(reference, name), dtype=float)
        bad = np.flatnonzero(~np.isfinite(values))
        if bad.size:
            raise ValueError(f"reference.{name}[{bad[0]}] = {values[bad[0]]}: must be finite")
    x = np.asarray(reference.position_m, dtype=float)
    if x.ndim != 1 or x.shape[0] < 2 or x.shape[0] != np.asarray(reference.speed_ms).shape[0]:
        raise ValueError(f"reference.position_m has shape {x.shape}: a trace needs >= 2 nodes and one speed per node")
    steps = np.diff(x)
    if (steps < 0).any():
        k = int(np.flatnonzero(steps < 0)[0])
        raise ValueError(f"reference.position_m[{k + 1}] = {x[k + 1]}: positions must not decrease")
    if (np.asarray(reference.speed_ms) < 0).any():
        k = int(np.flatnonzero(np.asarray(reference.speed_ms) < 0)[0])
        raise ValueError(f"reference.speed_ms[{k}] = {reference.speed_ms[k]}: speeds must be >= 0")


class Tracker:
    """A controller tracking reference curves on one case, on a fixed grid.

    Parameters
    ----------
    case : Case
    controller : Hysteresis, PID or FuzzyPID
    control_period_s : float
        Time between control instants (the command is held in between); default 0.2 s.
    dx_m : float, optional
        Grid step, as for :class:`pymoo_rail.sim.Simulator` (whose grid and model it uses).
    """

    def __init__(self, case: Case, controller: Controller, control_period_s: float = DEFAULT_CONTROL_PERIOD_S,
                 dx_m: float | None = None):
        self.controller = check_controller(controller)
        self.control_period_s = check_number("control_period_s", control_period_s, positive=True, error=FieldError)
        self.simulator = Simulator(case, dx_m)
        self._code = int(controller.code())
        self._params = np.ascontiguousarray(controller.params(), dtype=float)

    @property
    def case(self) -> Case:
        """The case the tracked train runs on."""
        return self.simulator.case

    def run(self, reference: Trajectory, speed_noise_ms: np.ndarray | None = None,
            traction_lag_s: float = 0.0) -> Trajectory:
        """The tracked run of one reference curve (any :class:`Trajectory` of this line).

        The summary has the simulator's keys plus the speed error (speed minus reference at the
        same position, km/h) over the whole run (``speed_error_rms_kmh``, ``speed_error_max_kmh``)
        and over the part the controller drives (``control_error_rms_kmh``,
        ``control_error_max_kmh``, between ``control_start_m`` and ``control_stop_m``).

        ``speed_noise_ms`` (m/s, added to the measured speed at successive control instants) and
        ``traction_lag_s`` (time constant of a first-order lag between command and force) disturb
        the controlled part; see :class:`pymoo_rail.control.Disturbance`.
        """
        _check_reference(reference)
        noise = np.zeros(0) if speed_noise_ms is None else np.ascontiguousarray(speed_noise_ms, dtype=float)
        if noise.ndim != 1 or not np.all(np.isfinite(noise)):
            raise ValueError("speed_noise_ms must be a finite 1-d array (m/s per control instant)")
        if not (np.isfinite(traction_lag_s) and traction_lag_s >= 0):
            raise ValueError(f"traction_lag_s = {traction_lag_s!r} must be a number >= 0")
        grid = self.simulator.grid
        x_ref = np.asarray(reference.position_m, dtype=float)
        v_ref_ms = np.asarray(reference.speed_ms, dtype=float)
        v_ref = np.interp(grid.position_m, x_ref, v_ref_ms, right=0.0)
        regime = np.ascontiguousarray(reference.regime, dtype=np.int8)
        x_start, x_stop = ck.reference_phases(np.ascontiguousarray(x_ref), regime, x_ref.shape[0])
        out, x, v, t, a, f, r, u = ck.track_trace(self.simulator.model, v_ref, float(x_start), float(x_stop),
                                                 self._code, self._params, self.control_period_s,
                                                 noise, float(traction_lag_s), np.zeros(ck.N_CARRY),
                                                 np.inf, np.inf)
        summary = summary_dict(out)
        err_kmh = (v - np.interp(x, x_ref, v_ref_ms, right=0.0)) * KMH_PER_MS
        summary["speed_error_rms_kmh"] = float(np.sqrt(np.mean(err_kmh**2)))
        summary["speed_error_max_kmh"] = float(np.max(np.abs(err_kmh)))
        middle = (x >= x_start) & (x < x_stop)
        summary["control_error_rms_kmh"] = float(np.sqrt(np.mean(err_kmh[middle] ** 2))) if middle.any() else 0.0
        summary["control_error_max_kmh"] = float(np.max(np.abs(err_kmh[middle]))) if middle.any() else 0.0
        summary["control_start_m"] = float(x_start)
        summary["control_stop_m"] = float(x_stop)
        return Trajectory(position_m=x, speed_ms=v, time_s=t, accel_ms2=a, force_n=f, regime=r,
                          limit_ms=grid.limit_ms[: x.shape[0]], energy=energy_from_summary(out),
                          running_time_s=float(out[sk.OUT_RUNNING_TIME_S]),
                          stop_error_m=float(out[sk.OUT_STOP_ERROR_M]), summary=summary)

    def run_program(self, program: np.ndarray) -> Trajectory:
        """Simulate a driving program (rows, 3 or 4) and track its ideal run."""
        return self.run(self.simulator.run(program))

    def run_batch(self, programs: np.ndarray) -> np.ndarray:
        """Summaries (N, N_OUT) of the tracked runs of programs (N, rows, 3), in parallel.

        The same array :meth:`pymoo_rail.sim.Simulator.run_batch` returns for the ideal runs. A fourth
        column, the traction share of ``toward`` rows (the exact solver's part-power cells), is the
        simulator's too.
        """
        programs = np.ascontiguousarray(programs, dtype=float)
        if programs.ndim != 3 or programs.shape[2] not in (3, 4):
            raise ValueError(f"programs must have shape (N, rows, 3) or (N, rows, 4), got {programs.shape}")
        return ck.track_programs(self.simulator.model, programs, self._code, self._params, self.control_period_s)


def track(case: Case, reference: Trajectory, controller: Controller,
          control_period_s: float = DEFAULT_CONTROL_PERIOD_S, dx_m: float | None = None) -> Trajectory:
    """Simulate the train following ``reference`` under ``controller``.

    Parameters
    ----------
    case : Case
    reference : Trajectory
        The recommended speed-distance curve, e.g. ``problem.trajectory(x)``, a
        :class:`~pymoo_rail.sim.Simulator` run or the exact solver's optimum.
    controller : Hysteresis, PID or FuzzyPID
    control_period_s : float
        Time between control instants; the command is held in between.
    dx_m : float, optional
        Grid step (the simulator's default if None).

    Returns
    -------
    Trajectory
        With the simulator's fields and summary keys (energy breakdown, running time, stop
        error, jerk, regime changes), plus the tracking errors in the summary.
    """
    return Tracker(case, controller, control_period_s, dx_m).run(reference)


def tracked_summaries(case: Case, programs: np.ndarray, controller: Controller,
                      control_period_s: float = DEFAULT_CONTROL_PERIOD_S, dx_m: float | None = None) -> np.ndarray:
    """Summaries (N, N_OUT) of the tracked runs of N driving programs (what a problem scores)."""
    return Tracker(case, controller, control_period_s, dx_m).run_batch(programs)
