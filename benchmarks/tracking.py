"""Tracking controllers on recommended curves (``pymoo_rail.control.compare_tracking``): ``yizhuang``,
hysteresis on the hold, DE-ideal and DE-tracked curves (Liu (2019), table 5-7); ``metro-a``, PID
against fuzzy PID on the paper's phases and a DE curve, nominal and 15 % heavier train (Meng et al.
(2017), 3.4-3.5). Text: ``benchmarks/templates/tracking_<case>.md``.

Usage: ``nice -n 10 python benchmarks/tracking.py {yizhuang,metro-a} [--gens N] [--seeds 1 2 3]``
"""

from __future__ import annotations

import argparse
import dataclasses
import time
from pathlib import Path

import numpy as np
import pandas as pd

from pymoo_rail.cases import load_case
from pymoo_rail.control import PID, FuzzyPID, Hysteresis, compare_tracking
from pymoo_rail.experiments import Study, algorithm, best_run, build_problem, load_results, problem, run_study
from pymoo_rail.experiments.report import fill_template, lower_priority, write_report
from pymoo_rail.optimal.baselines import constant_cruise
from pymoo_rail.plotting import plot_speed_runs, save_figure
from pymoo_rail.plotting.style import new_figure
from pymoo_rail.problems import SpeedProfileProblem
from pymoo_rail.sim import Simulator, switching_programs

HERE = Path(__file__).resolve().parent
A_KMH, B_VALUES = 2.0, (3.0, 4.0, 5.0, 6.0)
# table 5-7 of the thesis: B -> (energy kWh, running time s); its recommended curve: MOABC, 19.55 kWh at 149.89 s
SEED_TABLE_5_7 = {3.0: (20.53, 150.21), 4.0: (19.94, 150.62), 5.0: (19.28, 151.07), 6.0: (19.97, 151.29)}
SEED_PHASES_M = (262.37, 169.15, 369.69, 198.97)  # Meng et al. 3.3: traction, cruise, coast, brake
KP, KI, KD, PERIODS_S, HEAVIER = 0.5, 0.05, 0.0, (0.2, 1.0), 1.15


def reference_study(case: str, seeds, gens: int) -> Study:
    """DE on min energy with |T - T_plan| <= 0.5 s; on yizhuang scored on the ideal and on the tracked run."""
    common = dict(case=case, objectives=["energy"], time_tolerance_s=0.5)
    if case == "yizhuang":
        tracked = {"controller": "hysteresis", "a_kmh": A_KMH, "b_kmh": 3.0}
        return Study("tracking-yizhuang", problems=[problem("speed_profile", label="DE ideal", **common),
                                                    problem("speed_profile", label="DE tracked", tracking=tracked,
                                                            **common)],
                     algorithms=[algorithm("de", label="DE", pop_size=50, CR=0.9)], seeds=list(seeds),
                     budget={"n_gen": gens})
    return Study("tracking-" + case, problems=[problem("speed_profile", label="DE", **common)],
                 algorithms=[algorithm("de", label="DE", pop_size=40, CR=0.9)], seeds=list(seeds), budget={"n_gen": gens})


def de_curves(study: Study, work: Path, workers: int) -> dict:
    """The ideal run of the least-energy stored DE run of each problem of ``study`` (best of its seeds), and its codes."""
    print(run_study(study, work, workers=max(1, min(workers, 2))), flush=True)
    results, curves = load_results(work, study=study), {}
    for spec in study.problems:
        _, x = best_run(results, spec.display)
        p = build_problem(spec)
        curves[spec.display] = (p.simulator.run(p.encoding.programs(x[None, :])[0]),
                                "codes " + " / ".join(f"{c:.1f}" for c in x) + " km/h")
    return curves


def yizhuang_runs(args):
    """The three curves (with how each was made) and every hysteresis run: the table and the runs."""
    case = load_case("yizhuang")
    code, hold = constant_cruise(SpeedProfileProblem(case, objectives=("energy",)), tol_s=1e-6)
    curves = {"hold": (hold, f"one code, {code:.2f} km/h"),
              **de_curves(reference_study("yizhuang", args.seeds, args.gens), args.work / "tracking_yizhuang",
                          args.workers)}
    controllers = {b: Hysteresis(A_KMH, b) for b in B_VALUES}
    table, runs = compare_tracking({k: c[0] for k, c in curves.items()}, controllers, {"nominal": case}, (args.period,))
    more, more_runs = compare_tracking({"hold": hold}, controllers, {"nominal": case},
                                       [p for p in (0.1, 0.5, 1.0) if p != args.period])
    return curves, pd.concat([table, more], ignore_index=True), {**runs, **more_runs}


