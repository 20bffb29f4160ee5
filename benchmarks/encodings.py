"""Speed-profile encodings against the exact optimum: the CLI's default job, and TTOBench's long sparse lines.

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

``--job sparse``: per track of TTOBench's 48.5 km reference family (and the 20 km "wind" variant)
with the Dutch VIRM6 at 1.15 x its minimum running time, the gap (%) to the exact optimum of NSGA2's
best member within 2 s of the planned time (pop 40, ``--gen`` generations), per seed, for the
default speed codes (a code and a coasting point per section where sections average more than 2 km,
codes from the planned mean speed), "codes from 10 km/h" (the earlier default: codes bounded below
by 10 km/h) and "1 km pieces" (``max_section_m=1000``). ``--form front``: objectives energy and time
error (the protocol of ``benchmarks/ttobench_release.py``); ``punctual``: energy alone with
``|T - T_plan| <= 2 s``; ``window``: the front form with ``time_window_s="default"``. A run up to 2 s
late needs a little less energy than the optimum at the planned time, so gaps can be slightly
negative. Prints a table.

Usage::

    python benchmarks/encodings.py [--case yizhuang] [--seeds 5] [--workers 2] [--work out/default_encoding]
    python benchmarks/encodings.py --job de [--evals 4000] [--reference]
    python benchmarks/encodings.py --job sparse [--gen 200] [--seeds 3] [--only ID ...] [--form punctual]
"""

from __future__ import annotations

import argparse
import time
import warnings
from pathlib import Path

import numpy as np
from pymoo.algorithms.moo.nsga2 import NSGA2
from pymoo.algorithms.soo.nonconvex.de import DE
from pymoo.optimize import minimize

from pymoo_rail.cases import load_case
from pymoo_rail.cases.ttobench import TTOBenchWarning, from_ttobench
from pymoo_rail.cases.ttobench_release import release_pairs
from pymoo_rail.experiments import Study, algorithm, choose_member, load_records, problem, run_study
from pymoo_rail.experiments.report import markdown_rows, write_report
from pymoo_rail.indicators import energy_gap
from pymoo_rail.optimal import min_running_time, optimal_front, optimal_profile, solved_energy_gap
from pymoo_rail.problems import SpeedProfileProblem
from pymoo_rail.problems.encodings import SwitchingPoints

ROOT = Path(__file__).resolve().parents[1]
CLI_ENCODINGS = ("speed_codes", "switching_points")
TIME_TOL_S = 2.0
FORMS = {"front": {"objectives": ("energy", "time_error")},
         "window": {"objectives": ("energy", "time_error"), "time_window_s": "default"},
         "punctual": {"objectives": ("energy",), "time_tolerance_s": TIME_TOL_S}}
SPARSE_ENCODINGS = {"default": {}, "codes from 10 km/h": {}, "1 km pieces": {"max_section_m": 1000.0}}
EARLIER_FLOOR_KMH = 10.0
DE_CASES = ("yizhuang", "metro-a", "wuguang-crh3")
DE_ENCODINGS = {
    "speed codes, gradient/limit partition": dict(encoding="speed_codes"),
    "speed codes, gradient/limit, sections <= 200 m": dict(encoding="speed_codes", max_section_m=200.0),
    "speed codes, 12 equal sections": dict(encoding="speed_codes", partition="equal", n_sections=12),
    "switching points": dict(encoding="switching_points"),
}


def member_row(record, case, reference) -> tuple:
    """One run of the CLI job: members, feasible ones, their time range, the chosen member and the gaps."""
    front = record["front"]
    F, CV = np.asarray(front["F"]), np.asarray(front["CV"])
    t, e = np.asarray(front["extras"]["running_time_s"]), np.asarray(front["extras"]["energy_kwh"])
    ok = CV <= 0
    chosen = choose_member(F, CV, t, e, case.planned_time_s)
    gap_chosen = energy_gap(np.array([[t[chosen], e[chosen]]]), reference)["points"]["gap_rel"].iloc[0]
    mean_gap = energy_gap(np.column_stack([t[ok], e[ok]]), reference)["mean_gap_rel"] if ok.any() else np.nan
    return (record["problem_label"], record["seed"], len(F), int(ok.sum()),
            f"{t[ok].min():.1f}-{t[ok].max():.1f}" if ok.any() else "-", t[chosen], 100 * gap_chosen, 100 * mean_gap)


