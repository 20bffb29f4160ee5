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
from pymoo_rail.experiments.loop_study import latency_markdown
from pymoo_rail.experiments.report import write_filled

HERE = Path(__file__).parent


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
    print(write_filled(HERE / "reports" / "replan_latency.md", HERE / "templates" / "replan_latency.md", {
        "cases": " ".join(args.cases), "worlds": args.worlds, "seed": args.seed,
        "cpu_s": f"{time.process_time() - started:.0f}", "load": f"{os.getloadavg()[0]:.1f}",
        "table": latency_markdown(rows)}))


if __name__ == "__main__":
    main()
