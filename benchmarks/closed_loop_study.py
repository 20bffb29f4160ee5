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
(``--workers``), so a stopped study resumes where it was when run again (by the same code). With the tuned trackers
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

import pandas as pd

from pymoo_rail.cases import load_case
from pymoo_rail.control.study import STUDY_CONTROLLERS, TUNED_CONTROLLERS, loop_summary
from pymoo_rail.experiments.loop_study import (
    advice_markdown,
    load_loop_rows, loop_code,
    loop_tests,
    run_loop_study,
    study_items,
    summary_markdown,
    tests_markdown,
)
from pymoo_rail.experiments.loop_late import late_worlds_markdown
from pymoo_rail.experiments.report import lower_priority, write_filled
from pymoo_rail.plotting import plot_gap_lateness, save_figure

REPORTS = Path(__file__).parent / "reports"
TEMPLATE = Path(__file__).parent / "templates" / "closed_loop_study.md"
OUT = Path(__file__).parents[1] / "out" / "closed_loop_study"
CASES = ("yizhuang", "metro-a", "wuguang-crh3", "ttobench-ref")
TRACKING = ("tracking_pid", "tracking_fuzzy_pid", "tracking_hysteresis") + TUNED_CONTROLLERS


def report(runs: pd.DataFrame, seconds: float | None, args) -> str:
    """The report, its summary CSV and its figure, in the cases' order asked; returns the report's text."""
    runs = pd.concat([runs[runs["case"] == name] for name in args.cases])
    summary = loop_summary(runs)
    summary.to_csv(REPORTS / "closed_loop_study_summary.csv", index=False, float_format="%.6g")
    save_figure(plot_gap_lateness(runs, STUDY_CONTROLLERS + TUNED_CONTROLLERS), REPORTS / "closed_loop_study.png",
                dpi=80)
    worlds = runs.groupby(["case", "run"], sort=False)["world_cpu_s"].first()
    per_case = worlds.groupby(level=0, sort=False)
    return write_filled(REPORTS / "closed_loop_study.md", TEMPLATE, {
        "runs": args.runs, "runs_long": args.runs_long, "seed": args.seed,
        "world_cpu_s": f"{worlds.sum():.0f}", "code": loop_code()["pymoo-rail code"],
        "tuning": f", {seconds:.0f} s in the main process (the tuning)." if seconds else ".",
        "worlds": ", ".join(f"{c} {n}" for c, n in per_case.size().items()),
        "world_cpu": ", ".join(f"{c} {v:.1f} s" for c, v in per_case.median().items()),
        "summary": summary_markdown(summary), "advice": advice_markdown(runs), "late": late_worlds_markdown(runs),
        "tests": tests_markdown(loop_tests(runs, TRACKING))})


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
    items = study_items([load_case(name) for name in args.cases], args.runs, args.runs_long, not args.no_tuning,
                        say=lambda text: print(text, flush=True))
    runs = run_loop_study(items, args.seed, args.work, args.workers, args.chunk,
                          say=lambda text: print(text, flush=True))
    runs.to_csv(OUT / "runs.csv", index=False)
    print(report(runs, time.process_time() - started, args))  # the main process's CPU: the tuning


if __name__ == "__main__":
    main()
