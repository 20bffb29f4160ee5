"""What every benchmark script shares: the standard options, a polite process priority, the
per-run table a report is written from, markdown tables, number formats and writing the report.

The scripts in ``benchmarks/`` are thin calls of :func:`pymoo_rail.experiments.run_study`; they take
the same three options (where the records go, where the report goes, and whether to only rebuild
the report from stored records) and run at a lower priority so that a long study leaves an
interactive machine usable. Their run records stay out of git; the per-run CSV a report exports
is committed, so :func:`report_runs` rebuilds a report from that CSV when the records are absent.
"""

from __future__ import annotations

import argparse
import math
import numbers
import os
import string
import subprocess
import sys
from dataclasses import dataclass
from pathlib import Path
from typing import Callable, Iterable, Mapping, Sequence

import numpy as np

from pymoo_rail.atomic import atomic_write_text


def add_study_options(parser: argparse.ArgumentParser, work_dir: Path, reports_dir: Path, *,
                      runs: int | None = None, workers: bool = False) -> None:
    """Add ``--work`` (the study's record folder), ``--out`` (the report folder) and ``--report-only``.

    Parameters
    ----------
    parser : argparse.ArgumentParser
        The script's parser.
    work_dir, reports_dir : pathlib.Path
        The defaults of ``--work`` and ``--out``.
    runs : int, optional
        Also add ``--runs`` (seeds per cell) with this default.
    workers : bool
        Also add ``--workers`` (process pool size, default 2: the shared machine's cores).
    """
    if runs is not None:
        parser.add_argument("--runs", type=int, default=runs, help="runs (seeds) per problem and algorithm")
    if workers:
        parser.add_argument("--workers", type=int, default=2, help="process pool size (at most 2)")
    parser.add_argument("--work", type=Path, default=work_dir, help="study folder (one record per run)")
    parser.add_argument("--out", type=Path, default=reports_dir, help="report folder")
    parser.add_argument("--report-only", action="store_true", help="rebuild the report from the stored records")


def lower_priority(niceness: int = 10) -> None:
    """Raise this process's nice value to at least ``niceness`` (never lower it).

    Pool workers started afterwards inherit it.
    """
    current = os.nice(0)
    if current < niceness:
        os.nice(niceness - current)


def count_range(counts) -> str:
    """``"30"`` when every cell of a study has the same number of runs, else ``"28 to 30"``.

    Parameters
    ----------
    counts : pandas.Series or sequence of int
        Runs per cell (e.g. ``df.groupby(["problem", "algorithm"]).size()``).

    Returns
    -------
    str
    """
    low, high = int(min(counts)), int(max(counts))
    return f"{low}" if low == high else f"{low} to {high}"


def report_runs(results, run_row: Callable[[Mapping], dict], columns: Sequence[str],
                committed_csv: Path) -> tuple:
    """The per-run table of a study report and the fronts behind it: from the records, else the CSV.

    With stored records (``results`` of :func:`pymoo_rail.experiments.load_results` not empty),
    each run becomes one row by ``run_row`` and the fronts are returned for the figures. Without
    them, the table is read from ``committed_csv``, the per-run CSV the report exported when it
    was last built from records (every digit of a float survives the round trip), and there are
    no fronts: the report's numbers are rebuilt, the figures drawn from fronts are not.

    Parameters
    ----------
    results : pandas.DataFrame
        The stored runs, with fronts (``load_results(..., fronts=True)``); may be empty.
    run_row : callable
        One run (a row of ``results``) -> a dict with the ``columns``.
    columns : sequence of str
        The table's columns, in the CSV's order.
    committed_csv : pathlib.Path
        The per-run CSV next to the report.

    Returns
    -------
    (pandas.DataFrame, dict, bool)
        The table, ``{(problem, algorithm, seed): F}`` (empty without records), and whether the
        table came from the records (then the caller exports it to ``committed_csv``).

    Raises
    ------
    FileNotFoundError
        Neither records nor ``committed_csv``.
    ValueError
        The CSV lacks one of ``columns`` (written by another version of the script).
    """
    import pandas as pd

    if len(results):
        table = pd.DataFrame([run_row(row) for _, row in results.iterrows()], columns=list(columns))
        fronts = {(r.problem, r.algorithm, int(r.seed)): r.F for r in results.itertuples()}
        return table, fronts, True
    committed_csv = Path(committed_csv)
    if not committed_csv.is_file():
        raise FileNotFoundError(f"no run records to report and no per-run table {committed_csv}: run the study first")
    # every digit must come back: pandas >= 3 parses floats round-trip by default (and deprecates the option)
    exact = {} if int(pd.__version__.split(".")[0]) >= 3 else {"float_precision": "round_trip"}
    table = pd.read_csv(committed_csv, **exact)
    missing = [c for c in columns if c not in table.columns]
    if missing:
        raise ValueError(f"{committed_csv} lacks the column(s) {', '.join(missing)}: rerun the study to rebuild it")
    return table[list(columns)], {}, False


