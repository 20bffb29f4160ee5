"""PID vs adaptive fuzzy PID on metro-a, tuned fairly (Meng et al. 2017, 3.4-3.5, fig. 9): both families
tuned by DE with the same budget (study ``metro-controllers``), then compared on held-out disturbed
trains with a rank-sum test. Text: ``benchmarks/templates/metro_controllers.md``.

Usage: ``nice -n 10 python benchmarks/metro_controllers.py [--budget 400] [--tuning-seeds 3] [--test 20]``
"""

from __future__ import annotations

import argparse
from pathlib import Path

import pandas as pd

from pymoo_rail.cases import load_case
from pymoo_rail.control import PID, FuzzyPID, draw_disturbances, track_disturbed
from pymoo_rail.experiments import Study, algorithm, load_results, problem, run_study
from pymoo_rail.experiments.report import add_study_options, fill_template, lower_priority, write_report
from pymoo_rail.experiments.stats import rank_sum
from pymoo_rail.plotting import save_figure
from pymoo_rail.plotting.style import new_figure
from pymoo_rail.problems.controller_tuning import controller_from_gains, table3_reference
from pymoo_rail.sim import Simulator  # the flat-out run: limits held over the whole train

ROOT = Path(__file__).resolve().parents[1]
METRICS = {"control_error_rms_kmh": "tracking error rms km/h", "jerk_ms2": "jerk (sum of abs da) m/s^2",
           "energy_kwh": "energy kWh", "stop_error_m": "stop error m", "punctuality_s": "punctuality abs(T - 70 s) s"}
PAIRS = (("fuzzy PID (tuned)", "PID (tuned)"), ("fuzzy PID (defaults)", "PID (defaults)"))


def build_study(budget: int, seeds: int) -> Study:
    """DE (population 20) tuning both families with ``budget`` evaluations, ``seeds`` seeds each."""
    return Study("metro-controllers",
                 problems=[problem("controller_tuning", label="PID", case="metro-a", family="pid"),
                           problem("controller_tuning", label="fuzzy PID", case="metro-a", family="fuzzy_pid")],
                 algorithms=[algorithm("de", label="DE", pop_size=20)], seeds=seeds, budget={"n_eval": budget})


def held_out(case, reference, controllers: dict, n_test: int) -> pd.DataFrame:
    """Every controller on each of ``n_test`` held-out disturbed trains: one row per train and controller."""
    rows = []
    for k, d in enumerate(draw_disturbances(n_test, seed=1000)):
        for name, c in controllers.items():
            tr = track_disturbed(case, reference, c, d)
            rows.append({"scenario": k, "controller": name, "mass_factor": d.mass_factor,
                         "adhesion_factor": d.adhesion_factor, "speed_noise_kmh": d.speed_noise_kmh,
                         "traction_lag_s": d.traction_lag_s, "control_error_rms_kmh": tr.summary["control_error_rms_kmh"],
                         "jerk_ms2": tr.jerk_ms2, "energy_kwh": tr.energy.net_kwh, "stop_error_m": tr.stop_error_m,
                         "punctuality_s": abs(tr.running_time_s - case.planned_time_s),
                         "running_time_s": tr.running_time_s})
    return pd.DataFrame(rows)


def tuned(results) -> tuple[str, dict]:
    """The tuning table rows and the best gains of each family (lowest training cost)."""
    rows, best = [], {}
    for _, r in results.iterrows():
        family, f, x = "pid" if r["problem"] == "PID" else "fuzzy_pid", float(r["F"][0, 0]), r["X"][0]
        rows.append(f"| {r['problem']} | {r['seed']} | {r['n_eval']} | {f:.4f} | {', '.join(f'{v:.4g}' for v in x)} | "
                    f"{r['cpu_time_s']:.1f} |")
        if family not in best or f < best[family][0]:
            best[family] = (f, x)
    return "\n".join(rows), {family: x for family, (_, x) in best.items()}


