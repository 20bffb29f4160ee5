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
from pymoo.core.callback import Callback
from pymoo.indicators.hv import HV


class IOHLogger(Callback):
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
        self._algorithm = None
        self._ioh_problem = None
        self._pending: list[float] = []

    # ------------------------------------------------------------------ pymoo hook
    def notify(self, algorithm) -> None:
        """Log the individuals evaluated in this iteration (``algorithm.off``)."""
        if algorithm is not self._algorithm:
            self._start_run(algorithm)
        batch = algorithm.off
        n_new = algorithm.evaluator.n_eval - self._n_eval
        if n_new == 0:
            return
        if batch is None or len(batch) != n_new:
            raise RuntimeError(f"IOHLogger: {type(algorithm).__name__} evaluated {n_new} points but reported "
                               f"{0 if batch is None else len(batch)} as algorithm.off; it cannot be logged")
        self._n_eval = algorithm.evaluator.n_eval
        F, CV, X = batch.get("F"), batch.get("CV")[:, 0], batch.get("X")
        for x, f, cv in zip(X, F, CV):
            self._pending.append(self._gap_after(f, cv))
            for name, value in zip(self._objective_names, f):
                setattr(self.current, name, float(value))
            self.current.cv = float(cv)
            self._ioh_problem(np.asarray(x, dtype=float))

    # ------------------------------------------------------------------ runs
    def _start_run(self, algorithm) -> None:
        problem = algorithm.problem
        if self._ioh_problem is not None and problem.n_var == self._ioh_problem.meta_data.n_variables \
                and getattr(problem, "suite_name", None) == self._name:
            self._ioh_problem.reset()  # the same problem: a new run of it
        else:
            self._attach(problem)
        self._algorithm, self._n_eval, self._pending = algorithm, 0, []
        ideal = np.atleast_1d(problem.ideal_point()).astype(float)
        ref = np.atleast_1d(problem.hv_reference_point()).astype(float)
        self._ideal, self._scale = ideal, ref - ideal
        self._hv = HV(ref_point=np.ones(problem.n_obj))
        self._hv_front = float(self._hv(self._scaled(problem.pareto_front())))
        self._archive = np.empty((0, problem.n_obj))
        self._gap = 1.0

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

    def _scaled(self, F: np.ndarray) -> np.ndarray:
        return (np.atleast_2d(F) - self._ideal) / self._scale

    def _gap_after(self, f: np.ndarray, cv: float) -> float:
        """The HV gap of the feasible archive once ``f`` is added (unchanged by an infeasible or dominated ``f``)."""
        if cv > 0:
            return self._gap
        z = self._scaled(f)[0]
        if self._archive.shape[0] and np.any(np.all(self._archive <= z, axis=1)):
            return self._gap
        keep = ~np.all(z <= self._archive, axis=1)
        self._archive = np.vstack([self._archive[keep], z])
        inside = self._archive[np.all(self._archive < 1.0, axis=1)]
        hv = float(self._hv(inside)) if inside.shape[0] else 0.0
        self._gap = 1.0 - hv / self._hv_front
        return self._gap

    def close(self) -> None:
        """End the last run and write the IOH metadata (idempotent)."""
        if self._ioh_problem is not None:
            self._ioh_problem.reset()
            self._ioh_problem.detach_logger()
            self._ioh_problem = None
        self.logger.close()

    def __enter__(self) -> IOHLogger:
        return self

    def __exit__(self, *exc) -> None:
        self.close()
