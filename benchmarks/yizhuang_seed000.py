"""ABC and MOABC on yizhuang as in Liu (2019), chapter 5: tables 5-5 and 5-6, savings, gaps, figs. 5-3 to 5-7.

The seed's colony and budget, ABC on the constrained form and MOABC on (energy, time error), on the
non-equal and equal partitions, through ``run_study``. Text: ``benchmarks/templates/yizhuang_seed000.md``
and the hand-written ``reports/yizhuang_seed000_notes.md``; without records, ``--report-only`` rebuilds
the tables from the committed ``yizhuang_seed000.csv``.

Usage: ``nice -n 10 python benchmarks/yizhuang_seed000.py [--seeds 30] [--workers 2] [--report-only]``
"""

from __future__ import annotations

import argparse
import json
from pathlib import Path

import numpy as np
import pandas as pd

from pymoo_rail.cases import load_case
from pymoo_rail.control import Hysteresis, track
from pymoo_rail.experiments import Study, algorithm, load_results, problem, run_study
from pymoo_rail.experiments.front_table import punctual_choice
from pymoo_rail.experiments.report import fill_template, fixed, lower_priority, markdown_rows, write_report
from pymoo_rail.experiments.stats import nondominated, rank_sum
from pymoo_rail.optimal import optimal_profile
from pymoo_rail.optimal.baselines import strategy_baselines
from pymoo_rail.optimal.reference.gap import solved_energy_gap
from pymoo_rail.plotting import plot_convergence, plot_fronts, plot_speed_profile, save_figure
from pymoo_rail.plotting.style import new_figure
from pymoo_rail.problems import SpeedProfileProblem
from pymoo_rail.optimal.reference import exact_points

HERE = Path(__file__).resolve().parent
CASE, POP, LIMIT, ARCHIVE = "yizhuang", 40, 50, 100  # colony 20 + 20, limit and cycles: seed 5.2; archive: ours
N_GEN = 1 + 2 * 100  # initial colony + 100 cycles of two iterations (employed, onlooker)
TOLERANCE_S, N_EQUAL, NON_EQUAL = 1.0, (10, 20), "non-equal"
SEED = {"ABC": (150.0, 19.68, 8.2, 19.25), "MOABC": (149.89, 19.55, 8.81, 21.67),  # tables 5-3 to 5-6:
        "MOABC equal": (149.6, 20.43, 6.73, 35.64)}  # (running time s, energy kWh, saving %, computation s)


def build_studies(seeds, tolerance_s: float = TOLERANCE_S, n_equal=N_EQUAL) -> dict:
    """ABC on the constrained form and MOABC on the Pareto form, each on every partition."""
    def partitions(**common):
        return [problem("speed_profile", label=NON_EQUAL, case=CASE, **common)] + [
            problem("speed_profile", label=f"equal-{n}", case=CASE, partition="equal", n_sections=int(n), **common)
            for n in n_equal]

    budget = {"n_gen": N_GEN}
    return {"ABC": Study("yizhuang-seed000-abc", partitions(objectives=["energy"], time_tolerance_s=float(tolerance_s)),
                         [algorithm("abc", label="ABC", pop_size=POP, limit=LIMIT)], seeds=list(seeds), budget=budget),
            "MOABC": Study("yizhuang-seed000-moabc", partitions(objectives=["energy", "time_error"]),
                           [algorithm("moabc", label="MOABC", pop_size=POP, limit=LIMIT, archive_size=ARCHIVE)],
                           seeds=list(seeds), budget=budget)}


def run_studies(out: Path, seeds, workers: int = 2, tolerance_s: float = TOLERANCE_S, n_equal=N_EQUAL,
                progress: bool = True) -> None:
    for name, study in build_studies(seeds, tolerance_s, n_equal).items():
        print(f"{name}: {run_study(study, out / name.lower(), workers=workers, progress=progress)}", flush=True)


def load(out: Path, seeds, tolerance_s: float = TOLERANCE_S, n_equal=N_EQUAL) -> dict:
    return {name: load_results(out / name.lower(), study=study)
            for name, study in build_studies(seeds, tolerance_s, n_equal).items()}


