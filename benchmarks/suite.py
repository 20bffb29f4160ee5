"""The rail benchmark suite study: five algorithms on the suite's energy / running-time problems.

Runs ``examples/suite.toml`` (NSGA-II, MOABC, GoldenRatioNSGA2, SMS-EMOA, AGE-MOEA; 10,000
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
    python benchmarks/suite.py --costs                              # CPU per run; the study's budget
    python benchmarks/suite.py --best-known                         # recompute metro-a-4obj's front
    python benchmarks/suite.py --sanity                             # NSGA-II vs random, every problem
    python benchmarks/suite.py --trace PROBLEM [ENCODING] --seeds S # NSGA-II's population over the run
    python benchmarks/suite.py --ship-fronts                        # recompute the shipped fronts

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
    """Per run, from the stored fronts against the shipped certified front: IGD, HV ratio, energy gaps.

    IGD is recomputed here (pymoo's, the same call as the runner's) so that every indicator is
    against the front shipped now, even if a record was written against an earlier front version.
    """
    from pymoo_rail.experiments.metrics import hv_ratio
    from pymoo_rail.optimal.reference import certified_gap
    from pymoo_rail.experiments.metrics import front_indicators
    from pymoo_rail.suite import get_problem

    rows = []
    for problem_name, group in results.groupby("problem"):
        problem = get_problem(problem_name)
        pf = problem.pareto_front()
        front = problem.certified_front()
        for _, run in group.iterrows():
            feasible = run["CV"] <= 0
            extras = run["extras"]
            t, e = extras["running_time_s"][feasible], extras["energy_kwh"][feasible]
            gap = certified_gap(front, t, e)
            rows.append({"run_id": run["run_id"], "igd": front_indicators(run["F"][feasible], pf).get("igd", np.nan),
                         "hv_ratio": hv_ratio(run["F"][feasible], pf), **gap, **below_extent(front, t, e)})
    return results.drop(columns=["igd"], errors="ignore").merge(pd.DataFrame(rows), on="run_id")


def below_extent(front, running_time_s, energy_kwh) -> dict[str, float]:
    """How far a run's members go below the front beyond its certificate, and at which running times.

    ``excess_max_kwh`` is the largest ``E*(T) - bound(T) - E`` over the members the front covers
    (positive only for a member below the certificate); ``below_t_min_s`` / ``below_t_max_s`` the
    running-time range of those members (NaN when there are none).
    """
    t, e = np.asarray(running_time_s, dtype=float), np.asarray(energy_kwh, dtype=float)
    inside, below = front.below_certificate(t, e)
    out = {"excess_max_kwh": float("nan"), "below_t_min_s": float("nan"), "below_t_max_s": float("nan"),
           "worst_t_s": float("nan"), "worst_e_kwh": float("nan")}
    if inside.any():
        optimum, bound = front.energy_at(t[inside])
        worst = int(np.argmax(optimum - bound - e[inside]))
        out.update(excess_max_kwh=float(optimum[worst] - bound[worst] - e[inside][worst]),
                   worst_t_s=float(t[inside][worst]), worst_e_kwh=float(e[inside][worst]))
    if below.any():
        out.update(below_t_min_s=float(t[below].min()), below_t_max_s=float(t[below].max()))
    return out


def solve_again(below_runs: pd.DataFrame) -> list[str]:
    """Per problem with members below its front: the exact solver run alone at the worst member's time.

    A front is computed as one sweep of running times, each solve warm-started from the last; a
    single solve at the member's own running time tells a sweep artefact (the lone solve reaches
    the member) from a solver that misses the optimum there (it does not).
    """
    from pymoo_rail.experiments.stats import to_markdown
    from pymoo_rail.optimal import optimal_front
    from pymoo_rail.suite import get_problem

    rows = []
    for problem_name, group in below_runs.groupby("problem"):
        run = group.loc[group["excess_max_kwh"].idxmax()]
        problem = get_problem(problem_name)
        front = problem.certified_front()
        optimum, bound = front.energy_at([run["worst_t_s"]])
        alone = optimal_front(problem.case, [run["worst_t_s"]], dx_m=front.dx_m).iloc[0]
        rows.append({"problem": problem_name, "member": f"{run['algorithm']} seed {run['seed']}",
                     "running_time_s": run["worst_t_s"], "member_kwh": run["worst_e_kwh"],
                     "front_kwh": float(optimum[0]), "certificate_kwh": float(bound[0]),
                     "solved_alone_kwh": float(alone["energy_kwh"]), "solved_alone_at_s": float(alone["running_time_s"]),
                     "solver_bound_kwh": float(alone.get("energy_bound_kwh", np.nan))})
    if not rows:
        return []
    return ["The worst member of each such problem against the exact solver run alone at its running time "
            "(`optimal_front(case, [T])`, no sweep):", "", to_markdown(pd.DataFrame(rows).round(4)), ""]


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
    import matplotlib.pyplot as plt

    _, ax = plt.subplots(figsize=(5.0, 3.4))  # small figures: ten of them sit in the report
    fig = plot_fronts(fronts, problem.objectives, reference=problem.pareto_front(),
                      reference_label="certified optimal front", title=f"{problem_name}: median-IGD runs", ax=ax)
    name = f"suite_{problem_name}.png"
    save_figure(fig, out / name, dpi=80)
    return name


def complete_seeds(results: pd.DataFrame, study) -> tuple[list[int], str]:
    """The seeds whose runs are all stored, and a sentence saying exactly which runs are missing."""
    cells = len(study.problems) * len(study.algorithms)
    done = results.groupby("seed")["run_id"].nunique().reindex(list(study.seeds), fill_value=0)
    complete = [int(s) for s, n in done.items() if n == cells]
    partial = {int(s): int(n) for s, n in done.items() if 0 < n < cells}
    missing = [int(s) for s, n in done.items() if n == 0]
    if len(complete) == len(study.seeds):
        return complete, f"All {len(study.runs())} runs are stored."
    parts = [f"{len(complete)} complete seeds ({_ranges(complete)}, {len(complete) * cells} runs)"]
    if partial:
        parts.append("partly run seeds left out so that every cell has the same seeds: "
                     + ", ".join(f"seed {s} with {n} of {cells} runs" for s, n in partial.items()))
    if missing:
        parts.append(f"seeds {_ranges(missing)} not run ({len(missing) * cells} runs)")
    return complete, f"Not all {len(study.runs())} runs are stored: " + "; ".join(parts) + "."


def _ranges(values: list[int]) -> str:
    """``[1, 2, 3, 7]`` -> ``"1-3, 7"``."""
    out, start = [], None
    for k, v in enumerate(values):
        if start is None:
            start = v
        if k + 1 == len(values) or values[k + 1] != v + 1:
            out.append(f"{start}-{v}" if v != start else f"{v}")
            start = None
    return ", ".join(out) or "none"


def mean_ranks(results: pd.DataFrame, indicator: str, lower_better: bool) -> pd.Series:
    medians = results.groupby(["problem", "algorithm"])[indicator].median().unstack()
    return medians.rank(axis=1, ascending=lower_better).mean(axis=0).sort_values()


def write_report(results: pd.DataFrame, study, out: Path, note: str) -> Path:
    from pymoo_rail.experiments.stats import rank_sum_tests, to_markdown
    from pymoo_rail.optimal.reference import FRONT_VERSION

    baseline = study.baseline
    lines = ["# Rail benchmark suite: five algorithms against certified optimal fronts", "",
             f"Written by `benchmarks/suite.py` from the study records of `{STUDY_FILE.relative_to(ROOT)}`.", "",
             note, "",
             f"Fronts: the certified fronts shipped with the package (front version {FRONT_VERSION}); every "
             "indicator below is computed from each run's stored final front against them. "
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
    per_problem = results.groupby("problem").agg(
        members=("n_in_range", "sum"), below=("n_below_certificate", "sum"),
        runs_with_below=("n_below_certificate", lambda n: int((n > 0).sum())), runs=("seed", "count"),
        largest_excess_kwh=("excess_max_kwh", "max"), below_from_s=("below_t_min_s", "min"),
        below_to_s=("below_t_max_s", "max"))
    per_problem["largest_excess_kwh"] = per_problem["largest_excess_kwh"].clip(lower=0.0)
    lines += ["Per problem (excess: how far the lowest member lies below optimum minus certificate, 0 when "
              "none does; running times of the members below):", "",
              to_markdown(per_problem.astype({"members": int, "below": int}).round(4).reset_index()), ""]
    lines += solve_again(results[results["n_below_certificate"] > 0])
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

    from pymoo_rail.optimal import reference
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


def cost_table(study, budgets=(1000, 4000)) -> pd.DataFrame:
    """CPU seconds of one run per problem and algorithm at two budgets, and the fitted cost model.

    Each (problem, algorithm) runs seed 1 in this process at both budgets (after warm-up runs of
    every algorithm and problem, so no Numba compile is counted); ``fixed_s + per_eval_ms * n_eval / 1000`` fits
    the two CPU times (``time.process_time`` around the whole run: building the problem, reading
    its front, the run, the record). The machine may be loaded.
    """
    import time

    from pymoo_rail.experiments.runner import execute_run
    from pymoo_rail.experiments.spec import Budget, RunSpec

    rows = []
    for a in study.algorithms:  # compile every kernel (the simulator's, AGE-MOEA's) before timing
        execute_run(RunSpec(study.problems[0], a, 1, Budget("n_eval", 200)))
    for p in study.problems:
        execute_run(RunSpec(p, study.algorithms[0], 1, Budget("n_eval", 200)))  # read the front once
        for a in study.algorithms:
            cpu = []
            for n in budgets:
                start = time.process_time()
                execute_run(RunSpec(p, a, 1, Budget("n_eval", n)))
                cpu.append(time.process_time() - start)
            per_eval_ms = 1000 * (cpu[1] - cpu[0]) / (budgets[1] - budgets[0])
            rows.append({"problem": p.display, "algorithm": a.display, **{f"cpu_s_{n}": c for n, c in zip(budgets, cpu)},
                         "per_eval_ms": per_eval_ms, "fixed_s": cpu[0] - per_eval_ms * budgets[0] / 1000})
    return pd.DataFrame(rows)


def projected_cpu_min(costs: pd.DataFrame, n_eval: int, seeds: int) -> float:
    """CPU minutes of the whole study at ``n_eval`` evaluations per run, from :func:`cost_table`."""
    return float(seeds * (costs["fixed_s"] + costs["per_eval_ms"] * n_eval / 1000).sum() / 60)


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
    parser.add_argument("--costs", action="store_true",
                        help="measure the CPU cost of one run per problem and algorithm, project the study's, and stop")
    parser.add_argument("--best-known", action="store_true",
                        help="recompute and ship the best-known front of metro-a-4obj, print its size and CPU time, and stop")
    parser.add_argument("--sanity", action="store_true",
                        help="NSGA-II (100 x 200 generations) against random sampling on every suite problem "
                             "(seed 1, or seeds 1..--seeds), and stop")
    parser.add_argument("--encoding", default=None,
                        help="with --sanity: evaluate the problems under this encoding (e.g. speed_codes, the "
                             "-single forms of suite version 1)")
    parser.add_argument("--trace", nargs="+", metavar=("PROBLEM", "ENCODING"), default=None,
                        help="NSGA-II's population on one problem (seed --seeds or 1) over the generations "
                             "(optionally under another encoding, e.g. speed_codes), and stop")
    parser.add_argument("--ship-fronts", nargs="*", metavar="CASE", default=None,
                        help="recompute the shipped certified fronts (all suite cases, or those named), and stop")
    args = parser.parse_args(argv)
    if args.ship_fronts is not None:
        import time

        from pymoo_rail.suite.fronts_io import ship_fronts

        start = time.process_time()
        for path in ship_fronts(args.ship_fronts or None):
            print(path.name)
        print(f"{time.process_time() - start:.0f} s CPU")
        return 0
    if args.trace:
        from pymoo_rail.experiments.stats import to_markdown
        from pymoo_rail.suite.sanity import nsga2_trace

        kwargs = {"encoding": args.trace[1]} if len(args.trace) > 1 else {}
        print(to_markdown(pd.DataFrame(nsga2_trace(args.trace[0], seed=args.seeds or 1, **kwargs)).round(4)))
        return 0
    if args.sanity:
        from dataclasses import asdict

        from tqdm import tqdm

        from pymoo_rail.experiments.stats import to_markdown
        from pymoo_rail.suite import list_problems
        from pymoo_rail.suite.sanity import nsga2_against_random

        names = args.problems or list_problems()
        kwargs = {"encoding": args.encoding} if args.encoding else {}
        rows = [{**asdict(nsga2_against_random(name, seed=seed, **kwargs)), "seed": seed}
                for name in tqdm(names, desc="sanity", unit="problem") for seed in range(1, (args.seeds or 1) + 1)]
        table = pd.DataFrame(rows)
        table["passed"] = (np.isfinite(table["igd_nsga2"]) & (table["igd_nsga2"] < table["igd_random"])
                           & (table["n_below_certificate"] == 0))
        print(to_markdown(table.round(4)))
        return 0 if table["passed"].all() else 1
    if args.best_known:
        import time

        from pymoo_rail.suite import compute_best_known_front
        from pymoo_rail.suite.fronts_io import best_known_path

        start = time.process_time()
        table = compute_best_known_front(write=True)
        print(f"{best_known_path().name}: {len(table)} points, {time.process_time() - start:.0f} s CPU\n"
              f"{table.attrs['label']}\n{table.describe().loc[['min', 'max']].to_string()}")
        return 0
    if args.costs:
        from pymoo_rail.experiments.stats import to_markdown

        os.environ.setdefault("NUMBA_NUM_THREADS", "1")  # as in the study's pool workers
        study = build_study(False, None, args.problems)
        costs = cost_table(study)
        print(to_markdown(costs.round(3)))
        for n_eval in (5000, 8000, 10000, 15000, 20000, study.budget.value):
            print(f"n_eval = {n_eval}: {projected_cpu_min(costs, n_eval, len(study.seeds)):.0f} CPU min "
                  f"for {len(study.runs())} runs")
        return 0
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
    seeds, coverage = complete_seeds(results, study)
    if not seeds:
        raise SystemExit(f"no seed has all its runs stored in {args.work}: {coverage}")
    cpu_min = results["cpu_time_s"].sum() / 60
    results = scores(results[results["seed"].isin(seeds)].reset_index(drop=True))
    note = (f"Study: {len(study.problems)} problems x {len(study.algorithms)} algorithms x {len(study.seeds)} seeds, "
            f"{study.budget.kind} = {study.budget.value:,} per run for every problem and algorithm (NSGA-II: "
            f"population 100, {study.budget.value // 100} generations). The budget was set from "
            "`benchmarks/suite.py --costs` (CPU seconds per run at 1,000 and 4,000 evaluations, per problem and "
            "algorithm, projected to the whole study): 0.04-0.27 ms of CPU per evaluation, the 48.5 km lines and "
            "AGE-MOEA the dearest, about 35 CPU minutes for the study at 10,000 evaluations and 70 at 20,000, "
            "against about 80 CPU minutes available. "
            f"{coverage} The stored runs took {cpu_min:.1f} CPU minutes (sum of the records' CPU times); the wall "
            "time, not the CPU, limited the study: the 2-core machine was shared with five other jobs. "
            f"Every table below uses the {len(seeds)} complete seeds ({len(results)} runs).")
    path = write_report(results, study, Path(args.out), note)
    print(f"wrote {path}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
