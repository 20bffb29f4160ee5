"""Exact solver: timing of the yizhuang front, grid refinement, and the independent checks.

Prints, measured in this one run, and writes the same tables to ``benchmarks/reports/optimal.md``
with a front plot and a profile plot beside it:

1. ``optimal_front(yizhuang)`` at 10 running times from the minimum to 1.5 x the minimum (the
   issue asks for under a minute on 2 cores), after a warm-up that loads the Numba cache;
2. grid refinement at 135, 150 and 180 s: speed nodes 100 / 200 / 400 / 800 and position steps
   2 / 1 / 0.5 m, the energy moved to exactly the requested time along the front's slope;
3. the level-track closed form (maximum traction, hold, coast, maximum braking) against the DP;
4. a direct search over traction-hold-coast-brake strategies (hold speed and coast point; two
   holds with a coast between) against the DP, on yizhuang.

Usage: ``python benchmarks/optimal.py [--quick]`` (``--quick`` skips the 800-node and 0.5 m grids
and the two-hold search).
"""

from __future__ import annotations

import argparse
import os
from pathlib import Path

import numpy as np
import pandas as pd

from pymoo_rail.cases import load_case
from pymoo_rail.constants import KMH_PER_MS
from pymoo_rail.experiments import exact_checks as checks
from pymoo_rail.experiments.report import fill_template, markdown, write_report
from pymoo_rail.optimal import optimal_profile
from pymoo_rail.plotting import plot_fronts, plot_speed_profile, save_figure
from pymoo_rail.sim import Simulator, gradient_limit_partition, speed_code_programs

REPORTS = Path(__file__).resolve().parent / "reports"
TEMPLATES = Path(__file__).resolve().parent / "templates"


def draw(case, front, planned, out: Path) -> None:
    """The front beside the speed-code run and Liu's (2019) results, and the optimal profile at 150 s."""
    codes = Simulator(case).run(speed_code_programs(gradient_limit_partition(case.line), np.full(8, 60 / KMH_PER_MS))[0])
    seeds = pd.DataFrame({"running_time_s": [150.0, 149.89, 149.6], "energy_kwh": [19.68, 19.55, 20.43]})
    columns = ["running_time_s", "energy_kwh"]
    fig = plot_fronts({"60 km/h speed codes (simulator)": np.array([[codes.running_time_s, codes.energy.net_kwh]]),
                       "seed 000 results (own MATLAB model)": seeds[columns].to_numpy()},
                      objectives=("running_time", "energy"), reference=front[columns], reference_label="optimum (DP)",
                      title="yizhuang: minimum net energy against running time")
    save_figure(fig, out / "optimal_front.png")
    codes_label = f"60 km/h speed codes: {codes.running_time_s:.1f} s, {codes.energy.net_kwh:.2f} kWh"
    save_figure(plot_speed_profile(planned, case, others=[codes], other_labels=[codes_label],
                                   title=f"yizhuang: optimal profile at 150 s ({planned.running_time_s:.1f} s, "
                                         f"{planned.energy.net_kwh:.2f} kWh)"), out / "optimal_profile.png")


def report_text(case, quick: bool) -> tuple:
    """The report's text, the front and the optimal run at the planned time."""
    load = os.getloadavg()[0]
    front, elapsed, warm_up, fastest = checks.timed_front(case)
    planned = optimal_profile(case, case.planned_time_s)
    grids = checks.REFINEMENT_GRIDS + (() if quick else checks.FINE_GRIDS)
    text = fill_template(TEMPLATES / "optimal.md", {
        "quick": " --quick" if quick else "", "cores": os.cpu_count(), "load": f"{load:.1f}",
        "fastest": f"{fastest:.2f}", "slowest": f"{1.5 * fastest:.2f}", "elapsed": f"{elapsed:.1f}",
        "warm_up": f"{warm_up:.1f}", "front": markdown(front), "planned_kwh": f"{planned.energy.net_kwh:.3f}",
        "planned_s": f"{planned.running_time_s:.2f}", "planned_at_kwh": f"{checks.energy_at(planned, 150.0):.3f}",
        "flat_out_kwh": f"{Simulator(case).flat_out().energy.net_kwh:.2f}",
        "refinement": markdown(checks.grid_refinement(case, grids=grids)), "level": markdown(checks.level_track_table()),
        "search": markdown(checks.strategy_search_table(case, two_holds=not quick))})
    return text, front, planned


def main(argv=None) -> None:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--quick", action="store_true")
    parser.add_argument("--out", type=Path, default=REPORTS, help="report folder")
    args = parser.parse_args(argv)
    case = load_case("yizhuang")
    text, front, planned = report_text(case, args.quick)
    print(text, end="")
    args.out.mkdir(parents=True, exist_ok=True)
    draw(case, front, planned, args.out)
    write_report(args.out / "optimal.md", [text], newline=False)
    print(f"written {args.out / 'optimal.md'}")


if __name__ == "__main__":
    main()
