"""ABC vs PSO vs DE on Sphere, Griewank and Rosenbrock (Liu (2019), 3.5, tables 3-2 to 3-5), equal budgets.

One study per (dimension, iterations) through ``run_study``; text ``benchmarks/templates/abc_functions.md``,
the seed's values ``abc_functions_seed.csv``; without records, ``--report-only`` rebuilds the tables
from the committed ``abc_functions.csv``.

Usage: ``nice -n 10 python benchmarks/abc_functions.py [--runs 30] [--report-only]``
"""

from __future__ import annotations

import argparse
from pathlib import Path

import numpy as np
import pandas as pd

from pymoo_rail.experiments import Study, algorithm, load_results, problem, run_study
from pymoo_rail.experiments.report import (add_study_options, count_range, fill_template, lower_priority,
                                           markdown_rows, write_report)
from pymoo_rail.plotting import plot_convergence, save_figure

HERE = Path(__file__).resolve().parent
POP, FIRST_SEED = 30, 1000
SETTINGS = [(10, 500), (20, 1000), (30, 1000), (50, 5000)]
EXTRA = [("sphere", 30, 3000)]  # table 3-5
FUNCTIONS = ("sphere", "griewank", "rosenbrock")
ALGORITHMS = ("ABC", "PSO", "DE", "ABC-inverse")
FIELDS = ["function", "dim", "iterations", "algorithm", "run", "seed", "best", "n_eval", "n_gen", "time_s"]


def algorithm_specs() -> dict:
    """The four algorithms with the seed's parameters, as study specs by label."""
    return {"ABC": algorithm("abc", label="ABC", pop_size=POP, limit=50),
            "PSO": algorithm("pso", label="PSO", pop_size=POP, w=0.8, c1=1.5, c2=1.5, adaptive=False,
                             pertube_best=False),
            "DE": algorithm("de", label="DE", pop_size=POP, variant="DE/rand/1/bin", CR=0.5, F=0.6, prob_mut=0.0),
            "ABC-inverse": algorithm("abc", label="ABC-inverse", pop_size=POP, limit=50, onlooker_fitness="inverse")}


def build_studies(runs: int, settings=None, extra=EXTRA) -> dict:
    """``{(dim, iterations): Study}``: the seed's ``settings`` and the ``extra`` (function, dim, iterations)
    cells (run by the ABC variants alone), equal budgets, seeds 1000 .. 1000 + runs - 1."""
    specs = algorithm_specs()
    studies = {}
    for dim, iterations in list(SETTINGS if settings is None else settings) + [(d, it) for _, d, it in extra]:
        extras = [f for f, d, it in extra if (d, it) == (dim, iterations)]
        algorithms = [specs[a] for a in ALGORITHMS if not extras or a.startswith("ABC")]
        studies[(dim, iterations)] = Study(
            f"abc-functions-d{dim}-it{iterations}", problems=[problem(f, n_var=dim) for f in extras or FUNCTIONS],
            algorithms=algorithms, seeds=[FIRST_SEED + run for run in range(runs)],
            budget={"n_eval": POP * (iterations + 1)})
    return studies


def study_directory(work: Path, dim: int, iterations: int) -> Path:
    return Path(work) / f"d{dim}-it{iterations}"


def load_runs(work: Path, runs: int, settings=None, extra=EXTRA):
    """Every stored run: ``(table, results)``, one row per run and the stored runs (with their best-so-far
    histories) by ``(dim, iterations)``."""
    rows, results = [], {}
    for (dim, iterations), study in build_studies(runs, settings, extra).items():
        results[dim, iterations] = load_results(study_directory(work, dim, iterations), study=study)
        rows += [dict(function=r.problem, dim=dim, iterations=iterations, algorithm=r.algorithm,
                      run=int(r.seed) - FIRST_SEED, seed=int(r.seed), best=float(r.f_best), n_eval=int(r.n_eval),
                      n_gen=int(r.n_gen), time_s=round(float(r.wall_time_s), 4))
                 for r in results[dim, iterations].itertuples()]
    return pd.DataFrame(rows, columns=FIELDS), results


