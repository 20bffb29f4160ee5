"""Golden-ratio NSGA-II vs NSGA-II (and two ablations) on ZDT1-4 at equal budgets (Tang et al. (2020), 4.1).

Study ``grnsga2-zdt`` of ``run_study``; text ``benchmarks/templates/grnsga2_zdt.md``; without records,
``--report-only`` rebuilds the report from the committed ``grnsga2_zdt_runs.csv``.

Usage: ``nice -n 10 python benchmarks/grnsga2_zdt.py [--runs 30] [--report-only]``
"""

from __future__ import annotations

import argparse
from pathlib import Path

import numpy as np

from pymoo.problems import get_problem

from pymoo_rail.experiments import Study, algorithm, load_results, problem, run_study, tang2020_nsga2
from pymoo_rail.experiments.report import (add_study_options, count_range, fill_template, lower_priority, markdown_rows,
                                           report_runs, significant, write_report)
from pymoo_rail.experiments.metrics import raw_indicators
from pymoo_rail.experiments.stats import compare_means, describe_comparison, signed_percent
from pymoo_rail.plotting import plot_fronts, representative_runs, save_figure
from pymoo_rail.plotting.style import new_figure

HERE = Path(__file__).resolve().parent
BUDGET, POP_SIZE, N_PF = 60_000, 200, 500  # Deb et al. 2002 measured against 500 points of the true front
PROBLEMS = ("zdt1", "zdt2", "zdt3", "zdt4")
ALGORITHMS = ("NSGA-II", "GR-NSGA-II", "GR-NSGA-II no LS", "NSGA-II pm=1/n")
MAIN_PAIR = ("GR-NSGA-II", "NSGA-II")
HV_REF = np.array([1.1, 1.1])
RUNS_CSV = "grnsga2_zdt_runs.csv"
FIELDS = ["problem", "algorithm", "seed", "n_eval", "n_gen", "n_points", "sp", "delta", "gd", "gd_vv", "igd", "hv",
          "n_accepted", "cpu_s"]
METRICS = ("sp", "delta", "gd", "gd_vv", "igd", "hv")
# seed 003 table 1 (SP, GD) and Deb et al. 2002 tables II-III (Delta, Upsilon) for real-coded NSGA-II
SEED_TABLE = {"zdt1": {"NSGA-II": (0.46329, 0.033482), "GR-NSGA-II": (0.24016, 0.027263)},
              "zdt2": {"NSGA-II": (0.43511, 0.072391), "GR-NSGA-II": (0.42039, 0.049582)},
              "zdt3": {"NSGA-II": (0.57560, 0.114500), "GR-NSGA-II": (0.51095, 0.104832)},
              "zdt4": {"NSGA-II": (0.47947, 0.513053), "GR-NSGA-II": (0.45721, 0.463728)}}
DEB_2002 = {"zdt1": (0.463292, 0.033482), "zdt2": (0.435112, 0.072391), "zdt3": (0.575606, 0.114500),
            "zdt4": (0.479475, 0.513053)}


def algorithm_specs() -> dict:
    """The four algorithms as study specs, by label."""
    gr = dict(pop_size=POP_SIZE, pc_max=0.9, pm_max=0.1)
    return {"NSGA-II": tang2020_nsga2(label="NSGA-II", pop_size=POP_SIZE),
            "GR-NSGA-II": algorithm("grnsga2", label="GR-NSGA-II", local_size=40, **gr),
            "GR-NSGA-II no LS": algorithm("grnsga2", label="GR-NSGA-II no LS", local_size=0, **gr),
            "NSGA-II pm=1/n": algorithm("nsga2", label="NSGA-II pm=1/n", pop_size=POP_SIZE,
                                        crossover={"operator": "sbx", "prob": 0.9, "eta": 15},
                                        mutation={"operator": "pm", "prob": 1.0, "eta": 20})}


def build_study(runs: int, problems=PROBLEMS, algorithms=ALGORITHMS, budget: int = BUDGET) -> Study:
    """Problems x algorithms x seeds 1..runs at ``budget`` evaluations, NSGA-II the baseline."""
    specs = algorithm_specs()
    return Study("grnsga2-zdt", problems=[problem(p) for p in problems], algorithms=[specs[a] for a in algorithms],
                 seeds=runs, budget={"n_eval": int(budget)}, baseline="NSGA-II" if "NSGA-II" in algorithms else None)


