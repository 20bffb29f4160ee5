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
from pymoo_rail.journeys import (
    BudgetRepair,
    journey_from_ttobench,
    RunningTimeAllocationProblem,
    allocate_running_time,
    convex_front,
    front_energy,
    section_fronts,
    strategy_front,
    supplement_split,
)
from pymoo_rail.experiments.report import markdown
from pymoo_rail.model import CaseError

SUPPLEMENTS = (0.0, 0.03, 0.05, 0.075, 0.10, 0.15, 0.20, 0.25)
TRIP_TIME_S = 1800.0


def rule_energy(journey, total, fronts, rule):
    try:
        return supplement_split(journey, total, fronts=fronts, rule=rule).energy_kwh
    except CaseError:
        return float("nan")  # the rule pushes a section beyond its front: reported as "-"


def on_fronts(fronts, times):
    """Line energy of given section times on given fronts (CaseError outside a front's range)."""
    return float(sum(front_energy(f, t) for f, t in zip(fronts, times)))


def timed_fronts(journey, source, cache, **kwargs):
    """The fronts, the wall seconds they took, and how many sections were read from ``cache``."""
    read = []
    t0 = time.perf_counter()
    fronts = section_fronts(journey, source, cache_path=cache, on_front=lambda k, computed: read.append(not computed),
                            **kwargs)
    return fronts, time.perf_counter() - t0, sum(read)


