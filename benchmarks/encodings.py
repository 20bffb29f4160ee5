"""Speed-profile encodings against the exact optimum at the CLI's default budget, and DE with a fixed budget.

``--job cli`` (default): the job of ``pymoo-rail optimize CASE`` (NSGA-II, population 40, 50
generations, objectives energy and time error) with speed codes and with switching points, seeds
1..``--seeds``, through the study runner; per encoding and seed the distinct and feasible front
members, the running-time range they cover, the gap of the chosen member (``choose_member``: least
energy within 1 s of the planned time) to the exact optimum at its own running time (``energy_gap``
against ``optimal_front``) and the mean gap of the feasible members. Writes
``benchmarks/reports/default_encoding.md``.

``--job de``: per built-in single-run case (yizhuang, metro-a, wuguang-crh3) and encoding (speed
codes on the gradient/limit partition, with sections <= 200 m, on 12 equal sections; switching
points, also with hold_brake), evaluations per second through ``Problem.evaluate`` (population 200)
and the best net energy DE (pop 40, ``--evals`` evaluations, seed 1) finds in the constrained form
``min energy s.t. |T - T_plan| <= 1 s``; with ``--reference`` also the exact optimum solved at the
DE run's own running time (``solved_energy_gap``), its certificate and the gap. Writes
``benchmarks/reports/problems.md``.

The TTOBench sparse-line comparison (``--job sparse``, whose results docs/ttobench.md gives) is the
script's last version with it: ``git show 0e95633:benchmarks/encodings.py``.

Usage::

    python benchmarks/encodings.py [--case yizhuang] [--seeds 5] [--workers 2] [--work out/default_encoding]
    python benchmarks/encodings.py --job de [--evals 4000] [--reference]
"""

from __future__ import annotations

import argparse
from pathlib import Path

import numpy as np

from pymoo_rail.cases import load_case
from pymoo_rail.experiments import Study, algorithm, load_records, problem, run_study
from pymoo_rail.experiments.encodings import de_budget_row, de_encodings, front_row
from pymoo_rail.experiments.report import add_study_options, markdown_rows, write_filled
from pymoo_rail.optimal import min_running_time, optimal_front

ROOT = Path(__file__).resolve().parents[1]
TEMPLATES = Path(__file__).resolve().parent / "templates"
CLI_ENCODINGS = ("speed_codes", "switching_points")
DE_CASES = ("yizhuang", "metro-a", "wuguang-crh3")


def cli_job(args) -> None:
    """The CLI's default job with both encodings; writes default_encoding.md."""
    case = load_case(args.case)
    study = Study(f"default_encoding_{args.case}",
                  problems=[problem("speed_profile", label=enc, case=args.case,
                                    objectives=["energy", "time_error"], encoding=enc) for enc in CLI_ENCODINGS],
                  algorithms=[algorithm("nsga2", pop_size=40)], seeds=args.seeds, budget={"n_gen": 50})
    if not args.report_only:
        run_study(study, args.work, workers=args.workers)
    reference = optimal_front(case, np.linspace(1.005 * min_running_time(case), 1.4 * case.planned_time_s, 40))
    rows = sorted(front_row(record, case.planned_time_s, reference) for record in load_records(args.work, study))
    table = markdown_rows(["encoding", "seed", "distinct members", "feasible", "feasible time range s", "chosen time s",
                           "chosen gap %", "mean gap %"],
                          [(*r[:5], f"{r[5]:.2f}", f"{r[6]:.2f}", f"{r[7]:.2f}") for r in rows])
    medians = [f"- {enc}: median distinct members {np.median([r[2] for r in mine]):.0f}, median feasible "
               f"{np.median([r[3] for r in mine]):.0f}, median chosen gap {np.median([r[6] for r in mine]):.2f} %, "
               f"median mean gap {np.nanmedian([r[7] for r in mine]):.2f} %"
               for enc in CLI_ENCODINGS for mine in [[r for r in rows if r[0] == enc]]]
    print(write_filled(args.out / "default_encoding.md", TEMPLATES / "default_encoding.md", {
        "case": args.case, "seeds": args.seeds, "table": table, "medians": "\n".join(medians)}), end="")


def de_job(args) -> None:
    """DE with a fixed budget per case and encoding; writes problems.md."""
    header = "| case | encoding | n_var | evals/s | DE energy kWh | running time s |" + (
        " optimum kWh | certificate kWh | gap % |" if args.reference else "")
    print(header)
    rows = []
    for name in DE_CASES:
        case = load_case(name)
        for label, settings in de_encodings(case).items():
            r = de_budget_row(case, settings, args.evals, args.reference)
            rows.append(f"| {name} | {label} | {r['n_var']} | {r['evals_per_s']:,.0f} | {r['energy_kwh']:.3f} | "
                        f"{r['running_time_s']:.2f} |" + (f" {r['optimum_kwh']:.3f} | {r['certificate_kwh']:.3f} | "
                                                          f"{r['gap_pct']:.2f} |" if args.reference else ""))
            print(rows[-1], flush=True)
    write_filled(args.out / "problems.md", TEMPLATES / "problems.md", {
        "evals": args.evals, "header": header, "rule": "|" + "---|" * (header.count("|") - 1), "rows": "\n".join(rows)})


def main(argv=None) -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--job", choices=("cli", "de"), default="cli")
    parser.add_argument("--case", default="yizhuang", help="cli: the case")
    parser.add_argument("--seeds", type=int, default=5, help="cli: seeds 1..N")
    parser.add_argument("--evals", type=int, default=4000, help="de: DE's evaluations")
    parser.add_argument("--reference", action="store_true", help="de: add the exact optimum and the gap")
    add_study_options(parser, ROOT / "out" / "default_encoding", ROOT / "benchmarks" / "reports", workers=True)
    args = parser.parse_args(argv)
    if args.job == "cli":
        cli_job(args)
    else:
        de_job(args)


if __name__ == "__main__":
    main()