def function_table(df, seed, function: str) -> str:
    """Every dimension, budget and algorithm on ``function``, beside the seed's min / mean / max / time."""
    rows = []
    for (dim, iterations), g in df[df.function == function].groupby(["dim", "iterations"], sort=True):
        for a in ALGORITHMS:
            if len(b := g[g.algorithm == a].best) == 0:
                continue
            s = seed.get((function, dim, iterations if iterations == 3000 else None, a.split("-")[0]))  # eq. 3-3
            s = ["-" if s is None or np.isnan(v) else f"{v:.3g}" for v in (s if s is not None else [None] * 4)]
            t = g[g.algorithm == a]
            rows.append([dim, iterations, a, f"{b.min():.3e}", f"{b.mean():.3e}", f"{b.median():.3e}",
                         f"{b.max():.3e}", f"{t.time_s.mean():.2f}", f"{t.n_eval.mean():.0f}", *s])
    header = ["D", "iter", "alg", "min", "mean", "median", "max", "time s", "n_eval", "seed min", "seed mean",
              "seed max", "seed time s"]
    return f"## {function.capitalize()}\n\n" + markdown_rows(header, rows) + "\n"


def observations(df, seed) -> str:
    """Per cell, the algorithms by measured mean, and by the seed's mean where it has one."""
    lines = []
    for (function, dim, iterations), g in df.groupby(["function", "dim", "iterations"]):
        means = g.groupby("algorithm").best.mean().sort_values()
        order = " < ".join(f"{a} ({v:.2e})" for a, v in means.items())
        ours = sorted(((a, v[1]) for a in ALGORITHMS if iterations != 3000
                       and (v := seed.get((function, dim, None, a))) is not None), key=lambda t: t[1])
        lines.append(f"- {function} D={dim} {iterations} it: measured mean {order}"
                     + ("; seed " + " < ".join(f"{a} ({v:.2e})" for a, v in ours) if ours else ""))
    return "\n".join(lines)


def convergence_figures(results: dict, out: Path) -> list[str]:
    """Median and interquartile range of the best-so-far value over the runs (figs. 3-5 to 3-12), one
    figure per dimension and budget, one panel per function; the file names."""
    names = []
    for (dim, iterations), runs in results.items():
        if len(runs):
            names.append(f"abc_functions_d{dim}-it{iterations}.png")
            save_figure(plot_convergence(runs, "f0_min", log=True, ylabel=f"best-so-far f, D = {dim}"), out / names[-1],
                        dpi=110)
    return names


def report(out: Path, df, results: dict) -> None:
    """Report, per-run CSV and (with the stored ``results``) figures from :func:`load_runs`."""
    exported = df.assign(best=df.best.map(lambda v: repr(float(v))))  # every digit of the best value
    exported.sort_values(["run", "function", "dim", "iterations", "algorithm"], kind="stable").to_csv(
        out / "abc_functions.csv", index=False)
    table = pd.read_csv(HERE / "templates" / "abc_functions_seed.csv")
    seed = {(r.function, r.dim, None if np.isnan(r.iterations) else int(r.iterations), r.algorithm):
            (r.min, r.mean, r.max, r.time_s) for r in table.itertuples()}
    names = convergence_figures(results, out) or [f"abc_functions_d{d}-it{it}.png" for d, it in SETTINGS + [EXTRA[0][1:]]]
    values = {"runs": count_range(df.groupby(["function", "dim", "iterations", "algorithm"]).size()),
              "function_tables": "\n".join(function_table(df, seed, f) for f in FUNCTIONS),
              "observations": observations(df, seed), "figures": "\n".join(f"![{n}]({n})" for n in names)}
    write_report(out / "abc_functions.md", [fill_template(HERE / "templates" / "abc_functions.md", values)])
    print(f"wrote {out / 'abc_functions.md'}")


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    add_study_options(parser, HERE.parent / "out" / "abc_functions", HERE / "reports", runs=30, workers=True)
    args = parser.parse_args()
    if not args.report_only:
        lower_priority()  # be gentle on the shared 2-core machine
        for (dim, iterations), study in build_studies(args.runs).items():  # seed by seed, like with like
            print(run_study(study, study_directory(args.work, dim, iterations),
                            workers=max(1, min(args.workers, 2)), seed_major=True), flush=True)
    args.out.mkdir(parents=True, exist_ok=True)
    table, results = load_runs(args.work, args.runs)
    if table.empty:  # no records (they are not in git): the tables from the committed per-run CSV
        table = pd.read_csv(args.out / "abc_functions.csv")
    report(args.out, table, results)


if __name__ == "__main__":
    main()
