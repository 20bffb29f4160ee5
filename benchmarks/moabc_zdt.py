"""MOABC (three neighbour moves) vs NSGA-II, MOEA/D and SMS-EMOA on ZDT1-4, 25,000 evaluations each.

Study ``moabc-zdt`` of ``run_study``; text ``benchmarks/templates/moabc_zdt.md``; without records,
``--report-only`` rebuilds the report from the committed ``moabc_zdt.csv``.

Usage: ``nice -n 10 python benchmarks/moabc_zdt.py [--runs 30] [--report-only]``
"""

from __future__ import annotations

import argparse
from pathlib import Path

import numpy as np
from pymoo.indicators.hv import HV
from pymoo.problems import get_problem

from pymoo_rail.experiments import Study, algorithm, load_results, problem, run_study
from pymoo_rail.experiments.metrics import raw_indicators
from pymoo_rail.experiments.report import (add_study_options, count_range, fill_template, lower_priority,
                                           markdown_rows, report_runs, write_report)
from pymoo_rail.experiments.stats import rank_sum
from pymoo_rail.plotting import plot_boxplots, plot_fronts, save_figure
from pymoo_rail.plotting.style import new_figure

HERE = Path(__file__).resolve().parent
N_EVAL, FIRST_SEED = 25000, 1000
REF_POINT = np.array([1.1, 1.1])
PROBLEMS = ("ZDT1", "ZDT2", "ZDT3", "ZDT4")
ALGORITHMS = ("MOABC-centred", "MOABC-canonical", "MOABC-literal", "NSGA2", "MOEAD", "SMSEMOA")
INDICATORS = ("IGD", "GD", "HV", "SP")
RUNS_CSV = "moabc_zdt.csv"
FIELDS = ["problem", "algorithm", "run", "seed", "n_points", "n_eval", *INDICATORS, "time_s"]


def build_study(runs: int, budget: int = N_EVAL) -> Study:
    """ZDT1-4 x the six algorithms x seeds 1000 .. 1000 + runs - 1, ``budget`` evaluations each."""
    moabc = [algorithm("moabc", label=f"MOABC-{move}", pop_size=100, archive_size=100, move=move)
             for move in ("centred", "canonical", "literal")]
    return Study("moabc-zdt", problems=[problem(p.lower(), label=p) for p in PROBLEMS],
                 algorithms=[*moabc, algorithm("nsga2", label="NSGA2", pop_size=100),
                             algorithm("moead", label="MOEAD", pop_size=100, n_neighbors=20),
                             algorithm("sms-emoa", label="SMSEMOA", pop_size=100)],
                 seeds=[FIRST_SEED + run for run in range(runs)], budget={"n_eval": int(budget)}, baseline="NSGA2")


def exact_front(name: str) -> np.ndarray:
    """pymoo's exact front at its default resolution (100 points), as the indicators use."""
    return get_problem(name.lower()).pareto_front()


def run_row(result) -> dict:
    """The report's indicators of one stored run (a row of ``load_results``), from its front."""
    F = result["F"]
    ind = raw_indicators(F, exact_front(result["problem"]), REF_POINT)
    return dict(problem=result["problem"], algorithm=result["algorithm"], run=int(result["seed"]) - FIRST_SEED,
                seed=int(result["seed"]), n_points=len(F), n_eval=int(result["n_eval"]), IGD=ind["igd"], GD=ind["gd"],
                HV=ind["hv"], SP=ind["sp"] if len(F) >= 2 else 0.0,  # one point: nothing to space
                time_s=round(float(result["wall_time_s"]), 3))


