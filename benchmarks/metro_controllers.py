"""A fair PID vs adaptive fuzzy PID study on metro-a (Meng et al. 2017, sections 3.4-3.5, fig. 9).

1. Tuning, through ``pymoo_rail.experiments.run_study`` (study ``metro-controllers``): the gains of
   each family (PID: kp, ki, kd; fuzzy PID: the same plus its increment scales dkp, dki, dkd) are
   tuned by pymoo's DE with the same budget (population 20, ``--budget`` evaluations, default 400)
   and the same objective, the mean rms tracking error over a training set of 8 disturbed trains
   (``draw_disturbances(8, seed=0)``: mass x 0.85-1.15, adhesion x 0.8-1.0 on the traction and
   braking forces, speed-measurement noise of standard deviation 0-0.5 km/h at each 0.2 s control
   instant, first-order traction/brake lag of 0-0.6 s), ``--tuning-seeds`` DE seeds per family.
2. Held-out comparison: the best-tuned controller of each family (lowest training cost), and the
   untuned defaults both share, track the table-3 reference (``table3_reference``) on ``--test``
   held-out disturbed trains (``draw_disturbances(n, seed=1000)``, default 20): tracking error,
   jerk, energy, stop error, punctuality (|T - 70 s|); Wilcoxon rank-sum
   (``pymoo_rail.experiments.stats.rank_sum``) tuned fuzzy PID against tuned PID.
3. Fig. 9: time-speed of the reference, PID and fuzzy PID on the first held-out train.

Usage::

    nice -n 10 python benchmarks/metro_controllers.py [--budget 400] [--tuning-seeds 3] [--test 20]

Writes ``benchmarks/reports/metro_controllers.md``, ``metro_controllers.csv`` and
``metro_controllers_fig9.png``.
"""

from __future__ import annotations

import argparse
import os
import sys
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
if str(ROOT) not in sys.path:
    sys.path.insert(0, str(ROOT))

REPORTS = ROOT / "benchmarks" / "reports"
METRICS = {"control_error_rms_kmh": "tracking error rms km/h", "jerk_ms2": "jerk (sum of abs da) m/s^2",
           "energy_kwh": "energy kWh", "stop_error_m": "stop error m", "punctuality_s": "punctuality abs(T - 70 s) s"}


def build_study(budget: int, seeds: int):
    from pymoo_rail.experiments import Study, algorithm, problem

    return Study("metro-controllers",
                 problems=[problem("controller_tuning", label="PID", case="metro-a", family="pid"),
                           problem("controller_tuning", label="fuzzy PID", case="metro-a", family="fuzzy_pid")],
                 algorithms=[algorithm("de", label="DE", pop_size=20)], seeds=seeds, budget={"n_eval": budget})


def held_out(case, reference, controllers: dict, n_test: int) -> list[dict]:
    from pymoo_rail.control import draw_disturbances, track_disturbed

    rows = []
    for k, d in enumerate(draw_disturbances(n_test, seed=1000)):
        for name, c in controllers.items():
            tr = track_disturbed(case, reference, c, d)
            rows.append({"scenario": k, "controller": name, "mass_factor": d.mass_factor,
                         "adhesion_factor": d.adhesion_factor, "speed_noise_kmh": d.speed_noise_kmh,
                         "traction_lag_s": d.traction_lag_s,
                         "control_error_rms_kmh": tr.summary["control_error_rms_kmh"], "jerk_ms2": tr.jerk_ms2,
                         "energy_kwh": tr.energy.net_kwh, "stop_error_m": tr.stop_error_m,
                         "punctuality_s": abs(tr.running_time_s - case.planned_time_s),
                         "running_time_s": tr.running_time_s})
    return rows


