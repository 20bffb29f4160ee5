"""The rail benchmark suite study: five algorithms on the suite's energy / running-time problems.

Runs ``examples/suite.toml`` (NSGA-II, MOABC, GoldenRatioNSGA2, SMS-EMOA, AGE-MOEA; 20,000
evaluations per run) through ``pymoo_rail.experiments.run_study`` and writes
``benchmarks/reports/suite.md`` from the study's records: per problem the median IGD (pymoo's,
against the certified front), the median HV ratio (HV of the front over HV of the certified
front, both normalised by the certified front's ideal and nadir points), the median energy gap to
the optimum (kWh) at each member's own running time, Wilcoxon rank-sum tests against NSGA-II, mean
ranks over the problems, the number of members below a front by more than its certificate, and
one figure per problem (certified front and the median-IGD run of each algorithm).

Usage::

    nice -n 10 python benchmarks/suite.py --workers 2               # the full study (1500 runs)
    python benchmarks/suite.py --quick --workers 2                  # 3 problems x 3 seeds
    python benchmarks/suite.py --report-only                        # report from stored records
    python benchmarks/suite.py --fronts                             # fronts, certificates, call times

Records go to ``--work`` (default ``out/suite``, not committed); an interrupted study resumes.
"""

from __future__ import annotations

import argparse
import os
from dataclasses import replace
from pathlib import Path

import numpy as np
import pandas as pd

ROOT = Path(__file__).resolve().parent.parent
STUDY_FILE = ROOT / "examples" / "suite.toml"
QUICK_PROBLEMS = ("metro-a-bi", "ttobench-wanyuan-rongjing-bi", "yizhuang-bi")
QUICK_SEEDS = 3
INDICATORS = ("igd", "hv_ratio", "gap_median_kwh")


def build_study(quick: bool, seeds: int | None, problems):
    from pymoo_rail.experiments.study_file import read_study

    study = read_study(STUDY_FILE)
    chosen = problems or (QUICK_PROBLEMS if quick else None)
    if chosen:
        unknown = set(chosen) - {p.display for p in study.problems}
        if unknown:
            raise SystemExit(f"--problems: {sorted(unknown)} not in {STUDY_FILE.name}")
        study = replace(study, problems=tuple(p for p in study.problems if p.display in chosen))
    n = seeds or (QUICK_SEEDS if quick else None)
    if n:
        study = replace(study, seeds=tuple(range(1, n + 1)))
    return study


def scores(results: pd.DataFrame) -> pd.DataFrame:
    """Per run: HV ratio and the energy gap to the certified optimum, from the stored fronts."""
    from pymoo_rail.experiments.certified import certified_gap, hv_ratio
    from pymoo_rail.suite import get_problem

    rows = []
    for problem_name, group in results.groupby("problem"):
        problem = get_problem(problem_name)
        pf = problem.pareto_front()
        front = problem.certified_front()
        for _, run in group.iterrows():
            feasible = run["CV"] <= 0
            extras = run["extras"]
            gap = certified_gap(front, extras["running_time_s"][feasible], extras["energy_kwh"][feasible])
            rows.append({"run_id": run["run_id"], "hv_ratio": hv_ratio(run["F"][feasible], pf), **gap})
    return results.merge(pd.DataFrame(rows), on="run_id")


