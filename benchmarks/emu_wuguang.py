"""GR-NSGA-II vs NSGA-II on the CRH3 EMU run of Tang et al. (2020), 4.2, against the exact front.

Two studies (``encodings``: the choice of encoding; ``main``: 60,000 evaluations, ``--seeds`` seeds),
the cached exact front, and a check of every front member (``pymoo_rail.experiments.verify``). Text:
``benchmarks/templates/emu_wuguang.md`` and the hand-written ``reports/emu_wuguang_notes.md``.

Usage: ``nice -n 10 python benchmarks/emu_wuguang.py [--seeds 10] [--budget 60000] [--report-only]``
"""

from __future__ import annotations

import argparse
import sys
import time
from pathlib import Path

import numpy as np
import pandas as pd

from pymoo_rail.atomic import atomic_write_text
from pymoo_rail.cases import load_case
from pymoo_rail.experiments import (Study, algorithm, build_problem, load_results, problem, run_study,
                                    stats, tang2020_nsga2)
from pymoo_rail.experiments.front_table import exact_energy_kwh, exact_front_table, front_rows, most_punctual
from pymoo_rail.experiments.report import fill_template, markdown_rows, mean_std, significant, write_report
from pymoo_rail.experiments.verify import check_rows, worst_checks
from pymoo_rail.optimal.reference import exact_points

ROOT = Path(__file__).resolve().parents[1]
TEMPLATE = ROOT / "benchmarks" / "templates" / "emu_wuguang.md"
CASE, OBJECTIVES = "wuguang-crh3", ("energy", "running_time")
POP_SIZE, LOCAL_SIZE, BUDGET, ENCODING_BUDGET, ENCODING_SEEDS = 200, 40, 60_000, 20_000, 3
NSGA2_LABEL, GR_LABEL = "NSGA-II", "GR-NSGA-II"
ENCODINGS = {"speed codes": {"encoding": "speed_codes"},  # label -> SpeedProfileProblem keyword arguments
             "speed codes <= 1000 m": {"encoding": "speed_codes", "max_section_m": 1000.0},
             "switching points": {"encoding": "switching_points"}}
MAIN_ENCODING, MAIN_ENCODINGS = "speed codes", ("speed codes", "switching points")  # figs. 10-12 on the first
EXACT_TIMES_S = (990.0, 995.0, 1000.0, 1010.0, 1020.0, 1030.0, 1040.0, 1050.0, 1060.0, 1070.0, 1080.0, 1095.0, 1110.0)
EXACT_N_SPEEDS = 800  # 4x the solver's default: the front moves by under 0.01 % between 200, 400 and 800 nodes
SEED_TABLE4 = {NSGA2_LABEL: {"sp": 0.45638, "gd": 0.114832, "t_max": 1103, "t_min": 1012, "e_max": 714.27,
                             "e_min": 646.69},
               GR_LABEL: {"sp": 0.37867, "gd": 0.092534, "t_max": 1105, "t_min": 1008, "e_max": 707.46, "e_min": 639.56}}
SEED_TABLE5 = {NSGA2_LABEL: (657.13, 1051.5), GR_LABEL: (650.76, 1049.2)}
TABLE4 = [("points in the front", "n_points"), ("SP (Schott, kWh and s)", "spacing"),
          ("GD (eq. 13) to the union front", "gd_seed"), ("IGD to the union front", "igd_ref"),
          ("HV (normalised)", "hv_ref"), ("max running time (s)", "t_max"), ("min running time (s)", "t_min"),
          ("max energy (kWh)", "e_max"), ("min energy (kWh)", "e_min"),
          ("least energy with T <= 1050 s (kWh)", "e_at_plan"),
          ("mean energy gap to the exact front (%)", "gap_mean_pct"),
          ("largest energy gap to the exact front (%)", "gap_max_pct"),
          ("smallest energy gap to the exact front (%)", "gap_min_pct"), ("HV / HV of the exact front", "hv_ratio_exact"),
          ("evaluations", "n_eval"), ("generations", "n_gen"), ("wall time (s)", "wall_time_s"),
          ("CPU time (s)", "cpu_time_s")]
