"""Why re-planning tracked by a PID costs more than the policy's own controls: one disturbance at a time.

On each case (planned as in the closed-loop study), single worlds with one disturbance each
(none; speed-sensor noise; a heavier, draggier train with traction lag; weak adhesion) are
driven by PID tracking of the plan, re-planning every 10 s tracked by the same PID, hysteresis
tracking and the policy's controls applied directly, through
:func:`pymoo_rail.control.study.world_rows` (energy above the real train's exact optimum at the
run's own running time, lateness).

Writes ``benchmarks/reports/replanning_pid.md``. Usage:
``python benchmarks/replanning_pid.py [--cases yizhuang metro-a]``.
"""

from __future__ import annotations

import argparse
from pathlib import Path

from pymoo_rail.cases import load_case
from pymoo_rail.control.closed_loop import LoopDisturbance
from pymoo_rail.experiments.loop_study import disturbance_markdown, disturbance_rows
from pymoo_rail.experiments.report import lower_priority, write_filled

HERE = Path(__file__).parent
WORLDS = {"none": LoopDisturbance(),
          "speed noise 0.3 km/h": LoopDisturbance(speed_noise_kmh=0.3, noise_seed=1),
          "mass and resistance +10 %, traction lag 0.3 s": LoopDisturbance(mass_factor=1.1, resistance_factor=1.1,
                                                                             traction_lag_s=0.3),
          "adhesion 0.87": LoopDisturbance(adhesion_factor=0.87)}
CONTROLLERS = ("tracking_pid", "replanning", "tracking_hysteresis", "optimal_controls")


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--cases", nargs="+", default=["yizhuang", "metro-a"])
    args = parser.parse_args()
    lower_priority()
    runs = disturbance_rows([load_case(name) for name in args.cases], WORLDS, CONTROLLERS)
    print(write_filled(HERE / "reports" / "replanning_pid.md", HERE / "templates" / "replanning_pid.md",
                       {"cases": " ".join(args.cases), "table": disturbance_markdown(runs, CONTROLLERS)}))


if __name__ == "__main__":
    main()
