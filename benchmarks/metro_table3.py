"""Table 3 and the weight sensitivity of Meng et al. (2017): the study files ``examples/metro_table3.toml``
and ``examples/metro_weights.toml`` through ``run_study``, the grid optimum, the phases on the simulator.

Text: ``benchmarks/templates/metro_table3.md``.
Usage: ``nice -n 10 python benchmarks/metro_table3.py [--seeds N] [--report-only]``
"""

from __future__ import annotations

import argparse
import warnings
from dataclasses import replace
from pathlib import Path

import numpy as np
import pandas as pd

from pymoo_rail.cases import load_case
from pymoo_rail.constants import KMH_PER_MS
from pymoo_rail.experiments import build_problem, choose_member, load_results, read_study, run_study
from pymoo_rail.experiments.report import (add_study_options, fill_template, fixed, lower_priority, markdown_rows,
                                           write_report)
from pymoo_rail.plotting import save_figure
from pymoo_rail.plotting.style import new_figure
from pymoo_rail.problems import ConstantObjectiveWarning, SpeedProfileProblem, canonical_objective, phase_runs
from pymoo_rail.problems.phases import grid_optimum, phase_profile

ROOT = Path(__file__).resolve().parents[1]
STUDIES = (ROOT / "examples" / "metro_table3.toml", ROOT / "examples" / "metro_weights.toml")
PAPER = {"traction_m": 262.37, "cruise_m": 169.15, "coast_m": 369.69, "brake_m": 198.97, "stop_m": 1000.18,
         "stop_error_m": 0.18, "running_time_s": 68.87, "time_error_s": 1.13, "peak_kmh": 75.89,
         "energy_index_kwh": float("nan"), "f": float("nan"), "feasible": True}
COLUMNS = ["traction_m", "cruise_m", "coast_m", "brake_m", "stop_m", "stop_error_m", "running_time_s", "time_error_s",
           "peak_kmh", "energy_index_kwh", "f", "feasible"]
BRAKE_MS2, COAST_END = 1.1, "1.1 m/s^2 from the coast's end"


def quiet_problem(spec):
    """The study's problem; comfort is a constant objective here, which the report says."""
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", ConstantObjectiveWarning)
        return build_problem(spec)


def run_table(problem, lengths: np.ndarray) -> dict:
    """One row of table 3 from traction, cruise and coast lengths (the kinematic model, exact lengths)."""
    runs = phase_runs(lengths[None, :3], problem.accelerations_ms2, problem.mass_kg)
    idx = problem.indices(runs)
    F = np.array([[idx[canonical_objective(n)][0] for n in problem.objectives]])
    G = np.concatenate([problem.min_phase_s - runs.duration_s[0], problem.limit_excess_ms(runs)[0]])
    return {"traction_m": runs.length_m[0, 0], "cruise_m": runs.length_m[0, 1], "coast_m": runs.length_m[0, 2],
            "brake_m": runs.length_m[0, 3], "stop_m": runs.stop_position_m[0], "stop_error_m": idx["stop_error"][0],
            "running_time_s": runs.running_time_s[0], "time_error_s": idx["time_error"][0],
            "peak_kmh": runs.peak_speed_ms[0] * KMH_PER_MS, "energy_index_kwh": runs.energy_index_kwh[0],
            "f": float(((F / problem.scales) @ problem.weights)[0]), "feasible": bool((G <= 1e-9).all())}


def physical_replay(case, lengths: np.ndarray, latest: bool = False):
    """The phases on the simulator: traction, cruise, coast, then braking at 1.1 m/s^2 from the coast's
    end, or (``latest``) coasting on until the braking curve onto the platform."""
    objectives, ends = ("energy", "accel_variation", "stop_error", "time_error"), np.cumsum(lengths[:3])
    if latest:
        return SpeedProfileProblem(case, objectives=objectives, encoding="switching_points", stop_tolerance_m=None,
                                   regimes=("traction", "hold", "coast")).trajectory(ends[:2])
    return SpeedProfileProblem(case, objectives=objectives, encoding="braking_onset",
                               stop_tolerance_m=None).trajectory(np.array([*ends, BRAKE_MS2]))