def metro_runs(args):
    """The paper's phases and the DE curve, tracked by PID and fuzzy PID: the table and the runs."""
    case = load_case("metro-a")
    ends = np.cumsum(SEED_PHASES_M[:2]) * case.line.length_m / sum(SEED_PHASES_M)  # braking left to the curve
    phases = Simulator(case).run(switching_programs(ends, ("traction", "hold", "coast"), case.line.length_m)[0])
    curves = {"seed phases": (phases, ""), "DE 70 s": de_curves(reference_study("metro-a", (1, 2), args.gens),
                                                                args.work / "tracking_metro_a", args.workers)["DE"]}
    heavier = dataclasses.replace(case, train=dataclasses.replace(case.train, mass_t=case.train.mass_t * HEAVIER))
    table, runs = compare_tracking({k: c[0] for k, c in curves.items()}, {"PID": PID(KP, KI, KD),
                                   "fuzzy PID": FuzzyPID(KP, KI, KD)},
                                   {"nominal": case, f"+{100 * (HEAVIER - 1):.0f} % mass": heavier}, PERIODS_S)
    return curves, table, runs


def yizhuang_report(curves, table, runs, args) -> dict:
    """The CSV (one row per tracked run), the figures and the placeholders of the yizhuang report."""
    table = table.rename(columns={"curve": "reference"}).assign(a_kmh=A_KMH, b_kmh=table["controller"])
    table[["reference", "period_s", "a_kmh", "b_kmh", "energy_kwh", "running_time_s", "stop_error_m", "jerk_ms2",
           "regime_changes", "speed_error_rms_kmh", "speed_error_max_kmh"]].to_csv(args.out / "tracking_yizhuang.csv",
                                                                                   index=False)
    yizhuang_figures(curves, runs, args)
    at = {(n, b): runs[n, "nominal", args.period, b] for n in curves for b in B_VALUES}
    return {"gens": args.gens, "seeds": " ".join(map(str, args.seeds)), "period": args.period,
            "curve_rows": "\n".join(f"| {n} | {how} | {r.energy.net_kwh:.3f} | {r.running_time_s:.2f} |"
                                    for n, (r, how) in curves.items()),
            "table57_rows": "\n".join("| 2, {:g} | {:.2f} | {:.2f} | ".format(b, *SEED_TABLE_5_7[b]) + " | ".join(
                f"{at[n, b].energy.net_kwh:.3f} | {at[n, b].running_time_s:.2f}" for n in curves) + " |" for b in B_VALUES),
            "run_rows": "\n".join(f"| {r.reference} | {r.period_s:g} | {r.b_kmh:g} | {r.energy_kwh:.3f} | "
                                  f"{r.running_time_s:.2f} | {r.stop_error_m:.3f} | {r.jerk_ms2:.2f} | {r.regime_changes} | "
                                  f"{r.speed_error_rms_kmh:.2f} | {r.speed_error_max_kmh:.2f} |"
                                  for r in table.itertuples())}


def metro_report(curves, table, runs, args) -> dict:
    """The CSV (one row per tracked run), the figure and the placeholders of the metro-a report."""
    table.to_csv(args.out / "tracking_metro_a.csv", index=False)
    metro_figure(curves, runs, args.out / "tracking_metro_a.png")
    return {"gens": args.gens,
            "curve_rows": "\n".join(f"| {n} | {r.energy.net_kwh:.3f} | {r.running_time_s:.2f} | {r.speed_kmh.max():.1f} |"
                                    for n, (r, _) in curves.items()),
            "run_rows": "\n".join(
                f"| {r.curve} | {r.train} | {r.period_s:g} | {r.controller} | {r.speed_error_rms_kmh:.3f} | "
                f"{r.speed_error_max_kmh:.3f} | {r.control_error_rms_kmh:.3f} | {r.control_error_max_kmh:.3f} | "
                f"{r.jerk_ms2:.2f} | {r.max_abs_accel_ms2:.3f} | {r.stop_error_m:.3f} | {r.energy_kwh:.3f} | "
                f"{r.running_time_s:.2f} | {r.regime_changes} |" for r in table.itertuples())}