def choices(results: dict, planned_s: float, tolerance_s: float) -> pd.DataFrame:
    """One chosen solution per run, non-equal partition first, then the equal ones by size."""
    df = pd.DataFrame([punctual_choice(r, planned_s, tolerance_s) for d in results.values() for _, r in d.iterrows()])
    df["time_error_s"] = (df["running_time_s"] - planned_s).abs()
    order = df["partition"].map(lambda p: 0 if p == NON_EQUAL else int(p.split("-")[1]))
    return df.assign(order=order).sort_values(["algorithm", "order", "seed"]).drop(columns="order").reset_index(drop=True)


def make_problem(case, partition: str = NON_EQUAL, tolerance_s: float = TOLERANCE_S) -> SpeedProfileProblem:
    kwargs = {} if partition == NON_EQUAL else {"partition": "equal", "n_sections": int(partition.split("-")[1])}
    return SpeedProfileProblem(case, objectives=("energy",), time_tolerance_s=tolerance_s, **kwargs)


def reference_front(case, tolerance_s: float, path: Path) -> pd.DataFrame:
    """The exact optimum around T_plan and over the MOABC range, cached in ``path`` (``exact_points``)."""
    planned = case.planned_time_s
    near = np.round(np.arange(planned - tolerance_s - 0.5, planned + tolerance_s + 0.51, 0.25), 6)
    wide = planned + np.array([2.0, 4.0, 7.0, 10.0, 15.0, 20.0, 30.0, 40.0, 50.0])
    return exact_points(case, np.unique(np.concatenate([near, wide])), path).sort_values("running_time_s")


def saving(base: float, e) -> np.ndarray:
    return 100.0 * (base - np.asarray(e, dtype=float)) / base


def summary_rows(ch: pd.DataFrame, base: dict, gaps: pd.Series) -> pd.DataFrame:
    """Per algorithm and partition: energies, times, savings against the baselines and gaps to the optimum (%)."""
    rows = []
    for (alg, part), g in ch.groupby(["algorithm", "partition"], sort=False):
        ok = g.dropna(subset=["energy_kwh"])
        e, t = ok["energy_kwh"], ok["running_time_s"]
        row = {"algorithm": alg, "partition": part, "runs": len(g), "within": len(ok), "best_kwh": e.min(),
               "mean_kwh": e.mean(), "worst_kwh": e.max(), "std_kwh": e.std(ddof=1) if len(ok) > 1 else 0.0,
               "best_time_s": t[e.idxmin()] if len(ok) else np.nan, "mean_time_s": t.mean(), "min_time_s": t.min(),
               "max_time_s": t.max(), "wall_s": g["wall_time_s"].mean(), "gap_best": gaps[ok.index].min(),
               "gap_mean": gaps[ok.index].mean(), "gap_worst": gaps[ok.index].max()}
        for name, key in (("cruise", "cruise"), ("coast", "coast"), ("flat", "flat_out")):
            row[f"save_{name}"] = f"{fixed(saving(base[key]['energy_kwh'], row['best_kwh']), 1)} / " \
                                  f"{fixed(saving(base[key]['energy_kwh'], row['mean_kwh']), 1)}"
        rows.append(row)
    return pd.DataFrame(rows)


def summary_table(rows: pd.DataFrame, seed_rows: dict) -> str:
    """Table 5-5 / 5-6: energies, times, savings and wall time of the chosen runs, beside the seed's."""
    cells = [[r.algorithm, r.partition, f"{r.runs} ({r.within})",
              f"{fixed(r.best_kwh)} / {fixed(r.mean_kwh)} / {fixed(r.worst_kwh)}", fixed(r.std_kwh, 3),
              fixed(r.best_time_s), fixed(r.mean_time_s), f"{fixed(r.min_time_s)}-{fixed(r.max_time_s)}",
              r.save_cruise, r.save_coast, r.save_flat, fixed(r.wall_s, 1),
              *(fixed(v) for v in seed_rows.get((r.algorithm, r.partition), (None,) * 4))] for r in rows.itertuples()]
    return markdown_rows(["method", "partition", "runs (within window)", "energy best / mean / worst (kWh)", "std",
                          "T of best (s)", "T mean (s)", "T range (s)", "saving vs cruise best / mean (%)",
                          "saving vs coast point best / mean (%)", "saving vs flat-out best / mean (%)", "wall s/run",
                          "seed T (s)", "seed E (kWh)", "seed saving (%)", "seed time (s)"], cells)


