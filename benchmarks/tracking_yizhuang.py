"""Seed 000 table 5-7: hysteresis tracking (A = 2, B = 3 ... 6 km/h) of a recommended curve on yizhuang.

Three recommended curves, all speed codes on the non-equal partition (seed 000 fig. 4-4):

- ``hold``: one target speed everywhere, chosen so that the ideal run takes 150 s (traction,
  cruise, braking: the "traction-cruise" connection of seed 000 4.3);
- ``DE ideal``: the constrained single-objective form (min energy, |T - 150| <= 0.5 s) solved by
  pymoo's DE through ``SpeedProfileProblem``, scored on the ideal run (best of ``--seeds``; the
  DE runs go through ``pymoo_rail.experiments.run_study``, one record per run in ``--work``);
- ``DE tracked``: the same, scored on the run tracked with A = 2, B = 3
  (``SpeedProfileProblem(..., tracking=Hysteresis(2, 3))``), the procedure of seed 000 (its
  recommended curve is evaluated through the tracking simulation, 5.2).

Each is tracked with A = 2 and B = 3, 4, 5, 6 km/h at the control period ``--period`` (and, for
``hold``, at several periods). Writes ``benchmarks/reports/tracking_yizhuang.md`` (tables next to
the seed's numbers), ``tracking_yizhuang.csv`` (one row per tracked run, appended as each
finishes) and two figures.

Usage: ``python benchmarks/tracking_yizhuang.py [--gens 200] [--seeds 1 2 3] [--period 0.2]``
"""

from __future__ import annotations

import argparse
import csv
import time
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402

from pymoo_rail.cases import load_case  # noqa: E402
from pymoo_rail.constants import KMH_PER_MS  # noqa: E402
from pymoo_rail.control import Hysteresis, track  # noqa: E402
from pymoo_rail.experiments import (Study, algorithm, best_run, build_problem, load_results, problem,  # noqa: E402
                                     run_study)
from pymoo_rail.optimal.baselines import constant_cruise  # noqa: E402
from pymoo_rail.plotting import save_figure  # noqa: E402
from pymoo_rail.problems import SpeedProfileProblem  # noqa: E402
from pymoo_rail.sim import Simulator  # noqa: E402

REPORTS = Path(__file__).parent / "reports"
B_VALUES = (3.0, 4.0, 5.0, 6.0)
A_KMH = 2.0
# seed 000 table 5-7: (energy kWh, running time s); the recommended curve: MOABC, 19.55 kWh at 149.89 s
SEED_TABLE_5_7 = {3.0: (20.53, 150.21), 4.0: (19.94, 150.62), 5.0: (19.28, 151.07), 6.0: (19.97, 151.29)}
SEED_REFERENCE = (19.55, 149.89)
FIELDS = ("reference", "period_s", "a_kmh", "b_kmh", "energy_kwh", "running_time_s", "stop_error_m", "jerk_ms2",
          "regime_changes", "speed_error_rms_kmh", "speed_error_max_kmh")


def hold_reference(case, sim):
    """One speed code for every section, running in the planned time (``optimal.baselines.constant_cruise``)."""
    code, run = constant_cruise(SpeedProfileProblem(case, objectives=("energy",)), tol_s=1e-6)
    return run, f"one code, {code:.2f} km/h"


def reference_study(seeds, gens) -> Study:
    """DE (population 50, CR 0.9) on min energy with |T - T_plan| <= 0.5 s, scored on the ideal run
    (``DE ideal``) and on the run tracked with A = 2, B = 3 km/h (``DE tracked``)."""
    common = dict(case="yizhuang", objectives=["energy"], time_tolerance_s=0.5)
    tracked = {"controller": "hysteresis", "a_kmh": A_KMH, "b_kmh": 3.0}
    return Study("tracking-yizhuang", problems=[problem("speed_profile", label="DE ideal", **common),
                                                problem("speed_profile", label="DE tracked", tracking=tracked, **common)],
                 algorithms=[algorithm("de", label="DE", pop_size=50, CR=0.9)], seeds=list(seeds),
                 budget={"n_gen": gens})


def de_reference(sim, study, results, label):
    """The ideal run of the least-energy stored DE run of ``label`` (best of the seeds)."""
    _, x = best_run(results, label)
    problem = build_problem(next(p for p in study.problems if p.display == label))
    ideal = sim.run(problem.encoding.programs(x[None, :])[0])
    return ideal, "codes " + " / ".join(f"{c:.1f}" for c in x) + " km/h"


