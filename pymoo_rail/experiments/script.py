"""What a benchmark script does around a study: run it (unless ``--report-only``), read its records,
and refuse to report a study with missing runs.

>>> results = study_results(study, args, seed_major=True)            # doctest: +SKIP
"""

from __future__ import annotations

from pymoo_rail.experiments.report import require_runs
from pymoo_rail.experiments.results import load_results
from pymoo_rail.experiments.runner import run_study


def study_results(study, args, echo: bool = False, **run_kwargs):
    """Run ``study`` into ``args.work`` unless ``args.report_only``, then its stored runs, every one present.

    Parameters
    ----------
    study : pymoo_rail.experiments.Study
        The study.
    args : argparse.Namespace
        The script's options of :func:`pymoo_rail.experiments.report.add_study_options`
        (``work``, ``report_only``, ``workers``).
    echo : bool
        Print the runner's report.
    **run_kwargs
        Further keyword arguments of :func:`pymoo_rail.experiments.run_study` (e.g. ``seed_major``).

    Returns
    -------
    pandas.DataFrame
        :func:`pymoo_rail.experiments.load_results` of ``args.work``.

    Raises
    ------
    SystemExit
        A run of ``study`` has no stored record (the message names them, see
        :func:`~pymoo_rail.experiments.report.require_runs`).
    """
    if not args.report_only:
        report = run_study(study, args.work, workers=args.workers, **run_kwargs)
        if echo:
            print(report, flush=True)
    results = load_results(args.work, study=study)
    try:
        require_runs(results, study, args.work)
    except FileNotFoundError as error:
        raise SystemExit(str(error)) from None
    return results