def plot_problem(results: pd.DataFrame, problem_name: str, out: Path) -> str:
    import matplotlib

    matplotlib.use("Agg")
    from pymoo_rail.plotting import plot_fronts, save_figure
    from pymoo_rail.suite import get_problem

    problem = get_problem(problem_name)
    fronts = {}
    for algorithm, group in results[results["problem"] == problem_name].groupby("algorithm"):
        group = group.sort_values(["igd", "seed"])
        run = group.iloc[(len(group) - 1) // 2]  # the median-IGD run
        fronts[f"{algorithm} (seed {run['seed']})"] = run["F"][run["CV"] <= 0]
    fig = plot_fronts(fronts, problem.objectives, reference=problem.pareto_front(),
                      reference_label="certified optimal front", title=f"{problem_name}: median-IGD runs")
    name = f"suite_{problem_name}.png"
    save_figure(fig, out / name)
    return name


def mean_ranks(results: pd.DataFrame, indicator: str, lower_better: bool) -> pd.Series:
    medians = results.groupby(["problem", "algorithm"])[indicator].median().unstack()
    return medians.rank(axis=1, ascending=lower_better).mean(axis=0).sort_values()


def write_report(results: pd.DataFrame, study, out: Path, note: str) -> Path:
    from pymoo_rail.experiments.stats import rank_sum_tests, to_markdown

    baseline = study.baseline
    lines = ["# Rail benchmark suite: five algorithms against certified optimal fronts", "",
             f"Written by `benchmarks/suite.py` from the study records of `{STUDY_FILE.relative_to(ROOT)}`.", "",
             note, "",
             "IGD is pymoo's (mean distance from the certified front to the nearest obtained point, raw units: "
             "kWh and s). HV ratio: hypervolume of the obtained feasible front over that of the certified front, "
             "both normalised by the certified front's ideal and nadir points (reference point 1.1). Energy gap: "
             "median over a run's feasible members of E - E*(T) in kWh, E* the certified optimum at the member's "
             "own running time (interpolated between the front's nodes: a chord above the convex front, so small "
             "negative gaps within the certificate are expected). Tests: Wilcoxon rank-sum against "
             f"{baseline} at alpha = 0.05 (`+` better, `-` worse, `=` no significant difference).", ""]
    tests = rank_sum_tests(results, baseline, list(INDICATORS))
    for indicator, title, lower in (("igd", "Median IGD", True), ("hv_ratio", "Median HV ratio", False),
                                    ("gap_median_kwh", "Median energy gap to the optimum (kWh)", True)):
        med = results.groupby(["problem", "algorithm"])[indicator].median().unstack()
        cells = med.map(lambda v: f"{v:.4g}")
        for (problem_name, algorithm), value in med.stack().items():
            hit = tests[(tests.problem == problem_name) & (tests.algorithm == algorithm) & (tests.indicator == indicator)]
            if len(hit):
                cells.loc[problem_name, algorithm] = f"{value:.4g} {hit['verdict'].iloc[0]}"
        lines += [f"## {title}", "", to_markdown(cells.reset_index()), ""]
        ranks = mean_ranks(results, indicator, lower)
        lines += ["Mean rank over the problems (1 = best): "
                  + ", ".join(f"{a} {r:.2f}" for a, r in ranks.items()), ""]
    below = results.groupby("algorithm")["n_below_certificate"].sum()
    members = results.groupby("algorithm")["n_in_range"].sum()
    lines += ["## Members below a certified front", "",
              "Feasible front members whose energy lies below the certified optimum at their running time by "
              "more than its certificate (a correct certificate allows none): "
              + ", ".join(f"{a} {int(below[a])} of {int(members[a])}" for a in below.index) + ".", ""]
    lines += ["## Runs", "", to_markdown(results.groupby(["problem", "algorithm"]).agg(
        runs=("seed", "count"), cpu_s_median=("cpu_time_s", "median"), n_front_median=("n_front", "median"))
        .round(2).reset_index()), ""]
    lines += ["## Figures", ""]
    for problem_name in sorted(results["problem"].unique()):
        lines.append(f"![{problem_name}]({plot_problem(results, problem_name, out)})")
    path = out / "suite.md"
    path.write_text("\n".join(lines) + "\n")
    return path


def front_table() -> pd.DataFrame:
    """Per suite problem: its front (nodes, time range, certificate) and the CPU time of pareto_front().

    The first call reads the shipped file (or solves, if none is shipped); the second is pymoo's
    in-memory cache. CPU times (``time.process_time``) of one run; the machine may be loaded.
    """
    import time

    from pymoo_rail.problems import reference
    from pymoo_rail.suite import get_problem, list_problems

    rows = []
    for name in list_problems():
        problem = get_problem(name)
        try:
            start = time.process_time()
            pf = problem.pareto_front()
            first = time.process_time() - start
            start = time.process_time()
            problem.pareto_front()
            second = time.process_time() - start
        except reference.NoExactFrontError:
            rows.append({"problem": name, "front": "none (best-known only)"})
            continue
        front = problem.certified_front()
        lo, hi = front.time_range_s
        dense_bound = front.dense(200)["energy_bound_kwh"]
        rows.append({"problem": name, "front": f"{len(pf)} points" if len(pf) > 1 else f"optimum {pf[0, 0]:.4f} kWh",
                     "nodes": len(front.table), "time_range_s": f"{lo:.1f}-{hi:.1f}",
                     "node_bound_max_pct": 100 * float((front.table["energy_bound_kwh"] / front.table["energy_kwh"]).max()),
                     "dense_bound_max_kwh": float(dense_bound.max()), "certificate": front.certificate,
                     "first_call_cpu_s": first, "second_call_cpu_s": second})
    return pd.DataFrame(rows)


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--quick", action="store_true", help=f"{len(QUICK_PROBLEMS)} problems x {QUICK_SEEDS} seeds")
    parser.add_argument("--seeds", type=int, default=None, help="seeds 1..N (default: the study file's 30)")
    parser.add_argument("--problems", nargs="+", default=None, help="problem labels of the study file")
    parser.add_argument("--workers", type=int, default=None)
    parser.add_argument("--work", default=str(ROOT / "out" / "suite"), help="study directory (records)")
    parser.add_argument("--out", default=str(ROOT / "benchmarks" / "reports"), help="report directory")
    parser.add_argument("--report-only", action="store_true", help="write the report from stored records")
    parser.add_argument("--fronts", action="store_true",
                        help="print each problem's front, certificate and pareto_front() CPU times, and stop")
    args = parser.parse_args(argv)
    if args.fronts:
        from pymoo_rail.experiments.stats import to_markdown

        print(to_markdown(front_table().round(4)))
        return 0

    from pymoo_rail.experiments import run_study
    from pymoo_rail.experiments.results import load_results

    os.environ.setdefault("MPLBACKEND", "Agg")
    study = build_study(args.quick, args.seeds, args.problems)
    if not args.report_only:
        run_study(study, args.work, workers=args.workers, seed_major=True)
    results = load_results(args.work, study)
    if results.empty:
        raise SystemExit(f"no stored runs in {args.work}")
    results = scores(results)
    n_runs = len(study.runs())
    note = (f"This report covers {len(results)} of the {n_runs} runs of the study as run "
            f"({len(study.problems)} problems x {len(study.algorithms)} algorithms x {len(study.seeds)} seeds, "
            f"{study.budget.kind} = {study.budget.value}); the full study file has 10 problems and 30 seeds.")
    path = write_report(results, study, Path(args.out), note)
    print(f"wrote {path}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
