"""MOABC (three neighbour moves) vs NSGA-II, MOEA/D and SMS-EMOA on ZDT1-4.

Every algorithm gets 25,000 evaluations (``("n_eval", 25000)``; pymoo checks the budget
after a whole generation, so a run may use up to one generation more, reported below) and
is run with seeds 1000 + run.

* MOABC: ``pop_size=100`` (50 food sources), ``archive_size=100``, ``w=1``, default limit
  ``SN * D``; moves ``centred``, ``canonical`` and ``literal`` (eq. 4-27 of seed 000).
* NSGA-II: pymoo defaults, population 100 (SBX + PM).
* MOEA/D: pymoo defaults, 100 uniform reference directions, 20 neighbours.
* SMS-EMOA: pymoo defaults, population 100.

Indicators on the final result (``res.F``: the archive for MOABC, the non-dominated part
of the population for the others) against pymoo's exact ZDT fronts:

* IGD and GD from pymoo; pymoo's GD is the *mean* Euclidean distance from each obtained
  point to the nearest front point (not Van Veldhuizen's root-of-sum form).
* HV with reference point (1.1, 1.1) on raw objective values (higher is better).
* Schott's spacing SP = sqrt(sum (d_i - mean d)^2 / (n - 1)), d_i the city-block distance
  to the nearest other point (pymoo's ``SpacingIndicator`` divides by n). Taken from
  ``pymoo_rail.indicators.Spacing``.

Statistics: mean, median, std over runs and a two-sided Wilcoxon rank-sum test of each
algorithm against NSGA-II (``pymoo_rail.experiments.stats.rank_sum``), '+' better / '-' worse /
'=' no difference at 5 %.

Usage::

    nice -n 10 python benchmarks/moabc_zdt.py --runs 30 --out benchmarks/reports

Runs go through ``pymoo_rail.experiments.run_study`` (study ``moabc-zdt``, seed by seed): one JSON
record per finished run in ``--work`` (default ``out/moabc_zdt``, not committed), so an interrupted
study loses nothing and a re-run starts only the missing runs. The indicators above are
computed from the stored final fronts; ``moabc_zdt.csv`` (one row per run) is exported from
the records. ``--report-only`` rewrites the report from them or, when there are none (they are
not committed), from the committed ``moabc_zdt.csv`` by the same code.
"""

from __future__ import annotations

import argparse
from pathlib import Path

import numpy as np
from pymoo.indicators.gd import GD
from pymoo.indicators.hv import HV
from pymoo.indicators.igd import IGD
from pymoo.problems import get_problem

from pymoo_rail.indicators import Spacing

N_EVAL = 25000
FIRST_SEED = 1000
REF_POINT = np.array([1.1, 1.1])
PROBLEMS = ("ZDT1", "ZDT2", "ZDT3", "ZDT4")
ALGORITHMS = ("MOABC-centred", "MOABC-canonical", "MOABC-literal", "NSGA2", "MOEAD", "SMSEMOA")
INDICATORS = ("IGD", "GD", "HV", "SP")
LOWER_IS_BETTER = {"IGD": True, "GD": True, "HV": False, "SP": True}
RUNS_CSV = "moabc_zdt.csv"
FIELDS = ["problem", "algorithm", "run", "seed", "n_points", "n_eval", *INDICATORS, "time_s"]


def build_study(runs: int, budget: int = N_EVAL):
    """ZDT1-4 x the six algorithms x seeds 1000 .. 1000 + runs - 1, ``budget`` evaluations each."""
    from pymoo_rail.experiments import Study, algorithm, problem

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
    pf = exact_front(result["problem"])
    return dict(problem=result["problem"], algorithm=result["algorithm"], run=int(result["seed"]) - FIRST_SEED,
                seed=int(result["seed"]), n_points=len(F), n_eval=int(result["n_eval"]),
                IGD=float(IGD(pf)(F)), GD=float(GD(pf)(F)), HV=float(HV(ref_point=REF_POINT)(F)),
                SP=float(Spacing()(F)) if len(F) >= 2 else 0.0,  # one point: nothing to space
                time_s=round(float(result["wall_time_s"]), 3))


