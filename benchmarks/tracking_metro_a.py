"""Seed 002 sections 3.4-3.5: PID against adaptive fuzzy PID tracking a target curve on metro-a.

Two target curves (ideal simulator runs):

- ``seed phases``: seed 002's optimised phases (traction 262.37 m, cruise 169.15 m, coast
  369.69 m), then braking on the braking curve at the latest moment;
- ``DE 70 s``: the minimum-energy speed-code curve with |T - T_plan| <= 0.5 s found by pymoo's DE
  through ``SpeedProfileProblem`` (best of seeds 1 and 2; the runs go through
  ``pymoo_rail.experiments.run_study``, one record per run under ``--work``).

Each is tracked by ``PID(kp, ki, kd)`` and ``FuzzyPID`` with the same base gains, at control
periods 0.2 s and 1 s, by the nominal train and by a train 15 % heavier than the one the curve
was computed for (the robustness seed 002 claims for the fuzzy tuner). Figures like seed 002
figs. 8-10 (distance-speed, time-speed, rate of change of acceleration) for the first curve.

Writes ``benchmarks/reports/tracking_metro_a.md``, ``tracking_metro_a.csv`` (appended run by run)
and ``tracking_metro_a.png``.

Usage: ``python benchmarks/tracking_metro_a.py [--case metro-a] [--gens 150]``. ``--case`` takes
any case name or file (the script was first tested on ``yizhuang``, before metro-a was built in).
"""

from __future__ import annotations

import argparse
import csv
import dataclasses
import time
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

from pymoo_rail.cases import load_case  # noqa: E402
from pymoo_rail.control import PID, FuzzyPID, track  # noqa: E402
from pymoo_rail.experiments import (Study, algorithm, best_run, build_problem, load_results, problem,  # noqa: E402
                                     run_study)
from pymoo_rail.plotting import save_figure  # noqa: E402
from pymoo_rail.sim import Simulator, switching_programs  # noqa: E402

REPORTS = Path(__file__).parent / "reports"
SEED_PHASES_M = (262.37, 169.15, 369.69, 198.97)  # seed 002 3.3: traction, cruise, coast, brake
KP, KI, KD = 0.5, 0.05, 0.0
PERIODS_S = (0.2, 1.0)
HEAVIER = 1.15
FIELDS = ("curve", "train", "period_s", "controller", "energy_kwh", "running_time_s", "stop_error_m", "jerk_ms2",
          "max_abs_accel_ms2", "regime_changes", "speed_error_rms_kmh", "speed_error_max_kmh",
          "control_error_rms_kmh", "control_error_max_kmh")


def seed_phase_reference(case, sim):
    """Seed 002's phases scaled to the line length, the braking left to the braking curve."""
    scale = case.line.length_m / sum(SEED_PHASES_M)
    ends = np.cumsum(SEED_PHASES_M[:2]) * scale
    return sim.run(switching_programs(ends, ("traction", "hold", "coast"), case.line.length_m)[0])


def reference_study(case_name: str, gens: int, seeds=(1, 2)) -> Study:
    """DE (population 40, CR 0.9) on min energy with |T - T_plan| <= 0.5 s, ``gens`` generations."""
    return Study("tracking-" + Path(str(case_name)).stem,
                 problems=[problem("speed_profile", label="DE", case=str(case_name), objectives=["energy"],
                                   time_tolerance_s=0.5)],
                 algorithms=[algorithm("de", label="DE", pop_size=40, CR=0.9)], seeds=list(seeds),
                 budget={"n_gen": gens})


def de_reference(sim, study, work: Path, workers: int):
    """The ideal run of the least-energy DE run of ``study`` (best of its seeds, through the study runner)."""
    print(run_study(study, work, workers=max(1, min(workers, 2))), flush=True)
    _, x = best_run(load_results(work, study=study), "DE")
    return sim.run(build_problem(study.problems[0]).encoding.programs(x[None, :])[0])


