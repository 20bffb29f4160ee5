"""COCO logs of pymoo runs on suite family instances, in the formats of COCO's ``bbob-biobj`` and ``bbob`` loggers.

:class:`COCOLogger` is a pymoo callback (``minimize(problem, algorithm, callback=COCOLogger(...))``)
that writes what COCO's observers write, so that ``cocopp`` (COCO's post-processing) reads the
runs: the bi-objective observer's files for a two-objective instance (``-bi``), the
single-objective one's for a one-objective instance (``-single``, ``-trip``). The maintained
``coco-experiment`` package (``cocoex``, 2.8) observes only its own suites' problems and has no
hook for an external function, so the files are written here, in the documented formats of its
loggers. Two objectives, the ``bbob-biobj`` logger (indicator ``hyp``):

- ``<family>_hyp.info``: one header line (suite, algorithm, indicator, folder), the algorithm's
  description, then one line per (function, dimension) with its data file and, per run,
  ``instance:evaluations|final indicator value``;
- ``<family>/<suite>_fNN_dD_hyp.dat``: per run, a line whenever the indicator reaches a new target
  (20 per decade), and the last evaluation;
- ``<family>/<suite>_fNN_dD_hyp.tdat``: per run, the indicator at evaluations 1, 2, 3, ...,
  20 per decade, and at ``{1, 2, 5} x 10^k x dimension``, and the last evaluation;
- ``archive/<suite>_fNN_iII_dD_nondom_final.adat``: per run, the final feasible non-dominated
  points: evaluation, both objectives (raw units) and the decisions.

The indicator is COCO's: with the objectives scaled so that the certified front's ideal point is
0 and the problem's fixed HV reference point (``problem.hv_reference_point()``) 1, it is
``HV(certified front) - HV(feasible archive)`` once a point lies in the box below the reference
point, and ``HV(certified front)`` plus the scaled distance of the nearest point to that box
before. Infeasible evaluations count as evaluations and never enter the archive; before the first
feasible point the indicator is infinite and written as :data:`INFINITE_VALUE`, the value COCO's
own loggers write for an infinite one (cocopp needs every run to start at evaluation 1). The function is the problem (:func:`function_id`), the dimension ``n_var``, the instance
a family instance's seed.

One objective, the ``bbob`` logger (suite :data:`COCO_SINGLE_SUITE`, data format ``bbob-new2``):

- ``bbobexp_fN.info``: per dimension, a header line (suite, function, dimension, precision,
  algorithm), the algorithm's description, and the data file with ``instance:evaluations|final
  value`` per run;
- ``data_fN/bbobexp_fN_DIMD.dat`` (a line whenever the value reaches a new target, 20 per decade,
  and the last evaluation) and ``.tdat`` (at the same evaluations as above), each line: evaluation,
  constraint evaluations, the value, the evaluated point's objective, the best feasible objective,
  and the evaluated decisions.

The value is the best feasible objective so far minus the certified optimum (``Fopt``, in each
run's header: ``pareto_front()``, kWh), as the IOH logs' gap: infeasible evaluations count but
never improve it, and before the first feasible point it is written as :data:`INFINITE_VALUE`. It
can lie below 0 by at most the optimum's certificate. pymoo evaluates the constraints with the
objective, so the constraint evaluations are written as 0 (cocopp's ``bbob-new2`` format adds
that column to the evaluations).

cocopp knows only COCO's own suites; :func:`register_cocopp_suite` adds these two
(:data:`COCO_SUITE`, :data:`COCO_SINGLE_SUITE`) to a running ``cocopp`` before it reads the data,
as cocopp's own message asks.
"""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np

from pymoo_rail.suite.families import FAMILIES, list_families
from pymoo_rail.suite.run_log import EvaluationLogger, HVArchive

