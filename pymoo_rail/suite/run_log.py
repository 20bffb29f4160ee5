"""What the suite's log writers share: a pymoo callback that sees every evaluation, and the HV archive.

:class:`EvaluationLogger` turns pymoo's per-iteration callback into one call per evaluated point
(:meth:`EvaluationLogger.log_point`), with a call when a run starts and when it ends; the IOH and
COCO writers (:mod:`pymoo_rail.suite.ioh_logger`, :mod:`pymoo_rail.suite.coco_logger`) are its
subclasses. :class:`HVArchive` is the feasible non-dominated archive of a run in the objectives
scaled so that the certified front's ideal point is 0 and the problem's fixed HV reference point
is 1, with the hypervolume of its points inside that box: both logs' indicators come from it.
"""

from __future__ import annotations

import numpy as np
from pymoo.core.callback import Callback
from pymoo.indicators.hv import HV


class HVArchive:
    """The feasible non-dominated points of one run, scaled, with their hypervolume.

    Parameters
    ----------
    problem
        A problem with ``ideal_point()``, ``hv_reference_point()`` and ``pareto_front()`` (every
        family instance and named suite problem has them).
    """

    def __init__(self, problem):
        ideal = np.atleast_1d(problem.ideal_point()).astype(float)
        ref = np.atleast_1d(problem.hv_reference_point()).astype(float)
        self.ideal, self.scale = ideal, ref - ideal
        self._hv = HV(ref_point=np.ones(problem.n_obj))
        self.hv_front = float(self._hv(self.scaled(problem.pareto_front())))
        self.points = np.empty((0, problem.n_obj))  # scaled, non-dominated
        self.raw: list[tuple[int, np.ndarray, np.ndarray]] = []  # (evaluation, F, X) of each kept point
        self.hv = 0.0
        self.distance = np.inf  # of the nearest point to the box below the reference point (scaled)

    def scaled(self, F: np.ndarray) -> np.ndarray:
        """Objectives mapped so that the front's ideal point is 0 and the reference point 1."""
        return (np.atleast_2d(F) - self.ideal) / self.scale

    def add(self, evaluation: int, x: np.ndarray, f: np.ndarray, cv: float) -> bool:
        """Add an evaluated point; True when it changed the archive (feasible and not dominated)."""
        if cv > 0:
            return False
        z = self.scaled(f)[0]
        if self.points.shape[0] and np.any(np.all(self.points <= z, axis=1)):
            return False
        keep = ~np.all(z <= self.points, axis=1)
        self.points = np.vstack([self.points[keep], z])
        self.raw = [entry for entry, kept in zip(self.raw, keep) if kept] + [(evaluation, np.array(f), np.array(x))]
        inside = self.points[np.all(self.points < 1.0, axis=1)]
        self.hv = float(self._hv(inside)) if inside.shape[0] else 0.0
        self.distance = min(self.distance, float(np.linalg.norm(np.maximum(z - 1.0, 0.0))))
        return True

    @property
    def empty(self) -> bool:
        """No feasible point yet."""
        return self.points.shape[0] == 0


class EvaluationLogger(Callback):
    """A pymoo callback calling :meth:`log_point` for every evaluated point, in order.

    A run starts when the callback first sees an algorithm object and ends when it sees another
    one or :meth:`close` is called. Algorithms must report the individuals they evaluated as
    ``algorithm.off`` (pymoo's infill/advance algorithms, MOABC and GoldenRatioNSGA2 do).
    """

    label = "EvaluationLogger"

    def __init__(self):
        super().__init__()
        self._algorithm = None
        self._n_eval = 0

    def notify(self, algorithm) -> None:
        """Log the individuals evaluated in this iteration (``algorithm.off``)."""
        if algorithm is not self._algorithm:
            if self._algorithm is not None:
                self.end_run()
                self._algorithm = None
            self.start_run(algorithm.problem)  # may refuse the problem: then no run is open
            self._algorithm, self._n_eval = algorithm, 0
        batch = algorithm.off
        n_new = algorithm.evaluator.n_eval - self._n_eval
        if n_new == 0:
            return
        if batch is None or len(batch) != n_new:
            raise RuntimeError(f"{self.label}: {type(algorithm).__name__} evaluated {n_new} points but reported "
                               f"{0 if batch is None else len(batch)} as algorithm.off; it cannot be logged")
        F, CV, X = batch.get("F"), batch.get("CV")[:, 0], batch.get("X")
        for x, f, cv in zip(X, F, CV):
            self._n_eval += 1
            self.log_point(self._n_eval, np.asarray(x, dtype=float), np.asarray(f, dtype=float), float(cv))

    def start_run(self, problem) -> None:
        """A run on ``problem`` starts."""

    def log_point(self, evaluation: int, x: np.ndarray, f: np.ndarray, cv: float) -> None:
        """The ``evaluation``-th point of the run (1-based): decisions, objectives, constraint violation."""
        raise NotImplementedError

    def end_run(self) -> None:
        """The current run has ended (another one starts, or :meth:`close`)."""

    def close(self) -> None:
        """End the last run (idempotent)."""
        if self._algorithm is not None:
            self.end_run()
            self._algorithm = None

    def __enter__(self):
        return self

    def __exit__(self, *exc) -> None:
        self.close()
