"""The closed-loop study: curve tracking, recovery, re-planning and driver advice on disturbed trains.

Seeded worlds per case (:func:`pymoo_rail.control.study.draw_loop_disturbances`: mass, adhesion,
speed noise, traction lag, resistance and regeneration errors, a late departure in half of them,
a temporary speed restriction announced on the way in half of them), each driven by every
controller of :data:`pymoo_rail.control.study.STUDY_CONTROLLERS`. Energy is compared at equal
arrival against the real train's exact optimum at each run's own running time (``gap_pct``) and
through the exact plan's price of time (``cost_kwh = net energy + lambda x lateness``);
the lateness, stop error, comfort (acceleration variation) and advice changes are reported beside
it, with Wilcoxon rank-sum tests of every controller against the best curve-tracking one.

The worlds are computed by :func:`pymoo_rail.experiments.loop_study.run_loop_study`: one record per world
in a result store (``out/closed_loop_study/store``), in chunks handed to a process pool
(``--workers``), so a stopped study resumes where it was when run again. With the tuned trackers
(default), each case's PID and fuzzy PID are first tuned on its plan by pymoo's DE
(:func:`pymoo_rail.experiments.loop_study.tuned_trackers`).

Writes ``benchmarks/reports/closed_loop_study.md``, ``closed_loop_study_summary.csv`` and the
figure ``closed_loop_study.png`` (not tracked); the per-run rows also go to
``out/closed_loop_study/runs.csv`` (``--report-only`` rebuilds the report from the store).

Usage: ``python benchmarks/closed_loop_study.py [--runs 200] [--runs-long 200] [--seed 1]
[--workers 2] [--cases yizhuang metro-a wuguang-crh3 ttobench-ref] [--report-only]``. The
defaults are the full study (200 worlds per case); ``--runs-long`` sets the worlds of the lines
over 10 km.
"""

from __future__ import annotations

import argparse
import time
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import pandas as pd  # noqa: E402

from pymoo_rail.cases import load_case  # noqa: E402
from pymoo_rail.control.study import STUDY_CONTROLLERS, TUNED_CONTROLLERS, loop_summary, study_planned_time  # noqa: E402
from pymoo_rail.experiments.loop_study import (  # noqa: E402
    LoopStudyCase,
    load_loop_rows,
    loop_tests,
    run_loop_study,
    tuned_trackers,
)
from pymoo_rail.plotting import save_figure  # noqa: E402
from pymoo_rail.experiments.report import fixed, lower_priority  # noqa: E402

REPORTS = Path(__file__).parent / "reports"
OUT = Path(__file__).parents[1] / "out" / "closed_loop_study"
CASES = ("yizhuang", "metro-a", "wuguang-crh3", "ttobench-ref")
TRACKING = ("tracking_pid", "tracking_fuzzy_pid", "tracking_hysteresis") + TUNED_CONTROLLERS


def figure(runs: pd.DataFrame, path: Path) -> None:
    """Energy above the real train's exact optimum at the run's own time, against lateness; one panel per case."""
    import matplotlib.pyplot as plt

    cases = list(dict.fromkeys(runs["case"]))
    fig, axes = plt.subplots(1, len(cases), figsize=(4.2 * len(cases), 4.0), squeeze=False)
    palette = plt.get_cmap("tab20").colors
    colors = dict(zip(STUDY_CONTROLLERS + TUNED_CONTROLLERS, palette[::2] + palette[1::2]))
    for ax, case in zip(axes[0], cases):
        g = runs[runs["case"] == case]
        for name, h in g.groupby("controller", sort=False):
            ax.scatter(h["lateness_s"], h["gap_pct"], s=8, alpha=0.5, color=colors[name])
            ax.scatter([h["lateness_s"].median()], [h["gap_pct"].median()], s=60, marker="D", edgecolor="black",
                       color=colors[name], label=name)
        ax.axvline(0.0, color="grey", lw=0.6)
        ax.set_title(case)
        ax.set_xlabel("lateness (s)")
        ax.set_ylabel("energy above the exact optimum at the same time (%)")
        ax.grid(alpha=0.3)
    axes[0][0].legend(fontsize=7, loc="upper right")
    fig.tight_layout()
    save_figure(fig, path, dpi=80)


def header(runs: pd.DataFrame, seconds: float | None, args) -> list[str]:
    worlds = runs.groupby(["case", "run"], sort=False)["world_cpu_s"].first()
    return ["# Closed-loop study: tracking, recovery, re-planning and driver advice on disturbed trains", "",
            f"Produced by `benchmarks/closed_loop_study.py --runs {args.runs} --runs-long {args.runs_long} "
            f"--seed {args.seed}`; {worlds.sum():.0f} s of CPU in the worlds (every controller and the exact optima)"
            + (f", {seconds:.0f} s in the main process (the tuning)." if seconds else "."),
            "Worlds per case: " + ", ".join(f"{c} {n}" for c, n in worlds.groupby(level=0, sort=False).size().items())
            + "; CPU per world (median): " + ", ".join(
                f"{c} {v:.1f} s" for c, v in worlds.groupby(level=0, sort=False).median().items())
            + ". Energy at equal arrival, two ways: `gap to exact`, the run's energy above the real train's exact "
            "optimum at the run's own running time (the exact solver on the world's own model, restriction known "
            "from the start); `cost_kwh = net energy + lambda x lateness` with the exact plan's price of time. On "
            "time: within 2 s of the plan, among the worlds where the real train flat out could be.", ""]