COCO_SUITE = "pymoo-rail-biobj"
"""The suite name written in every ``.info`` header (and registered with cocopp)."""
TARGETS_PER_DECADE = 20
"""Targets per decade of the indicator that trigger a ``.dat`` line (COCO's bi-objective default)."""
EVALUATIONS_PER_DECADE = 20
"""Evaluation numbers per decade that trigger a ``.tdat`` line (COCO's default)."""
BASE_EVALUATIONS = (1, 2, 5)
"""Multiples of ``10^k x dimension`` that trigger a ``.tdat`` line (COCO's default)."""
COCO_FORMAT_VERSION = "2.8.2"
"""The ``coco_version`` written in the headers: the version of COCO whose ``bbob-biobj`` files these follow."""
INFINITE_VALUE = 3e21
"""What is written for an infinite indicator (no feasible point yet), as COCO's loggers write infinity."""
COCO_SINGLE_SUITE = "pymoo-rail-single"
"""The suite name written in the single-objective (``bbob``-format) ``.info`` headers (and registered with cocopp)."""
SINGLE_PREFIX = "bbobexp"
"""The file name prefix of the single-objective data, as COCO's ``bbob`` logger names its files."""
SINGLE_PRECISION = 1e-8
"""The ``Precision`` of the single-objective headers: COCO's final target."""
SINGLE_COLUMNS = ("% f evaluations | g evaluations | best noise-free fitness - Fopt ({fopt:.12e}) + sum g_i+ | "
                  "measured fitness | best measured fitness or single-digit g-values | x1 | x2...")
"""The header line of each run in a single-objective ``.dat`` or ``.tdat`` file (COCO's ``bbob`` logger's)."""


def function_id(problem) -> int:
    """The COCO function number of a family instance: its family's position in
    :data:`~pymoo_rail.suite.families.FAMILIES` plus 1 (1-10).

    Raises ``ValueError`` naming the problem for any other problem: the named suite problems have
    no fixed HV reference point, which COCO's indicator needs.
    """
    family = getattr(problem, "family", None)
    if family in list_families():
        return list_families().index(family) + 1
    name = getattr(problem, "suite_name", None) or type(problem).__name__
    raise ValueError(f"COCOLogger: problem {name!r} is not a family instance (pymoo_rail.suite.get_problem("
                     "'generated-<kind>-bi', n_var=..., seed=...)); COCO needs its function number and the "
                     "family's fixed HV reference point")


def function_name(problem) -> str:
    """The problem's name in the logs: its family."""
    return str(problem.family)


def evaluation_triggers(dimension: int, budget: int) -> set[int]:
    """Evaluation numbers at which COCO's observer writes a ``.tdat`` line, up to ``budget``."""
    triggers = {1}
    for k in range(int(EVALUATIONS_PER_DECADE * math.log10(max(budget, 1))) + 2):
        triggers.add(int(math.floor(10 ** (k / EVALUATIONS_PER_DECADE) + 1e-9)))
    for k in range(int(math.log10(max(budget, 1))) + 1):
        triggers.update(b * 10 ** k * dimension for b in BASE_EVALUATIONS)
    return {t for t in triggers if t <= budget}


def target_of(value: float) -> float:
    """The target hit by an indicator value: the smallest of the target grid at or above it."""
    if value <= 0:
        return value  # inside the certificate: every improvement is a new target
    return 10 ** (math.ceil(TARGETS_PER_DECADE * math.log10(value) - 1e-9) / TARGETS_PER_DECADE)