def require_runs(results, study, work_dir: str | Path) -> None:
    """Refuse a report whose study has runs without a stored record (instead of writing an empty one).

    Parameters
    ----------
    results : pandas.DataFrame
        The stored runs (:func:`pymoo_rail.experiments.load_results`), with their ``run_id``.
    study : pymoo_rail.experiments.Study
        The study the report is written from.
    work_dir : str or pathlib.Path
        Where the records were read from (named in the message).

    Raises
    ------
    FileNotFoundError
        Some run of ``study`` has no record; the message names the first ones (problem / algorithm
        / seed) and how many are missing.
    """
    stored = set(results["run_id"]) if "run_id" in getattr(results, "columns", ()) else set()
    missing = [run for run in study.runs() if run.run_id not in stored]
    if missing:
        named = ", ".join(f"{r.problem.display} / {r.algorithm.display} / seed {r.seed}" for r in missing[:3])
        raise FileNotFoundError(f"{work_dir}: no stored record of {len(missing)} of the {len(study.runs())} runs of "
                                f"study {study.name!r} (e.g. {named}): run the study first (without --report-only)")


# ------------------------------------------------------------------------------------ numbers
def _missing(value) -> bool:
    """None, or a number that is not finite (NaN, +-inf)."""
    if value is None:
        return True
    return isinstance(value, numbers.Real) and not isinstance(value, (bool, np.bool_)) and not math.isfinite(value)


def _not_a_float(value, missing: str) -> str | None:
    """The cell of a boolean (yes/no), a missing number (``missing``) or an integer; None for anything else."""
    if isinstance(value, (bool, np.bool_)):
        return "yes" if value else "no"
    if _missing(value):
        return missing
    if isinstance(value, numbers.Integral):
        return str(int(value))
    return None


def fixed(value, digits: int = 2, missing: str = "-") -> str:
    """A number with ``digits`` decimals; ``missing`` for None/NaN/inf, yes/no for booleans.

    Integers are written as integers, anything else (a label) as ``str(value)``.

    >>> fixed(3.14159), fixed(float("nan")), fixed(True), fixed(7), fixed(2.5, 0, missing="n/a")
    ('3.14', '-', 'yes', '7', '2')
    """
    plain = _not_a_float(value, missing)
    if plain is not None:
        return plain
    if isinstance(value, numbers.Real):
        return f"{float(value):.{digits}f}"
    return str(value)


def significant(value, digits: int = 4, missing: str = "") -> str:
    """A number with ``digits`` significant digits, in scientific notation below 1e-3 and from 1e5.

    ``missing`` for None/NaN/inf, yes/no for booleans, integers as integers.

    >>> significant(1234.5678), significant(0.00012345), significant(0), significant(None, missing="nan")
    ('1235', '1.234e-04', '0', 'nan')
    """
    plain = _not_a_float(value, missing)
    if plain is not None:
        return plain
    value = float(value)
    if value != 0 and (abs(value) < 1e-3 or abs(value) >= 1e5):
        return f"{value:.{digits - 1}e}"
    return f"{value:.{digits}g}"