SEED_KEYS = {"spacing": "sp", "gd_seed": "gd", "t_max": "t_max", "t_min": "t_min", "e_max": "e_max", "e_min": "e_min"}
TESTED = (("hv_ref", False), ("igd_ref", True), ("gd_ref", True), ("gd_seed", True), ("spacing", True),
          ("gap_mean_pct", True), ("hv_ratio_exact", False), ("e_at_plan", True), ("punctual_e", True), ("e_min", True))


def make_study(name: str, encodings, seeds, budget: int, pop_size: int = POP_SIZE, local_size: int = LOCAL_SIZE):
    """NSGA-II (the seed's settings) and GR-NSGA-II on ``encodings`` of the case at ``budget`` evaluations."""
    margin = float(load_case(CASE).time_margin_s)
    problems = [problem("speed_profile", label=e, case=CASE, objectives=list(OBJECTIVES), time_tolerance_s=margin,
                        **ENCODINGS[e]) for e in encodings]
    algorithms = [tang2020_nsga2(label=NSGA2_LABEL, pop_size=pop_size),
                  algorithm("grnsga2", label=GR_LABEL, pop_size=pop_size, local_size=local_size, pc_max=0.9, pm_max=0.1)]
    return Study(name, problems, algorithms, seeds=list(seeds), budget={"n_eval": int(budget)}, baseline=NSGA2_LABEL)


def exact_front(path: Path, profile_path: Path):
    """The exact front at :data:`EXACT_TIMES_S` cached in ``path``; the optimum at the planned time in ``profile_path``."""
    case = load_case(CASE)

    def keep_profile(t, traj):
        if t == case.planned_time_s:
            atomic_write_text(profile_path, traj.to_frame().to_csv(index=False))
        print(f"exact front: {t:g} s -> {traj.running_time_s:.2f} s, {traj.energy.net_kwh:.2f} kWh", flush=True)

    redo = [] if profile_path.exists() else [case.planned_time_s]
    return exact_points(case, EXACT_TIMES_S, path, n_speeds=EXACT_N_SPEEDS, redo_s=redo, on_run=keep_profile)


def pair(rows, enc: str, key: str):
    """(NSGA-II values, GR-NSGA-II values) of ``key`` on encoding ``enc``, finite only; None when no run has it."""
    runs = [r for r in rows if r["problem"] == enc]
    if not any(np.isfinite(r.get(key, np.nan)) for r in runs):
        return None
    return tuple([r.get(key, np.nan) for r in runs if r["algorithm"] == a] for a in (NSGA2_LABEL, GR_LABEL))


def rank_sum(rows, enc: str, key: str, lower_better: bool):
    """(p, verdict, difference of the means) of GR-NSGA-II against NSGA-II: in %, or in points for ``*_pct``."""
    base, gr = (np.asarray([v for v in side if np.isfinite(v)], dtype=float) for side in pair(rows, enc, key) or ([], []))
    if len(gr) < 2 or len(base) < 2:
        return np.nan, "", ""
    _, p, verdict = stats.rank_sum(gr, base, lower_better=lower_better)
    if key.endswith("_pct"):
        return p, verdict, f"{gr.mean() - base.mean():+.3f} points"
    return p, verdict, f"{100 * ((gr.mean() - base.mean()) / abs(base.mean())):+.3f} %" if base.mean() != 0 else ""


def punctual_choices(results, rows, problems: dict) -> dict:
    """Per (encoding, algorithm): the most punctual member of the median-HV run, re-simulated."""
    chosen = {}
    for enc in sorted({r["problem"] for r in rows}):
        for alg in (NSGA2_LABEL, GR_LABEL):
            seed = stats.median_run(rows, enc, alg)["seed"]
            run = results[(results["problem"] == enc) & (results["algorithm"] == alg) & (results["seed"] == seed)].iloc[0]
            F, X = run["F"][run["CV"] <= 0], run["X"][run["CV"] <= 0]
            k = most_punctual(F, problems[enc].case.planned_time_s)
            chosen[enc, alg] = {"seed": seed, "F": F[k], "front": F, "trajectory": problems[enc].trajectory(X[k])}
    return chosen


