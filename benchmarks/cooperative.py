"""Two trains sharing braking energy (Chen et al. 2017): every offset and the gradient study, with statistics.

A thin script over ``pymoo_rail.experiments.cooperative`` and ``run_study``:

1. offsets: ``CooperativeTrainsProblem(cooperative-pair, offset_s=x)`` for x in -45, 0, 45, 90, 135 s,
   plain pymoo ``GA(pop_size=60)`` for 6000 evaluations, ``--seeds`` seeds (default 15);
2. gradients (Chen et al. 2017, fig. 6): the same with every gradient times phi (``--phis``, default
   0.7, 0.4, 0), ``--phi-seeds`` seeds (default 15).

Each run is compared with the exact uncoordinated baseline at its phi (``exact_baseline``, each
train exactly optimal alone, recomputed here: about a CPU second each): median, IQR and a one-sample
Wilcoxon signed-rank test. The report also shows, from the kernel's traces, how much regenerated
energy there is to share at each offset. Records: ``--work`` (a second invocation skips finished
runs); report: ``<--out>/cooperative.md``. The offsets study's seeds 1-10 at x = -45 s are the user's
call of docs/cooperative.md (``minimize(CooperativeTrainsProblem(case, offset_s=-45), GA(pop_size=60),
("n_eval", 6000), seed=s)``).

``--nested OUTER_POP OUTER_GEN`` runs instead the nested GA of the paper once (``nested_minimize``,
inner GA 100 x 80, seed 1) after timing one evaluation, and writes ``<--out>/cooperative_nested.md``.

Usage: ``python benchmarks/cooperative.py [--seeds 15] [--phis 0.7,0.4,0] [--phi-seeds 15] [--workers 2]``
(set ``NUMBA_NUM_THREADS=1`` when the pool has several workers), ``python benchmarks/cooperative.py
--nested 8 6 --offset 45``.
"""

from __future__ import annotations

import argparse
from pathlib import Path

import pandas as pd

from pymoo_rail.cases import load_case
from pymoo_rail.experiments import load_results, run_study
from pymoo_rail.experiments.cooperative import exact_baselines, nested_run, offsets_study, savings_table, sharing_rows
from pymoo_rail.experiments.report import add_study_options, fill_template, lower_priority, write_report

REPORTS = Path(__file__).parent / "reports"
TEMPLATES = Path(__file__).resolve().parent / "templates"
# the earlier model (the paper's subsection encoding on its own integrator, DE with the punctuality
# repair, train-by-train turns and a joint polish; one run per offset) against its heuristic baseline
EARLIER = {1.0: (25.57, {-45.0: 22.45, 0.0: 24.51, 45.0: 25.47, 90.0: 25.39, 135.0: 25.01}),
           0.7: (26.71, {-45.0: 23.91, 0.0: 25.43, 45.0: 26.74, 90.0: 26.54, 135.0: 25.91}),
           0.4: (27.86, {-45.0: 24.22, 0.0: 26.14, 45.0: 27.82, 90.0: 27.82, 135.0: 26.70}),
           0.0: (29.49, {-45.0: 25.64, 0.0: 27.66, 45.0: 29.49, 90.0: 29.49, 135.0: 27.94})}
PAPER = {-45.0: "1.3 %", 45.0: "5.8 %", 135.0: "3.8 %"}  # Chen et al. (2017) sections 4.2-4.3


def savings_lines(table: pd.DataFrame) -> list[str]:
    lines = ["| phi | x (s) | seeds | exact baseline | shared by chance | median result | best | median saving "
             "(IQR) | Wilcoxon p | earlier model (one run) | paper |", "|---|---|---|---|---|---|---|---|---|---|---|"]
    for r in table.itertuples():
        b_old, runs = EARLIER.get(r.phi, (None, {}))
        earlier = f"{runs[r.offset_s]:.2f} ({100 * (1 - runs[r.offset_s] / b_old):.1f} % vs {b_old:.2f})" if runs else ""
        paper = PAPER.get(r.offset_s, "") if r.phi == 1.0 else ""
        lines.append(f"| {r.phi:g} | {r.offset_s:+g} | {r.seeds} | {r.baseline_kwh:.3f} | {r.chance_kwh:.3f} | "
                     f"{r.median_kwh:.3f} | {r.best_kwh:.3f} | {r.saving_median_pct:.2f} % ({r.saving_q1_pct:.2f}-"
                     f"{r.saving_q3_pct:.2f}) | {r.p:.2g} {r.verdict} | {earlier} | {paper} |")
    return lines


def potential_lines(case, results: pd.DataFrame, paper_results, base) -> list[str]:
    """Regenerated energy per train and offset, from the traces of the exact runs and of the best GA runs."""
    lines = ["| x (s) | runs | A regenerates (kWh, when on the clock) | of it while B moves | B regenerates | "
             "of it while A moves | shared |", "|---|---|---|---|---|---|---|"]
    for x, label, pot in sharing_rows(case, results, paper_results, base):
        a, b = pot.iloc[0], pot.iloc[1]
        lines.append(f"| {x:+g} | {label} | {a.regen_kwh:.2f} ({a.braking_from_s:.0f}-{a.braking_to_s:.0f} s) | "
                     f"{a.while_others_move_kwh:.2f} | {b.regen_kwh:.2f} ({b.braking_from_s:.0f}-"
                     f"{b.braking_to_s:.0f} s) | {b.while_others_move_kwh:.2f} | "
                     f"{a.others_draw_kwh + b.others_draw_kwh:.2f} |")
    return lines


