"""Whole-line running-time allocation on the Beijing Yizhuang line (TTOBench data).

Measures, in one run:

- the section fronts (simulated strategy search by default, or the exact solver with
  ``--fronts optimal``): time to compute, range, and how much the line result moves when the
  strategy search is refined (31 x 31 against 61 x 61 strategies per section);
- for several trip times, the line's net energy under the exact energy-optimal split, an equal
  supplement per section and a supplement proportional to each section's minimum time;
- pymoo's DE with the budget repair on the same allocation problem, against the exact optimum;
- a plot (energy against trip time, the saving over the equal split, the per-section supplements).

Usage::

    nice -n 10 python benchmarks/journeys.py [--fronts simulated|optimal] [--out benchmarks/reports]

Writes ``journeys.md``, ``journeys.png`` and ``journeys_fronts.csv`` into ``--out``.
"""

from __future__ import annotations

import argparse
import sys
import time
from pathlib import Path

import numpy as np
import pandas as pd

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

from pymoo_rail.cases.ttobench import BEIJING_SUBWAY_TRAIN, YIZHUANG_STOP_NAMES, YIZHUANG_TRACK  # noqa: E402
from pymoo_rail.journeys import (  # noqa: E402
    BudgetRepair,
    Journey,
    RunningTimeAllocationProblem,
    allocate_running_time,
    section_fronts,
    strategy_front,
    supplement_split,
)
from pymoo_rail.model import CaseError  # noqa: E402

SUPPLEMENTS = (0.0, 0.03, 0.05, 0.075, 0.10, 0.15, 0.20, 0.25)
TRIP_TIME_S = 1800.0


def markdown(df: pd.DataFrame, floatfmt: str = ".2f") -> str:
    cols = list(df.columns)
    lines = ["| " + " | ".join(cols) + " |", "|" + "---|" * len(cols)]
    for row in df.astype(object).itertuples(index=False):
        cells = [format(v, floatfmt) if isinstance(v, (float, np.floating)) else str(v) for v in row]
        lines.append("| " + " | ".join(cells) + " |")
    return "\n".join(lines)


def rule_energy(journey, total, fronts, rule):
    try:
        return supplement_split(journey, total, fronts=fronts, rule=rule).energy_kwh
    except CaseError:
        return float("nan")  # the rule pushes a section beyond its front: reported as "-"