def cli_job(args) -> None:
    """The CLI's default job with both encodings; writes default_encoding.md."""
    case = load_case(args.case)
    study = Study(f"default_encoding_{args.case}",
                  problems=[problem("speed_profile", label=enc, case=args.case,
                                    objectives=["energy", "time_error"], encoding=enc) for enc in CLI_ENCODINGS],
                  algorithms=[algorithm("nsga2", pop_size=40)], seeds=args.seeds, budget={"n_gen": 50})
    run_study(study, args.work, workers=args.workers)
    reference = optimal_front(case, np.linspace(1.005 * min_running_time(case), 1.4 * case.planned_time_s, 40))
    rows = sorted(member_row(record, case, reference) for record in load_records(args.work, study))
    lines = [f"# Default encoding at the CLI's default budget ({args.case}, NSGA-II 40 x 50, energy and time error)",
             "", f"Written by `benchmarks/encodings.py` ({args.seeds} seeds); gaps to the exact optimum at the "
             "same running time, over the feasible members whose running time lies in the reference range "
             "(1.005 x the minimum to 1.4 x the planned time). Gaps of a few hundredths of a percent below zero "
             "are within the exact solver's accuracy (the reference is interpolated between 40 optimal points).", "",
             markdown_rows(["encoding", "seed", "distinct members", "feasible", "feasible time range s",
                            "chosen time s", "chosen gap %", "mean gap %"],
                           [(*r[:5], f"{r[5]:.2f}", f"{r[6]:.2f}", f"{r[7]:.2f}") for r in rows]), ""]
    for enc in CLI_ENCODINGS:
        mine = [r for r in rows if r[0] == enc]
        lines.append(f"- {enc}: median distinct members {np.median([r[2] for r in mine]):.0f}, median feasible "
                     f"{np.median([r[3] for r in mine]):.0f}, median chosen gap {np.median([r[6] for r in mine]):.2f} %, "
                     f"median mean gap {np.nanmedian([r[7] for r in mine]):.2f} %")
    write_report(args.out / "default_encoding.md", lines)
    print("\n".join(lines))


def evals_per_s(problem, pop: int = 200, repeats: int = 5) -> float:
    """Evaluations per second through ``Problem.evaluate`` (random vectors, after a compile call)."""
    X = problem.xl + np.random.default_rng(0).random((pop, problem.n_var)) * (problem.xu - problem.xl)
    problem.evaluate(X[:2])
    start = time.perf_counter()
    for _ in range(repeats):
        problem.evaluate(X)
    return pop * repeats / (time.perf_counter() - start)


def de_row(name: str, case, label: str, settings: dict, args) -> str:
    """One case and encoding: throughput, DE's energy and time, and (``--reference``) the gap to the optimum."""
    problem_ = SpeedProfileProblem(case, objectives=("energy",), time_tolerance_s=1.0, **settings)
    rate = evals_per_s(problem_)
    tr = problem_.trajectory(minimize(problem_, DE(pop_size=40), ("n_evals", args.evals), seed=1).X)
    row = f"| {name} | {label} | {problem_.n_var} | {rate:,.0f} | {tr.energy.net_kwh:.3f} | {tr.running_time_s:.2f} |"
    if args.reference:  # at the run's own time: a solve may end 0.5 s off, ~1 kWh along a 2.5 kWh/s slope
        point = solved_energy_gap(np.array([[tr.running_time_s, tr.energy.net_kwh]]), case)["points"]
        best, bound = float(point["optimal_kwh"].iloc[0]), float(point["energy_bound_kwh"].iloc[0])
        row += f" {best:.3f} | {bound:.3f} | {100 * (tr.energy.net_kwh / best - 1):.2f} |"
    return row