def main(argv=None) -> None:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--budget", type=int, default=400, help="DE evaluations per tuning run")
    parser.add_argument("--tuning-seeds", type=int, default=3)
    parser.add_argument("--test", type=int, default=20, help="held-out disturbed trains")
    parser.add_argument("--work", type=Path, default=ROOT / "out" / "metro_controllers")
    parser.add_argument("--out", type=Path, default=REPORTS)
    parser.add_argument("--report-only", action="store_true")
    args = parser.parse_args(argv)
    current = os.nice(0)
    if current < 10:
        os.nice(10 - current)

    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    import pandas as pd

    from pymoo_rail.cases import load_case
    from pymoo_rail.control import PID, FuzzyPID, draw_disturbances, track_disturbed
    from pymoo_rail.control.tuning import controller_from_gains, table3_reference
    from pymoo_rail.experiments import load_results, run_study
    from pymoo_rail.experiments.stats import rank_sum

    study = build_study(args.budget, args.tuning_seeds)
    if not args.report_only:
        print(run_study(study, args.work, workers=1), flush=True)
    results = load_results(args.work, study=study)
    case = load_case("metro-a")
    reference = table3_reference(case)

    L = ["# PID vs adaptive fuzzy PID on metro-a, tuned fairly (Meng et al. 2017, 3.4-3.5, fig. 9)", "",
         "Generated by `benchmarks/metro_controllers.py`; tuning runs stored by "
         "`pymoo_rail.experiments.run_study` (study `metro-controllers`).", "",
         f"Reference curve: `table3_reference(metro-a)`, the braking-onset run fitted to table 3: "
         f"{reference.running_time_s:.2f} s (table 3: 68.87 s), stop at {reference.position_m[-1]:.2f} m "
         f"(1000.18 m), peak {reference.speed_kmh.max():.2f} km/h (75.89 km/h), "
         f"{reference.energy.net_kwh:.2f} kWh. The 65 km/h departure zone binds over the whole train up to "
         "280 m and the flat-out run takes 68.7 s, so a 68.87 s run cannot peak at 75.89 km/h here.", "",
         "## Tuning (same budget, same objective, same training set)", "",
         "| family | DE seed | evaluations | training cost (mean rms error km/h) | gains | CPU s |",
         "|---|---:|---:|---:|---|---:|"]
    best = {}
    for _, r in results.iterrows():
        family = "pid" if r["problem"] == "PID" else "fuzzy_pid"
        f = float(r["F"][0, 0])
        x = r["X"][0]
        L.append(f"| {r['problem']} | {r['seed']} | {r['n_eval']} | {f:.4f} | "
                 f"{', '.join(f'{v:.4g}' for v in x)} | {r['cpu_time_s']:.1f} |")
        if family not in best or f < best[family][0]:
            best[family] = (f, x)
    controllers = {"PID (defaults)": PID(), "fuzzy PID (defaults)": FuzzyPID(),
                   "PID (tuned)": controller_from_gains("pid", best["pid"][1]),
                   "fuzzy PID (tuned)": controller_from_gains("fuzzy_pid", best["fuzzy_pid"][1])}
    L += ["", "Gains: PID kp, ki, kd; fuzzy PID kp, ki, kd, dkp, dki, dkd (units of `pymoo_rail.control.PID`). "
          "Defaults: PID(0.5, 0.05, 0), FuzzyPID(0.5, 0.05, 0, dkp 0.3, dki 0.03, dkd 0.05).", ""]

    args.out.mkdir(parents=True, exist_ok=True)
    rows = held_out(case, reference, controllers, args.test)
    frame = pd.DataFrame(rows)
    frame.to_csv(args.out / "metro_controllers.csv", index=False)
    L += [f"## Held-out comparison ({args.test} disturbed trains, `draw_disturbances({args.test}, seed=1000)`)", "",
          "Median (and mean) per controller:", "",
          "| controller | " + " | ".join(METRICS.values()) + " |", "|---|" + "---:|" * len(METRICS)]
    for name in controllers:
        sub = frame[frame["controller"] == name]
        L.append(f"| {name} | " + " | ".join(f"{sub[m].median():.3f} ({sub[m].mean():.3f})" for m in METRICS) + " |")
    L += ["", "Wilcoxon rank-sum, tuned fuzzy PID against tuned PID ('+' fuzzy significantly better, '-' worse, "
          "'=' no significant difference at 0.05), and the same for the defaults:", "",
          "| metric | tuned: U | p | verdict | defaults: U | p | verdict |", "|---|---:|---:|---|---:|---:|---|"]
    for m, label in METRICS.items():
        cells = []
        for a, b in (("fuzzy PID (tuned)", "PID (tuned)"), ("fuzzy PID (defaults)", "PID (defaults)")):
            u, p, v = rank_sum(frame[frame["controller"] == a][m], frame[frame["controller"] == b][m])
            cells += [f"{u:.0f}", f"{p:.3g}", v]
        L.append(f"| {label} | " + " | ".join(cells) + " |")
    verdicts = [rank_sum(frame[frame["controller"] == "fuzzy PID (tuned)"][m],
                         frame[frame["controller"] == "PID (tuned)"][m])[2] for m in METRICS]
    better = [label for (m, label), v in zip(METRICS.items(), verdicts) if v == "+"]
    worse = [label for (m, label), v in zip(METRICS.items(), verdicts) if v == "-"]
    L += ["", f"Verdict over {args.test} held-out trains: tuned fuzzy PID is significantly better on "
          f"{', '.join(better) if better else 'no metric'} and significantly worse on "
          f"{', '.join(worse) if worse else 'no metric'} than tuned PID with the same tuning budget. "
          "The paper's claim (fuzzy PID follows the curve better and more smoothly) is a comparison "
          "against an untuned PID on one run; gains at a bound of the search box (see the tuning "
          "table) mean a wider box could still move both. The table-3 run is close to the flat-out run "
          f"({reference.running_time_s:.1f} s against a 68.7 s minimum): the controlled part is mostly the "
          "climb to 80 km/h and the hold at the limit, which leaves the controllers little to differ on; "
          "a slower reference (e.g. the kinematic optimum's phases, 77.6 s) would test them harder.", ""]
    L += ["", "The stop error is 0 for every controller by construction: the tracking kernel hands the "
          "stop over to the braking envelope (the ATP's curve, rebuilt with the reduced adhesion), as "
          "the simulator does; what differs is the speed on the way.", ""]

    # fig. 9
    d0 = draw_disturbances(args.test, seed=1000)[0]
    fig, ax = plt.subplots(figsize=(8, 4))
    ax.plot(reference.time_s, reference.speed_kmh, "k--", lw=1.2, label="reference (table 3 run)")
    for name in ("PID (tuned)", "fuzzy PID (tuned)"):
        tr = track_disturbed(case, reference, controllers[name], d0)
        ax.plot(tr.time_s, tr.speed_kmh, label=name)
    ax.set_xlabel("time s")
    ax.set_ylabel("speed km/h")
    ax.set_title(f"fig. 9 analogue: held-out train 0 (mass x{d0.mass_factor:.2f}, adhesion x{d0.adhesion_factor:.2f}, "
                 f"noise {d0.speed_noise_kmh:.2f} km/h, lag {d0.traction_lag_s:.2f} s)", fontsize="small")
    ax.grid(True, alpha=0.3)
    ax.legend()
    fig.tight_layout()
    fig.savefig(args.out / "metro_controllers_fig9.png", dpi=120)
    L += ["![fig. 9 analogue](metro_controllers_fig9.png)", ""]
    (args.out / "metro_controllers.md").write_text("\n".join(L) + "\n")
    print(f"wrote {args.out / 'metro_controllers.md'}")


if __name__ == "__main__":
    main()