def row_of(name, period, b, tr):
    s = tr.summary
    return {"reference": name, "period_s": period, "a_kmh": A_KMH, "b_kmh": b, "energy_kwh": tr.energy.net_kwh,
            "running_time_s": tr.running_time_s, "stop_error_m": tr.stop_error_m, "jerk_ms2": s["jerk_ms2"],
            "regime_changes": int(s["regime_changes"]), "speed_error_rms_kmh": s["speed_error_rms_kmh"],
            "speed_error_max_kmh": s["speed_error_max_kmh"]}


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--gens", type=int, default=200)
    parser.add_argument("--seeds", type=int, nargs="+", default=[1, 2, 3])
    parser.add_argument("--period", type=float, default=0.2)
    parser.add_argument("--out", default=str(REPORTS))
    parser.add_argument("--work", type=Path, default=Path(__file__).resolve().parents[1] / "out" / "tracking_yizhuang",
                        help="study folder of the DE runs (one record per run, not committed)")
    parser.add_argument("--workers", type=int, default=2, help="process pool size (at most 2)")
    args = parser.parse_args()
    out_dir = Path(args.out)
    out_dir.mkdir(parents=True, exist_ok=True)
    csv_path = out_dir / "tracking_yizhuang.csv"
    t_start = time.perf_counter()

    case = load_case("yizhuang")
    sim = Simulator(case)
    references = {}
    references["hold"] = hold_reference(case, sim)
    study = reference_study(args.seeds, args.gens)
    print(run_study(study, args.work, workers=max(1, min(args.workers, 2))), flush=True)
    results = load_results(args.work, study=study)
    for label in ("DE ideal", "DE tracked"):
        references[label] = de_reference(sim, study, results, label)
    for name, (ref, how) in references.items():
        print(f"{name:10s} ideal {ref.energy.net_kwh:.3f} kWh {ref.running_time_s:.2f} s  ({how})", flush=True)

    rows, runs = [], {}
    with csv_path.open("w", newline="") as fh:
        writer = csv.DictWriter(fh, fieldnames=FIELDS)
        writer.writeheader()
        plan = [(name, args.period) for name in references]
        plan += [("hold", p) for p in (0.1, 0.5, 1.0) if p != args.period]
        for name, period in plan:
            ref = references[name][0]
            for b in B_VALUES:
                tr = track(case, ref, Hysteresis(A_KMH, b), control_period_s=period)
                runs[name, period, b] = tr
                row = row_of(name, period, b, tr)
                rows.append(row)
                writer.writerow(row)
                fh.flush()
                print(f"{name:10s} T_c={period:.1f} s B={b:.0f}: {tr.energy.net_kwh:.3f} kWh {tr.running_time_s:.2f} s "
                      f"stop {tr.stop_error_m:.3f} m, {row['regime_changes']} regime changes", flush=True)

    # ---- figures
    profiles_figure(references, runs, args, out_dir)

    table_figure(references, runs, args, out_dir)

    # ---- report
    write_report(args, t_start, references, runs, rows, out_dir)
    print(f"wrote {out_dir / 'tracking_yizhuang.md'}")


def profiles_figure(references, runs, args, out_dir):
    """The tracked profiles for each B beside the DE-tracked reference."""
    fig, axes = plt.subplots(2, 2, figsize=(12, 7.5), sharex=True, sharey=True)
    ref = references["DE tracked"][0]
    for ax, b in zip(axes.ravel(), B_VALUES):
        tr = runs["DE tracked", args.period, b]
        ax.plot(ref.position_m, ref.speed_kmh, "r-", lw=1.2, label="recommended (ideal run)")
        ax.plot(tr.position_m, tr.speed_kmh, "b--", lw=1.0, label="tracked")
        ax.plot(tr.position_m, tr.limit_ms * KMH_PER_MS, "k:", lw=0.8, label="limit")
        ax.set_title(f"A = {A_KMH:g}, B = {b:g} km/h: {tr.energy.net_kwh:.2f} kWh, {tr.running_time_s:.1f} s")
        ax.grid(alpha=0.3)
    for ax in axes[1]:
        ax.set_xlabel("position (m)")
    for ax in axes[:, 0]:
        ax.set_ylabel("speed (km/h)")
    axes[0, 0].legend(loc="lower center", fontsize=8)
    fig.suptitle("yizhuang: hysteresis tracking of the DE-tracked recommended curve (cf. seed 000 fig. 5-8)")
    fig.tight_layout()
    save_figure(fig, out_dir / "tracking_yizhuang_profiles.png", dpi=110)