def best_runs(results) -> list[dict]:
    """The best feasible point of each run with one (``experiments.choose_member`` on the weighted sum)."""
    rows = []
    for _, r in results.iterrows():
        if (r["CV"] <= 0).any():
            none = np.zeros(len(r["F"]))  # one objective: the running time and energy play no part
            j = choose_member(r["F"][:, :1], r["CV"], none, none, 0.0)
            rows.append({"problem": r["problem"], "seed": r["seed"], "f": float(r["F"][j, 0]), "X": r["X"][j],
                         "cpu_time_s": r["cpu_time_s"]})
    return rows


def weight_rows(weights) -> tuple[str, list]:
    """Per weight vector: the median over the seeds of the best runs, and the 2 m grid optimum; the runs."""
    runs_w, rows = best_runs(weights), []
    for spec in read_study(STUDIES[1]).problems:
        pw = quiet_problem(spec)
        if not (mine := [r for r in runs_w if r["problem"] == spec.display]):
            continue
        tab = [run_table(pw, pw.lengths(r["X"])[0]) for r in mine]
        med = {c: float(np.median([t[c] for t in tab])) for c in ("running_time_s", "time_error_s", "stop_error_m",
                                                                    "peak_kmh", "energy_index_kwh", "f")}
        gx, gf = grid_optimum(pw, 2.0)
        g = run_table(pw, gx)
        rows.append(f"| {spec.display[2:]} | {len(mine)} | {med['running_time_s']:.2f} | {med['time_error_s']:.2f} | "
                    f"{med['stop_error_m']:.3f} | {med['peak_kmh']:.2f} | {med['energy_index_kwh']:.2f} | "
                    f"{med['f']:.4f} | {g['running_time_s']:.2f} | {g['peak_kmh']:.2f} | {g['energy_index_kwh']:.2f} | "
                    f"{gf:.4f} |")
    return "\n".join(rows), runs_w


def table3_figure(lengths: dict, problem, trace, path: Path) -> None:
    """Distance-speed and time-speed of the kinematic runs and of the simulator's replay (figs. 3 and 5)."""
    fig, axes = new_figure(1, 2, figsize=(11, 4))
    for name, x in lengths.items():
        px, pv, pt = phase_profile(x, problem.accelerations_ms2)
        axes[0, 0].plot(px, pv * KMH_PER_MS, label=f"kinematic, {name}")
        axes[0, 1].plot(pt, pv * KMH_PER_MS, label=f"kinematic, {name}")
    axes[0, 0].plot(trace.position_m, trace.speed_kmh, "k--", label="simulator, grid optimum's phases")
    axes[0, 1].plot(trace.time_s, trace.speed_kmh, "k--", label="simulator, grid optimum's phases")
    axes[0, 0].plot(trace.position_m, trace.limit_ms * KMH_PER_MS, color="0.6", lw=0.8, label="limit (whole train)")
    for ax, xlabel in zip(axes[0], ("position m", "time s")):
        ax.set(xlabel=xlabel, ylabel="speed km/h")
        ax.grid(True, alpha=0.3)
    axes[0, 0].legend(fontsize="small")
    save_figure(fig, path, dpi=120)