def fig9(case, reference, controllers: dict, n_test: int, path: Path) -> None:
    """Time-speed of the reference and both tuned controllers on the first held-out train."""
    d0 = draw_disturbances(n_test, seed=1000)[0]
    fig, axes = new_figure(1, 1, figsize=(8, 4))
    ax = axes[0, 0]
    ax.plot(reference.time_s, reference.speed_kmh, "k--", lw=1.2, label="reference (table 3 run)")
    for name in ("PID (tuned)", "fuzzy PID (tuned)"):
        tr = track_disturbed(case, reference, controllers[name], d0)
        ax.plot(tr.time_s, tr.speed_kmh, label=name)
    ax.set(xlabel="time s", ylabel="speed km/h")
    ax.set_title(f"fig. 9 analogue: held-out train 0 (mass x{d0.mass_factor:.2f}, adhesion x{d0.adhesion_factor:.2f}, "
                 f"noise {d0.speed_noise_kmh:.2f} km/h, lag {d0.traction_lag_s:.2f} s)", fontsize="small")
    ax.grid(True, alpha=0.3)
    ax.legend()
    save_figure(fig, path, dpi=120)


def comparison_values(frame: pd.DataFrame, controllers: dict) -> dict:
    """The held-out table (median and mean), the rank-sum tests and the verdict's lists."""
    def sample(name, m):
        return frame[frame["controller"] == name][m]

    tests = {m: [rank_sum(sample(a, m), sample(b, m)) for a, b in PAIRS] for m in METRICS}
    verdict = {word: [METRICS[m] for m in METRICS if tests[m][0][2] == sign] for word, sign in (("better", "+"),
                                                                                                ("worse", "-"))}
    return {"held_out_rows": "\n".join(f"| {name} | " + " | ".join(f"{sample(name, m).median():.3f} "
                                                                  f"({sample(name, m).mean():.3f})" for m in METRICS) + " |"
                                       for name in controllers),
            "test_rows": "\n".join(f"| {label} | " + " | ".join(f"{u:.0f} | {p:.3g} | {v}" for u, p, v in tests[m]) + " |"
                                   for m, label in METRICS.items()),
            **{word: ", ".join(names) if names else "no metric" for word, names in verdict.items()}}


def main(argv=None) -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--budget", type=int, default=400, help="DE evaluations per tuning run")
    parser.add_argument("--tuning-seeds", type=int, default=3)
    parser.add_argument("--test", type=int, default=20, help="held-out disturbed trains")
    add_study_options(parser, ROOT / "out" / "metro_controllers", ROOT / "benchmarks" / "reports")
    args = parser.parse_args(argv)
    lower_priority()
    study = build_study(args.budget, args.tuning_seeds)
    if not args.report_only:
        print(run_study(study, args.work, workers=1), flush=True)
    case = load_case("metro-a")
    reference = table3_reference(case)
    tuning_rows, best = tuned(load_results(args.work, study=study))
    controllers = {"PID (defaults)": PID(), "fuzzy PID (defaults)": FuzzyPID(),
                   "PID (tuned)": controller_from_gains("pid", best["pid"]),
                   "fuzzy PID (tuned)": controller_from_gains("fuzzy_pid", best["fuzzy_pid"])}
    args.out.mkdir(parents=True, exist_ok=True)
    frame = held_out(case, reference, controllers, args.test)
    frame.to_csv(args.out / "metro_controllers.csv", index=False)
    fig9(case, reference, controllers, args.test, args.out / "metro_controllers_fig9.png")
    values = {"ref_time_s": f"{reference.running_time_s:.2f}", "ref_stop_m": f"{reference.position_m[-1]:.2f}",
              "ref_peak_kmh": f"{reference.speed_kmh.max():.2f}", "ref_kwh": f"{reference.energy.net_kwh:.2f}",
              "ref_time_1": f"{reference.running_time_s:.1f}", "tuning_rows": tuning_rows, "n_test": args.test,
              "fastest_s": f"{Simulator(case).flat_out().running_time_s:.1f}",
              **comparison_values(frame, controllers)}
    write_report(args.out / "metro_controllers.md", [fill_template(ROOT / "benchmarks" / "templates" /
                                                                   "metro_controllers.md", values)], newline=False)
    print(f"wrote {args.out / 'metro_controllers.md'}")


if __name__ == "__main__":
    main()