def ranksum(ch, a: tuple, b: tuple) -> str:
    """p of the two-sided rank-sum test of the chosen energies of (algorithm, partition) ``a`` and ``b``."""
    p = rank_sum(*(ch[(ch["algorithm"] == alg) & (ch["partition"] == part)]["energy_kwh"] for alg, part in (a, b)))[1]
    return f"{p:.2g}" if np.isfinite(p) else "-"


def archive_table(ch: pd.DataFrame, tight: pd.DataFrame | None) -> str:
    """MOABC archive statistics per partition, and the choice within the tighter window ``tight`` (needs the records)."""
    cells = []
    for part, g in ch[ch["algorithm"] == "MOABC"].groupby("partition", sort=False):
        t = tight[tight["partition"] == part]["energy_kwh"] if tight is not None else pd.Series(dtype=float)
        cells.append([part, f"{g['n_front'].mean():.1f}", f"{g['n_within'].mean():.1f}",
                      f"{g['front_time_error_min_s'].min():.3f} / {g['front_time_error_max_s'].median():.1f}",
                      f"{g['front_energy_min_kwh'].min():.2f}-{g['front_energy_max_kwh'].max():.2f}",
                      f"{t.notna().sum()} of {len(t)}", f"{fixed(t.min())} / {fixed(t.mean())} / {fixed(t.max())}"])
    return markdown_rows(["partition", "archive size (mean)", "members within window (mean)",
                          "time error range over the archive (min of min / median of max, s)", "energy range (kWh)",
                          "runs with a member within 0.2 s", "its energy best / mean / worst (kWh)"], cells)


def report_values(case, ch, base, ref, gaps, tight, args, reports: Path) -> dict:
    """Every placeholder of the report template."""
    planned, summ = case.planned_time_s, summary_rows(ch, base, gaps)
    fo, cr, co = base["flat_out"], base["cruise"], base["coast"]
    e150 = float(np.interp(planned, ref["running_time_s"], ref["energy_kwh"]))
    solved = solved_energy_gap(np.array([[b["running_time_s"], b["energy_kwh"]] for b in (cr, co)]), case)["points"]
    seed_55 = {("ABC", NON_EQUAL): SEED["ABC"], ("MOABC", NON_EQUAL): SEED["MOABC"]}
    seed_56 = {("MOABC", NON_EQUAL): SEED["MOABC"], **{("MOABC", f"equal-{n}"): SEED["MOABC equal"] for n in args.n_equal}}
    notes = reports / "yizhuang_seed000_notes.md"
    return {
        "planned_s": f"{planned:g}", "n_eval": int(ch["n_eval"].mean()), "n_seeds": args.seeds,
        "tolerance_s": f"{args.tolerance:g}", "n_equal": ", ".join(map(str, args.n_equal)),
        "flat_kwh": f"{fo['energy_kwh']:.2f}", "flat_s": f"{fo['running_time_s']:.2f}",
        "flat_early_s": f"{planned - fo['running_time_s']:.1f}", "cruise_code": f"{cr['code_kmh']:.2f}",
        "cruise_kwh": f"{cr['energy_kwh']:.2f}", "cruise_s": f"{cr['running_time_s']:.2f}",
        "coast_m": f"{co['coast_m']:.0f}", "coast_kwh": f"{co['energy_kwh']:.2f}", "coast_s": f"{co['running_time_s']:.2f}",
        "table55": summary_table(summ[summ["partition"] == NON_EQUAL], seed_55),
        "p55": ranksum(ch, ("ABC", NON_EQUAL), ("MOABC", NON_EQUAL)), "table56": summary_table(summ, seed_56),
        "partition_tests": "\n".join(f"* {alg}: non-equal vs equal-{n}, rank-sum p = "
                                     f"{ranksum(ch, (alg, NON_EQUAL), (alg, f'equal-{n}'))}"
                                     for alg in ("ABC", "MOABC") for n in args.n_equal),
        "archive_table": archive_table(ch, tight), "e150": f"{e150:.3f}",
        "e150_saving": f"{saving(cr['energy_kwh'], e150):.1f}",
        "gap_rows": "\n".join([f"| {r.algorithm} | {r.partition} | {fixed(r.gap_best)} / {fixed(r.gap_mean)} / "
                               f"{fixed(r.gap_worst)} |" for r in summ.itertuples()]
                              + [f"| {label} | - | {100 * g:.2f} |" for label, g in
                                 zip(("constant cruise (baseline)", "coast point (baseline)"), solved["gap_rel"])]),
        "notes": notes.read_text().rstrip() if notes.exists() else "",
        "figures": "\n".join(f"![{n}]({n})" for n in figure_names(ch))}


