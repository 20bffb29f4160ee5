"""Whole-line running-time allocation on the Beijing Yizhuang line (TTOBench data).

Measures, in one run:

- the section fronts from the exact solver (``pymoo_rail.optimal.optimal_front``) and from the
  simulated strategy search (31 x 31 and 61 x 61 strategies per section): time to compute, and how
  far the search's fronts lie above the exact ones;
- for several trip times, the line's net energy under the exact energy-optimal split, an equal
  supplement per section and a supplement proportional to each section's minimum time, and what
  the split computed on the simulated fronts costs on the exact ones;
- pymoo's DE with the budget repair on the same allocation problem, against the exact optimum;
- a plot (energy against trip time, the saving over the equal split, the per-section supplements).

Usage::

    nice -n 10 python benchmarks/journeys.py [--out benchmarks/reports]

Writes ``journeys.md``, ``journeys.png`` and the fronts ``journeys_fronts_optimal.csv`` /
``journeys_fronts_simulated.csv`` into ``--out``. The exact fronts take minutes; each finished
section is added to its CSV at once and read back on a re-run, so an interrupted run loses
nothing that had finished. A section is read back only when its content, the version of what
computed it (``pymoo_rail.optimal.solver.SOLVER_VERSION``, ``pymoo_rail.journeys.fronts.STRATEGY_VERSION``)
and the settings match (``pymoo_rail.journeys.section_fronts``); anything else is recomputed.
"""

from __future__ import annotations

import argparse
import json
import time
from pathlib import Path

import numpy as np
import pandas as pd

from pymoo_rail.cases.ttobench import BEIJING_SUBWAY_TRAIN, YIZHUANG_STOP_NAMES, YIZHUANG_TRACK
from pymoo_rail.experiments.report import fill_template, markdown
from pymoo_rail.journeys import (allocate_running_time, convex_front, journey_from_ttobench, strategy_front,
                                 supplement_split)
from pymoo_rail.journeys.compare import (de_allocation_runs, front_gaps, split_sweep, supplement_tables,
                                         timed_section_fronts)
from pymoo_rail.plotting import save_figure
from pymoo_rail.plotting.journey import plot_split_costs

SUPPLEMENTS = (0.0, 0.03, 0.05, 0.075, 0.10, 0.15, 0.20, 0.25)
TRIP_TIME_S = 1800.0
TEMPLATE = Path(__file__).resolve().parent / "templates" / "journeys.md"
GAP_COLUMNS = ["section", "label", "range s", "31x31 mean %", "31x31 min %", "31x31 max %", "61x61 mean %",
               "combined mean %", "combined min %"]


def cache_notes(journey, timing: Path, exact_time: float, exact_cached: int, sim_cached: int):
    """The exact fronts' time (as measured when computed, if every section was read back) and the notes."""
    cached_note = ""
    if exact_cached:
        cached_note = f" ({exact_cached} of 13 sections read from the CSV of an earlier run"
        if exact_cached == journey.n_sections and timing.is_file():
            exact_time = json.loads(timing.read_text())["seconds"]
            cached_note += ", time measured when they were computed"
        cached_note += ")"
    sim_note = f" ({sim_cached} of 13 sections read from the CSV of an earlier run)" if sim_cached else ""
    return exact_time, cached_note, sim_note


def main(argv=None) -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--out", type=Path, default=Path(__file__).resolve().parent / "reports")
    parser.add_argument("--n-times", type=int, default=16, help="running times per section for the exact fronts")
    parser.add_argument("--de-gens", type=int, default=200)
    args = parser.parse_args(argv)
    args.out.mkdir(parents=True, exist_ok=True)
    journey = journey_from_ttobench(YIZHUANG_TRACK, BEIJING_SUBWAY_TRAIN, stop_names=YIZHUANG_STOP_NAMES)
    strategy_front(journey.sections[0], n_speeds=3, n_coast=3)  # JIT warm-up outside the timings
    exact, exact_time, exact_cached = timed_section_fronts(journey, "optimal", args.out / "journeys_fronts_optimal.csv",
                                                   n_times=args.n_times)
    timing = args.out / "journeys_fronts_optimal.time.json"
    if exact_cached == 0:  # all computed in this run: keep the time for re-runs that read the CSV
        timing.write_text(json.dumps({"seconds": exact_time, "n_times": args.n_times}) + "\n")
    sim, sim_time, sim_cached = timed_section_fronts(journey, "simulated", args.out / "journeys_fronts_simulated.csv")
    t0 = time.perf_counter()
    fine = [strategy_front(c, n_speeds=61, n_coast=61) for c in journey.sections]
    fine_time = time.perf_counter() - t0
    columns = ["running_time_s", "energy_kwh"]
    combined = [convex_front(pd.concat([e[columns], s_[columns]], ignore_index=True)) for e, s_ in zip(exact, sim)]
    gaps = front_gaps(exact, {"31x31": sim, "61x61": fine, "combined": combined}, journey)[GAP_COLUMNS]
    lo = np.array([f.running_time_s.iloc[0] for f in exact]).sum()
    hi = np.array([f.running_time_s.iloc[-1] for f in exact]).sum()
    table, cross = supplement_tables(journey, exact, sim, combined, SUPPLEMENTS)
    total = journey.running_time_s(TRIP_TIME_S)
    best = allocate_running_time(journey, total, fronts=exact)
    equal = supplement_split(journey, total, fronts=exact)
    de = de_allocation_runs(exact, total, best.energy_kwh, args.de_gens)
    save_figure(plot_split_costs(split_sweep(journey, exact), best, equal, "Yizhuang line, 13 sections (exact fronts)"),
                args.out / "journeys.png", dpi=110)
    per_section = best.table[["section", "label", "length_m", "min_time_s", "running_time_s", "supplement_s",
                              "energy_kwh"]].assign(equal_supplement_s=equal.table.supplement_s,
                                                    equal_energy_kwh=equal.energies_kwh)
    exact_time, cached_note, sim_note = cache_notes(journey, timing, exact_time, exact_cached, sim_cached)
    report = fill_template(TEMPLATE, {
        "n_times": args.n_times, "exact_time": f"{exact_time:.0f}", "cached_note": cached_note,
        "sim_time": f"{sim_time:.1f}", "sim_note": sim_note, "fine_time": f"{fine_time:.1f}", "lo": f"{lo:.1f}",
        "trip_lo": f"{journey.trip_time_s(lo):.1f}", "hi": f"{hi:.1f}", "table": markdown(table, 2, missing="-"),
        "cross": markdown(cross, 2, missing="-"), "trip_min": f"{TRIP_TIME_S / 60:.0f}",
        "best_kwh": f"{best.energy_kwh:.2f}", "equal_kwh": f"{equal.energy_kwh:.2f}",
        "saved_pct": f"{100 * (equal.energy_kwh - best.energy_kwh) / equal.energy_kwh:.2f}",
        "price_wh_per_s": f"{1000 * best.price_kwh_per_s:.1f}", "per_section": markdown(per_section, 2, missing="-"),
        "de_gens": args.de_gens, "best_kwh_4": f"{best.energy_kwh:.4f}", "de": markdown(de, 4, missing="-"),
        "gaps": markdown(gaps, 3, missing="-")})
    (args.out / "journeys.md").write_text(report, encoding="utf-8")
    print(report)


if __name__ == "__main__":
    main()