class COCOLogger(EvaluationLogger):
    """A pymoo callback writing COCO ``bbob-biobj``- or ``bbob``-format data that ``cocopp`` reads.

    Parameters
    ----------
    folder : str or Path
        Root folder; the data go to ``folder/<algorithm_name>`` (``_001``, ``_002``, ... appended
        when that exists, as COCO's observer does).
    algorithm_name : str
        Name in the ``.info`` headers (no spaces: COCO's rule).
    algorithm_info : str
        Free text written below each header (settings, budget).

    Notes
    -----
    Family instances only (:func:`function_id`): a two-objective one (``-bi``: a certified front
    and a fixed ``hv_reference_point()``) is logged in the ``bbob-biobj`` format, a one-objective
    one (``-single``, ``-trip``: a certified optimum) in the ``bbob`` format. Call :meth:`close`
    (or use the logger as a context manager) after the last run: a run is written when it ends.
    Read the data with ``cocopp`` after :func:`register_cocopp_suite`.
    """

    label = "COCOLogger"

    def __init__(self, folder: str | Path, algorithm_name: str, algorithm_info: str = ""):
        super().__init__()
        name = str(algorithm_name)
        if not name or any(c.isspace() for c in name):
            raise ValueError(f"COCOLogger: algorithm_name = {algorithm_name!r}: must be non-empty, without spaces")
        self.algorithm_name, self.algorithm_info = name, str(algorithm_info).replace("\n", " ")
        root = Path(folder) / name
        number = 0
        while root.exists() and any(root.iterdir()):
            number += 1
            root = Path(folder) / f"{name}_{number:03d}"
        self.folder = root
        self._entries: dict[str, dict[tuple[int, int], list[str]]] = {}  # info file -> (function, dim) -> runs
        self._run_index: dict[tuple[int, int], int] = {}

    # ------------------------------------------------------------------ runs
    def start_run(self, problem) -> None:
        """Check the problem and start the run's archive (or best point) and logs."""
        if problem.n_obj not in (1, 2):
            raise ValueError(f"COCOLogger: problem {getattr(problem, 'suite_name', type(problem).__name__)} has "
                             f"n_obj = {problem.n_obj}; COCO's formats take 2 objectives (bbob-biobj) or 1 (bbob)")
        self._problem, self._fid, self._fname = problem, function_id(problem), function_name(problem)
        self.single = problem.n_obj == 1
        self.archive = None if self.single else HVArchive(problem)
        self.f_opt = float(np.ravel(problem.pareto_front())[0]) if self.single else math.nan
        self._best_f = math.inf  # the best feasible objective (one objective)
        self._dat: list[tuple] = []  # (evaluation, value, target, objectives, decisions)
        self._tdat: list[tuple] = []  # (evaluation, value, objectives, decisions)
        self._value = math.inf
        self._last_target = math.inf
        self._evaluations = 0
        self._last_point: tuple[np.ndarray, np.ndarray] | None = None

    def indicator(self) -> float:
        """COCO's ``hyp`` indicator of the archive now, or for one objective the best feasible value
        minus the optimum (``inf`` before the first feasible point)."""
        if self.single:
            return self._best_f - self.f_opt
        archive = self.archive
        if archive.empty:
            return math.inf
        if archive.hv > 0:
            return archive.hv_front - archive.hv
        return archive.hv_front + archive.distance

    def _add(self, evaluation: int, x: np.ndarray, f: np.ndarray, cv: float) -> bool:
        """Keep the point if it improves the run (feasible, and better or non-dominated); True if it did."""
        if not self.single:
            return self.archive.add(evaluation, x, f, cv)
        if cv > 0 or not f[0] < self._best_f:
            return False
        self._best_f = float(f[0])
        return True

    def log_point(self, evaluation: int, x: np.ndarray, f: np.ndarray, cv: float) -> None:
        """Update the archive; remember the ``.dat`` and ``.tdat`` lines this evaluation triggers."""
        self._evaluations, self._last_point = evaluation, (f, x)
        if self._add(evaluation, x, f, cv) or evaluation == 1:
            self._value = min(self.indicator(), INFINITE_VALUE)
            target = target_of(self._value)
            if target < self._last_target:
                self._dat.append((evaluation, self._value, target, f, x))
                self._last_target = target
        if self._is_trigger(evaluation):
            self._tdat.append((evaluation, self._value, f, x))

    def _is_trigger(self, evaluation: int) -> bool:
        if evaluation > getattr(self, "_trigger_budget", 0):  # extend the trigger set as the run grows
            self._trigger_budget = max(10 * evaluation, 1000)
            self._triggers = evaluation_triggers(self._problem.n_var, self._trigger_budget)
        return evaluation in self._triggers

    def end_run(self) -> None:
        """Write the run: ``.dat``, ``.tdat`` (and for two objectives ``.adat``) lines and its ``.info`` entry."""
        n, value = self._evaluations, self._value
        f, x = self._last_point
        if self._dat[-1][0] != n:
            self._dat.append((n, value, target_of(value), f, x))
        if self._tdat[-1][0] != n:
            self._tdat.append((n, value, f, x))
        key = (self._fid, int(self._problem.n_var))
        index = self._run_index.get(key, 0)
        self._run_index[key] = index + 1
        if self.single:
            self._write_single_run()
        else:
            self._write_biobj_run(index)

    def _write_biobj_run(self, index: int) -> None:
        problem, n, value = self._problem, self._evaluations, self._value
        key, dim, seed = (self._fid, problem.n_var), int(problem.n_var), int(getattr(problem, "seed", 1))
        stem = f"{COCO_SUITE}_f{self._fid:02d}_d{dim:02d}"
        (self.folder / self._fname).mkdir(parents=True, exist_ok=True)
        header = (f"%\n% index = {index}, name = {getattr(problem, 'suite_name', self._fname)}\n"
                  f"% instance = {seed}, reference value = {self.archive.hv_front:.15e}\n")
        with open(self.folder / self._fname / f"{stem}_hyp.dat", "a") as out:
            out.write(header + "% function evaluation | indicator value | target hit\n")
            out.writelines(f"{e}\t{v:.15e}\t{t:.15e}\n" for e, v, t, _, _ in self._dat)
        with open(self.folder / self._fname / f"{stem}_hyp.tdat", "a") as out:
            out.write(header + "% function evaluation | indicator value\n")
            out.writelines(f"{e}\t{v:.15e}\n" for e, v, _, _ in self._tdat)
        self._write_archive(seed, dim, n)
        info = f"{self._fname}_hyp.info"
        runs = self._entries.setdefault(info, {}).setdefault(key, [])
        runs.append(f"{seed}:{n}|{value:.1e}")
        self._write_info(info)

    def _single_line(self, evaluation: int, value: float, f: np.ndarray, x: np.ndarray) -> str:
        best = value + self.f_opt if value < INFINITE_VALUE else INFINITE_VALUE  # the best feasible objective then
        return " ".join([f"{evaluation} 0 {value:+.9e} {float(f[0]):+.9e} {best:+.9e}",
                         *(f"{v:+.4e}" for v in x)]) + "\n"

    def _write_single_run(self) -> None:
        problem, n, value = self._problem, self._evaluations, self._value
        key, dim, seed = (self._fid, problem.n_var), int(problem.n_var), int(getattr(problem, "seed", 1))
        folder = self.folder / f"data_f{self._fid}"
        folder.mkdir(parents=True, exist_ok=True)
        header = SINGLE_COLUMNS.format(fopt=self.f_opt) + "\n"
        stem = f"{SINGLE_PREFIX}_f{self._fid}_DIM{dim}"
        with open(folder / f"{stem}.dat", "a") as out:
            out.write(header)
            out.writelines(self._single_line(e, v, f, x) for e, v, _, f, x in self._dat)
        with open(folder / f"{stem}.tdat", "a") as out:
            out.write(header)
            out.writelines(self._single_line(e, v, f, x) for e, v, f, x in self._tdat)
        info = f"{SINGLE_PREFIX}_f{self._fid}.info"
        runs = self._entries.setdefault(info, {}).setdefault(key, [])
        runs.append(f"{seed}:{n}|{value:.1e}")
        lines = []
        for (fid, dim_), entries in self._entries[info].items():
            lines += [f"suite = '{COCO_SINGLE_SUITE}', funcId = {fid}, DIM = {dim_}, Precision = {SINGLE_PRECISION:.3e}, "
                      f"algId = '{self.algorithm_name}', coco_version = '{COCO_FORMAT_VERSION}', logger = 'bbob', "
                      "data_format = 'bbob-new2', settings = ''",
                      f"% {self.algorithm_info}",
                      f"data_f{fid}/{SINGLE_PREFIX}_f{fid}_DIM{dim_}.dat, " + ", ".join(entries)]
        (self.folder / info).write_text("\n".join(lines) + "\n")

    def _write_archive(self, seed: int, dim: int, n: int) -> None:
        problem = self._problem
        (self.folder / "archive").mkdir(parents=True, exist_ok=True)
        path = self.folder / "archive" / f"{COCO_SUITE}_f{self._fid:02d}_i{seed:02d}_d{dim:02d}_nondom_final.adat"
        with open(path, "a") as out:
            out.write(f"% instance = {seed}, name = {getattr(problem, 'suite_name', self._fname)}\n"
                      f"% function evaluation | 2 objectives | {dim} variables\n")
            for evaluation, f, x in sorted(self.archive.raw, key=lambda entry: entry[0]):
                out.write("\t".join([str(evaluation), *(f"{v:.15e}" for v in f), *(f"{v:.8e}" for v in x)]) + "\n")
            out.write(f"% evaluations = {n}\n")

    def _write_info(self, info: str) -> None:
        fname = info[: -len("_hyp.info")]
        lines = [f"suite = '{COCO_SUITE}', algorithm = '{self.algorithm_name}', indicator = 'hyp', "
                 f"folder = '{fname}', coco_version = '{COCO_FORMAT_VERSION}', settings = ''",
                 f"% {self.algorithm_info}"]
        for (fid, dim), runs in self._entries[info].items():
            lines.append(f"function = {fid:2d}, dim = {dim:2d}, {COCO_SUITE}_f{fid:02d}_d{dim:02d}_hyp.dat, "
                         + ", ".join(runs))
        (self.folder / info).write_text("\n".join(lines) + "\n")