def run_studies(args, phis: list[float]):
    """Run (or, with ``--report-only``, read) the offsets, gradient and paper-encoding studies."""
    studies = [(offsets_study("cooperative_offsets", [1.0], args.seeds), args.work / "offsets")]
    if phis and args.phi_seeds > 0:
        studies.append((offsets_study("cooperative_gradients", phis, args.phi_seeds), args.work / "gradients"))
    paper_dir = args.work / "paper_encoding"
    paper = [(offsets_study("cooperative_paper_encoding", [1.0], args.paper_seeds, paper_encoding=True), paper_dir)
             ] if args.paper_seeds > 0 else []  # a study needs a seed
    for study, directory in studies + paper:
        if not args.report_only:
            run_study(study, directory, workers=args.workers, seed_major=True)
    missing = [str(d) for _, d in studies if not d.exists()]
    if missing:
        raise SystemExit(f"no study records in {', '.join(missing)}: run without --report-only first")
    results = pd.concat([load_results(d) for _, d in studies], ignore_index=True)
    return results, (load_results(paper_dir) if paper_dir.exists() else None)


def report_text(results, paper_results, baselines) -> str:
    """The report: savings per (phi, offset), the baselines, what there is to share, the paper's encoding."""
    table = savings_table(results, baselines)
    paper_table = savings_table(paper_results, {1.0: baselines[1.0]}) if paper_results is not None else None
    paper_section = "" if paper_table is None or not len(paper_table) else "\n\n" + fill_template(
        TEMPLATES / "cooperative_paper.md", {"savings": "\n".join(savings_lines(paper_table)),
                                              "cpu_s": f"{paper_table['cpu_s'].sum():.0f}"}).rstrip("\n")
    return fill_template(TEMPLATES / "cooperative.md", {
        "savings": "\n".join(savings_lines(table)),
        "baselines": "; ".join(f"phi {phi:g}: {' + '.join(f'{e:.3f}' for e in b.energies_kwh)} = {b.energy_kwh:.3f}"
                               for phi, b in baselines.items()),
        "cpu_s": f"{table['cpu_s'].sum():.0f}", "cpu_per_run_s": f"{table['cpu_s'].sum() / table['seeds'].sum():.1f}",
        "feasible": table["feasible"].sum(), "runs": table["seeds"].sum(),
        "potential": "\n".join(potential_lines(load_case("cooperative-pair"), results, paper_results, baselines[1.0])), "paper_section": paper_section})


def nested_text(args, case) -> str:
    """The nested GA of Chen et al. (2017), once, at ``--nested OUTER_POP OUTER_GEN`` (inner GA 100 x 80)."""
    outer_pop, outer_gen = args.nested
    run = nested_run(case, args.offset, outer_pop, outer_gen)
    problem, x, f, sol, base, per_eval_s = (run[k] for k in ("problem", "x", "f_kwh", "solution", "baseline",
                                                             "per_eval_s"))
    paper, asked = 24 * 20 * 100 * 80, outer_pop * outer_gen * 100 * 80  # pymoo's GA: pop_size per generation
    return fill_template(TEMPLATES / "cooperative_nested.md", {
        "outer_pop": outer_pop, "outer_gen": outer_gen, "offset": f"{args.offset:g}", "evaluations": f"{asked:,}",
        "cpu_min": f"{run['cpu_s'] / 60:.1f}", "per_eval_ms": f"{1e3 * per_eval_s:.2f}", "paper_evaluations": f"{paper:,}",
        "paper_cpu_min": f"{paper * per_eval_s / 60:.0f}", "f_kwh": f"{f:.3f}", "a_kwh": f"{sol.traction_a_kwh:.3f}",
        "b_kwh": f"{sol.traction_b_kwh:.3f}", "shared_kwh": f"{sol.shared_kwh:.3f}", "feasible": sol.feasible,
        "constraints": ", ".join(f"{k} {v:.3g}" for k, v in sol.constraints.items()),
        "baseline_kwh": f"{base.energy_kwh:.3f}", "saving_pct": f"{100 * (1 - f / base.energy_kwh):.2f}",
        "brake_a_m": f"{x[problem.brake_columns[0]]:.1f}", "brake_b_m": f"{x[problem.brake_columns[1]]:.1f}"})


def main(argv=None) -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--seeds", type=int, default=15)
    parser.add_argument("--phis", default="0.7,0.4,0")
    parser.add_argument("--phi-seeds", type=int, default=15)
    parser.add_argument("--paper-seeds", type=int, default=0,
                        help="also the same GA call on the paper's encoding (CooperativeSeedProblem), this many seeds")
    parser.add_argument("--nested", type=int, nargs=2, metavar=("OUTER_POP", "OUTER_GEN"),
                        help="instead: the paper's nested GA once (inner GA 100 x 80), report cooperative_nested.md")
    parser.add_argument("--offset", type=float, default=45.0, help="offset of the --nested run (s)")
    parser.add_argument("--workers", type=int, default=2)
    add_study_options(parser, Path(__file__).resolve().parents[1] / "out" / "cooperative_study", REPORTS)
    args = parser.parse_args(argv)
    lower_priority()
    case = load_case("cooperative-pair")
    if args.nested:
        path, text = args.out / "cooperative_nested.md", nested_text(args, case)
    else:
        phis = [float(p) for p in args.phis.split(",") if p.strip()]
        results, paper_results = run_studies(args, phis)
        path, text = args.out / "cooperative.md", report_text(results, paper_results, exact_baselines(case, [1.0] + phis))
    write_report(path, [text], newline=False)
    print(text)


if __name__ == "__main__":
    main()