def encoding_table(rows, problems) -> str:
    """Section 1: the encoding study, mean +- std per encoding and algorithm."""
    cells = [[enc, problems[enc].n_var, int(problems[enc].encoding.fixed().sum()), alg, len(rs),
              *(mean_std(r.get(k, np.nan) for r in rs) for k in ("hv_ref", "e_at_plan", "e_min", "t_min", "wall_time_s"))]
             for enc in ENCODINGS for alg in (NSGA2_LABEL, GR_LABEL)
             if (rs := [r for r in rows if r["problem"] == enc and r["algorithm"] == alg])]
    return markdown_rows(["encoding", "n_var", "fixed genes", "algorithm", "runs", "hv (union of this study)",
                          "least E with T <= 1050 s (kWh)", "E min (kWh)", "T min (s)", "wall s"], cells) \
        if cells else "(encoding study not run)"


def table4(rows, enc: str) -> str:
    """Table 4 on ``enc``: front statistics, mean +- std, beside the seed's."""
    cells = [[name, mean_std(p[0]), mean_std(p[1]), *(significant(SEED_TABLE4[a][SEED_KEYS[key]])
                                                      if key in SEED_KEYS else "" for a in (NSGA2_LABEL, GR_LABEL))]
             for name, key in TABLE4 if (p := pair(rows, enc, key)) is not None]
    return (f"Table 4 ({enc}): mean +- std over the runs; the seed's values in the last columns (its line profile "
            "differs: only magnitudes compare).\n\n" + markdown_rows(["statistic", NSGA2_LABEL, GR_LABEL,
                                                                      f"seed {NSGA2_LABEL}", f"seed {GR_LABEL}"], cells))


def tests_table(rows, enc: str) -> str:
    """Section 3 on ``enc``: the rank-sum test of every indicator."""
    cells = []
    for key, lower in TESTED:
        if (p := pair(rows, enc, key)) is not None:
            pval, verdict, rel = rank_sum(rows, enc, key, lower)
            cells.append([key, "lower" if lower else "higher", mean_std(p[0]), mean_std(p[1]), rel,
                          significant(pval, 3), verdict])
    return f"**{enc}**\n\n" + markdown_rows(["indicator", "better", NSGA2_LABEL, GR_LABEL, "GR vs NSGA-II (means)", "p",
                                             "verdict"], cells)


def table5(encodings, chosen, rows, exact) -> str:
    """Table 5: the most punctual member of each median-HV run, and the means over all runs."""
    cells = []
    for enc in encodings:
        for alg in (NSGA2_LABEL, GR_LABEL):
            traj, rs = chosen[enc, alg]["trajectory"], [r for r in rows if r["problem"] == enc and r["algorithm"] == alg]
            opt = exact_energy_kwh(exact, traj.running_time_s) if exact is not None else np.nan
            cells.append([enc, alg, chosen[enc, alg]["seed"], f"{traj.energy.net_kwh:.2f}", f"{traj.running_time_s:.1f}",
                          f"{opt:.2f} (+{100 * (traj.energy.net_kwh / opt - 1):.2f} %)" if np.isfinite(opt) else "",
                          f"{traj.energy.traction_kwh:.1f} / {traj.energy.regen_kwh:.1f}",
                          *(mean_std(r.get(k, np.nan) for r in rs) for k in ("punctual_e", "punctual_t", "e_at_plan")),
                          "{} at {}".format(*SEED_TABLE5[alg])])
    return markdown_rows(["encoding", "algorithm", "run (seed)", "energy (kWh)", "running time (s)",
                          "exact optimum at that time (kWh)", "traction / regen (kWh)", "all runs: energy (kWh)",
                          "all runs: time (s)", "all runs: least E with T <= 1050 s", "seed 003 table 5"], cells)


