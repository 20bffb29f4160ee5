"""The rail benchmark suite's study report: indicators against the certified fronts, tests, figures.

:func:`suite_report` turns the stored runs of ``examples/suite.toml`` (any selection of its
problems and seeds) into the markdown of ``benchmarks/reports/suite.md``: per problem the median
IGD, HV ratio and energy gap to the optimum with Wilcoxon rank-sum tests against the baseline, mean
ranks, the members below a front by more than its certificate (and the exact solver run alone at
the worst one's running time), and one figure per problem. :func:`complete_seeds` keeps the seeds
whose runs are all stored; :func:`front_table`, :func:`cost_table` and :func:`sanity_table` are the
measurements behind the suite's documentation (docs/suite.md).
"""

from __future__ import annotations

import time
from dataclasses import asdict
from pathlib import Path

import numpy as np
import pandas as pd

from pymoo_rail.experiments.metrics import front_indicators, hv_ratio
from pymoo_rail.experiments.runner import execute_run
from pymoo_rail.experiments.spec import Budget, RunSpec
from pymoo_rail.experiments.stats import rank_sum_tests, to_markdown
from pymoo_rail.optimal import optimal_front
from pymoo_rail.optimal import reference
from pymoo_rail.optimal.reference import FRONT_VERSION, certified_gap
from pymoo_rail.suite import get_problem, list_problems
from pymoo_rail.suite.sanity import nsga2_against_random

INDICATORS = (("igd", "Median IGD", True), ("hv_ratio", "Median HV ratio", False),
              ("gap_median_kwh", "Median energy gap to the optimum (kWh)", True))


def below_extent(front, running_time_s, energy_kwh) -> dict[str, float]:
    """How far a run's members go below the front beyond its certificate, and at which running times.

    Parameters
    ----------
    front : pymoo_rail.problems.reference.CertifiedFront
        The certified front.
    running_time_s, energy_kwh : array_like
        The run's feasible members.

    Returns
    -------
    dict
        ``excess_max_kwh``: the largest ``E*(T) - bound(T) - E`` over the members the front covers
        (positive only for a member below the certificate), with that member's ``worst_t_s`` and
        ``worst_e_kwh``; ``below_t_min_s`` / ``below_t_max_s``: the running-time range of the
        members below (NaN when there are none).
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


def scores(results: pd.DataFrame) -> pd.DataFrame:
    """Per run, from its stored front against the shipped certified front: IGD, HV ratio, energy gaps.

    IGD is recomputed (pymoo's, the runner's call) so that every indicator is against the front
    shipped now, even if a record was written against an earlier front version.

    Parameters
    ----------
    results : pandas.DataFrame
        Stored runs of suite problems (:func:`pymoo_rail.experiments.load_results`).

    Returns
    -------
    pandas.DataFrame
        ``results`` with ``igd``, ``hv_ratio``, the columns of ``certified_gap`` and of
        :func:`below_extent`.
    """
    rows = []
    for problem_name, group in results.groupby("problem"):
        problem = get_problem(problem_name)
        pf, front = problem.pareto_front(), problem.certified_front()
        for _, run in group.iterrows():
            feasible = run["CV"] <= 0
            t, e = run["extras"]["running_time_s"][feasible], run["extras"]["energy_kwh"][feasible]
            rows.append({"run_id": run["run_id"], "igd": front_indicators(run["F"][feasible], pf).get("igd", np.nan),
                         "hv_ratio": hv_ratio(run["F"][feasible], pf), **certified_gap(front, t, e),
                         **below_extent(front, t, e)})
    return results.drop(columns=["igd"], errors="ignore").merge(pd.DataFrame(rows), on="run_id")


def seed_ranges(values: list[int]) -> str:
    """``[1, 2, 3, 7]`` -> ``"1-3, 7"`` (``"none"`` for no value)."""
    out, start = [], None
    for k, v in enumerate(values):
        if start is None:
            start = v
        if k + 1 == len(values) or values[k + 1] != v + 1:
            out.append(f"{start}-{v}" if v != start else f"{v}")
            start = None
    return ", ".join(out) or "none"


def complete_seeds(results: pd.DataFrame, study) -> tuple[list[int], str]:
    """The seeds whose runs are all stored, and a sentence saying exactly which runs are missing.

    Parameters
    ----------
    results : pandas.DataFrame
        The stored runs (``run_id`` and ``seed`` columns).
    study : pymoo_rail.experiments.Study
        The study they belong to.
    """
    cells = len(study.problems) * len(study.algorithms)
    done = results.groupby("seed")["run_id"].nunique().reindex(list(study.seeds), fill_value=0)
    complete = [int(s) for s, n in done.items() if n == cells]
    partial = {int(s): int(n) for s, n in done.items() if 0 < n < cells}
    missing = [int(s) for s, n in done.items() if n == 0]
    if len(complete) == len(study.seeds):
        return complete, f"All {len(study.runs())} runs are stored."
    parts = [f"{len(complete)} complete seeds ({seed_ranges(complete)}, {len(complete) * cells} runs)"]
    if partial:
        parts.append("partly run seeds left out so that every cell has the same seeds: "
                     + ", ".join(f"seed {s} with {n} of {cells} runs" for s, n in partial.items()))
    if missing:
        parts.append(f"seeds {seed_ranges(missing)} not run ({len(missing) * cells} runs)")
    return complete, f"Not all {len(study.runs())} runs are stored: " + "; ".join(parts) + "."


def mean_ranks(results: pd.DataFrame, indicator: str, lower_better: bool) -> pd.Series:
    """Mean rank (1 = best) of each algorithm's median ``indicator`` over the problems."""
    medians = results.groupby(["problem", "algorithm"])[indicator].median().unstack()
    return medians.rank(axis=1, ascending=lower_better).mean(axis=0).sort_values()