def table_figure(references, runs, args, out_dir):
    """Table 5-7 as a figure: energy and running time against B, ours beside the seed's."""
    fig, (ax_e, ax_t) = plt.subplots(1, 2, figsize=(11, 4))
    for name in references:
        e = [runs[name, args.period, b].energy.net_kwh for b in B_VALUES]
        t = [runs[name, args.period, b].running_time_s for b in B_VALUES]
        ax_e.plot(B_VALUES, e, "o-", label=name)
        ax_t.plot(B_VALUES, t, "o-", label=name)
    ax_e.plot(B_VALUES, [SEED_TABLE_5_7[b][0] for b in B_VALUES], "ks--", label="seed 000 table 5-7")
    ax_t.plot(B_VALUES, [SEED_TABLE_5_7[b][1] for b in B_VALUES], "ks--", label="seed 000 table 5-7")
    ax_e.set_xlabel("B (km/h), A = 2 km/h")
    ax_t.set_xlabel("B (km/h), A = 2 km/h")
    ax_e.set_ylabel("net energy (kWh)")
    ax_t.set_ylabel("running time (s)")
    ax_e.legend(fontsize=8)
    ax_e.grid(alpha=0.3)
    ax_t.grid(alpha=0.3)
    fig.tight_layout()
    save_figure(fig, out_dir / "tracking_yizhuang_table.png", dpi=110)


def write_report(args, t_start, references, runs, rows, out_dir):
    """Write the report: the references, table 5-7 beside the seed's, every tracked run."""
    lines = ["# Hysteresis tracking on yizhuang (seed 000, table 5-7)", "",
             f"Produced by `benchmarks/tracking_yizhuang.py --gens {args.gens} --seeds "
             f"{' '.join(map(str, args.seeds))} --period {args.period}` in "
             f"{time.perf_counter() - t_start:.0f} s. Controller `Hysteresis(A, B)`: coast when the speed is "
             "within A of the recommended speed, maximum traction when it is more than B below, the previous "
             "regime in between (seed 000 5.1.3, fig. 5-2); exact start (maximum traction) and stop (the "
             "braking curve) phases. Energies are net kWh at the wheel (the case has no efficiencies, no "
             "regeneration, no auxiliaries). How to read it: docs/control.md, section Results.", "",
             "## Recommended curves", "",
             "| curve | how | ideal energy kWh | ideal time s |", "|---|---|---|---|"]
    for name, (ref, how) in references.items():
        lines.append(f"| {name} | {how} | {ref.energy.net_kwh:.3f} | {ref.running_time_s:.2f} |")
    lines.append(f"| seed 000 (MOABC) | fig. 5-6 | {SEED_REFERENCE[0]:.2f} | {SEED_REFERENCE[1]:.2f} |")
    lines += ["", f"## Table 5-7 side by side (control period {args.period} s)", "",
              "| A, B (km/h) | seed kWh | seed s | " + " | ".join(f"{n} kWh | {n} s" for n in references) + " |",
              "|---|---|---|" + "---|---|" * len(references)]
    for b in B_VALUES:
        cells = [f"{runs[n, args.period, b].energy.net_kwh:.3f} | {runs[n, args.period, b].running_time_s:.2f}"
                 for n in references]
        seed_e, seed_t = SEED_TABLE_5_7[b]
        lines.append(f"| 2, {b:g} | {seed_e:.2f} | {seed_t:.2f} | " + " | ".join(cells) + " |")
    lines += ["", "## Every tracked run", "",
              "| curve | period s | B | energy kWh | time s | stop error m | jerk m/s^2 | regime changes | "
              "rms speed error km/h | max speed error km/h |", "|---|---|---|---|---|---|---|---|---|---|"]
    for r in rows:
        lines.append(f"| {r['reference']} | {r['period_s']:g} | {r['b_kmh']:g} | {r['energy_kwh']:.3f} | "
                     f"{r['running_time_s']:.2f} | {r['stop_error_m']:.3f} | {r['jerk_ms2']:.2f} | "
                     f"{r['regime_changes']} | {r['speed_error_rms_kmh']:.2f} | {r['speed_error_max_kmh']:.2f} |")
    lines += ["", "![profiles](tracking_yizhuang_profiles.png)", "", "![table](tracking_yizhuang_table.png)", ""]
    (out_dir / "tracking_yizhuang.md").write_text("\n".join(lines))


if __name__ == "__main__":
    main()
