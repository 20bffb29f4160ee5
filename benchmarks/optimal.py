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
import time
from pathlib import Path

import numpy as np
import pandas as pd

from pymoo_rail.constants import J_PER_KWH, KMH_PER_MS
from pymoo_rail.cases import load_case
from pymoo_rail.experiments.report import markdown
from pymoo_rail.optimal import optimal_profile
from pymoo_rail.plotting import plot_fronts, plot_speed_profile, save_figure
from pymoo_rail.sim import Simulator, gradient_limit_partition, speed_code_programs

REPORT = Path(__file__).resolve().parent / "reports" / "optimal.md"


def level_case():
    """5 km of level track with Davis resistance (as in tests/optimal/cases.py)."""
    from pymoo_rail.model import case_from_dict

    return case_from_dict({
        "name": "level", "source": "synthetic", "run": {"planned_time_s": 300.0},
        "train": {"mass_t": 100.0, "length_m": 100.0, "max_speed_kmh": 100.0,
                  "resistance": {"a": 2.0, "b": 0.1, "c": 0.03, "unit": "kN", "speed_unit": "ms"},
                  "traction": {"max_force_kn": 100.0}, "braking": {"max_force_kn": 100.0}},
        "line": {"length_m": 5000.0, "gradients": [[0.0, 5000.0, 0.0]], "speed_limits": [[0.0, 5000.0, 100.0]]}})


def _at(tr, t):
    """Net energy of a run moved to exactly t along the front's slope lambda (kWh)."""
    return tr.energy.net_kwh + tr.summary["lambda_w"] / J_PER_KWH * (tr.running_time_s - t)


def timing(case):
    from pymoo_rail.optimal import OptimalSolver, min_running_time, optimal_front

    t0 = time.perf_counter()
    OptimalSolver(case, n_speeds=20, dx_m=50.0).profile(1.2 * min_running_time(case, dx_m=50.0))
    warm_up_s = time.perf_counter() - t0
    t0 = time.perf_counter()
    fastest = min_running_time(case)
    times = np.linspace(fastest, 1.5 * fastest, 10)
    front = optimal_front(case, times)
    elapsed = time.perf_counter() - t0
    return front, elapsed, warm_up_s, fastest


def refinement(case, quick: bool):
    from pymoo_rail.optimal import OptimalSolver

    rows = []
    times = (135.0, 150.0, 180.0)
    grids = [(1.0, 100), (1.0, 200), (1.0, 400), (2.0, 200)]
    if not quick:
        grids += [(1.0, 800), (0.5, 200), (0.5, 400)]
    for dx, n_speeds in grids:
        solver = OptimalSolver(case, dx_m=dx, n_speeds=n_speeds)
        t0 = time.perf_counter()
        row = {"dx_m": dx, "n_speeds": n_speeds}
        for t in times:
            tr = solver.profile(t)
            row[f"E({t:.0f} s) kWh"] = _at(tr, t)
        row["seconds (3 profiles)"] = time.perf_counter() - t0
        row["memory MB"] = sum(a.nbytes for a in solver._tables) / 1e6 + solver._value.nbytes / 1e6
        rows.append(row)
    table = pd.DataFrame(rows)
    finest = table.iloc[int(np.argmax(table["n_speeds"] / table["dx_m"]))]
    for t in times:
        col = f"E({t:.0f} s) kWh"
        table[f"vs finest {t:.0f} s %"] = 100 * (table[col] / finest[col] - 1)
    return table


def level_track():
    from pymoo_rail.optimal import OptimalSolver
    from pymoo_rail.optimal.flat import flat_track_optimum

    case = level_case()
    solver = OptimalSolver(case)
    rows = []
    for t in (230.0, 260.0, 300.0, 350.0):
        exact = flat_track_optimum(case, t)
        tr = solver.profile(t)
        e = _at(tr, t)
        rows.append({"running time s": t, "closed form kWh": exact.energy_kwh, "DP kWh": e,
                     "difference %": 100 * (e / exact.energy_kwh - 1),
                     "hold speed km/h (closed form)": exact.hold_speed_ms * KMH_PER_MS,
                     "brake speed km/h (closed form)": exact.brake_speed_ms * KMH_PER_MS})
    return pd.DataFrame(rows)


def direct_search(case, quick: bool):
    from pymoo_rail.optimal import OptimalSolver
    from pymoo_rail.optimal.strategies import hold_coast_search, two_holds_search

    solver = OptimalSolver(case)
    rows = []
    for t in (135.0, 150.0, 170.0, 200.0):
        tr = solver.profile(t)
        e = _at(tr, t)
        t0 = time.perf_counter()
        hc = hold_coast_search(case, t)
        row = {"running time s": t, "DP kWh": e, "hold-coast kWh": hc.energy_kwh,
               "hold speed km/h": hc.params[0] * KMH_PER_MS}
        if not quick:
            th = two_holds_search(case, t, start=hc)
            row["two-holds kWh"] = th.energy_kwh
        row["search s"] = time.perf_counter() - t0
        best = min(v for k, v in row.items() if k.endswith("holds kWh") or k == "hold-coast kWh")
        row["DP vs best search %"] = 100 * (e / best - 1)
        rows.append(row)
    return pd.DataFrame(rows)


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


def main(argv=None) -> None:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--quick", action="store_true")
    args = parser.parse_args(argv)
    case = load_case("yizhuang")
    out = [f"# Exact solver benchmark (`benchmarks/optimal.py{' --quick' if args.quick else ''}`)", "",
           f"{os.cpu_count()} cores, load average {os.getloadavg()[0]:.1f} at the start (the machine is shared: "
           "times are wall clock).", ""]

    def emit(text: str) -> None:
        """Print one report section now and keep it for the report file."""
        print(text, flush=True)
        out.extend([text, ""])

    front, elapsed, warm_up, fastest = timing(case)
    emit(f"## 1. `optimal_front(yizhuang)`, 10 running times from {fastest:.2f} s to {1.5 * fastest:.2f} s\n\n"
         f"{elapsed:.1f} s wall clock (default grid: 1 m x 200 speed nodes), after a {warm_up:.1f} s warm-up "
         "that loads or compiles the Numba kernels.\n\n" + markdown(front))
    planned = optimal_profile(case, case.planned_time_s)
    emit(f"Optimum at the planned 150 s: {planned.energy.net_kwh:.3f} kWh at {planned.running_time_s:.2f} s "
         f"({_at(planned, 150.0):.3f} kWh at exactly 150 s); the flat-out run: "
         f"{Simulator(case).flat_out().energy.net_kwh:.2f} kWh at {fastest:.2f} s.")
    emit("## 2. Grid refinement (energy moved to exactly the requested time along the slope lambda)\n\n"
         + markdown(refinement(case, args.quick)))
    emit("## 3. Level track (5 km, Davis resistance): Pontryagin's closed form against the DP\n\n"
         + markdown(level_track()))
    emit("## 4. Direct search over traction-hold-coast-brake strategies on yizhuang\n\n"
         + markdown(direct_search(case, args.quick)))
    REPORT.parent.mkdir(parents=True, exist_ok=True)
    draw(case, front, planned, REPORT.parent)
    out += ["![front](optimal_front.png)", "", "![profile](optimal_profile.png)", ""]
    REPORT.write_text("\n".join(out))
    print(f"written {REPORT}")


if __name__ == "__main__":
    main()
