"""Where the CPU time of one study run goes: the simulator kernel, the problem, pymoo, indicators, the record.

:func:`cpu_breakdown` runs :func:`pymoo_rail.experiments.runner.execute_run` once with timers
around its parts (each the CPU time of this process inside the part, nested parts subtracted):

- ``setup``: building the problem and the algorithm and reading the certified front;
- ``kernel``: the simulator's batch runs (:meth:`pymoo_rail.sim.Simulator.run_batch`);
- ``problem``: the rest of the problems' evaluation (decoding, objectives, constraints);
- ``history``: the per-generation indicators of the run's history (IGD and HV of the front so far);
- ``pymoo``: the algorithm itself (mating, survival, pymoo's bookkeeping), what remains of ``minimize``;
- ``final``: the record's final front and its indicators, after ``minimize``;
- ``write``: storing the record (:meth:`pymoo_rail.experiments.store.ResultStore.write`);
- ``report``: the baseline table's indicators of the record
  (:func:`pymoo_rail.experiments.baseline.baseline_indicators`), computed when the report is written.

The timers wrap the parts by patching them for the duration of the call (restored after); the
results are those of an unpatched run. :func:`cpu_profile` splits a list of runs, :func:`cpu_shares`
sums its rows into each algorithm's shares (``python benchmarks/suite_baseline.py --profile``).
"""

from __future__ import annotations

import tempfile
import time
from contextlib import ExitStack, contextmanager
from dataclasses import replace
from typing import Any, Callable, Iterable, Iterator

import pandas as pd

from pymoo_rail.experiments.spec import Budget

PARTS = ("setup", "kernel", "problem", "history", "pymoo", "final", "write", "report")
"""The parts of a run's CPU time, in the order a run meets them."""


class _Clock:
    """CPU seconds spent inside wrapped callables, by part, each exclusive of the wrapped calls it makes."""

    def __init__(self):
        self.spent: dict[str, float] = {}
        self._children: list[float] = []  # CPU of wrapped calls made by each open call

    def wrap(self, part: str, fn: Callable) -> Callable:
        def timed(*args, **kwargs):
            self._children.append(0.0)
            start = time.process_time()
            try:
                return fn(*args, **kwargs)
            finally:
                elapsed = time.process_time() - start
                inner = self._children.pop()
                self.spent[part] = self.spent.get(part, 0.0) + elapsed - inner
                if self._children:
                    self._children[-1] += elapsed
        return timed


@contextmanager
def _patched(target: Any, name: str, replacement: Callable):
    original = getattr(target, name)
    setattr(target, name, replacement)
    try:
        yield
    finally:
        setattr(target, name, original)


def cpu_breakdown(run) -> tuple[dict[str, float], dict]:
    """CPU seconds of one run of a baseline study, by part (:data:`PARTS`), ``total`` and ``n_eval``; and its record.

    ``run`` is a :class:`~pymoo_rail.experiments.spec.RunSpec` of a ``suite_family`` problem.
    Parts are exclusive: ``total`` is their sum.
    """
    import pymoo.core.problem
    import pymoo.optimize

    from pymoo_rail.experiments import baseline, runner
    from pymoo_rail.experiments.store import ResultStore
    from pymoo_rail.sim import Simulator

    clock = _Clock()
    with ExitStack() as stack:
        for name in ("build_problem", "build_algorithm", "true_front_and_reason"):
            stack.enter_context(_patched(runner, name, clock.wrap("setup", getattr(runner, name))))
        stack.enter_context(_patched(runner, "convergence_point", clock.wrap("history", runner.convergence_point)))
        stack.enter_context(_patched(pymoo.optimize, "minimize", clock.wrap("pymoo", pymoo.optimize.minimize)))
        stack.enter_context(_patched(pymoo.core.problem.Problem, "evaluate",
                                     clock.wrap("problem", pymoo.core.problem.Problem.evaluate)))
        stack.enter_context(_patched(Simulator, "run_batch", clock.wrap("kernel", Simulator.run_batch)))
        record = clock.wrap("final", runner.execute_run)(run)  # what is not in a part: the final front
    with tempfile.TemporaryDirectory() as folder:
        clock.wrap("write", ResultStore(folder).write)(record)
    problem = baseline.instance_of(record)
    clock.wrap("report", baseline.baseline_indicators)(record, problem)
    parts = {part: clock.spent.get(part, 0.0) for part in PARTS}
    parts["total"] = sum(parts.values())
    parts["n_eval"] = float(record["n_eval"])
    return parts, record


def cpu_profile(runs: Iterable, warm_n_eval: int = 200) -> Iterator[dict]:
    """Split each run's CPU (:func:`cpu_breakdown`), one row per run, yielded as each run ends.

    A short first run of each algorithm (``warm_n_eval`` evaluations, not yielded) loads the compiled
    kernels and the fronts and pays one-time compilations (pymoo's AGE-MOEA compiles its Numba
    functions in every process), so the rows hold what every later run of the process pays.

    Yields
    ------
    dict
        ``instance`` (the problem's display name: ``problem`` is a part) and ``algorithm``, the CPU
        seconds of each part (:data:`PARTS`), ``total``, ``n_eval`` and ``ms_per_eval`` (milliseconds of CPU per evaluation).
    """
    runs = list(runs)
    warmed: set[str] = set()
    for run in runs:
        if run.algorithm.display not in warmed:
            cpu_breakdown(replace(run, budget=Budget("n_eval", warm_n_eval)))
            warmed.add(run.algorithm.display)
    for run in runs:
        parts, _ = cpu_breakdown(run)
        yield {"instance": run.problem.display, "algorithm": run.algorithm.display, **parts,
               "ms_per_eval": 1000 * parts["total"] / parts["n_eval"]}


def cpu_shares(rows: Iterable[dict]) -> pd.DataFrame:
    """Each algorithm's share (%) of each part in the CPU of its rows of :func:`cpu_profile`, and its ``ms_per_eval``.

    One row per algorithm, in the order they first appear; columns :data:`PARTS` and ``ms_per_eval``.
    """
    sums = pd.DataFrame(list(rows)).groupby("algorithm", sort=False)[[*PARTS, "total", "n_eval"]].sum()
    shares = 100 * sums[list(PARTS)].div(sums["total"], axis=0)
    shares["ms_per_eval"] = 1000 * sums["total"] / sums["n_eval"]
    return shares
