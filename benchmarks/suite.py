"""The rail benchmark suite study: five algorithms on the suite's energy / running-time problems.

Runs ``examples/suite.toml`` (NSGA-II, MOABC, GoldenRatioNSGA2, SMS-EMOA, AGE-MOEA; 10,000
evaluations per run) through ``pymoo_rail.experiments.run_study`` and writes
``benchmarks/reports/suite.md`` from the study's records with
``pymoo_rail.experiments.suite_report`` (median IGD, HV ratio and energy gap to the certified
fronts, Wilcoxon rank-sum tests against NSGA-II, mean ranks, members below a front by more than its
certificate, one figure per problem).

Usage::

    nice -n 10 python benchmarks/suite.py --workers 2               # the full study (1500 runs)
    python benchmarks/suite.py --quick --workers 2                  # 3 problems x 3 seeds
    python benchmarks/suite.py --report-only                        # report from stored records

Records go to ``--work`` (default ``out/suite``, not committed); an interrupted study resumes. The
measurements behind docs/suite.md are library calls: ``suite_report.front_table()`` (fronts,
certificates, call times), ``suite_report.cost_table(study)`` (CPU per run, the study's budget),
``suite_report.sanity_table(seeds=5)`` (NSGA-II against random sampling), ``suite.sanity.nsga2_trace``,
``suite.compute_best_known_front(write=True)`` and ``suite.fronts_io.ship_fronts()``.
"""

from __future__ import annotations

import argparse
import os
from dataclasses import replace
from pathlib import Path

from pymoo_rail.experiments import load_results, read_study, run_study
from pymoo_rail.experiments.report import add_study_options, fill_template, write_report
from pymoo_rail.experiments.suite_report import complete_seeds, scores, suite_report

ROOT = Path(__file__).resolve().parent.parent
STUDY_FILE = ROOT / "examples" / "suite.toml"
TEMPLATES = Path(__file__).resolve().parent / "templates"
QUICK_PROBLEMS = ("metro-a-bi", "ttobench-wanyuan-rongjing-bi", "yizhuang-bi")
QUICK_SEEDS = 3


def build_study(quick: bool, seeds: int | None, problems):
    """The study file, cut to the problems asked for and seeds 1..``seeds``."""
    study = read_study(STUDY_FILE)
    chosen = problems or (QUICK_PROBLEMS if quick else None)
    if chosen:
        unknown = set(chosen) - {p.display for p in study.problems}
        if unknown:
            raise SystemExit(f"--problems: {sorted(unknown)} not in {STUDY_FILE.name}")
        study = replace(study, problems=tuple(p for p in study.problems if p.display in chosen))
    n = seeds or (QUICK_SEEDS if quick else None)
    return replace(study, seeds=tuple(range(1, n + 1))) if n else study


def study_note(study, coverage: str, cpu_min: float, seeds: list[int], n_runs: int) -> str:
    """The report's paragraph on the study's size, its budget and which runs it uses."""
    return fill_template(TEMPLATES / "suite_note.md", {
        "problems": len(study.problems), "algorithms": len(study.algorithms), "seeds": len(study.seeds),
        "budget_kind": study.budget.kind, "budget": f"{study.budget.value:,}", "generations": study.budget.value // 100,
        "coverage": coverage, "cpu_min": f"{cpu_min:.1f}", "complete": len(seeds), "runs": n_runs}).rstrip("\n")


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--quick", action="store_true", help=f"{len(QUICK_PROBLEMS)} problems x {QUICK_SEEDS} seeds")
    parser.add_argument("--seeds", type=int, default=None, help="seeds 1..N (default: the study file's 30)")
    parser.add_argument("--problems", nargs="+", default=None, help="problem labels of the study file")
    parser.add_argument("--workers", type=int, default=None)
    add_study_options(parser, ROOT / "out" / "suite", ROOT / "benchmarks" / "reports")
    args = parser.parse_args(argv)
    os.environ.setdefault("MPLBACKEND", "Agg")
    study = build_study(args.quick, args.seeds, args.problems)
    if not args.report_only:
        run_study(study, args.work, workers=args.workers, seed_major=True)
    results = load_results(args.work, study)
    if results.empty:
        raise SystemExit(f"no stored runs in {args.work}")
    seeds, coverage = complete_seeds(results, study)
    if not seeds:
        raise SystemExit(f"no seed has all its runs stored in {args.work}: {coverage}")
    cpu_min = results["cpu_time_s"].sum() / 60
    results = scores(results[results["seed"].isin(seeds)].reset_index(drop=True))
    note = study_note(study, coverage, cpu_min, seeds, len(results))
    path = write_report(Path(args.out) / "suite.md",
                        suite_report(results, study, args.out, note, str(STUDY_FILE.relative_to(ROOT))))
    print(f"wrote {path}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
