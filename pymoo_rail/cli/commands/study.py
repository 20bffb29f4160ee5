"""``pymoo-rail study``: run (or resume) a study file, then write its tables and figures."""

from __future__ import annotations

import textwrap
from pathlib import Path

from pymoo_rail.cli.arguments import UsageError, add_command, out_dir, positive_int, say

ORDER = 50


def add_parser(sub) -> None:
    """Add ``study`` to the subcommands."""
    p = add_command(
        sub, "study", run, compiles=False, help="run a study file (problems x algorithms x seeds)",
        interrupted="every run finished so far is stored in the study directory; run the same command again "
                    "to resume",
        description="Run every run of a study file not yet stored in --out (an interrupted study resumes "
                    "where it stopped), then write the statistics tables (--out/tables: summary, mean (std) "
                    "per indicator, Wilcoxon rank-sum tests against the baseline) and the figures "
                    "(--out/figures). Same seeds, same results on the local pool and on Dask.",
        epilog=textwrap.dedent("""\
            examples:
              pymoo-rail study examples/study_zdt.toml --workers 2 --out out/zdt
              pymoo-rail study examples/study_zdt.toml --scheduler local --workers 4 --out out/zdt
              pymoo-rail study examples/study_zdt.toml --scheduler tcp://10.0.0.5:8786 --out out/zdt

            See docs/experiments.md for the study file format."""))
    p.add_argument("file", metavar="FILE", help="study file (.toml)")
    p.add_argument("--workers", "-w", type=positive_int, default=None, metavar="N",
                   help="worker processes (default: all CPUs; 1 runs in this process)")
    p.add_argument("--scheduler", default=None, metavar="ADDRESS",
                   help="run on Dask: 'local' for a LocalCluster of --workers processes, or the address "
                        "of a running scheduler (tcp://host:8786)")
    p.add_argument("--out", default=None, metavar="DIR", help="study directory (default: out/<study name>)")
    p.add_argument("--baseline", default=None, metavar="ALGORITHM",
                   help="algorithm the others are tested against (default: the file's baseline)")
    p.add_argument("--no-plots", action="store_true", help="write the tables only")
    p.add_argument("--seed-major", action="store_true",
                   help="start the runs seed by seed, so a study stopped early has every algorithm on every "
                        "problem for the same seeds (results are the same)")
    p.add_argument("--quiet", "-q", action="store_true", help="no progress bar")
    add_trust_argument(p)


def add_trust_argument(p) -> None:
    """``--trust``: allow a study file or results folder to name code to import (``module:callable``)."""
    p.add_argument("--trust", action="store_true",
                   help="allow problems, algorithms and operators given as 'package.module:callable' in the "
                        "study file or results folder: importing them runs their code, so only for files you "
                        "trust (built-in names need no trust)")


def study_outputs(directory: Path, out: Path, baseline: str | None, plots: bool, trusted: bool = False) -> list[Path]:
    """Write the tables (and figures) of the study stored in ``directory`` under ``out``; returns the files."""
    from pymoo_rail.experiments import load_results
    from pymoo_rail.experiments.registry import UntrustedCodeError
    from pymoo_rail.experiments.stats import write_tables
    from pymoo_rail.experiments.store import RecordError
    from pymoo_rail.plotting import plot_study

    try:
        results = load_results(directory, trusted=trusted)
    except UntrustedCodeError as err:
        raise UsageError("--trust", f"{directory / 'study.toml'}: {err}") from None
    except RecordError as err:
        raise UsageError("DIR", str(err)) from None
    if results.empty:
        raise RuntimeError(f"no stored runs in {directory}")
    algorithms = sorted(results["algorithm"].unique())
    if baseline is not None and baseline not in algorithms:
        raise UsageError("--baseline", f"unknown algorithm {baseline!r} (the study has {', '.join(algorithms)})")
    written = write_tables(results, out / "tables", baseline=baseline)
    if plots:
        written += plot_study(results, out / "figures", trusted=trusted)
    return written


def run(args) -> int:
    """Run (or resume) the study file of ``args`` and write its tables; returns the exit code."""
    from pymoo_rail.experiments import read_study, run_study
    from pymoo_rail.experiments.registry import UntrustedCodeError
    from pymoo_rail.experiments.spec import StudyError

    try:
        study = read_study(args.file)
    except StudyError as err:
        raise UsageError("FILE", str(err)) from None
    baseline = args.baseline or study.baseline
    if baseline is not None and baseline not in {a.display for a in study.algorithms}:
        raise UsageError("--baseline", f"unknown algorithm {baseline!r} (the study has "
                                       f"{', '.join(a.display for a in study.algorithms)})")
    out = out_dir(args.out or str(Path("out") / study.name))
    where = (f"Dask scheduler {args.scheduler}" if args.scheduler else
             "this process" if args.workers == 1 else "a local process pool")
    say(f"study {study.name}: {len(study.problems)} problems x {len(study.algorithms)} algorithms x "
        f"{len(study.seeds)} seeds = {len(study.runs())} runs on {where}; results in {out}")
    try:
        report = run_study(study, out, workers=args.workers, scheduler=args.scheduler, progress=not args.quiet,
                           seed_major=args.seed_major, trusted=args.trust)
    except UntrustedCodeError as err:
        raise UsageError("--trust", f"{args.file}: {err}") from None
    except StudyError as err:
        raise UsageError("--scheduler" if err.field == "scheduler" else "FILE", str(err)) from None
    say(str(report))
    written = study_outputs(out, out, baseline, plots=not args.no_plots, trusted=args.trust)
    say(f"wrote {len(written)} tables and figures under {out / 'tables'}"
        + ("" if args.no_plots else f" and {out / 'figures'}"))
    return 0 if not report.failures else 1
