"""The user-facing simulator of one case."""

from __future__ import annotations

import numba
import numpy as np

from pymoo_rail.model import Case, InfeasibleCaseError, TrackGrid, build_grid
from pymoo_rail.sim import kernel as k
from pymoo_rail.sim.drivers import flat_out_program
from pymoo_rail.sim.physics import KernelModel, build_kernel_model
from pymoo_rail.sim.stall import explain_stall
from pymoo_rail.constants import J_PER_KWH
from pymoo_rail.sim.trajectory import EnergyBreakdown, Trajectory, energy_from_summary, summary_dict

# Below this many cells (runs x grid cells) a batch runs in the calling thread: waking the
# other threads and waiting for the slowest one costs more than it saves, and waiting threads
# spin on a busy machine. Measured by ``benchmarks/throughput.py`` (serial vs parallel rows).
PARALLEL_MIN_CELLS = 50_000


class Simulator:
    """Runs driving programs for one case on a fixed grid.

    Parameters
    ----------
    case : Case
    dx_m : float, optional
        Grid step (default 1 m up to 10 km of line, else 5 m); halving it changes energy and
        time by far less than 0.1 % (``tests/sim/test_convergence.py``).
    """

    def __init__(self, case: Case, dx_m: float | None = None):
        self.case = case
        self.grid: TrackGrid = build_grid(case, dx_m)
        self.model: KernelModel = build_kernel_model(case, self.grid)

    @property
    def length_m(self) -> float:
        """Length of the line (m)."""
        return float(self.case.line.length_m)

    def run_batch(self, programs: np.ndarray) -> np.ndarray:
        """Summaries (N, N_OUT) of programs (N, rows, 3) (or 4 columns: a traction share, see ``kernel``).

        Evaluated on Numba's threads (``numba.set_num_threads``) when the batch has at least
        :data:`PARALLEL_MIN_CELLS` cells, else in the calling thread; the results are the same.
        """
        programs = np.ascontiguousarray(programs, dtype=float)
        if programs.ndim != 3 or programs.shape[2] not in (3, 4):
            raise ValueError(f"programs must have shape (N, rows, 3) or (N, rows, 4), got {programs.shape}")
        n_cells = programs.shape[0] * (self.model.position_m.shape[0] - 1)
        if n_cells < PARALLEL_MIN_CELLS or numba.get_num_threads() == 1:
            return k.simulate_batch_serial(self.model, programs)
        return k.simulate_batch(self.model, programs)

    def run(self, program: np.ndarray) -> Trajectory:
        """The full trajectory of one program (rows, 3) or (rows, 4)."""
        program = np.ascontiguousarray(program, dtype=float)
        if program.ndim != 2 or program.shape[1] not in (3, 4):
            raise ValueError(f"a program must have shape (rows, 3) or (rows, 4), got {program.shape}")
        out, x, v, t, a, f, r = k.simulate_trace(self.model, program)
        return Trajectory(position_m=x, speed_ms=v, time_s=t, accel_ms2=a, force_n=f, regime=r,
                          limit_ms=self.grid.limit_ms[: x.shape[0]], energy=energy_from_summary(out),
                          running_time_s=float(out[k.OUT_RUNNING_TIME_S]),
                          stop_error_m=float(out[k.OUT_STOP_ERROR_M]), summary=summary_dict(out))

    def energy_of(self, run: Trajectory) -> EnergyBreakdown:
        """The energy of a recorded run (any train's, on this line) drawn by this case's train.

        The run's positions, speeds and forces are kept; the accounting is this train's (its
        efficiencies or efficiency maps, regeneration caps and auxiliary power), cell by cell as the
        kernel does (``kernel.trace_cell_energies``): what a run planned under one efficiency model
        costs under another (docs/efficiency.md).
        """
        x, v, f = (np.ascontiguousarray(a, dtype=float) for a in (run.position_m, run.speed_ms, run.force_n))
        traction_j, regen_j = k.trace_cell_energies(self.model, x, v, f)
        traction, regen = float(traction_j.sum()) / J_PER_KWH, float(regen_j.sum()) / J_PER_KWH
        aux = self.model.aux_power_w * run.running_time_s / J_PER_KWH
        return EnergyBreakdown(traction_kwh=traction, regen_kwh=regen, aux_kwh=aux, net_kwh=traction + aux - regen)

    def flat_out(self) -> Trajectory:
        """The fastest run: maximum traction, held at the limits, latest braking."""
        return self.run(flat_out_program(self.length_m))

    def min_running_time_s(self) -> float:
        """Running time of the flat-out run, the shortest the train can do on this grid.

        Raises :class:`InfeasibleCaseError` naming the cause when even that run stops short
        (a time for a run that never arrives would be meaningless)."""
        return self.check_reachable().running_time_s

    def check_reachable(self) -> Trajectory:
        """The flat-out run; :class:`InfeasibleCaseError` naming the cause when it stops short."""
        fastest = self.flat_out()
        if not fastest.reached:
            raise explain_stall(self.case, self.grid, float(fastest.summary["stop_position_m"]))
        return fastest

    def check_planned_time(self, planned_time_s: float | None = None) -> float:
        """Raise :class:`InfeasibleCaseError` when the planned time is below the minimum.

        Returns the minimum running time.
        """
        planned = self.case.planned_time_s if planned_time_s is None else planned_time_s
        fastest = self.check_reachable()
        if planned < fastest.running_time_s:
            raise InfeasibleCaseError("run.planned_time_s", planned,
                                      f"is below the minimum running time {fastest.running_time_s:.2f} s "
                                      f"of the train on this line", self.case.name)
        return fastest.running_time_s