def verdict_text(rows) -> str:
    """The measured verdict per encoding, from the rank-sum tests."""
    lines = []
    for enc in [e for e in ENCODINGS if any(r["problem"] == e for r in rows)]:
        parts = []
        for key, lower, name in (("hv_ref", False, "hypervolume"), ("igd_ref", True, "IGD"),
                                 ("gap_mean_pct", True, "mean energy gap to the exact front"),
                                 ("e_at_plan", True, "least energy with T <= 1050 s")):
            if any(np.isfinite(r.get(key, np.nan)) for r in rows):
                p, verdict, rel = rank_sum(rows, enc, key, lower)
                word = {"+": "better (significant)", "-": "worse (significant)",
                        "=": "not significantly different"}.get(verdict, "untested")
                parts.append(f"{name}: GR-NSGA-II {word}, means differ by {rel} (p = {significant(p, 3)})")
        lines.append(f"- Measured on {enc}: " + "; ".join(parts) + ".")
    return "\n".join(lines)


def front_figures(results, chosen: dict, planned: float, exact, out: Path) -> None:
    """Figs. 10-11 (each algorithm's median-HV front), the fronts overlaid, near the planned time, and the HV boxes."""
    from pymoo_rail.plotting import plot_boxplots, plot_fronts, save_figure
    from pymoo_rail.plotting.style import new_figure

    exact_F = exact[["energy_kwh", "running_time_s"]].to_numpy(float) if exact is not None else None
    exact_label = "exact optimum (pymoo_rail.optimal)"
    fig, axes = new_figure(1, 2, figsize=(12.5, 4.8), sharex=True, sharey=True)
    for ax, alg, number in zip(axes[0], (NSGA2_LABEL, GR_LABEL), (10, 11)):
        c = chosen[MAIN_ENCODING, alg]
        plot_fronts({f"{alg}, seed {c['seed']} (median HV)": c["front"]}, OBJECTIVES,
                    reference=stats.reference_fronts(results)[MAIN_ENCODING], reference_label="union of all runs' fronts",
                    highlight=c["F"], highlight_label=f"most punctual: {c['F'][0]:.1f} kWh, {c['F'][1]:.1f} s",
                    title=f"fig. {number}: {alg} front, {MAIN_ENCODING} ({len(c['front'])} points)", ax=ax)
        if exact_F is not None:
            ax.plot(exact_F[:, 0], exact_F[:, 1], "x--", color="black", lw=1.0, ms=6, label=exact_label)
            ax.legend(fontsize="small")
        ax.axhline(planned, color="0.5", lw=0.8, ls=":")
    save_figure(fig, out / "emu_wuguang_fronts.png")
    fronts = {f"{alg}, {enc} (seed {c['seed']})": c["front"] for (enc, alg), c in chosen.items()}
    for name, title in (("overlay", "median-HV run of each algorithm and encoding"),
                        ("zoom", "near the planned time (1050 s)")):
        fig = plot_fronts(fronts, OBJECTIVES, reference=exact_F, reference_label=exact_label, title=title)
        near = np.vstack([F[np.abs(F[:, 1] - planned) <= 15] for F in fronts.values()])
        if name == "zoom" and len(near):  # the seed's fig. 12 only covers the neighbourhood of the planned time
            fig.axes[0].set(xlim=(near[:, 0].min() - 2, near[:, 0].max() + 2), ylim=(planned - 15, planned + 15))
        fig.axes[0].axhline(planned, color="0.5", lw=0.8, ls=":")
        save_figure(fig, out / f"emu_wuguang_fronts_{name}.png")
    save_figure(plot_boxplots(results, "hv_ref"), out / "emu_wuguang_box_hv.png")


