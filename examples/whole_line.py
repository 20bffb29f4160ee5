"""Energy-minimal timetable for the whole Beijing Yizhuang line (TTOBench data, 22.7 km, 13 sections).

Splits a total trip time (departure at Songjiazhuang to arrival at Yizhuang Railway Station, with
30 s dwells at the 12 stops between) over the sections so that the line's net energy is minimal,
prints the split, and plots energy against trip time for the optimal split and for the usual
equal-supplement rule.

Usage::

    python examples/whole_line.py [--trip-time 1800] [--fronts optimal|simulated|combined] [--out out/whole_line]

The exact section fronts (default) take a few minutes for the whole line and are kept in
``<out>/fronts_optimal.csv`` as each section finishes (a re-run reads them back); ``--fronts
simulated`` (a direct search with the simulator, mean gap below 1 %) takes seconds; ``--fronts
combined`` takes the lower hull of both.
Writes ``allocation.csv`` (per section), ``energy_vs_trip_time.csv`` and ``energy_vs_trip_time.png``.
"""

from __future__ import annotations

import argparse
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402
import pandas as pd  # noqa: E402

from pymoo_rail.cases.ttobench import BEIJING_SUBWAY_TRAIN, YIZHUANG_STOP_NAMES, YIZHUANG_TRACK  # noqa: E402
from pymoo_rail.journeys import (  # noqa: E402
    DEFAULT_FRONT_SOURCE,
    journey_from_ttobench,
    allocate_running_time,
    section_fronts,
    supplement_split,
)


def main(argv: list[str] | None = None) -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--trip-time", type=float, default=1800.0, help="total trip time in s (default 30 min)")
    parser.add_argument("--dwell", type=float, default=30.0, help="dwell at each intermediate stop, s")
    parser.add_argument("--fronts", default=DEFAULT_FRONT_SOURCE, choices=("optimal", "simulated", "combined"),
                        help="section fronts: the exact solver, a strategy search with the simulator, or both")
    parser.add_argument("--out", type=Path, default=Path("out/whole_line"))
    args = parser.parse_args(argv)
    args.out.mkdir(parents=True, exist_ok=True)

    journey = journey_from_ttobench(YIZHUANG_TRACK, BEIJING_SUBWAY_TRAIN, stop_names=YIZHUANG_STOP_NAMES,
                                    dwell_s=args.dwell)
    print(f"{journey.name}: {journey.length_m / 1000:.3f} km, {journey.n_sections} sections, "
          f"train {journey.train.name}; computing {args.fronts} section fronts ...")
    fronts = section_fronts(journey, args.fronts, cache_path=args.out / f"fronts_{args.fronts}.csv")
    lo = sum(f.running_time_s.iloc[0] for f in fronts)
    hi = sum(f.running_time_s.iloc[-1] for f in fronts)
    print(f"trip time between {journey.trip_time_s(lo):.1f} s (flat out) and {journey.trip_time_s(hi):.1f} s "
          f"(the fronts' range); dwells {journey.total_dwell_s:.0f} s")

    best = allocate_running_time(journey, journey.running_time_s(args.trip_time), fronts=fronts)
    equal = supplement_split(journey, best.total_time_s, fronts=fronts, rule="equal")
    table = best.table.assign(equal_split_time_s=equal.running_times_s, equal_split_energy_kwh=equal.energies_kwh)
    table.to_csv(args.out / "allocation.csv", index=False)
    with pd.option_context("display.width", 140):
        print(table[["label", "length_m", "min_time_s", "running_time_s", "energy_kwh", "equal_split_time_s",
                     "equal_split_energy_kwh"]].to_string(index=False, float_format=lambda v: f"{v:.2f}"))
    saved = 100 * (equal.energy_kwh - best.energy_kwh) / equal.energy_kwh
    print(f"trip {best.trip_time_s:.1f} s: optimal split {best.energy_kwh:.2f} kWh, equal supplement "
          f"{equal.energy_kwh:.2f} kWh (the optimal split saves {saved:.2f} %); marginal price "
          f"{1000 * best.price_kwh_per_s:.1f} Wh per extra second")

    # energy against trip time, as far as the equal split stays inside every front
    widest_equal = lo + journey.n_sections * min(f.running_time_s.iloc[-1] - f.running_time_s.iloc[0] for f in fronts)
    running = np.linspace(lo, min(hi, widest_equal), 40)
    rows = []
    for t in running:
        rows.append({"trip_time_s": journey.trip_time_s(t), "running_time_s": t,
                     "optimal_kwh": allocate_running_time(journey, t, fronts=fronts).energy_kwh,
                     "equal_supplement_kwh": supplement_split(journey, t, fronts=fronts).energy_kwh})
    sweep = pd.DataFrame(rows)
    sweep.to_csv(args.out / "energy_vs_trip_time.csv", index=False)

    fig, ax = plt.subplots(figsize=(7, 4.5))
    ax.plot(sweep.trip_time_s / 60, sweep.optimal_kwh, label="energy-optimal split")
    ax.plot(sweep.trip_time_s / 60, sweep.equal_supplement_kwh, "--", label="equal supplement per section")
    ax.plot(best.trip_time_s / 60, best.energy_kwh, "o", color="C0", label=f"{args.trip_time / 60:.1f} min trip")
    ax.set_xlabel("trip time Songjiazhuang -> Yizhuang Railway Station (min, incl. dwells)")
    ax.set_ylabel("net energy of the line, traction - regen (kWh)")
    ax.set_title(f"Yizhuang line, {journey.train.name} ({args.fronts} section fronts)")
    ax.grid(alpha=0.3)
    ax.legend()
    fig.tight_layout()
    fig.savefig(args.out / "energy_vs_trip_time.png", dpi=130)
    print(f"wrote {args.out / 'allocation.csv'}, {args.out / 'energy_vs_trip_time.csv'}, "
          f"{args.out / 'energy_vs_trip_time.png'}")


if __name__ == "__main__":
    main()