def de_job(args) -> None:
    """DE with a fixed budget per case and encoding; writes problems.md."""
    header = "| case | encoding | n_var | evals/s | DE energy kWh | running time s |" + (
        " optimum kWh | certificate kWh | gap % |" if args.reference else "")
    print(header)
    rows = []
    for name in DE_CASES:
        case = load_case(name)
        hold_brake = tuple("hold_brake" if r == "hold" else r for r in SwitchingPoints.build(case).regimes)
        encodings = {**DE_ENCODINGS, "switching points, hold_brake": dict(encoding="switching_points",
                                                                         regimes=hold_brake)}
        for label, settings in encodings.items():
            rows.append(de_row(name, case, label, settings, args))
            print(rows[-1], flush=True)
    write_report(args.out / "problems.md", [
        "# Speed-profile problems: throughput and DE with a fixed budget", "",
        f"DE (pop 40, {args.evals} evaluations, seed 1), constrained form |T - T_plan| <= 1 s; evaluations per "
        "second through `Problem.evaluate` with a population of 200.", "",
        header, "|" + "---|" * (header.count("|") - 1), *rows])


def sparse_gap(case, optimum_kwh: float, form: dict, label: str, seed: int, n_gen: int) -> tuple[float, int]:
    """NSGA2's best member within 2 s of the planned time against the optimum (%), and the problem's n_var."""
    problem_ = SpeedProfileProblem(case, **form, **SPARSE_ENCODINGS[label])
    if label == "codes from 10 km/h":  # pymoo samples within xl; the programs take any code
        n = problem_.encoding.n_sections
        problem_.xl[:n] = np.minimum(problem_.xl[:n], EARLIER_FLOOR_KMH)
    F = minimize(problem_, NSGA2(pop_size=40), ("n_gen", n_gen), seed=seed).F
    if F is None:  # no member met the constraints
        return float("nan"), problem_.n_var
    F = np.atleast_2d(F)
    close = F[F[:, 1] <= TIME_TOL_S] if F.shape[1] > 1 else F  # punctual: feasible only
    return (100.0 * (close[:, 0].min() / optimum_kwh - 1.0) if close.size else float("nan")), problem_.n_var


def sparse_job(args) -> None:
    """Print the gaps of NSGA2 on the sparse reference family, per track, encoding and seed."""
    print("| track | encoding | n_var | gaps % by seed | median % | CPU s |\n|---|---|---|---|---|---|")
    for track, train in release_pairs(ROOT / "tests" / "data" / "ttobench"):
        if not track.stem.startswith("00_") or (args.only and track.stem not in args.only):
            continue
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", TTOBenchWarning)
            case = from_ttobench(track, train, 0, -1, 1.0)
        case = case.with_planned_time(1.15 * min_running_time(case))
        optimum = optimal_profile(case, case.planned_time_s, certify=False).energy.net_kwh
        for label in args.encodings:
            start = time.process_time()
            runs = [sparse_gap(case, optimum, FORMS[args.form], label, seed, args.gen) for seed in args.seeds]
            gaps = [g for g, _ in runs]
            print(f"| {track.stem} | {label} | {runs[-1][1]} | {', '.join(f'{g:.2f}' for g in gaps)} | "
                  f"{np.median(gaps):.2f} | {time.process_time() - start:.1f} |", flush=True)


def main(argv=None) -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--job", choices=("cli", "de", "sparse"), default="cli")
    parser.add_argument("--case", default="yizhuang", help="cli: the case")
    parser.add_argument("--seeds", type=int, nargs="+", default=None, help="cli: N seeds (5); sparse: the seeds (1 2 3)")
    parser.add_argument("--workers", type=int, default=2)
    parser.add_argument("--work", type=Path, default=ROOT / "out" / "default_encoding", help="cli: study records")
    parser.add_argument("--out", type=Path, default=ROOT / "benchmarks" / "reports", help="cli: report folder")
    parser.add_argument("--evals", type=int, default=4000, help="de: DE's evaluations")
    parser.add_argument("--reference", action="store_true", help="de: add the exact optimum and the gap")
    parser.add_argument("--gen", type=int, default=200, help="sparse: NSGA2 generations")
    parser.add_argument("--only", nargs="*", help="sparse: track ids")
    parser.add_argument("--form", choices=tuple(FORMS), default="front")
    parser.add_argument("--encodings", nargs="*", choices=tuple(SPARSE_ENCODINGS), default=tuple(SPARSE_ENCODINGS))
    args = parser.parse_args(argv)
    if args.job == "cli":
        args.seeds = args.seeds[0] if args.seeds else 5
        cli_job(args)
    elif args.job == "de":
        de_job(args)
    else:
        args.seeds = args.seeds or [1, 2, 3]
        sparse_job(args)


if __name__ == "__main__":
    main()