def yizhuang_figures(curves, runs, args) -> None:
    """The tracked profiles for each B beside the DE-tracked curve (cf. fig. 5-8), and table 5-7 as a figure."""
    ref, tracked = curves["DE tracked"][0], {b: runs["DE tracked", "nominal", args.period, b] for b in B_VALUES}
    panels = [(f"A = {A_KMH:g}, B = {b:g} km/h: {tr.energy.net_kwh:.2f} kWh, {tr.running_time_s:.1f} s",
               [("recommended (ideal run)", ref.position_m, ref.speed_ms, "r", "-"),
                ("tracked", tr.position_m, tr.speed_ms, "b", "--"), ("limit", tr.position_m, tr.limit_ms, "k", ":")])
              for b, tr in tracked.items()]
    save_figure(plot_speed_runs(panels, figsize=(12, 7.5)), args.out / "tracking_yizhuang_profiles.png", dpi=110)
    fig, axes = new_figure(1, 2, figsize=(11, 4))
    for k, (ax, unit) in enumerate(zip(axes[0], ("net energy (kWh)", "running time (s)"))):
        for n in curves:
            tracked = [runs[n, "nominal", args.period, b] for b in B_VALUES]
            ax.plot(B_VALUES, [t.energy.net_kwh if k == 0 else t.running_time_s for t in tracked], "o-", label=n)
        ax.plot(B_VALUES, [SEED_TABLE_5_7[b][k] for b in B_VALUES], "ks--", label="table 5-7 of the thesis")
        ax.set(xlabel="B (km/h), A = 2 km/h", ylabel=unit)
        ax.grid(alpha=0.3)
    axes[0, 0].legend(fontsize=8)
    save_figure(fig, args.out / "tracking_yizhuang_table.png", dpi=110)


def metro_figure(curves, runs, path: Path) -> None:
    """Figs. 8-10 analogue: speed over distance and time, and jerk, of both controllers on the DE curve."""
    ref = curves["DE 70 s"][0]
    fig, axes = new_figure(3, 2, figsize=(13, 10))
    for col, period in enumerate(PERIODS_S):
        ax_x, ax_t, ax_j = axes[:, col]
        ax_x.plot(ref.position_m, ref.speed_kmh, "k-", lw=1.5, label="target curve")
        ax_t.plot(ref.time_s, ref.speed_kmh, "k-", lw=1.5, label="target curve")
        for name, style in (("PID", "r--"), ("fuzzy PID", "b-.")):
            tr = runs["DE 70 s", "nominal", period, name]
            ax_x.plot(tr.position_m, tr.speed_kmh, style, lw=1.0, label=name)
            ax_t.plot(tr.time_s, tr.speed_kmh, style, lw=1.0, label=name)
            dt = np.diff(tr.time_s)
            ok = dt > 0
            ax_j.plot(tr.time_s[1:][ok], np.diff(tr.accel_ms2)[ok] / dt[ok], style, lw=0.8, label=name)
        ax_x.set(xlabel="position (m)", ylabel="speed (km/h)", title=f"metro-a, DE 70 s: control period {period:g} s")
        ax_t.set(xlabel="time (s)", ylabel="speed (km/h)")
        ax_j.set(xlabel="time (s)", ylabel="rate of change of acceleration (m/s^3)")
        for ax in (ax_x, ax_t, ax_j):
            ax.grid(alpha=0.3)
        ax_x.legend(fontsize=8)
    save_figure(fig, path, dpi=100)


def main(argv=None) -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("case", choices=("yizhuang", "metro-a"))
    parser.add_argument("--gens", type=int, default=None, help="DE generations (yizhuang 200, metro-a 150)")
    parser.add_argument("--seeds", type=int, nargs="+", default=[1, 2, 3], help="DE seeds (yizhuang)")
    parser.add_argument("--period", type=float, default=0.2, help="control period of table 5-7 (yizhuang)")
    parser.add_argument("--out", type=Path, default=HERE / "reports")
    parser.add_argument("--work", type=Path, default=HERE.parent / "out", help="parent of the DE study folder")
    parser.add_argument("--workers", type=int, default=2, help="process pool size (at most 2)")
    args = parser.parse_args(argv)
    args.gens = args.gens or (200 if args.case == "yizhuang" else 150)
    lower_priority()
    args.out.mkdir(parents=True, exist_ok=True)
    start = time.perf_counter()
    runs_of, report_of = (yizhuang_runs, yizhuang_report) if args.case == "yizhuang" else (metro_runs, metro_report)
    values = report_of(*runs_of(args), args)
    stem = "tracking_" + args.case.replace("-", "_")
    write_report(args.out / f"{stem}.md", [fill_template(HERE / "templates" / f"{stem}.md",
                                                         {**values, "seconds": f"{time.perf_counter() - start:.0f}"})],
                 newline=False)
    print(f"wrote {args.out / stem}.md")


if __name__ == "__main__":
    main()