def register_cocopp_suite() -> str:
    """Make a running ``cocopp`` read this package's logs; returns the bi-objective suite's name (:data:`COCO_SUITE`).

    cocopp maps a suite name to its settings (``cocopp.testbedsettings``) and refuses unknown
    ones; this adds :data:`COCO_SUITE` with the settings of COCO's bi-objective testbed and
    :data:`COCO_SINGLE_SUITE` with those of its single-objective one, each with the families'
    names, the dimension ladder 10-1000, every instance and no reference algorithm.
    Call it after ``import cocopp`` and before ``cocopp.main`` or ``cocopp.pproc.DataSetList``.
    """
    from cocopp import testbedsettings  # the optional post-processing: imported only when asked for

    _register(testbedsettings, testbedsettings.GECCOBiObjBBOBTestbed, COCO_SUITE, "RailBiObjTestbed")
    _register(testbedsettings, testbedsettings.GECCOBBOBTestbed, COCO_SINGLE_SUITE, "RailSingleObjTestbed")
    return COCO_SUITE


def _register(testbedsettings, base, suite: str, class_name: str) -> None:
    """Add ``suite`` to cocopp as a subclass ``class_name`` of its testbed ``base``."""
    names = {i + 1: entry.name for i, entry in enumerate(FAMILIES)}
    settings = dict(base.settings, name=suite, short_names=names,
                    dimensions_to_display=(10, 30, 100, 300, 1000), goto_dimension=100,
                    rldDimsOfInterest=(10, 100), tabDimsOfInterest=(10, 100),
                    functions_with_legend=(1, len(FAMILIES)), first_function_number=1,
                    last_function_number=len(FAMILIES),
                    reference_values_hash_dimensions=[], instancesOfInterest=None,
                    reference_algorithm_filename="", reference_algorithm_displayname="",
                    plots_on_main_html_page=[f"pprldmany_{d:02d}D_noiselessall.svg" for d in (10, 30, 100, 300, 1000)])

    class RailTestbed(base):
        """cocopp's settings for the rail suite's logs."""

        def __init__(self, target_values):
            super().__init__(target_values)
            for key, value in settings.items():
                setattr(self, key, value)
                if "target_values" in key or "targetsOfInterest" in key:
                    self.instantiate_attributes(target_values, [key])

        def filter(self, dsl):
            """Every data set (the base class keeps its own suites only)."""
            return dsl

    RailTestbed.__name__ = RailTestbed.__qualname__ = class_name
    RailTestbed.settings = settings
    setattr(testbedsettings, class_name, RailTestbed)
    testbedsettings.suite_to_testbed[suite] = class_name