def mean_std(values, digits: int = 4) -> str:
    """``"mean +- sample std"`` of the finite values (:func:`significant`), one value alone, "" for none."""
    v = np.asarray([x for x in values if not _missing(x)], dtype=float)
    if len(v) == 0:
        return ""
    if len(v) == 1:
        return significant(v[0], digits)
    return f"{significant(v.mean(), digits)} +- {significant(v.std(ddof=1), 2)}"


# ------------------------------------------------------------------------------------ markdown
def markdown_rows(header: Sequence, rows: Iterable[Sequence], right_from: int | None = None) -> str:
    """A GitHub markdown table of already formatted cells (``str`` of each); the columns from index
    ``right_from`` on (none by default) right-aligned, as numbers read best."""
    right = len(header) if right_from is None else right_from
    lines = ["| " + " | ".join(map(str, header)) + " |",
             "|" + "".join("---:|" if i >= right else "---|" for i in range(len(header)))]
    lines += ["| " + " | ".join(str(c) for c in row) + " |" for row in rows]
    return "\n".join(lines)


def markdown(table, digits: int = 4, missing: str | None = None) -> str:
    """A DataFrame as a GitHub markdown table: floats with ``digits`` decimals, the rest by ``str``.

    Parameters
    ----------
    table : pandas.DataFrame
        The table; its columns are the header.
    digits : int
        Decimals of float cells.
    missing : str, optional
        Cell of a NaN float (default: ``"nan"``, as Python formats it).
    """
    def cell(v) -> str:
        if isinstance(v, (float, np.floating)):
            return missing if (missing is not None and np.isnan(v)) else f"{v:.{digits}f}"
        return str(v)

    return markdown_rows(list(table.columns), ([cell(v) for v in row]
                                               for row in table.astype(object).itertuples(index=False)))


# ------------------------------------------------------------------------------------ templates
def fill_template(template: str | Path, values: Mapping[str, object]) -> str:
    """A report's text: its markdown template with every ``${name}`` replaced by ``str(values[name])``.

    A report's prose is written by hand in markdown (``benchmarks/templates/<report>.md``); the
    script computes only the numbers and tables it names. ``$$`` writes a literal ``$``.

    Parameters
    ----------
    template : str or pathlib.Path
        The template file.
    values : mapping
        The value of each placeholder.

    Returns
    -------
    str

    Raises
    ------
    KeyError
        A placeholder has no value (the message names the template and the placeholder).
    ValueError
        A value names no placeholder of the template (a typo on one side or the other).
    """
    text = string.Template(Path(template).read_text(encoding="utf-8"))
    names = {m.group("named") or m.group("braced") for m in text.pattern.finditer(text.template)} - {None}
    missing = sorted(names - set(values))
    if missing:
        raise KeyError(f"template {template}: no value for {', '.join('${' + n + '}' for n in missing)}")
    unused = sorted(set(values) - names)
    if unused:
        raise ValueError(f"template {template}: no placeholder for the value(s) {', '.join(unused)}")
    return text.substitute({k: str(v) for k, v in values.items()})


# ------------------------------------------------------------------------------------ files
def write_filled(path: str | Path, template: str | Path, values: Mapping[str, object]) -> str:
    """Write the report ``path`` from its template (:func:`fill_template`), atomically; returns its text."""
    text = fill_template(template, values)
    atomic_write_text(path, text)
    return text


def write_report(path: str | Path, lines: Sequence[str], newline: bool = True) -> Path:
    """Write a report's lines (joined by newlines, one more at the end unless ``newline=False``), atomically.

    Returns
    -------
    pathlib.Path
        ``path``.
    """
    return atomic_write_text(path, "\n".join(lines) + ("\n" if newline else ""))