def profile_figure(chosen, exact_profile, planned, exact, case, path: Path) -> None:
    """Fig. 12: the most punctual GR-NSGA-II and NSGA-II profiles, and the exact optimum when it was solved."""
    from matplotlib.lines import Line2D

    from pymoo_rail.plotting import plot_speed_profile, save_figure

    ns = chosen[MAIN_ENCODING, NSGA2_LABEL]["trajectory"]
    others = [ns] + ([exact_profile] if exact_profile is not None else [])
    labels = [f"{NSGA2_LABEL} most punctual ({ns.running_time_s:.1f} s, {ns.energy.net_kwh:.1f} kWh)"]
    if exact_profile is not None:
        labels.append(f"exact optimum at {planned:g} s ({exact_energy_kwh(exact, planned):.1f} kWh)")
    fig = plot_speed_profile(chosen[MAIN_ENCODING, GR_LABEL]["trajectory"], case, others=others, other_labels=labels,
                             label=f"fig. 12: {GR_LABEL} most punctual")
    ax = fig.axes[0]
    for line in ax.lines:
        if exact_profile is not None and line.get_label() == labels[-1]:
            line.set(color="tab:purple", linestyle="-", lw=1.4)
    legend = ax.get_legend()  # redrawn above the runs (the default one hides the stations), the optimum restyled
    texts = [t.get_text() for t in legend.get_texts()]
    handles = [Line2D([], [], color="tab:purple", linestyle="-", lw=1.4) if text == labels[-1] and exact_profile is not None
               else h for h, text in zip(legend.legend_handles, texts)]
    ax.set_ylim(0.0, 420.0)
    ax.legend(handles, texts, fontsize="small", loc="upper center", ncol=3, framealpha=0.9)
    save_figure(fig, path)