def solve_again(below_runs: pd.DataFrame) -> pd.DataFrame:
    """Per problem with members below its front: the exact solver run alone at the worst member's time.

    A front is one sweep of running times, each solve warm-started from the last; a single solve at
    the member's own running time tells a sweep artefact (the lone solve reaches the member) from a
    solver that misses the optimum there (it does not).
    """
    rows = []
    for problem_name, group in below_runs.groupby("problem"):
        run = group.loc[group["excess_max_kwh"].idxmax()]
        front = get_problem(problem_name).certified_front()
        optimum, bound = front.energy_at([run["worst_t_s"]])
        alone = optimal_front(get_problem(problem_name).case, [run["worst_t_s"]], dx_m=front.dx_m).iloc[0]
        rows.append({"problem": problem_name, "member": f"{run['algorithm']} seed {run['seed']}",
                     "running_time_s": run["worst_t_s"], "member_kwh": run["worst_e_kwh"],
                     "front_kwh": float(optimum[0]), "certificate_kwh": float(bound[0]),
                     "solved_alone_kwh": float(alone["energy_kwh"]), "solved_alone_at_s": float(alone["running_time_s"]),
                     "solver_bound_kwh": float(alone.get("energy_bound_kwh", np.nan))})
    return pd.DataFrame(rows)


def _indicator_lines(results: pd.DataFrame, baseline: str) -> list[str]:
    """One table per indicator (medians with the rank-sum verdict) and the mean ranks below it."""
    tests = rank_sum_tests(results, baseline, [name for name, _, _ in INDICATORS])
    lines = []
    for indicator, title, lower in INDICATORS:
        med = results.groupby(["problem", "algorithm"])[indicator].median().unstack()
        cells = med.map(lambda v: f"{v:.4g}")
        for (problem_name, algorithm), value in med.stack().items():
            hit = tests[(tests.problem == problem_name) & (tests.algorithm == algorithm) & (tests.indicator == indicator)]
            if len(hit):
                cells.loc[problem_name, algorithm] = f"{value:.4g} {hit['verdict'].iloc[0]}"
        lines += [f"## {title}", "", to_markdown(cells.reset_index()), ""]
        lines += ["Mean rank over the problems (1 = best): "
                  + ", ".join(f"{a} {r:.2f}" for a, r in mean_ranks(results, indicator, lower).items()), ""]
    return lines