# ------------------------------------------------------------------------------------ committed members
def committed_members(reports_dir: str | Path, limit: int | None = None):
    """Every optimiser member the committed study CSVs in ``reports_dir`` hold (``benchmarks/reports``).

    With ``limit``, only the first ``limit`` members of each case (a quick check).

    Returns
    -------
    pandas.DataFrame
        One row per member: ``source``, ``case``, ``label`` (run / algorithm), ``seed``, ``member``,
        ``running_time_s`` and ``energy_kwh``; the cases are named as :func:`member_cases` names them.
    """
    import pandas as pd

    reports_dir = Path(reports_dir)
    rows = []
    y = pd.read_csv(reports_dir / "yizhuang_seed000.csv")
    for r in y.itertuples():
        rows.append(("yizhuang_seed000", "yizhuang", f"{r.algorithm} {r.partition}", r.seed, "best",
                     r.running_time_s, r.energy_kwh))
    w = pd.read_csv(reports_dir / "emu_wuguang_runs.csv")
    for r in w.itertuples():
        for kind, t, e in (("fastest", r.t_min, r.e_max), ("slowest", r.t_max, r.e_min),
                           ("punctual", r.punctual_t, r.punctual_e)):
            rows.append(("emu_wuguang", "wuguang-crh3", f"{r.algorithm} {r.problem}", r.seed, kind, t, e))
    j = pd.read_csv(reports_dir / "journeys_fronts_simulated.csv")
    for r in j.itertuples():
        rows.append(("journeys", f"section {int(r.section)}", r.case, int(r.section), "strategy",
                     r.running_time_s, r.energy_kwh))
    table = pd.DataFrame(rows, columns=["source", "case", "label", "seed", "member", "running_time_s", "energy_kwh"])
    return table if limit is None else table.groupby("case", sort=False).head(limit)


def member_cases() -> dict:
    """The cases the members of :func:`committed_members` ran on, by the names it gives them."""
    from pymoo_rail.cases import load_case
    from pymoo_rail.cases.ttobench import BEIJING_SUBWAY_TRAIN, YIZHUANG_STOP_NAMES, YIZHUANG_TRACK
    from pymoo_rail.journeys import journey_from_ttobench

    journey = journey_from_ttobench(YIZHUANG_TRACK, BEIJING_SUBWAY_TRAIN, stop_names=YIZHUANG_STOP_NAMES)
    cases = {"yizhuang": load_case("yizhuang"), "wuguang-crh3": load_case("wuguang-crh3")}
    cases.update({f"section {k}": c for k, c in enumerate(journey.sections)})
    return cases


# ------------------------------------------------------------------------------------ figures
@dataclass(frozen=True)
class ScriptFigures:
    """The figures a benchmark script draws and what its ``--report-only`` draws them from.

    Parameters
    ----------
    script : str
        The script's name in ``benchmarks/`` without ``.py``.
    figures : tuple of str
        The PNG files it writes next to its report.
    records : str, optional
        The folder (relative to the repository) whose study records ``--report-only`` reads; None:
        the script has no report mode.
    from_committed : tuple of str
        The figures ``--report-only`` draws from committed files alone.
    args : tuple of str
        Arguments the script needs on every call (e.g. the case it runs on).
    """

    script: str
    figures: tuple[str, ...]
    records: str | None = None
    from_committed: tuple[str, ...] = ()
    args: tuple[str, ...] = ()

    @property
    def command(self) -> str:
        """The command that reruns the script's study."""
        return " ".join((f"python benchmarks/{self.script}.py", *self.args))

    def has_records(self, root: str | Path) -> bool:
        """Whether the script's study records (or per-run tables) are under ``root / records``."""
        folder = Path(root) / self.records if self.records is not None else None
        return folder is not None and folder.is_dir() and any(p.is_file() for p in folder.rglob("*"))

    def ready(self, root: str | Path) -> bool:
        """Whether ``--report-only`` has its inputs (the records or, for some figures, the committed files)."""
        return self.has_records(root) or bool(self.from_committed)

    def rebuild(self, root: str | Path) -> int:
        """Run ``benchmarks/<script>.py --report-only`` in a child (``root``'s package first); its exit status."""
        root = Path(root)
        env = dict(os.environ, MPLBACKEND="Agg",
                   PYTHONPATH=os.pathsep.join(filter(None, (str(root), os.environ.get("PYTHONPATH")))))
        done = subprocess.run([sys.executable, str(root / "benchmarks" / f"{self.script}.py"), *self.args,
                               "--report-only"],
                              cwd=root, env=env, capture_output=True, text=True)
        if done.returncode:
            print(f"  failed ({done.returncode}): {done.stderr.strip().splitlines()[-1] if done.stderr else ''}")
        return done.returncode