def run_row(result) -> dict:
    """The report's indicators of one stored run (a row of ``load_results``), from its front."""
    accepted = result.get("n_accepted_total", np.nan)
    return {"problem": result["problem"], "algorithm": result["algorithm"], "seed": int(result["seed"]),
            "n_eval": int(result["n_eval"]), "n_gen": int(result["n_gen"]), "n_points": len(result["F"]),
            **raw_indicators(result["F"], get_problem(result["problem"]).pareto_front(N_PF), HV_REF),
            "n_accepted": "" if not np.isfinite(accepted) else int(accepted),
            "cpu_s": round(float(result["cpu_time_s"]), 2)}


def cell(df, p: str, a: str):
    return df[(df.problem == p) & (df.algorithm == a)]


def compare(df, p: str, metric: str, a: str, b: str):
    """(a better?, relative difference of means in %, rank-sum p) of algorithm a against b, None below 2 runs."""
    return compare_means(cell(df, p, a)[metric].dropna(), cell(df, p, b)[metric].dropna(), lower_better=metric != "hv")


def metric_tables(df, problems, algorithms) -> str:
    """Per problem: mean +- std (median) of every metric and algorithm, and the p of GR vs NSGA-II."""
    blocks = []
    for p in problems:
        rows = []
        for m in METRICS:
            cells = [f"{significant(v.mean(), missing='nan')} +- {significant(v.std(), missing='nan')} "
                     f"({significant(v.median(), missing='nan')})" if len(v) else "-"
                     for v in (cell(df, p, a)[m].dropna() for a in algorithms)]
            pair = compare(df, p, m, *MAIN_PAIR)
            rows.append([m, *cells, f"{pair[2] if pair else float('nan'):.2e}"])
        blocks.append(f"### {p.upper()}\n\n" + markdown_rows(["metric", *algorithms, "p (GR vs NSGA-II)"], rows))
    return "\n\n".join(blocks)


def in_words(df, problems, algorithms) -> str:
    """Who wins, problem by problem, and where a difference comes from (from the numbers only)."""
    lines, counts = [], {"better": 0, "worse": 0, "same": 0}
    for p in problems:
        pairs = [(m, r) for m in ("igd", "hv", "gd", "sp", "delta") if (r := compare(df, p, m, *MAIN_PAIR))]
        for _, r in pairs:
            counts["same" if r[2] >= 0.05 else "better" if r[0] else "worse"] += 1
        lines.append(f"- {p.upper()}, GR-NSGA-II vs NSGA-II: " + "; ".join(f"{m} {describe_comparison(r)}" for m, r in pairs) + ".")
    lines += ["", f"Over {sum(counts.values())} problem-indicator pairs GR-NSGA-II is significantly better in "
              f"{counts['better']}, significantly worse in {counts['worse']} and not significantly different in "
              f"{counts['same']} (rank-sum p < 0.05)."]
    if {"GR-NSGA-II no LS", "NSGA-II pm=1/n"} <= set(algorithms):
        lines += ["", "Where a difference comes from (IGD, the indicator that sees both convergence and spread):"]
        for p in problems:
            parts = [compare(df, p, "igd", a, b) for a, b in (("GR-NSGA-II", "GR-NSGA-II no LS"),
                                                            ("GR-NSGA-II no LS", "NSGA-II"), ("NSGA-II pm=1/n", "NSGA-II"))]
            if None not in parts:
                lines.append(f"- {p.upper()}: golden-ratio local search (GR vs GR no LS) {describe_comparison(parts[0])}; "
                             f"adaptive pc/pm alone (GR no LS vs NSGA-II) {describe_comparison(parts[1])}; "
                             f"mutation 1/n instead of 0.01 (NSGA-II pm=1/n vs NSGA-II) {describe_comparison(parts[2])}.")
    return "\n".join(lines)