def heavier(case, factor):
    return dataclasses.replace(case, train=dataclasses.replace(case.train, mass_t=case.train.mass_t * factor))


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--case", default="metro-a")
    parser.add_argument("--gens", type=int, default=150)
    parser.add_argument("--out", default=str(REPORTS))
    parser.add_argument("--work", type=Path, default=Path(__file__).resolve().parents[1] / "out",
                        help="parent of the DE study folder (one record per run, not committed)")
    parser.add_argument("--workers", type=int, default=2, help="process pool size (at most 2)")
    args = parser.parse_args()
    out_dir = Path(args.out)
    out_dir.mkdir(parents=True, exist_ok=True)
    stem = "tracking_metro_a" if args.case == "metro-a" else f"tracking_{Path(str(args.case)).stem}_pid"
    t_start = time.perf_counter()

    case = load_case(args.case)
    sim = Simulator(case)
    curves = {"seed phases": seed_phase_reference(case, sim), "DE 70 s" if args.case == "metro-a" else "DE": None}
    study = reference_study(args.case, args.gens)
    curves[list(curves)[1]] = de_reference(sim, study, args.work / study.name.replace("-", "_"), args.workers)
    trains = {"nominal": case, f"+{100 * (HEAVIER - 1):.0f} % mass": heavier(case, HEAVIER)}
    controllers = {"PID": PID(KP, KI, KD), "fuzzy PID": FuzzyPID(KP, KI, KD)}
    for name, ref in curves.items():
        print(f"{name}: ideal {ref.energy.net_kwh:.3f} kWh, {ref.running_time_s:.2f} s, "
              f"peak {ref.speed_kmh.max():.1f} km/h", flush=True)

    rows, runs = [], {}
    with (out_dir / f"{stem}.csv").open("w", newline="") as fh:
        writer = csv.DictWriter(fh, fieldnames=FIELDS)
        writer.writeheader()
        for curve, ref in curves.items():
            for train, tcase in trains.items():
                for period in PERIODS_S:
                    for cname, ctrl in controllers.items():
                        tr = track(tcase, ref, ctrl, control_period_s=period)
                        runs[curve, train, period, cname] = tr
                        s = tr.summary
                        row = {"curve": curve, "train": train, "period_s": period, "controller": cname,
                               "energy_kwh": tr.energy.net_kwh, "running_time_s": tr.running_time_s,
                               "stop_error_m": tr.stop_error_m, "jerk_ms2": s["jerk_ms2"],
                               "max_abs_accel_ms2": s["max_abs_accel_ms2"],
                               "regime_changes": int(s["regime_changes"]),
                               "speed_error_rms_kmh": s["speed_error_rms_kmh"],
                               "speed_error_max_kmh": s["speed_error_max_kmh"],
                               "control_error_rms_kmh": s["control_error_rms_kmh"],
                               "control_error_max_kmh": s["control_error_max_kmh"]}
                        rows.append(row)
                        writer.writerow(row)
                        fh.flush()
                        print(f"{curve:12s} {train:12s} T_c={period:.1f} {cname:9s}: rms {s['speed_error_rms_kmh']:.3f} "
                              f"max {s['speed_error_max_kmh']:.3f} km/h (controlled part rms "
                              f"{s['control_error_rms_kmh']:.3f} max {s['control_error_max_kmh']:.3f}), "
                              f"jerk {s['jerk_ms2']:.2f}, stop "
                              f"{tr.stop_error_m:.3f} m, {tr.energy.net_kwh:.3f} kWh, {tr.running_time_s:.2f} s",
                              flush=True)

    # ---- figures like seed 002 figs. 8-10 (the optimised curve: traction phases in the controlled part)
    tracking_figure(curves, runs, case, out_dir, stem)

    # ---- report
    write_report(case, args, t_start, curves, rows, stem, out_dir)
    print(f"wrote {out_dir / (stem + '.md')}")


