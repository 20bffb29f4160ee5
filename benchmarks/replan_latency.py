"""Time per re-plan of :class:`pymoo_rail.control.OptimalPolicy` against a fresh exact solve, in one run, one core.

For each case (:func:`pymoo_rail.control.study.replan_latency`): the policy is built once; in
seeded disturbed worlds the re-planning controller drives closed-loop runs, giving the states a
train really re-plans from (every 10 s and at announcements). Their CPU time per re-plan is
measured as the loop made them (``in the loop``: including the sweeps of prices and the tables of
the world's train not yet computed), then again from the same states right after (``warm``: the
train's own policy computed; also over the states in the first half of the line, where more line
is left to plan; a state too late to be on time gets the flat-out run, counted apart). Beside
them, in the same process, a fresh exact solve of the whole run
(:meth:`pymoo_rail.optimal.OptimalSolver.profile`, new solver: tables, price search, certificate)
at the planned time.

Writes ``benchmarks/reports/replan_latency.md``. Usage:
``python benchmarks/replan_latency.py [--cases yizhuang wuguang-crh3 ttobench-ref] [--worlds 3]``.
"""

from __future__ import annotations

import argparse
import os
import time
from pathlib import Path

import numba

from pymoo_rail.cases import load_case
from pymoo_rail.control.study import replan_latency, study_planned_time

REPORTS = Path(__file__).parent / "reports"


def table(rows: list[dict]) -> list[str]:
    lines = ["| case | km | re-plans (flat out) | policy built s | in the loop median / p90 ms | warm median / p90 ms "
             "| warm median, first half of the line ms | warm median, on-time plans only ms | fresh exact solve s "
             "| fresh / warm median | fresh / warm first half |",
             "|---|---|---|---|---|---|---|---|---|---|---|"]
    for r in rows:
        lines.append(f"| {r['case']} | {r['length_km']:.1f} | {r['replans']} ({r['fastest']}) | {r['build_s']:.2f} "
                     f"| {r['loop_median_ms']:.1f} / {r['loop_p90_ms']:.1f} | {r['warm_median_ms']:.1f} / "
                     f"{r['warm_p90_ms']:.1f} | {r['first_half_ms']:.1f} | {r['on_time_plans_ms']:.1f} | {r['fresh_s']:.2f} "
                     f"| {1000 * r['fresh_s'] / r['warm_median_ms']:.0f}x | {1000 * r['fresh_s'] / r['first_half_ms']:.0f}x |")
    return lines


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--cases", nargs="+", default=["yizhuang", "wuguang-crh3", "ttobench-ref"])
    parser.add_argument("--worlds", type=int, default=3)
    parser.add_argument("--seed", type=int, default=7)
    args = parser.parse_args()
    numba.set_num_threads(1)  # one core
    started = time.process_time()
    rows = []
    for name in args.cases:
        case = load_case(name)
        rows.append(replan_latency(case, study_planned_time(case), args.worlds, args.seed))
    lines = ["# Re-planning latency", "",
             f"Produced by `benchmarks/replan_latency.py --cases {' '.join(args.cases)} --worlds {args.worlds} "
             f"--seed {args.seed}` in {time.process_time() - started:.0f} s of CPU, one Numba thread "
             f"(load average {os.getloadavg()[0]:.1f}), each case planned as in the closed-loop study "
             "(`study_planned_time`). CPU time per re-plan (process time), over the states the "
             "re-planning controller met in closed-loop runs of seeded disturbed worlds; warm: again from the same "
             "states right after each world's run; a fresh exact solve of the whole run at the planned time (new "
             "solver) in the same process.", ""] + table(rows)
    text = "\n".join(lines) + "\n"
    (REPORTS / "replan_latency.md").write_text(text, encoding="utf-8")
    print(text)


if __name__ == "__main__":
    main()