def table_values(df, problems, algorithms) -> dict:
    """The seed-table, budget and verdict rows of the report."""
    seed_rows, budget_rows, verdict_rows = [], [], []
    for p in problems:
        ours = {a: f"{significant(s.delta.mean(), missing='nan')} / {significant(s.gd.mean(), missing='nan')}"
                if len(s := cell(df, p, a)) else "-" for a in MAIN_PAIR}
        st = SEED_TABLE[p]
        seed_rows.append(f"| {p.upper()} | {DEB_2002[p][0]} / {DEB_2002[p][1]} | {st['NSGA-II'][0]} / {st['NSGA-II'][1]} "
                         f"| {st['GR-NSGA-II'][0]} / {st['GR-NSGA-II'][1]} | {ours['NSGA-II']} | {ours['GR-NSGA-II']} |")
        budget_rows += [f"| {p.upper()} | {a} | {s.n_eval.mean():.0f} | {s.n_gen.mean():.0f} | {s.n_points.mean():.0f} | "
                        f"{s.cpu_s.mean():.1f} |" for a in algorithms if len(s := cell(df, p, a))]
        for m in METRICS:
            if (pair := compare(df, p, m, *MAIN_PAIR)) is None:
                continue
            better, rel, pval = pair
            a_v, b_v = (cell(df, p, a)[m].dropna() for a in MAIN_PAIR)
            rel_med = (a_v.median() - b_v.median()) / abs(b_v.median()) * 100
            verdict_rows.append(f"| {p.upper()} | {m} | {'yes' if better else 'no'} | {signed_percent(rel)} | "
                                f"{signed_percent(rel_med)} | {pval:.2e} | {'yes' if pval < 0.05 else 'no'} |")
    return {"seed_table_rows": "\n".join(seed_rows), "budget_rows": "\n".join(budget_rows),
            "verdict_rows": "\n".join(verdict_rows)}


def median_fronts_figure(df, fronts: dict, p: str):
    """The median-IGD run of NSGA-II and GR-NSGA-II on problem ``p`` beside the true front (seed figs. 6-9)."""
    fig, axes = new_figure(1, 2, figsize=(10, 4.2), sharex=True, sharey=True)
    median = representative_runs(df, p, "igd").set_index("algorithm")
    for ax, (label, alg) in zip(axes[0], (("(a) NSGA-II", "NSGA-II"), ("(b) golden-ratio NSGA-II", "GR-NSGA-II"))):
        if alg not in median.index:
            ax.set_title(f"{p.upper()} {label}: no run")
            continue
        row = median.loc[alg]
        plot_fronts({f"obtained (seed {int(row.seed)}, median IGD {row.igd:.2e})": fronts[p, alg, int(row.seed)]},
                    reference=get_problem(p).pareto_front(N_PF), reference_label="true Pareto front",
                    title=f"{p.upper()} {label}", ax=ax)
    return fig


def write_report_files(out: Path, results, problems, algorithms) -> None:
    """The report, the per-run CSV and the front figures, from the stored runs or else the committed CSV."""
    table, fronts, from_records = report_runs(results, run_row, FIELDS, out / RUNS_CSV)
    if from_records:
        table.sort_values(["seed", "problem", "algorithm"], kind="stable").to_csv(out / RUNS_CSV, index=False)
    df = table[table.problem.isin(problems) & table.algorithm.isin(algorithms)]
    n_runs = df.groupby(["problem", "algorithm"]).size()
    if fronts:
        for p in problems:
            save_figure(median_fronts_figure(df, fronts, p), out / f"grnsga2_{p}_fronts.png", dpi=110)
    source = ("This report was built from the run records." if from_records else "This report was rebuilt from "
              "that CSV (the run records are not in git), the front figures are those of the last build from the records.")
    values = {"source": source, "runs": count_range(n_runs),
              "results": metric_tables(df, problems, algorithms), "in_words": in_words(df, problems, algorithms),
              "reading": (HERE / "templates" / "grnsga2_zdt_reading.md").read_text()
              if set(MAIN_PAIR) <= set(algorithms) and n_runs.min() >= 30 else "",
              "figures": "\n\n".join(f"![grnsga2_{p}_fronts.png](grnsga2_{p}_fronts.png)" for p in problems),
              **table_values(df, problems, algorithms)}
    write_report(out / "grnsga2_zdt.md", [fill_template(HERE / "templates" / "grnsga2_zdt.md", values)], newline=False)
    print(f"wrote {out / 'grnsga2_zdt.md'}")


def main(argv=None) -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    add_study_options(parser, HERE.parent / "out" / "grnsga2_zdt", HERE / "reports", runs=30, workers=True)
    parser.add_argument("--problems", nargs="+", default=list(PROBLEMS), choices=PROBLEMS)
    parser.add_argument("--algorithms", nargs="+", default=list(ALGORITHMS), choices=ALGORITHMS)
    args = parser.parse_args(argv)
    lower_priority()
    study = build_study(args.runs, args.problems, args.algorithms)
    if not args.report_only:  # seed by seed: a study stopped early still compares on the same seeds
        print(run_study(study, args.work, workers=max(1, min(args.workers, 2)), seed_major=True), flush=True)
    args.out.mkdir(parents=True, exist_ok=True)
    write_report_files(args.out, load_results(args.work, study=study), args.problems, args.algorithms)


if __name__ == "__main__":
    main()