def main(argv=None) -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--fronts", default="simulated", choices=("simulated", "optimal"))
    parser.add_argument("--out", type=Path, default=Path(__file__).resolve().parent / "reports")
    parser.add_argument("--de-gens", type=int, default=200)
    args = parser.parse_args(argv)
    args.out.mkdir(parents=True, exist_ok=True)

    journey = Journey.from_ttobench(YIZHUANG_TRACK, BEIJING_SUBWAY_TRAIN, stop_names=YIZHUANG_STOP_NAMES)
    strategy_front(journey.sections[0], n_speeds=3, n_coast=3)  # JIT warm-up outside the timings
    t0 = time.perf_counter()
    fronts = section_fronts(journey, args.fronts)
    front_time = time.perf_counter() - t0
    pd.concat([f.assign(section=k, label=journey.section_label(k)) for k, f in enumerate(fronts)]).to_csv(
        args.out / "journeys_fronts.csv", index=False)
    lo = np.array([f.running_time_s.iloc[0] for f in fronts])
    hi = np.array([f.running_time_s.iloc[-1] for f in fronts])

    rows = []
    for s in SUPPLEMENTS:
        total = lo.sum() * (1 + s)
        if total > hi.sum():
            continue
        best = allocate_running_time(journey, total, fronts=fronts)
        equal = rule_energy(journey, total, fronts, "equal")
        prop = rule_energy(journey, total, fronts, "proportional")
        rows.append({"supplement %": 100 * s, "trip time s": journey.trip_time_s(total), "running time s": total,
                     "optimal kWh": best.energy_kwh, "equal suppl. kWh": equal, "proportional kWh": prop,
                     "saving vs equal kWh": equal - best.energy_kwh,
                     "saving vs equal %": 100 * (equal - best.energy_kwh) / equal,
                     "price Wh/s": 1000 * best.price_kwh_per_s,
                     "marginal violation": best.marginal_violation()})
    table = pd.DataFrame(rows)

    # refinement of the strategy search: the line result at +10 %
    refine = []
    if args.fronts == "simulated":
        t0 = time.perf_counter()
        fine = [strategy_front(c, n_speeds=61, n_coast=61) for c in journey.sections]
        fine_time = time.perf_counter() - t0
        for s in (0.05, 0.10, 0.20):
            for label, fr in (("31 x 31", fronts), ("61 x 61", fine)):
                total = sum(f.running_time_s.iloc[0] for f in fr) * (1 + s)
                refine.append({"supplement %": 100 * s, "strategies per section": label,
                               "optimal kWh": allocate_running_time(journey, total, fronts=fr).energy_kwh})
    refine = pd.DataFrame(refine)

    # DE with the budget repair against the exact split at the 30-minute trip
    from pymoo.algorithms.soo.nonconvex.de import DE
    from pymoo.optimize import minimize

    total = journey.running_time_s(TRIP_TIME_S)
    best = allocate_running_time(journey, total, fronts=fronts)
    equal = supplement_split(journey, total, fronts=fronts)
    de_rows = []
    for seed in (1, 2, 3):
        problem = RunningTimeAllocationProblem(fronts, total)
        t0 = time.perf_counter()
        res = minimize(problem, DE(pop_size=40, repair=BudgetRepair()), ("n_gen", args.de_gens), seed=seed)
        de_rows.append({"seed": seed, "DE kWh": float(res.F[0]), "gap to exact %": 100 * (res.F[0] / best.energy_kwh - 1),
                        "evaluations": res.algorithm.evaluator.n_eval, "time s": time.perf_counter() - t0})
    de = pd.DataFrame(de_rows)

    # plots
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    widest_equal = lo.sum() + len(fronts) * (hi - lo).min()
    sweep_t = np.linspace(lo.sum(), min(hi.sum(), widest_equal), 60)
    opt_e = np.array([allocate_running_time(journey, t, fronts=fronts).energy_kwh for t in sweep_t])
    eq_e = np.array([rule_energy(journey, t, fronts, "equal") for t in sweep_t])
    pr_e = np.array([rule_energy(journey, t, fronts, "proportional") for t in sweep_t])
    trip_min = np.array([journey.trip_time_s(t) for t in sweep_t]) / 60
    fig, axes = plt.subplots(1, 3, figsize=(16, 4.6))
    ax = axes[0]
    ax.plot(trip_min, opt_e, label="energy-optimal split")
    ax.plot(trip_min, eq_e, "--", label="equal supplement")
    ax.plot(trip_min, pr_e, ":", label="proportional supplement")
    ax.set_xlabel("trip time incl. 12 x 30 s dwells (min)")
    ax.set_ylabel("net energy of the line (kWh)")
    ax.set_title("Yizhuang line, 13 sections")
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
    ax.legend()
    for a in axes:
        a.grid(alpha=0.3)
    fig.tight_layout()
    fig.savefig(args.out / "journeys.png", dpi=110)

    per_section = best.table[["section", "label", "length_m", "min_time_s", "running_time_s", "supplement_s",
                              "energy_kwh"]].assign(equal_supplement_s=equal.table.supplement_s,
                                                    equal_energy_kwh=equal.energies_kwh)
    source = {"simulated": "simulated strategy search (`strategy_front`, 31 x 31 traction-hold-coast-brake "
                           "runs per section, lower convex hull)",
              "optimal": "the exact solver `pymoo_rail.optimal.optimal_front` (25 running times per section, "
                         "lower convex hull)"}[args.fronts]
    report = f"""# Whole-line running-time allocation: Beijing Yizhuang line (TTOBench)

Generated by `benchmarks/journeys.py --fronts {args.fronts}` (numbers measured in this run).

Line: TTOBench track `CN_Songjiazhuang_Yizhuang` (22.728 km, 14 stops, 13 sections), train
`CN_Beijing_Subway` (278 t, 310 kN / 3100 kW, regen 260 kN / 4333 kW, efficiencies 70 % / 80 %),
point mass, 1 m grid, 30 s dwells. Energies are net (traction / 0.7 - 0.8 x electric braking).
Section fronts: {source}; computed in {front_time:.1f} s. Flat-out running time of the line
{lo.sum():.1f} s (trip {journey.trip_time_s(lo.sum()):.1f} s); the fronts reach {hi.sum():.1f} s.
Every allocation is exact on these piecewise-linear fronts (marginal violation = largest breach of
the equal-marginal-energy condition, kWh/s). The price is the energy one more second of running
time would save (at 0 % it is the value of the first extra second on the steepest section).

## Optimal split against the timetable rules of thumb

Supplement = total running time over the sum of the sections' flat-out times. "-" = the rule gives
some section more time than its front covers.

{markdown(table.fillna(float('nan')).replace({np.nan: '-'}))}

## The {TRIP_TIME_S / 60:.0f}-minute trip, section by section

Optimal split {best.energy_kwh:.2f} kWh against {equal.energy_kwh:.2f} kWh for the equal supplement
({100 * (equal.energy_kwh - best.energy_kwh) / equal.energy_kwh:.2f} % saved), marginal price
{1000 * best.price_kwh_per_s:.1f} Wh per second of running time.

{markdown(per_section)}

## pymoo DE on the same problem (`RunningTimeAllocationProblem` + `BudgetRepair`)

DE(pop_size=40), {args.de_gens} generations, against the exact {best.energy_kwh:.4f} kWh:

{markdown(de, ".4f")}
"""
    if len(refine):
        report += f"""
## Refinement of the simulated fronts

The 61 x 61 search took {fine_time:.1f} s. Line energy of the optimal split at the same supplement:

{markdown(refine, ".3f")}
"""
    report += "\n![energy against trip time](journeys.png)\n"
    (args.out / "journeys.md").write_text(report, encoding="utf-8")
    print(report)


if __name__ == "__main__":
    main()
