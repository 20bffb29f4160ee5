"""Time per re-plan of :class:`pymoo_rail.control.OptimalPolicy` against a fresh exact solve, in one run, one core.

For each case: the policy is built once; closed-loop runs of the re-planning controller on seeded
disturbed worlds (:func:`pymoo_rail.control.study.draw_loop_disturbances`) give the states a train
really re-plans from (every 10 s and at announcements). Their CPU time per re-plan is measured as
the loop made them (``in the loop``: including the sweeps of prices not yet on the lattice), then
again from the same states with the lattice warm (``warm``; also over the states in the first half
of the line, where more line is left to plan; a state too late to be on time gets the flat-out
run, counted apart). Beside them, in the same process, a
fresh exact solve of the whole run (:meth:`pymoo_rail.optimal.OptimalSolver.profile`, new solver:
tables, price search, certificate) at the planned time.

Writes ``benchmarks/reports/replan_latency.md``. Usage:
``python benchmarks/replan_latency.py [--cases yizhuang wuguang-crh3] [--worlds 3]``.
"""

from __future__ import annotations

import argparse
import os
import time
from pathlib import Path

import numba
import numpy as np

from pymoo_rail.cases import load_case
from pymoo_rail.control import PID, OptimalPolicy, Replanning, closed_loop
from pymoo_rail.control.study import draw_loop_disturbances
from pymoo_rail.optimal import OptimalSolver

REPORTS = Path(__file__).parent / "reports"


class RecordingReplanning(Replanning):
    """The re-planning controller, keeping the states it planned from."""

    def reference(self, state):
        self.states.append(state)
        return super().reference(state)


def measure(name: str, worlds: int, seed: int) -> dict:
    case = load_case(name)
    t0 = time.process_time()
    policy = OptimalPolicy(case, case.planned_time_s)
    build_s = time.process_time() - t0
    in_loop, states = [], []
    for world in draw_loop_disturbances(case, worlds, seed):
        ctl = RecordingReplanning(policy, PID(), 10.0)
        ctl.states = []
        closed_loop(case, ctl, world)
        in_loop += ctl.cpu_s
        states += ctl.states
    warm, first_half, fastest = [], [], 0
    for s in states:
        started = time.process_time()
        if s.elapsed_s >= policy.planned_time_s:
            rest = policy.fastest(s.position_m, min(s.speed_ms, policy.envelope_ms(s.position_m, s.restriction, s.mass_t)),
                           s.elapsed_s, s.restriction, s.mass_t)
        else:
            rest = policy.replan(s.position_m, min(s.speed_ms, policy.envelope_ms(s.position_m, s.restriction, s.mass_t)),
                          s.elapsed_s, s.restriction, s.mass_t)
        warm.append(time.process_time() - started)
        fastest += not np.isfinite(rest.summary["lambda_w"])  # late beyond recovery: the flat-out run
        if s.position_m < 0.5 * case.line.length_m:
            first_half.append(warm[-1])
    fresh = []
    for _ in range(2):
        started = time.process_time()
        OptimalSolver(case).profile(case.planned_time_s)
        fresh.append(time.process_time() - started)
    return {"case": name, "length_km": case.line.length_m / 1000.0, "replans": len(states), "build_s": build_s,
            "loop_median_ms": 1000 * float(np.median(in_loop)), "loop_p90_ms": 1000 * float(np.percentile(in_loop, 90)),
            "warm_median_ms": 1000 * float(np.median(warm)), "warm_p90_ms": 1000 * float(np.percentile(warm, 90)),
            "first_half_ms": 1000 * float(np.median(first_half)), "fastest": fastest,
            "fresh_s": float(np.median(fresh))}


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--cases", nargs="+", default=["yizhuang", "wuguang-crh3"])
    parser.add_argument("--worlds", type=int, default=3)
    parser.add_argument("--seed", type=int, default=7)
    args = parser.parse_args()
    numba.set_num_threads(1)  # one core
    started = time.process_time()
    rows = [measure(name, args.worlds, args.seed) for name in args.cases]
    lines = ["# Re-planning latency", "",
             f"Produced by `benchmarks/replan_latency.py --cases {' '.join(args.cases)} --worlds {args.worlds} "
             f"--seed {args.seed}` in {time.process_time() - started:.0f} s of CPU, one Numba thread "
             f"(load average {os.getloadavg()[0]:.1f}). CPU time per re-plan (process time), over the states the "
             "re-planning controller met in closed-loop runs of seeded disturbed worlds; a fresh exact solve of the "
             "whole run at the planned time (new solver) in the same process.", "",
             "| case | km | re-plans (flat out) | policy built s | in the loop median / p90 ms | warm median / p90 ms "
             "| warm median, first half of the line ms | fresh exact solve s | fresh / warm median "
             "| fresh / warm first half |",
             "|---|---|---|---|---|---|---|---|---|---|"]
    for r in rows:
        lines.append(f"| {r['case']} | {r['length_km']:.1f} | {r['replans']} ({r['fastest']}) | {r['build_s']:.2f} "
                     f"| {r['loop_median_ms']:.1f} / {r['loop_p90_ms']:.1f} | {r['warm_median_ms']:.1f} / "
                     f"{r['warm_p90_ms']:.1f} | {r['first_half_ms']:.1f} | {r['fresh_s']:.2f} "
                     f"| {1000 * r['fresh_s'] / r['warm_median_ms']:.0f}x | {1000 * r['fresh_s'] / r['first_half_ms']:.0f}x |")
    text = "\n".join(lines) + "\n"
    (REPORTS / "replan_latency.md").write_text(text, encoding="utf-8")
    print(text)


if __name__ == "__main__":
    main()