def summary_lines(summary: pd.DataFrame) -> list[str]:
    lines = ["| case | controller | median gap to exact % | median cost kWh | median energy kWh | median lateness s "
             "| on time (of possible) | late | median stop error m | median accel. variation m/s^2 "
             "| s per advice change | ms per re-plan |",
             "|---|---|---|---|---|---|---|---|---|---|---|---|"]
    for _, r in summary.iterrows():
        lines.append(f"| {r['case']} | {r['controller']} | {fixed(r['median_gap_pct'], missing='n/a')} "
                     f"| {fixed(r['median_cost_kwh'], 3, missing='n/a')} | {fixed(r['median_net_kwh'], 3, missing='n/a')} "
                     f"| {fixed(r['median_lateness_s'], missing='n/a')} | {fixed(100 * r['on_time_share'], 0, missing='n/a')} % of "
                     f"{int(r['n_can_be_on_time'])} | {fixed(100 * r['late_share'], 0, missing='n/a')} % "
                     f"| {fixed(r['median_stop_error_m'], 3, missing='n/a')} | {fixed(r['median_jerk_ms2'], missing='n/a')} "
                     f"| {fixed(r['median_seconds_per_change'], 1, missing='n/a')} | {fixed(r['median_decision_cpu_ms'], 1, missing='n/a')} |")
    return lines


def advice_lines(runs: pd.DataFrame) -> list[str]:
    lines = ["", "## Driver advice (1.5 s reaction) against the policy's own controls, world by world", "",
             "Paired by world: `cost_kwh` of the advised run over that of `optimal_controls` (both re-plan every "
             "10 s from the same states of the same worlds).", "",
             "| case | worlds | median extra cost | 90th percentile | worlds over 1 % |", "|---|---|---|---|---|"]
    for case, g in runs.groupby("case", sort=False):
        adv = g[g["controller"] == "advice"].set_index("run")["cost_kwh"]
        opt = g[g["controller"] == "optimal_controls"].set_index("run")["cost_kwh"]
        extra = 100.0 * (adv / opt.reindex(adv.index) - 1.0)
        lines.append(f"| {case} | {len(extra)} | {extra.median():+.2f} % | {extra.quantile(0.9):+.2f} % "
                     f"| {int((extra > 1.0).sum())} |")
    return lines


def tests_lines(tests: pd.DataFrame) -> list[str]:
    lines = ["", "## Wilcoxon signed-rank tests (paired by world) against the best curve tracking of each case", "",
             "`+`: significantly lower (better) than the tracking controller at p < 0.05, `-`: higher, `=`: no "
             "significant difference.", "",
             "| case | controller | against | measure | median | median of tracking | p | verdict |",
             "|---|---|---|---|---|---|---|---|"]
    for _, r in tests.iterrows():
        lines.append(f"| {r['case']} | {r['controller']} | {r['against']} | {r['measure']} | {fixed(r['median'], 3, missing='n/a')} "
                     f"| {fixed(r['median_against'], 3, missing='n/a')} | {fixed(r['p_value'], 4, missing='n/a')} | {r['verdict']} |")
    return lines


def report(runs: pd.DataFrame, seconds: float | None, args) -> str:
    runs = pd.concat([runs[runs["case"] == name] for name in args.cases])  # the cases in the order asked
    summary = loop_summary(runs)
    summary.to_csv(REPORTS / "closed_loop_study_summary.csv", index=False, float_format="%.6g")
    figure(runs, REPORTS / "closed_loop_study.png")
    lines = (header(runs, seconds, args) + summary_lines(summary) + advice_lines(runs)
             + tests_lines(loop_tests(runs, TRACKING)) + ["", "![energy against lateness](closed_loop_study.png)", ""])
    text = "\n".join(lines)
    (REPORTS / "closed_loop_study.md").write_text(text, encoding="utf-8")
    return text


def study_items(names, runs: int, runs_long: int, tune: bool) -> list:
    """Each case with its planned time, worlds and (with ``tune``) the PID and fuzzy PID tuned on its plan."""
    from pymoo_rail.control.policy import OptimalPolicy

    items = []
    for name in names:
        case = load_case(name)
        planned = study_planned_time(case)
        n = runs if case.line.length_m <= 10_000 else runs_long
        tuned = {}
        if tune:
            plan = OptimalPolicy(case, planned, certify=False).plan
            tuned = tuned_trackers(case, plan)
            print(f"{name}: tuned {tuned}", flush=True)
        items.append(LoopStudyCase(case, planned, n, tuned))
    return items


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--runs", type=int, default=200, help="worlds per case (lines up to 10 km)")
    parser.add_argument("--runs-long", type=int, default=None, help="worlds per case over 10 km (default: --runs)")
    parser.add_argument("--seed", type=int, default=1)
    parser.add_argument("--cases", nargs="+", default=list(CASES))
    parser.add_argument("--workers", type=int, default=1, help="processes of the pool")
    parser.add_argument("--chunk", type=int, default=5, help="worlds of one case per task")
    parser.add_argument("--no-tuning", action="store_true", help="leave out the tuned PID and fuzzy PID")
    parser.add_argument("--work", type=Path, default=OUT / "store", help="the result store (resumable)")
    parser.add_argument("--report-only", action="store_true")
    args = parser.parse_args()
    args.runs_long = args.runs if args.runs_long is None else args.runs_long
    lower_priority()
    OUT.mkdir(parents=True, exist_ok=True)
    if args.report_only:
        runs = load_loop_rows(args.work)
        print(report(runs, None, args))
        return
    started = time.process_time()
    items = study_items(args.cases, args.runs, args.runs_long, not args.no_tuning)
    runs = run_loop_study(items, args.seed, args.work, args.workers, args.chunk,
                          say=lambda text: print(text, flush=True))
    runs.to_csv(OUT / "runs.csv", index=False)
    print(report(runs, time.process_time() - started, args))  # the main process's CPU: the tuning


if __name__ == "__main__":
    main()