def plot_first_fronts(fronts: dict, path: Path) -> None:
    """The first seed's front of every algorithm on each problem; ``fronts[(problem, algorithm, seed)] = F``."""
    import matplotlib.pyplot as plt

    from pymoo_rail.plotting import plot_fronts, save_figure

    if not fronts:  # report rebuilt from the per-run CSV: the committed figure stays
        return
    fig, axes = plt.subplots(1, 4, figsize=(18, 4))
    for ax, p in zip(axes, PROBLEMS):
        runs = {a: fronts.get((p, a, FIRST_SEED)) for a in ALGORITHMS}
        runs = {a: F for a, F in runs.items() if F is not None and len(F)}
        if not runs:  # a reduced study
            ax.set_axis_off()
            continue
        dense = get_problem(p.lower()).pareto_front(500)  # dots: ZDT3's gaps stay visible
        plot_fronts(runs, reference=dense, reference_label="exact front", title=f"{p}, run 0", ax=ax)
        ax.set_ylim(min(-1.0, ax.get_ylim()[0]), 2.0)
    fig.tight_layout()
    save_figure(fig, path, dpi=110)


def igd_median_rows(df) -> list[str]:
    """One row per algorithm: its median IGD on each problem."""
    lines = []
    for a in ALGORITHMS:
        cells = []
        for p in PROBLEMS:
            v = df[(df.problem == p) & (df.algorithm == a)].IGD
            cells.append(f"{v.median():.4g}" if len(v) else "-")
        lines.append(f"| {a} | " + " | ".join(cells) + " |")
    lines.append("")
    return lines


def problem_tables(df) -> list[str]:
    """Per problem, every indicator of every algorithm with its rank-sum mark against NSGA-II."""
    from pymoo_rail.experiments.stats import rank_sum

    lines = []
    for p in PROBLEMS:
        lines += [f"## {p}", "",
                  "| algorithm | runs | n_eval | " + " | ".join(
                      f"{i} mean | {i} median | {i} std | W" for i in INDICATORS) + " | time s |",
                  "|---|---|---|" + "---|---|---|---|" * len(INDICATORS) + "---|"]
        base = df[(df.problem == p) & (df.algorithm == "NSGA2")]
        for a in ALGORITHMS:
            g = df[(df.problem == p) & (df.algorithm == a)]
            if len(g) == 0:
                continue
            cells = []
            for ind in INDICATORS:
                v = g[ind].astype(float)
                mark = ""
                if a != "NSGA2" and len(base) > 1 and len(g) > 1:
                    mark = rank_sum(v, base[ind].astype(float), lower_better=LOWER_IS_BETTER[ind])[2]
                cells.append(f"{v.mean():.4g} | {v.median():.4g} | {v.std(ddof=1) if len(v) > 1 else 0:.2g} | {mark}")
            lines.append(f"| {a} | {len(g)} | {g.n_eval.mean():.0f} | " + " | ".join(cells)
                         + f" | {g.time_s.mean():.2f} |")
        lines.append("")
    return lines