def main(argv=None) -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--out", type=Path, default=Path(__file__).resolve().parent / "reports")
    parser.add_argument("--n-times", type=int, default=16, help="running times per section for the exact fronts")
    parser.add_argument("--de-gens", type=int, default=200)
    args = parser.parse_args(argv)
    args.out.mkdir(parents=True, exist_ok=True)

    journey = journey_from_ttobench(YIZHUANG_TRACK, BEIJING_SUBWAY_TRAIN, stop_names=YIZHUANG_STOP_NAMES)
    strategy_front(journey.sections[0], n_speeds=3, n_coast=3)  # JIT warm-up outside the timings
    exact, exact_time, exact_cached = timed_fronts(journey, "optimal", args.out / "journeys_fronts_optimal.csv",
                                                   n_times=args.n_times)
    timing = args.out / "journeys_fronts_optimal.time.json"
    if exact_cached == 0:  # all computed in this run: keep the time for re-runs that read the CSV
        timing.write_text(json.dumps({"seconds": exact_time, "n_times": args.n_times}) + "\n")
    sim, sim_time, sim_cached = timed_fronts(journey, "simulated", args.out / "journeys_fronts_simulated.csv")
    t0 = time.perf_counter()
    fine = [strategy_front(c, n_speeds=61, n_coast=61) for c in journey.sections]
    fine_time = time.perf_counter() - t0

    combined = [convex_front(pd.concat([e[["running_time_s", "energy_kwh"]], s_[["running_time_s", "energy_kwh"]]],
                                       ignore_index=True)) for e, s_ in zip(exact, sim)]

    # how far the fronts lie from the exact ones, on the common time range
    gaps = []
    for k, (fe, fs, ff, fc) in enumerate(zip(exact, sim, fine, combined)):
        t_lo = max(f.running_time_s.iloc[0] for f in (fe, fs, ff))
        t_hi = min(f.running_time_s.iloc[-1] for f in (fe, fs, ff))
        t = np.linspace(t_lo, t_hi, 200)
        e = front_energy(fe, t)

        def rel(f):
            return 100 * (front_energy(f, t) - e) / np.abs(e)

        gaps.append({"section": k, "label": journey.section_label(k), "range s": f"{t_lo:.1f}-{t_hi:.1f}",
                     "31x31 mean %": np.mean(rel(fs)), "31x31 min %": np.min(rel(fs)),
                     "31x31 max %": np.max(rel(fs)), "61x61 mean %": np.mean(rel(ff)),
                     "combined mean %": np.mean(rel(fc)), "combined min %": np.min(rel(fc))})
    gaps = pd.DataFrame(gaps)

    lo = np.array([f.running_time_s.iloc[0] for f in exact])
    hi = np.array([f.running_time_s.iloc[-1] for f in exact])
    rows, cross = [], []
    for s in SUPPLEMENTS:
        total = lo.sum() * (1 + s)
        if total > hi.sum():
            continue
        best = allocate_running_time(journey, total, fronts=exact)
        equal = rule_energy(journey, total, exact, "equal")
        prop = rule_energy(journey, total, exact, "proportional")
        rows.append({"supplement %": 100 * s, "trip time s": journey.trip_time_s(total),
                     "optimal kWh": best.energy_kwh, "equal kWh": equal, "proportional kWh": prop,
                     "saving vs equal kWh": equal - best.energy_kwh,
                     "saving vs equal %": 100 * (equal - best.energy_kwh) / equal,
                     "price Wh/s": 1000 * best.price_kwh_per_s, "marginal violation": best.marginal_violation()})
        # every split run on the combined fronts (the closest estimate of the optimal fronts)
        row = {"supplement %": 100 * s,
               "optimal on combined kWh": allocate_running_time(journey, total, fronts=combined).energy_kwh}
        for name, fr in (("split from exact fronts", exact), ("split from simulated fronts", sim)):
            try:
                split = allocate_running_time(journey, total, fronts=fr).running_times_s
                row[name + " kWh"] = on_fronts(combined, split)
            except CaseError:
                row[name + " kWh"] = float("nan")
        try:
            row["equal split kWh"] = on_fronts(combined, supplement_split(journey, total, fronts=combined)
                                               .running_times_s)
        except CaseError:
            row["equal split kWh"] = float("nan")
        cross.append(row)
    table = pd.DataFrame(rows)
    cross = pd.DataFrame(cross)

    # DE with the budget repair against the exact split at the 30-minute trip
    from pymoo.algorithms.soo.nonconvex.de import DE
    from pymoo.optimize import minimize

    total = journey.running_time_s(TRIP_TIME_S)
    best = allocate_running_time(journey, total, fronts=exact)
    equal = supplement_split(journey, total, fronts=exact)
    de_rows = []
    for seed in (1, 2, 3):
        problem = RunningTimeAllocationProblem(exact, total)
        t0 = time.perf_counter()
        res = minimize(problem, DE(pop_size=40, repair=BudgetRepair()), ("n_gen", args.de_gens), seed=seed)
        de_rows.append({"seed": seed, "DE kWh": float(res.F[0]),
                        "gap to exact %": 100 * (res.F[0] / best.energy_kwh - 1),
                        "evaluations": res.algorithm.evaluator.n_eval, "time s": time.perf_counter() - t0})
    de = pd.DataFrame(de_rows)

    # plots
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    from pymoo_rail.plotting import save_figure

    widest_equal = lo.sum() + len(exact) * (hi - lo).min()
    sweep_t = np.linspace(lo.sum(), min(hi.sum(), widest_equal), 60)
    opt_e = np.array([allocate_running_time(journey, t, fronts=exact).energy_kwh for t in sweep_t])
    eq_e = np.array([rule_energy(journey, t, exact, "equal") for t in sweep_t])
    pr_e = np.array([rule_energy(journey, t, exact, "proportional") for t in sweep_t])
    trip_min = np.array([journey.trip_time_s(t) for t in sweep_t]) / 60
    fig, axes = plt.subplots(1, 3, figsize=(16, 4.6))
    ax = axes[0]
    ax.plot(trip_min, opt_e, label="energy-optimal split")
    ax.plot(trip_min, eq_e, "--", label="equal supplement")
    ax.plot(trip_min, pr_e, ":", label="proportional supplement")
    ax.set_xlabel("trip time incl. 12 x 30 s dwells (min)")
    ax.set_ylabel("net energy of the line (kWh)")
    ax.set_title("Yizhuang line, 13 sections (exact fronts)")
    ax.legend()
    ax = axes[1]
    ax.plot(trip_min, eq_e - opt_e, "--", label="equal supplement")
    ax.plot(trip_min, pr_e - opt_e, ":", label="proportional supplement")
    ax.set_xlabel("trip time incl. dwells (min)")
    ax.set_ylabel("extra energy over the optimal split (kWh)")
    ax.set_title("cost of a rule-of-thumb split")
    ax.legend()
    ax = axes[2]
    x = np.arange(journey.n_sections)
    ax.bar(x - 0.2, best.table.supplement_s, 0.4, label="energy-optimal")
    ax.bar(x + 0.2, equal.table.supplement_s, 0.4, label="equal")
    ax.set_xticks(x, [f"{k}" for k in x])
    ax.set_xlabel("section (0 = Songjiazhuang -> Xiaocun)")
    ax.set_ylabel("running-time supplement over flat-out (s)")
    ax.set_title(f"split of a {TRIP_TIME_S / 60:.0f}-min trip")
    ax.legend(loc="lower right")
    for a in axes:
        a.grid(alpha=0.3)
    fig.tight_layout()
    save_figure(fig, args.out / "journeys.png", dpi=110)

    per_section = best.table[["section", "label", "length_m", "min_time_s", "running_time_s", "supplement_s",
                              "energy_kwh"]].assign(equal_supplement_s=equal.table.supplement_s,
                                                    equal_energy_kwh=equal.energies_kwh)
    cached_note = ""
    if exact_cached:
        cached_note = f" ({exact_cached} of 13 sections read from the CSV of an earlier run"
        if exact_cached == journey.n_sections and timing.is_file():
            exact_time = json.loads(timing.read_text())["seconds"]
            cached_note += ", time measured when they were computed"
        cached_note += ")"
    sim_note = f" ({sim_cached} of 13 sections read from the CSV of an earlier run)" if sim_cached else ""
    report = f"""# Whole-line running-time allocation: Beijing Yizhuang line (TTOBench)

Generated by `benchmarks/journeys.py` (numbers measured in this run).

Line: TTOBench track `CN_Songjiazhuang_Yizhuang` (22.728 km, 14 stops, 13 sections), train
`CN_Beijing_Subway` (278 t, 310 kN / 3100 kW, regen 260 kN / 4333 kW, efficiencies 70 % / 80 %),
point mass, 1 m grid, 30 s dwells. Energies are net (traction / 0.7 - 0.8 x electric braking).

Section fronts (lower convex hulls):
- exact: `pymoo_rail.optimal.optimal_front` at {args.n_times} running times per section from 0.5 % above
  the flat-out time to 1.5 times it (spaced quadratically), plus the flat-out run:
  {exact_time:.0f} s{cached_note};
- simulated: `strategy_front`, 31 x 31 traction-hold-coast-brake runs per section: {sim_time:.1f} s{sim_note}
  (61 x 61: {fine_time:.1f} s).

Flat-out running time of the line {lo.sum():.1f} s (trip {journey.trip_time_s(lo.sum()):.1f} s); the
exact fronts reach {hi.sum():.1f} s. Every allocation is exact on its piecewise-linear fronts
(marginal violation = largest breach of the equal-marginal-energy condition, kWh/s). The price is
the energy one more second of running time would save (at 0 % it is the value of the first extra
second on the steepest section).

## Optimal split against the timetable rules of thumb (exact fronts)

Supplement = total running time over the sum of the sections' flat-out times. "-" = the rule gives
some section more time than its front covers.

{markdown(table, 2, missing="-")}

## Every split run on the combined fronts

The combined fronts are the lower hull of the exact solver's and the strategy search's points
(every point is a simulated run, so this is still an upper estimate of the optimal front, and the
closest one here). Each split below is computed on the fronts named and then run on the combined
fronts: how much a split suffers from the errors of the fronts it was computed on.

{markdown(cross, 2, missing="-")}

## The {TRIP_TIME_S / 60:.0f}-minute trip, section by section (exact fronts)

Optimal split {best.energy_kwh:.2f} kWh against {equal.energy_kwh:.2f} kWh for the equal supplement
({100 * (equal.energy_kwh - best.energy_kwh) / equal.energy_kwh:.2f} % saved), marginal price
{1000 * best.price_kwh_per_s:.1f} Wh per second of running time.

{markdown(per_section, 2, missing="-")}

## pymoo DE on the same problem (`RunningTimeAllocationProblem` + `BudgetRepair`)

DE(pop_size=40), {args.de_gens} generations, against the exact {best.energy_kwh:.4f} kWh:

{markdown(de, 4, missing="-")}

## Simulated and combined fronts against the exact ones

Relative energy difference (front - exact) / |exact| over 200 running times spanning the range
common to the fronts. Positive = more energy than the exact solver's front. Xiaohongmen ->
Jiugong (section 2) crosses zero net energy (downhill with regen), which inflates its relative
numbers.

{markdown(gaps, 3, missing="-")}

![energy against trip time](journeys.png)
"""
    (args.out / "journeys.md").write_text(report, encoding="utf-8")
    print(report)


if __name__ == "__main__":
    main()