def problem_table(df, p: str) -> str:
    """Every indicator of every algorithm on ``p`` (mean, median, std) with its rank-sum mark against NSGA-II."""
    base, rows = df[(df.problem == p) & (df.algorithm == "NSGA2")], []
    for a in ALGORITHMS:
        g = df[(df.problem == p) & (df.algorithm == a)]
        if len(g) == 0:
            continue
        cells = []
        for ind in INDICATORS:
            v = g[ind].astype(float)
            mark = rank_sum(v, base[ind].astype(float), lower_better=ind != "HV")[2] \
                if a != "NSGA2" and len(base) > 1 and len(g) > 1 else ""
            cells.append(f"{v.mean():.4g} | {v.median():.4g} | {v.std(ddof=1) if len(v) > 1 else 0:.2g} | {mark}")
        rows.append([a, len(g), f"{g.n_eval.mean():.0f}", *cells, f"{g.time_s.mean():.2f}"])
    header = ["algorithm", "runs", "n_eval", *(c for i in INDICATORS for c in (f"{i} mean", f"{i} median", f"{i} std", "W")),
              "time s"]
    return f"## {p}\n\n" + markdown_rows(header, rows) + "\n"


def figures(df, fronts: dict, out: Path) -> None:
    """The IGD box plots per problem and (with the records) the first seed's front of every algorithm."""
    fig = plot_boxplots(df, "IGD", problems=[p for p in PROBLEMS if (df.problem == p).any()], algorithms=ALGORITHMS)
    for ax in fig.axes:
        ax.set_yscale("log")
    save_figure(fig, out / "moabc_zdt_igd.png", dpi=110)
    if not fronts:  # rebuilt from the per-run CSV: the front figure needs the records
        return
    fig, axes = new_figure(1, 4, figsize=(18, 4))
    for ax, p in zip(axes[0], PROBLEMS):
        runs = {a: F for a in ALGORITHMS if (F := fronts.get((p, a, FIRST_SEED))) is not None and len(F)}
        if not runs:  # a reduced study
            ax.set_axis_off()
            continue
        plot_fronts(runs, reference=get_problem(p.lower()).pareto_front(500), reference_label="exact front",
                    title=f"{p}, run 0", ax=ax)
        ax.set_ylim(min(-1.0, ax.get_ylim()[0]), 2.0)
    save_figure(fig, out / "moabc_zdt_fronts.png", dpi=110)


def report(out: Path, results) -> None:
    """Report, per-run CSV and figures from the stored runs, or else from the committed ``moabc_zdt.csv``."""
    df, fronts, from_records = report_runs(results, run_row, FIELDS, out / RUNS_CSV)
    if from_records:
        df.sort_values(["run", "problem", "algorithm"], kind="stable").to_csv(out / RUNS_CSV, index=False)
    medians = [[a] + [f"{v.median():.4g}" if len(v := df[(df.problem == p) & (df.algorithm == a)].IGD) else "-"
                      for p in PROBLEMS] for a in ALGORITHMS]
    values = {"runs": count_range(df.groupby(["problem", "algorithm"]).size()),
              "source": "Built from the run records." if from_records else "Rebuilt from the per-run CSV "
              "`moabc_zdt.csv` (the run records are not in git); the front figure is that of the last build from "
              "the records.",
              "exact_hv": ", ".join(f"{p} {HV(ref_point=REF_POINT)(exact_front(p)):.4f}" for p in PROBLEMS),
              "igd_medians": markdown_rows(["algorithm", *PROBLEMS], medians) + "\n",
              "problem_tables": "\n".join(problem_table(df, p) for p in PROBLEMS)}
    figures(df, fronts, out)
    write_report(out / "moabc_zdt.md", [fill_template(HERE / "templates" / "moabc_zdt.md", values)], newline=False)
    print(f"wrote {out / 'moabc_zdt.md'}")


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    add_study_options(parser, HERE.parent / "out" / "moabc_zdt", HERE / "reports", runs=30, workers=True)
    args = parser.parse_args()
    study = build_study(args.runs)
    if not args.report_only:
        lower_priority()  # be gentle on the shared 2-core machine
        print(run_study(study, args.work, workers=max(1, min(args.workers, 2)), seed_major=True), flush=True)
    args.out.mkdir(parents=True, exist_ok=True)
    report(args.out, load_results(args.work, study=study))


if __name__ == "__main__":
    main()