def _below_lines(results: pd.DataFrame) -> list[str]:
    """The members below a certified front, per algorithm and per problem, and the lone solves."""
    below = results.groupby("algorithm")["n_below_certificate"].sum()
    members = results.groupby("algorithm")["n_in_range"].sum()
    per_problem = results.groupby("problem").agg(
        members=("n_in_range", "sum"), below=("n_below_certificate", "sum"),
        runs_with_below=("n_below_certificate", lambda n: int((n > 0).sum())), runs=("seed", "count"),
        largest_excess_kwh=("excess_max_kwh", "max"), below_from_s=("below_t_min_s", "min"),
        below_to_s=("below_t_max_s", "max"))
    per_problem["largest_excess_kwh"] = per_problem["largest_excess_kwh"].clip(lower=0.0)
    lines = ["## Members below a certified front", "",
             "Feasible front members whose energy lies below the certified optimum at their running time by "
             "more than its certificate (a correct certificate allows none): "
             + ", ".join(f"{a} {int(below[a])} of {int(members[a])}" for a in below.index) + ".", "",
             "Per problem (excess: how far the lowest member lies below optimum minus certificate, 0 when "
             "none does; running times of the members below):", "",
             to_markdown(per_problem.astype({"members": int, "below": int}).round(4).reset_index()), ""]
    again = solve_again(results[results["n_below_certificate"] > 0])
    if len(again):
        lines += ["The worst member of each such problem against the exact solver run alone at its running time "
                  "(`optimal_front(case, [T])`, no sweep):", "", to_markdown(again.round(4)), ""]
    return lines