def plot_igd_boxes(df, path: Path) -> None:
    """Box plots of the IGD of every algorithm, one panel per problem."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    from pymoo_rail.plotting import save_figure

    fig, axes = plt.subplots(1, 4, figsize=(18, 4))
    for ax, p in zip(axes, PROBLEMS):
        present = [a for a in ALGORITHMS if ((df.problem == p) & (df.algorithm == a)).any()]
        if not present:  # a reduced study
            ax.set_axis_off()
            continue
        data = [df[(df.problem == p) & (df.algorithm == a)].IGD.astype(float).values for a in present]
        ax.boxplot(data)
        ax.set_xticks(range(1, len(present) + 1), [a.replace("MOABC-", "MOABC\n") for a in present])
        ax.set_yscale("log")
        ax.set_title(f"{p}: IGD")
        ax.tick_params(axis="x", labelsize=7)
    fig.tight_layout()
    save_figure(fig, path, dpi=110)


def report(out: Path, results) -> None:
    """Report, per-run CSV and figures from the stored runs (``load_results``).

    Without stored runs the report is rebuilt from the committed ``moabc_zdt.csv`` by the same
    code (the IGD box plot is redrawn; the front figure, which needs the fronts, is kept).
    """
    from pymoo_rail.experiments.report import count_range, report_runs

    df, fronts, from_records = report_runs(results, run_row, FIELDS, out / RUNS_CSV)
    if from_records:
        df.sort_values(["run", "problem", "algorithm"], kind="stable").to_csv(out / RUNS_CSV, index=False)
    counts = df.groupby(["problem", "algorithm"]).size()
    pf_hv = {p: HV(ref_point=REF_POINT)(exact_front(p)) for p in PROBLEMS}
    lines = [
        "# MOABC vs NSGA-II, MOEA/D and SMS-EMOA on ZDT1-4",
        "",
        "Generated by `benchmarks/moabc_zdt.py` (runs by `pymoo_rail.experiments.run_study`, "
        "indicators from the stored final fronts). "
        f"Runs per cell: {count_range(counts)}. "
        f"Budget {N_EVAL} evaluations per run, seeds 1000 + run. "
        + ("Built from the run records." if from_records else
           "Rebuilt from the per-run CSV `moabc_zdt.csv` (the run records are not in git); the front "
           "figure is that of the last build from the records."),
        "",
        "MOABC: `pop_size=100` (50 food sources), `archive_size=100`, `w=1`, default limit; "
        "NSGA-II, SMS-EMOA: pymoo defaults with population 100; MOEA/D: pymoo defaults, "
        "100 uniform reference directions, 20 neighbours. Indicators on `res.F` "
        "(MOABC: its archive). GD is pymoo's GD, the mean distance of each obtained point to "
        "the nearest point of the exact front. HV uses reference point (1.1, 1.1) on raw "
        "objectives; HV of the exact front: "
        + ", ".join(f"{p} {v:.4f}" for p, v in pf_hv.items())
        + ". SP is Schott's spacing (city-block nearest-neighbour distances, divisor n - 1). "
        "`W` is the two-sided Wilcoxon rank-sum (Mann-Whitney U) test against NSGA-II at 5 % "
        "(`pymoo_rail.experiments.stats.rank_sum`: scipy's `mannwhitneyu`, exact when a side has at "
        "most 8 runs and there are no ties, otherwise the normal approximation with tie and continuity "
        "corrections): `+` significantly better, `-` worse, `=` no significant difference.",
        "",
        "## IGD medians",
        "",
        "| algorithm | " + " | ".join(PROBLEMS) + " |",
        "|---|" + "---|" * len(PROBLEMS),
    ]
    lines += igd_median_rows(df)

    lines += problem_tables(df)
    plot_first_fronts(fronts, out / "moabc_zdt_fronts.png")

    plot_igd_boxes(df, out / "moabc_zdt_igd.png")
    lines += ["![fronts](moabc_zdt_fronts.png)", "", "![IGD](moabc_zdt_igd.png)", ""]
    (out / "moabc_zdt.md").write_text("\n".join(lines) + "\n")
    print(f"wrote {out / 'moabc_zdt.md'}")


def main() -> None:
    from pymoo_rail.experiments.report import add_study_options

    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    add_study_options(parser, Path(__file__).resolve().parents[1] / "out" / "moabc_zdt", Path(__file__).parent / "reports",
                      runs=30, workers=True)
    args = parser.parse_args()
    from pymoo_rail.experiments import load_results, run_study
    from pymoo_rail.experiments.report import lower_priority

    study = build_study(args.runs)
    if not args.report_only:
        lower_priority()  # be gentle on the shared 2-core machine
        print(run_study(study, args.work, workers=max(1, min(args.workers, 2)), seed_major=True), flush=True)
    args.out.mkdir(parents=True, exist_ok=True)
    report(args.out, load_results(args.work, study=study))


if __name__ == "__main__":
    main()