def tracking_figure(curves, runs, case, out_dir, stem):
    """Figs. 8-10 analogue: speed and control of each controller on the optimised curve, per control period."""
    curve = list(curves)[1]
    ref = curves[curve]
    fig, axes = plt.subplots(3, 2, figsize=(13, 10))
    for col, period in enumerate(PERIODS_S):
        ax_x, ax_t, ax_j = axes[:, col]
        ax_x.plot(ref.position_m, ref.speed_kmh, "k-", lw=1.5, label="target curve")
        ax_t.plot(ref.time_s, ref.speed_kmh, "k-", lw=1.5, label="target curve")
        for cname, style in (("PID", "r--"), ("fuzzy PID", "b-.")):
            tr = runs[curve, "nominal", period, cname]
            ax_x.plot(tr.position_m, tr.speed_kmh, style, lw=1.0, label=cname)
            ax_t.plot(tr.time_s, tr.speed_kmh, style, lw=1.0, label=cname)
            dt = np.diff(tr.time_s)
            ok = dt > 0
            jerk = np.diff(tr.accel_ms2)[ok] / dt[ok]
            ax_j.plot(tr.time_s[1:][ok], jerk, style, lw=0.8, label=cname)
        ax_x.set_xlabel("position (m)")
        ax_t.set_xlabel("time (s)")
        ax_j.set_xlabel("time (s)")
        for ax in (ax_x, ax_t):
            ax.set_ylabel("speed (km/h)")
            ax.grid(alpha=0.3)
        ax_j.set_ylabel("rate of change of acceleration (m/s^3)")
        ax_j.grid(alpha=0.3)
        ax_x.set_title(f"{case.name}, {curve}: control period {period:g} s")
        ax_x.legend(fontsize=8)
    fig.tight_layout()
    save_figure(fig, out_dir / f"{stem}.png", dpi=100)


def write_report(case, args, t_start, curves, rows, stem, out_dir):
    """Write the report: the reference curves, the tracking table per train, controller and period."""
    lines = [f"# PID and adaptive fuzzy PID tracking on {case.name} (seed 002, sections 3.4-3.5)", "",
             f"Produced by `benchmarks/tracking_metro_a.py --case {args.case} --gens {args.gens}` in "
             f"{time.perf_counter() - t_start:.0f} s. Both controllers have the base gains kp = {KP}, ki = {KI}, "
             f"kd = {KD} (force command per km/h of speed error); the fuzzy PID adds the increments of its "
             "rule base (`FuzzyPID()` defaults, symmetric classic tables; see docs/control.md). Start "
             "(maximum traction) and stop (braking curve) phases are exact; the controllers track the "
             "middle part. Speed errors are speed minus target at the same position. How to read it: "
             "docs/control.md, section Results.", "", "## Target curves", "",
             "| curve | ideal energy kWh | ideal time s | peak km/h |", "|---|---|---|---|"]
    for name, ref in curves.items():
        lines.append(f"| {name} | {ref.energy.net_kwh:.3f} | {ref.running_time_s:.2f} | {ref.speed_kmh.max():.1f} |")
    lines += ["", "Seed 002 (GA curve, table 3): stop error 0.18 m, running time 68.87 s, peak 75.89 km/h; "
              "for the tracking it gives figures only (figs. 8-10).", "", "## Tracked runs", "",
              "Speed error over the whole run (rms / max) and over the part the controller drives "
              "(between the end of the start phase and the start of the stop phase); jerk is the "
              "comfort figure of the problem, the sum of |a_i - a_(i-1)| over the run.", "",
              "| curve | train | period s | controller | rms error km/h | max error km/h | controlled rms km/h | "
              "controlled max km/h | jerk m/s^2 | max abs accel m/s^2 | stop error m | energy kWh | time s | "
              "regime changes |",
              "|---|---|---|---|---|---|---|---|---|---|---|---|---|---|"]
    for r in rows:
        lines.append(f"| {r['curve']} | {r['train']} | {r['period_s']:g} | {r['controller']} | "
                     f"{r['speed_error_rms_kmh']:.3f} | {r['speed_error_max_kmh']:.3f} | "
                     f"{r['control_error_rms_kmh']:.3f} | {r['control_error_max_kmh']:.3f} | {r['jerk_ms2']:.2f} | "
                     f"{r['max_abs_accel_ms2']:.3f} | {r['stop_error_m']:.3f} | {r['energy_kwh']:.3f} | "
                     f"{r['running_time_s']:.2f} | {r['regime_changes']} |")
    lines += ["", f"![seed 002 figs. 8-10 analogue]({stem}.png)", ""]
    (out_dir / f"{stem}.md").write_text("\n".join(lines))


if __name__ == "__main__":
    main()