def plot_problem(results: pd.DataFrame, problem_name: str, out: Path) -> str:
    """Draw the certified front and the median-IGD run of each algorithm; returns the PNG's name."""
    import matplotlib.pyplot as plt

    from pymoo_rail.plotting import plot_fronts, save_figure

    problem = get_problem(problem_name)
    fronts = {}
    for algorithm, group in results[results["problem"] == problem_name].groupby("algorithm"):
        run = group.sort_values(["igd", "seed"]).iloc[(len(group) - 1) // 2]  # the median-IGD run
        fronts[f"{algorithm} (seed {run['seed']})"] = run["F"][run["CV"] <= 0]
    _, ax = plt.subplots(figsize=(5.0, 3.4))  # small figures: ten of them sit in the report
    fig = plot_fronts(fronts, problem.objectives, reference=problem.pareto_front(),
                      reference_label="certified optimal front", title=f"{problem_name}: median-IGD runs", ax=ax)
    name = f"suite_{problem_name}.png"
    save_figure(fig, Path(out) / name, dpi=80)
    return name


def suite_report(results: pd.DataFrame, study, out: str | Path, note: str, source: str) -> list[str]:
    """The lines of the suite report from scored runs (:func:`scores`); draws its figures into ``out``.

    Parameters
    ----------
    results : pandas.DataFrame
        Scored runs of complete seeds.
    study : pymoo_rail.experiments.Study
        The study (its baseline algorithm is the tests' reference).
    out : str or pathlib.Path
        Folder of the figures.
    note, source : str
        The paragraph on the study's size and coverage; the study file named in the header.
    """
    lines = ["# Rail benchmark suite: five algorithms against certified optimal fronts", "",
             f"Written by `benchmarks/suite.py` from the study records of `{source}`.", "", note, "",
             f"Fronts: the certified fronts shipped with the package (front version {FRONT_VERSION}); every "
             "indicator below is computed from each run's stored final front against them. "
             "IGD is pymoo's (mean distance from the certified front to the nearest obtained point, raw units: "
             "kWh and s). HV ratio: hypervolume of the obtained feasible front over that of the certified front, "
             "both normalised by the certified front's ideal and nadir points (reference point 1.1). Energy gap: "
             "median over a run's feasible members of E - E*(T) in kWh, E* the certified optimum at the member's "
             "own running time (interpolated between the front's nodes: a chord above the convex front, so small "
             "negative gaps within the certificate are expected). Tests: Wilcoxon rank-sum against "
             f"{study.baseline} at alpha = 0.05 (`+` better, `-` worse, `=` no significant difference).", ""]
    lines += _indicator_lines(results, study.baseline) + _below_lines(results)
    lines += ["## Runs", "", to_markdown(results.groupby(["problem", "algorithm"]).agg(
        runs=("seed", "count"), cpu_s_median=("cpu_time_s", "median"), n_front_median=("n_front", "median"))
        .round(2).reset_index()), "", "## Figures", ""]
    return lines + [f"![{name}]({plot_problem(results, name, out)})" for name in sorted(results["problem"].unique())]


def front_table() -> pd.DataFrame:
    """Per suite problem: its front (nodes, time range, certificate) and the CPU time of ``pareto_front()``.

    The first call reads the shipped file (or solves, if none is shipped); the second is pymoo's
    in-memory cache. CPU times (``time.process_time``) of one run; the machine may be loaded.
    """
    rows = []
    for name in list_problems():
        problem = get_problem(name)
        try:
            start = time.process_time()
            pf = problem.pareto_front()
            first, start = time.process_time() - start, time.process_time()
            problem.pareto_front()
            second = time.process_time() - start
        except reference.NoExactFrontError:
            rows.append({"problem": name, "front": "none (best-known only)"})
            continue
        front = problem.certified_front()
        lo, hi = front.time_range_s
        rows.append({"problem": name, "front": f"{len(pf)} points" if len(pf) > 1 else f"optimum {pf[0, 0]:.4f} kWh",
                     "nodes": len(front.table), "time_range_s": f"{lo:.1f}-{hi:.1f}",
                     "node_bound_max_pct": 100 * float((front.table["energy_bound_kwh"] / front.table["energy_kwh"]).max()),
                     "dense_bound_max_kwh": float(front.dense(200)["energy_bound_kwh"].max()),
                     "certificate": front.certificate, "first_call_cpu_s": first, "second_call_cpu_s": second})
    return pd.DataFrame(rows)


def cost_table(study, budgets=(1000, 4000)) -> pd.DataFrame:
    """CPU seconds of one run per problem and algorithm at two budgets, and the fitted cost model.

    Each (problem, algorithm) runs seed 1 in this process at both budgets, after warm-up runs of
    every algorithm and problem (no Numba compile is counted); ``fixed_s + per_eval_ms * n_eval /
    1000`` fits the two CPU times (the whole run: building the problem, reading its front, the run,
    the record). Project a study with :func:`projected_cpu_min`.
    """
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
    """CPU minutes of a study at ``n_eval`` evaluations per run and ``seeds`` seeds, from :func:`cost_table`."""
    return float(seeds * (costs["fixed_s"] + costs["per_eval_ms"] * n_eval / 1000).sum() / 60)


def sanity_table(names=None, seeds: int = 1, **kwargs) -> pd.DataFrame:
    """NSGA-II (100 x 200 generations) against random sampling on suite problems, seeds 1..``seeds``.

    ``kwargs`` go to :func:`pymoo_rail.suite.sanity.nsga2_against_random` (e.g. ``encoding``). The
    column ``passed``: NSGA-II's IGD finite and below random sampling's, and no member below the
    certificate.
    """
    rows = [{**asdict(nsga2_against_random(name, seed=seed, **kwargs)), "seed": seed}
            for name in (names or list_problems()) for seed in range(1, seeds + 1)]
    table = pd.DataFrame(rows)
    table["passed"] = (np.isfinite(table["igd_nsga2"]) & (table["igd_nsga2"] < table["igd_random"])
                       & (table["n_below_certificate"] == 0))
    return table