def figure_names(ch) -> list[str]:
    parts = ch.dropna(subset=["energy_kwh"]).groupby(["algorithm", "partition"], sort=False).size().index
    return [f"yizhuang_seed000_profile_{a.lower()}_{p}.png" for a, p in parts] + [
        "yizhuang_seed000_front.png", "yizhuang_seed000_convergence.png"]


def profile_figures(case, ch, ref_traj, tolerance_s: float, reports: Path) -> None:
    """Figs. 5-4, 5-6, 5-7: the best profile of each algorithm and partition, tracked (A = 2, B = 3) and the optimum."""
    for (alg, part), g in ch.dropna(subset=["energy_kwh"]).groupby(["algorithm", "partition"], sort=False):
        b, p = g.loc[g["energy_kwh"].idxmin()], make_problem(case, part, tolerance_s)
        run = p.trajectory(np.asarray(b["x"]))
        tracked = track(case, run, Hysteresis(2.0, 3.0))
        fig = plot_speed_profile(run, case, others=[tracked, ref_traj], other_labels=[
            f"tracked, hysteresis A = 2, B = 3 km/h ({tracked.energy.net_kwh:.2f} kWh, {tracked.running_time_s:.1f} s)",
            f"exact optimum ({ref_traj.energy.net_kwh:.2f} kWh, {ref_traj.running_time_s:.1f} s)"],
            title=f"{alg}, {part} partition, seed {int(b['seed'])}: T = {run.running_time_s:.2f} s, "
                  f"E = {run.energy.net_kwh:.2f} kWh")
        ax = fig.axes[0]
        for xb in p.encoding.boundaries_m[1:-1]:
            ax.axvline(xb, color="0.75", lw=0.6, ls=":", zorder=0)
        for line in ax.get_lines():  # the tracked run dashed, as in the seed's figures; the optimum black
            if line.get_label().startswith("tracked"):
                line.set(linestyle="--", color="tab:purple")
            elif line.get_label().startswith("exact optimum"):
                line.set(color="black", linewidth=0.9)
        ax.legend(fontsize="small", loc="lower center", ncol=3, framealpha=0.9)
        save_figure(fig, reports / f"yizhuang_seed000_profile_{alg.lower()}_{part}.png")


def front_figure(results, ch, ref, planned: float, tolerance_s: float, reports: Path) -> None:
    """Fig. 5-5: the MOABC archive of the run with the best choice, the union over seeds, the exact optimum."""
    mo = results["MOABC"][results["MOABC"]["problem"] == NON_EQUAL]
    chm = ch[(ch["algorithm"] == "MOABC") & (ch["partition"] == NON_EQUAL)].dropna(subset=["energy_kwh"])
    if not len(chm):
        return
    b = chm.loc[chm["energy_kwh"].idxmin()]
    feasible = [np.asarray(r["F"])[np.asarray(r["CV"]).reshape(-1) <= 0] for _, r in mo.iterrows()]
    F, union = feasible[list(mo["seed"]).index(b["seed"])], nondominated(np.vstack(feasible))
    keep = ref["running_time_s"] >= planned - 0.05  # the solver lands within a few hundredths of a second
    reference = np.column_stack([ref["energy_kwh"][keep], np.abs(ref["running_time_s"][keep] - planned)])
    fig, axes = new_figure(1, 2, figsize=(12.0, 4.6))
    for ax, zoom in zip(axes[0], (False, True)):
        plot_fronts({f"archive, seed {int(b['seed'])}": F, f"non-dominated union of {len(mo)} runs": union},
                    objectives=["energy", "time_error"], reference=reference,
                    reference_label="exact optimum (T >= 150 s)", highlight=[b["energy_kwh"], b["time_error_s"]],
                    highlight_label=f"chosen: {b['energy_kwh']:.2f} kWh at {b['running_time_s']:.2f} s", ax=ax)
        ax.set_title("MOABC, non-equal partition (fig. 5-5)")
        if zoom:
            sel = union[union[:, 1] <= 3 * tolerance_s]
            ax.set(ylim=(-0.15 * tolerance_s, 3 * tolerance_s), title=f"zoom: time error <= {3 * tolerance_s:g} s "
                   "(dashed: tolerance)", **({"xlim": (sel[:, 0].min() - 0.3, sel[:, 0].max() + 0.3)} if len(sel) else {}))
            ax.axhline(tolerance_s, color="0.5", ls="--", lw=1)
    save_figure(fig, reports / "yizhuang_seed000_front.png")