def report_values(rows, enc_rows, chosen, problems, exact, args) -> dict:
    """Every placeholder of the report template."""
    case, main = load_case(CASE), problems[MAIN_ENCODING]
    encodings = [e for e in ENCODINGS if any(r["problem"] == e for r in rows)]
    seeds = sorted({r["seed"] for r in rows})
    ver = worst_checks(rows + enc_rows)
    notes = (args.out / "emu_wuguang_notes.md").read_text() if (args.out / "emu_wuguang_notes.md").exists() else ""
    encoding_note, _, discussion = notes.partition("<!-- verdict -->")  # hand-written: "<note> <!-- verdict --> <verdict>"
    budget = "; the seed's 200 x 300 generations" if args.budget == BUDGET and args.pop_size == POP_SIZE else \
        f"; the seed's is {BUDGET:,} with population {POP_SIZE}"
    return {
        "date": time.strftime("%Y-%m-%d"), "length_km": f"{case.line.length_m / 1000:.3f}",
        "planned_s": f"{case.planned_time_s:g}", "margin_s": f"{case.time_margin_s:g}",
        "neutral_sections": ", ".join(f"{a / 1000:.3f}-{b / 1000:.3f} km" for a, b in case.line.neutral_sections),
        "min_time_s": f"{main.min_running_time_s:.1f}", "main_encoding": MAIN_ENCODING, "n_var": main.n_var,
        "n_fixed": int(main.encoding.fixed().sum()),
        "other_encodings": ", ".join(f"**{e}** ({problems[e].n_var} variables, {int(problems[e].encoding.fixed().sum())} "
                                     "fixed)" for e in encodings if e != MAIN_ENCODING),
        "budget": f"{args.budget:,}", "budget_raw": args.budget, "budget_note": budget, "seeds": ", ".join(map(str, seeds)),
        "n_seeds": len(seeds),
        "pop_size": args.pop_size, "local_size": args.local_size, "workers": args.workers,
        "exact_times": ", ".join(f"{t:g}" for t in exact["requested_time_s"]) + " s, cached in `emu_wuguang_optimal.csv` "
                       "(section 5)." if exact is not None else "(not computed).",
        "encoding_table": encoding_table(enc_rows, problems), "encoding_note": encoding_note.strip(),
        "table4": "\n\n".join(table4(rows, e) for e in encodings),
        "tests": "\n\n".join(tests_table(rows, e) for e in encodings), "table5": table5(encodings, chosen, rows, exact),
        "n_speeds": int(exact["n_speeds"].iloc[0]) if exact is not None else EXACT_N_SPEEDS,
        "exact_table": exact_front_table(exact) if exact is not None else "(not computed: `--no-exact`)",
        "n_members": ver["n_members"], "n_runs": ver["n_runs"],
        "train_length_m": f"{case.train.length_m:g}",
        "verification_table": markdown_rows(["check", "worst value over all members", "required", "result"],
                                            check_rows(ver, significant)),
        "all_ok": "yes" if ver["all_ok"] else "NO",
        "verdict": (verdict_text(rows) + "\n\n" + discussion.strip()).strip()}, ver


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--seeds", type=int, default=10, help="runs per algorithm and encoding in the main study")
    parser.add_argument("--budget", type=int, default=BUDGET, help="evaluations per run (main study)")
    parser.add_argument("--pop-size", type=int, default=POP_SIZE)
    parser.add_argument("--local-size", type=int, default=LOCAL_SIZE)
    parser.add_argument("--encodings", nargs="+", default=list(MAIN_ENCODINGS), choices=list(ENCODINGS),
                        help=f"encodings of the main study (the first one is drawn; default: {MAIN_ENCODINGS})")
    parser.add_argument("--encoding-seeds", type=int, default=ENCODING_SEEDS, help="0 skips the encoding study")
    parser.add_argument("--encoding-budget", type=int, default=ENCODING_BUDGET)
    parser.add_argument("--workers", type=int, default=2)
    parser.add_argument("--work", type=Path, default=ROOT / "out" / "emu_wuguang", help="study directories")
    parser.add_argument("--out", type=Path, default=ROOT / "benchmarks" / "reports", help="report directory")
    parser.add_argument("--report-only", action="store_true", help="analyse the stored runs only")
    parser.add_argument("--no-exact", action="store_true", help="leave out the exact front (13 solves, cached)")
    parser.add_argument("--no-progress", action="store_true")
    args = parser.parse_args(argv)
    if args.encodings[0] != MAIN_ENCODING:
        parser.error(f"--encodings: the first encoding must be {MAIN_ENCODING!r} (figs. 10-12 are drawn on it)")
    studies = {"encodings": make_study("emu_wuguang_encodings", list(ENCODINGS), range(1, args.encoding_seeds + 1),
                                       args.encoding_budget, args.pop_size, args.local_size)} if args.encoding_seeds else {}
    studies["main"] = make_study("emu_wuguang", args.encodings, range(1, args.seeds + 1), args.budget, args.pop_size,
                                 args.local_size)
    for name, study in studies.items():  # seed by seed: a study stopped early still compares like with like
        if not args.report_only:
            print(run_study(study, args.work / name, workers=args.workers, progress=not args.no_progress,
                            seed_major=True), flush=True)
    results = {name: load_results(args.work / name, study=study) for name, study in studies.items()}
    args.out.mkdir(parents=True, exist_ok=True)
    args.work.mkdir(parents=True, exist_ok=True)
    exact = None if args.no_exact else exact_front(args.out / "emu_wuguang_optimal.csv", args.work / "optimal_profile.csv")
    exact_profile = None if args.no_exact else pd.read_csv(args.work / "optimal_profile.csv")
    problems = {p.display: build_problem(p) for p in make_study("all", ENCODINGS, [1], 1).problems}
    main_results, rows = front_rows(results["main"], problems, exact)
    enc_rows = front_rows(results["encodings"], problems, exact)[1] if len(results.get("encodings", ())) else []
    chosen = punctual_choices(main_results, rows, problems)
    case = problems[MAIN_ENCODING].case
    front_figures(main_results, chosen, case.planned_time_s, exact, args.out)
    profile_figure(chosen, exact_profile, case.planned_time_s, exact, case, args.out / "emu_wuguang_profile.png")
    pd.DataFrame([{"study": "main", **r} for r in rows] + [{"study": "encodings", **r} for r in enc_rows]).to_csv(
        args.out / "emu_wuguang_runs.csv", index=False, float_format="%.6g", na_rep="nan")
    values, ver = report_values(rows, enc_rows, chosen, problems, exact, args)
    write_report(args.out / "emu_wuguang.md", [fill_template(TEMPLATE, values)], newline=False)
    print(values["verdict"])
    print(f"verification of {ver['n_members']} members in {ver['n_runs']} runs:",
          "all pass" if ver["all_ok"] else "FAILURES")
    return 0 if ver["all_ok"] else 1


if __name__ == "__main__":
    sys.exit(main())
