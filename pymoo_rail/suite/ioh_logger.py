"""IOHprofiler logs of pymoo runs on suite problems, written by the maintained ``ioh`` package.

:class:`IOHLogger` is a pymoo callback (``minimize(problem, algorithm, callback=IOHLogger(...))``).
Every evaluation becomes one line of an IOHprofiler ``.dat`` file (``ioh.logger.Analyzer``):

- ``raw_y``: the *hypervolume gap* of the feasible points evaluated so far, as COCO's bi-objective
  suite logs it: ``1 - HV(archive) / HV(certified front)``, objectives scaled so that the
  certified front's ideal point maps to 0 and the problem's fixed HV reference point
  (``problem.hv_reference_point()``) to 1. It is 1 until the first feasible point and falls
  towards 0 (slightly below within the front's certificate: the interpolated front lies above the
  true one). A single objective is the same with one coordinate: the gap of the best feasible
  energy to the certified optimum, in units of the reference point's distance from it.
- one column per objective (e.g. ``energy`` and ``running_time``) and ``cv``, pymoo's constraint
  violation, of the point evaluated: post-processing (``iohinspector``'s hypervolume or IGD+)
  can rebuild any indicator from them, taking the rows with ``cv == 0``.

The IOH function is the problem (name, ``n_var`` as the dimension); the instance is a family
instance's seed (1 for a named problem). Each pymoo run on the logger is one IOH run.
"""

from __future__ import annotations

from pathlib import Path
from types import SimpleNamespace

import numpy as np

from pymoo_rail.suite.run_log import EvaluationLogger, HVArchive


class IOHLogger(EvaluationLogger):
    """A pymoo callback writing IOHprofiler data through ``ioh`` (the ``suite`` extra).

    Parameters
    ----------
    folder : str or Path
        Root folder; the run's data go to ``folder/<algorithm_name>`` (ioh numbers a second one).
    algorithm_name : str
        Name recorded in the IOH metadata.
    algorithm_info : str
        Free text recorded beside it (settings, budget).

    Notes
    -----
    The problem must have a certified front (``pareto_front()``) and ``hv_reference_point()``:
    every family instance has both. Algorithms must report the individuals they evaluated as
    ``algorithm.off`` (pymoo's infill/advance algorithms do); call :meth:`close` (or use the logger
    as a context manager) after the last run to write the IOH metadata file.
    """

    label = "IOHLogger"

    def __init__(self, folder: str | Path, algorithm_name: str, algorithm_info: str = ""):
        super().__init__()
        import ioh  # the optional ``suite`` extra: imported only when a logger is made

        self._ioh = ioh
        self.folder = Path(folder)
        self.algorithm_name = str(algorithm_name)
        self.logger = ioh.logger.Analyzer(root=str(self.folder), folder_name=self.algorithm_name,
                                          algorithm_name=self.algorithm_name, algorithm_info=str(algorithm_info),
                                          triggers=[ioh.logger.trigger.ALWAYS])
        self.current = SimpleNamespace()  # the evaluated point's objectives and cv, read by ioh
        self._watched: list[str] | None = None
        self._ioh_problem = None
        self._pending: list[float] = []

    # ------------------------------------------------------------------ runs
    def start_run(self, problem) -> None:
        """Attach ioh to ``problem`` (a new run of the same problem keeps it) and start the HV archive."""
        if self._ioh_problem is None or problem.n_var != self._ioh_problem.meta_data.n_variables \
                or getattr(problem, "suite_name", None) != self._name:
            self._attach(problem)
        self._pending = []
        self._archive = HVArchive(problem)
        self._gap = 1.0

    def log_point(self, evaluation: int, x: np.ndarray, f: np.ndarray, cv: float) -> None:
        """Write one evaluation: the HV gap after it as ``raw_y``, its objectives and ``cv``."""
        if self._archive.add(evaluation, x, f, cv):
            self._gap = 1.0 - self._archive.hv / self._archive.hv_front
        self._pending.append(self._gap)
        for name, value in zip(self._objective_names, f):
            setattr(self.current, name, float(value))
        self.current.cv = float(cv)
        self._ioh_problem(x)

    def end_run(self) -> None:
        """End the IOH run (ioh writes its run record)."""
        self._ioh_problem.reset()

    def _attach(self, problem) -> None:
        ioh = self._ioh
        if self._ioh_problem is not None:
            self._ioh_problem.detach_logger()
        self._name = getattr(problem, "suite_name", type(problem).__name__)
        self._objective_names = list(getattr(problem, "objectives", [f"f{j}" for j in range(problem.n_obj)]))
        columns = [*self._objective_names, "cv"]
        if self._watched is None:  # ioh reads the watched attributes at every logged evaluation
            for column in columns:
                setattr(self.current, column, float("nan"))
            self.logger.watch(self.current, columns)
            self._watched = columns
        elif columns != self._watched:
            raise ValueError(f"IOHLogger: problem {self._name} has columns {columns}, this logger writes "
                             f"{self._watched}; use one logger per kind of problem")
        name = str(getattr(problem, "family", self._name))
        self._ioh_problem = ioh.wrap_problem(lambda x: self._pending.pop(0), name=name,
                                             optimization_type=ioh.OptimizationType.MIN,
                                             dimension=int(problem.n_var), instance=int(getattr(problem, "seed", 1)),
                                             lb=float(np.min(problem.xl)), ub=float(np.max(problem.xu)))
        self._ioh_problem.attach_logger(self.logger)

    def close(self) -> None:
        """End the last run and write the IOH metadata (idempotent)."""
        super().close()
        if self._ioh_problem is not None:
            self._ioh_problem.detach_logger()
            self._ioh_problem = None
        self.logger.close()