def convergence_figure(results, tolerance_s: float, reports: Path) -> None:
    """Fig. 5-3: ABC's best feasible energy against evaluations, median and interquartile range of the seeds."""
    fig = plot_convergence(results["ABC"], "f0_min", ylabel=f"best feasible energy (kWh), |T - 150 s| <= {tolerance_s:g} s")
    save_figure(fig, reports / "yizhuang_seed000_convergence.png")


def write_report_files(args, results: dict | None) -> None:
    """The per-run CSV (from the records), the report and (from the records) the figures."""
    case = load_case(CASE)
    planned, csv_path = case.planned_time_s, args.reports / "yizhuang_seed000.csv"
    if results is not None:
        ch = choices(results, planned, args.tolerance)
        ch.drop(columns=["x"]).assign(x=[json.dumps(x) for x in ch["x"]]).to_csv(csv_path, index=False,
                                                                                 float_format="%.6g")
    else:  # no records (they are not in git): the chosen solutions the committed CSV holds
        ch = pd.read_csv(csv_path).assign(x=lambda d: d["x"].map(lambda s: json.loads(s) if isinstance(s, str) else None))
    ref = reference_front(case, args.tolerance, args.out / "reference.csv")
    ok = ch.dropna(subset=["energy_kwh"])
    points = solved_energy_gap(ok[["running_time_s", "energy_kwh"]].to_numpy(float), case)["points"]
    gaps = pd.Series(100 * points["gap_rel"].to_numpy(), index=ok.index)
    tight = choices({"MOABC": results["MOABC"]}, planned, 0.2) if results is not None else None
    values = report_values(case, ch, strategy_baselines(make_problem(case)), ref, gaps, tight, args, args.reports)
    write_report(args.reports / "yizhuang_seed000.md", [fill_template(HERE / "templates" / "yizhuang_seed000.md", values)],
                 newline=False)
    if results is not None:
        profile_figures(case, ch, optimal_profile(case, planned), args.tolerance, args.reports)
        front_figure(results, ch, ref, planned, args.tolerance, args.reports)
        convergence_figure(results, args.tolerance, args.reports)
    print(f"wrote {args.reports / 'yizhuang_seed000.md'}", flush=True)


def main(argv=None) -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--seeds", type=int, default=30, help="runs per algorithm and partition (seeds 1..N)")
    parser.add_argument("--workers", type=int, default=2, choices=(1, 2), help="process pool size")
    parser.add_argument("--out", type=Path, default=HERE.parent / "out" / "yizhuang_seed000",
                        help="run records and caches")
    parser.add_argument("--reports", type=Path, default=HERE / "reports", help="report, CSV and figures")
    parser.add_argument("--tolerance", type=float, default=TOLERANCE_S, help="|T - 150 s| window (s)")
    parser.add_argument("--n-equal", type=int, nargs="+", default=list(N_EQUAL), help="equal-partition sizes")
    parser.add_argument("--report-only", action="store_true", help="do not run; rewrite the report")
    args = parser.parse_args(argv)
    if args.seeds < 1 or not (np.isfinite(args.tolerance) and args.tolerance > 0):
        parser.error(f"--seeds {args.seeds} and --tolerance {args.tolerance} must be positive")
    lower_priority()
    seeds = list(range(1, args.seeds + 1))
    args.out.mkdir(parents=True, exist_ok=True)
    args.reports.mkdir(parents=True, exist_ok=True)
    if not args.report_only:
        run_studies(args.out, seeds, args.workers, args.tolerance, args.n_equal)
    results = load(args.out, seeds, args.tolerance, args.n_equal)
    write_report_files(args, results if all(len(r) for r in results.values()) else None)


if __name__ == "__main__":
    main()