def write_report_files(out: Path, table3, weights) -> None:
    """The report, ``metro_table3_runs.csv`` and the figure from the stored runs of both studies."""
    case, problem = load_case("metro-a"), quiet_problem(read_study(STUDIES[0]).problems[0])
    runs3 = best_runs(table3)
    fs = np.array([r["f"] for r in runs3])
    order = np.argsort(fs)
    best, median = runs3[int(order[0])], runs3[int(order[len(order) // 2])]
    grid_x, grid_f = grid_optimum(problem, 1.0)
    lengths = {"paper's lengths": np.array([PAPER["traction_m"], PAPER["cruise_m"], PAPER["coast_m"]]),
               "GA best": problem.lengths(best["X"])[0], "grid optimum": grid_x}
    paper, ga, mid, grid = (run_table(problem, x) for x in (lengths["paper's lengths"], lengths["GA best"],
                                                            problem.lengths(median["X"])[0], grid_x))
    rows = {"Meng et al. (2017), table 3": PAPER, "paper's lengths in the paper's model": paper,
            f"GA best of {len(runs3)} seeds (seed {best['seed']})": ga, f"GA median seed (seed {median['seed']})": mid,
            "1 m grid optimum (reference)": grid}
    replays = {(name, latest): physical_replay(case, x, latest) for latest in (False, True) for name, x in lengths.items()}
    weight_table, runs_w = weight_rows(weights)
    values = {
        "accelerations": problem.accelerations_ms2, "min_phase_s": f"{problem.min_phase_s:g}",
        "scales": ", ".join(f"{s:.4g}" for s in problem.scales),
        "table3": markdown_rows(["run", *COLUMNS], [[name, *(fixed(row.get(c, float("nan"))) for c in COLUMNS)]
                                                    for name, row in rows.items()], right_from=1),
        "n_seeds": len(fs), "f_best": f"{fs.min():.4f}", "f_median": f"{np.median(fs):.4f}", "f_worst": f"{fs.max():.4f}",
        "grid_f": f"{grid_f:.4f}", "cpu_median": f"{np.median([r['cpu_time_s'] for r in runs3]):.2f}",
        "replay_rows": "\n".join(
            f"| {name.replace(' lengths', '')}, {'latest braking' if latest else COAST_END} "
            f"| {tr.energy.net_kwh:.2f} | {tr.running_time_s:.2f} | {tr.position_m[-1]:.2f} | {tr.stop_error_m:.2f} | "
            f"{tr.speed_kmh.max():.2f} |" for (name, latest), tr in replays.items()),
        "paper_peak_kmh": f"{paper['peak_kmh']:.2f}", "paper_brake_m": f"{paper['brake_m']:.2f}",
        "paper_stop_m": f"{paper['stop_m']:.2f}", "paper_time_s": f"{paper['running_time_s']:.2f}",
        "best_stop_error": f"{ga['stop_error_m']:.3f}", "median_stop_error": f"{mid['stop_error_m']:.3f}",
        "grid_time_s": f"{grid['running_time_s']:.2f}", "energy_scale": f"{problem.scales[0]:.2f}",
        "best_time_s": f"{ga['running_time_s']:.2f}", "grid_peak_kmh": f"{grid['peak_kmh']:.2f}",
        "paper_energy_index": f"{paper['energy_index_kwh']:.2f}",
        "paper_wheel_kwh": f"{replays[(next(iter(lengths)), False)].energy.net_kwh:.2f}",
        "grid_wheel_kwh": f"{replays[('grid optimum', False)].energy.net_kwh:.2f}",
        "comfort_scale": f"{problem.scales[1]:.3f}", "weight_rows": weight_table}
    write_report(out / "metro_table3.md", [fill_template(ROOT / "benchmarks" / "templates" / "metro_table3.md", values)],
                 newline=False)
    table3_figure(lengths, problem, replays[("grid optimum", False)], out / "metro_table3.png")
    pd.DataFrame([{"study": study, "problem": r["problem"], "seed": r["seed"], "f": f"{r['f']:.6f}",
                   **dict(zip(("traction_m", "cruise_m", "coast_m"), (f"{v:.3f}" for v in problem.lengths(r["X"])[0])))}
                  for study, rs in (("metro-table3", runs3), ("metro-weights", runs_w)) for r in rs]).to_csv(
        out / "metro_table3_runs.csv", index=False)


def main(argv=None) -> None:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--seeds", type=int, default=None, help="seeds per study (default: the study files')")
    add_study_options(parser, ROOT / "out" / "metro_table3", ROOT / "benchmarks" / "reports")
    args = parser.parse_args(argv)
    lower_priority()
    results = []
    for path in STUDIES:
        study = read_study(path)
        study = study if args.seeds is None else replace(study, seeds=tuple(range(1, args.seeds + 1)))
        if not args.report_only:
            with warnings.catch_warnings():
                warnings.simplefilter("ignore")
                print(run_study(study, args.work / study.name, workers=1, seed_major=True), flush=True)
        results.append(load_results(args.work / study.name, study=study))
    args.out.mkdir(parents=True, exist_ok=True)
    write_report_files(args.out, *results)
    print(f"wrote {args.out / 'metro_table3.md'}")


if __name__ == "__main__":
    main()
