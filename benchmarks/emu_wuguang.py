"""Golden-ratio NSGA-II vs NSGA-II on the CRH3 EMU run of seed 003 (section 4.2, figs. 10-12,
tables 4 and 5), at equal evaluation budgets, through the study runner, against the exact front.

Problem: ``SpeedProfileProblem(load_case("wuguang-crh3"), objectives=("energy", "running_time"),
time_tolerance_s=case.time_margin_s)``: the seed's energy / running-time front inside its 60 s
margin around the planned 1050 s (the seed's fronts, 1008-1105 s, lie inside 1050 +- 60).

Two studies, each stored by ``pymoo_rail.experiments.run_study`` (one JSON record per finished
run, resumable):

* ``encodings`` (quick): NSGA-II and GR-NSGA-II on speed codes with the default partition,
  speed codes split at ``max_section_m = 1000`` and switching points, a few seeds, a smaller
  budget. It chooses the encoding of the main study.
* ``main``: NSGA-II vs GR-NSGA-II, population 200, 60,000 evaluations (the seed's 200 x 300
  generations), ``--seeds`` seeds (default 10), on speed codes (the chosen encoding, figs. 10-12)
  and on switching points (the best fronts of the encoding study, as a check).

The exact front of ``pymoo_rail.optimal`` at 13 running times from 990 to 1110 s is computed once
and cached in ``reports/emu_wuguang_optimal.csv`` by ``pymoo_rail.optimal.reference.exact_points``
(``--no-exact`` leaves it out). Its rows are read back only for the same case content, speed nodes
and solver version (``pymoo_rail.optimal.solver.SOLVER_VERSION``); rows without that key (written
before rows carried it) or of another key are solved again (13 solves at 800 nodes; the CSV's
``solve_s`` gives their wall seconds).
``--resolution`` prints how that front moves with the solver's speed nodes (200 / 400 / 800) and
where the stored fronts' lowest members lie against each.

Algorithms (seed 003, 4.1: crossover 0.9, mutation 0.01; 2m = 40, Pc_max 0.9, Pm_max 0.1):

* ``NSGA-II``: pymoo NSGA2, SBX(prob 0.9, eta 15), PM(eta 20) with per-variable probability
  0.01 (the same reading as ``benchmarks/grnsga2_zdt.py``): ``pymoo_rail.experiments.tang2020_nsga2``;
* ``GR-NSGA-II``: ``GoldenRatioNSGA2(pop_size=200, local_size=40, pc_max=0.9, pm_max=0.1)``; the
  runner passes the neutral-section genes as ``fixed_genes``.

Then, for the report: fronts (figs. 10-11), table 4 (front statistics), table 5 (most punctual
solution of each algorithm), fig. 12 (speed-distance profile of the most punctual solutions),
hypervolume / IGD / GD against the union front and the energy gap to the exact front with the
rank-sum test, and a check of every front member of every run: no traction in either neutral
section, never above a limit over the train length, stopped at the platform, neutral-section
genes at their fixed value. A hand-written discussion in ``reports/emu_wuguang_notes.md`` (an
encoding note, then ``<!-- verdict -->`` and the verdict) is folded into the report.

Usage::

    nice -n 10 python benchmarks/emu_wuguang.py                   # both studies, then the report
    nice -n 10 python benchmarks/emu_wuguang.py --seeds 5 --budget 30000
    python benchmarks/emu_wuguang.py --report-only                # re-analyse stored runs
    python benchmarks/emu_wuguang.py --resolution                 # exact front vs speed nodes

Interrupting loses only the runs in flight; the next start runs the missing ones. The main
study runs seed by seed, so an interrupted study still holds as many runs of each algorithm.
"""

from __future__ import annotations

import argparse
import csv
import sys
import time
from pathlib import Path

import numpy as np

from pymoo_rail.experiments.fronts import choose_member
from pymoo_rail.sim.checks import check_run
from pymoo_rail.experiments.report import markdown_rows, mean_std, significant

ROOT = Path(__file__).resolve().parents[1]

CASE = "wuguang-crh3"
OBJECTIVES = ("energy", "running_time")
POP_SIZE = 200
LOCAL_SIZE = 40
BUDGET = 60_000
ENCODING_BUDGET = 20_000
ENCODING_SEEDS = 3
NSGA2_LABEL = "NSGA-II"
GR_LABEL = "GR-NSGA-II"
ENCODINGS = {  # label -> SpeedProfileProblem keyword arguments
    "speed codes": {"encoding": "speed_codes"},
    "speed codes <= 1000 m": {"encoding": "speed_codes", "max_section_m": 1000.0},
    "switching points": {"encoding": "switching_points"},
}
MAIN_ENCODING = "speed codes"  # figs. 10-12 are drawn on it
MAIN_ENCODINGS = ("speed codes", "switching points")
STOP_TOLERANCE_M = 0.25
SPEED_TOLERANCE_MS = 1e-6

# seed 003 tables 4 and 5
SEED_TABLE4 = {NSGA2_LABEL: {"sp": 0.45638, "gd": 0.114832, "t_max": 1103, "t_min": 1012, "e_max": 714.27,
                             "e_min": 646.69},
               GR_LABEL: {"sp": 0.37867, "gd": 0.092534, "t_max": 1105, "t_min": 1008, "e_max": 707.46,
                          "e_min": 639.56}}
SEED_TABLE5 = {NSGA2_LABEL: (657.13, 1051.5), GR_LABEL: (650.76, 1049.2)}


# --------------------------------------------------------------------------------- studies


def problem_params(case, encoding: str) -> dict:
    return {"case": CASE, "objectives": list(OBJECTIVES), "time_tolerance_s": float(case.time_margin_s),
            **ENCODINGS[encoding]}


def algorithm_specs(pop_size: int, local_size: int):
    from pymoo_rail.experiments import algorithm, tang2020_nsga2

    return [tang2020_nsga2(label=NSGA2_LABEL, pop_size=pop_size),
            algorithm("grnsga2", label=GR_LABEL, pop_size=pop_size, local_size=local_size, pc_max=0.9,
                      pm_max=0.1)]


def make_study(name: str, encodings, seeds, budget: int, pop_size: int = POP_SIZE, local_size: int = LOCAL_SIZE):
    from pymoo_rail.cases import load_case
    from pymoo_rail.experiments import Study, problem

    case = load_case(CASE)
    problems = [problem("speed_profile", label=enc, **problem_params(case, enc)) for enc in encodings]
    return Study(name, problems, algorithm_specs(pop_size, local_size), seeds=list(seeds),
                 budget={"n_eval": int(budget)}, baseline=NSGA2_LABEL)


# ------------------------------------------------------------------------------ analysis


EXACT_TIMES_S = (990.0, 995.0, 1000.0, 1010.0, 1020.0, 1030.0, 1040.0, 1050.0, 1060.0, 1070.0, 1080.0, 1095.0,
                 1110.0)
# 4x the solver's default speed nodes: the older solver's front moved by up to 0.15 % between 200,
# 400 and 800 nodes on this 47.6 km line; the current one's by under 0.01 % (--resolution)
EXACT_N_SPEEDS = 800


def exact_front(path: Path, times_s=EXACT_TIMES_S, profile_path: Path | None = None, n_speeds: int = EXACT_N_SPEEDS):
    """The exact solver's front at ``times_s``, cached row by row in ``path`` (resumable); with
    ``profile_path``, the optimal run at the planned time is kept there as a trajectory table (fig. 12)."""
    from pymoo_rail.atomic import atomic_write_text
    from pymoo_rail.cases import load_case
    from pymoo_rail.optimal.reference import exact_points

    case = load_case(CASE)

    def keep_profile(t, traj):
        if profile_path is not None and t == case.planned_time_s:
            atomic_write_text(profile_path, traj.to_frame().to_csv(index=False))
        print(f"exact front: {t:g} s -> {traj.running_time_s:.2f} s, {traj.energy.net_kwh:.2f} kWh", flush=True)

    redo = [case.planned_time_s] if profile_path is not None and not profile_path.exists() else []
    return exact_points(case, times_s, path, n_speeds=n_speeds, redo_s=redo, on_run=keep_profile)


RESOLUTION_N_SPEEDS = (200, 400, 800)
RESOLUTION_TIMES_S = (1050.0, 1060.0, 1100.0)  # the planned time, and two on the front


def resolution(results, n_speeds=RESOLUTION_N_SPEEDS, times_s=RESOLUTION_TIMES_S, front_times_s=EXACT_TIMES_S):
    """How the exact front moves with the solver's speed nodes, and where the stored fronts lie against it.

    For each number of speed nodes, ``pymoo_rail.optimal.ReferenceAtTime`` solves the optimum at
    exactly ``times_s`` (with its certificate) and at ``front_times_s``; each run's feasible front
    in ``results`` is compared with that front, interpolated between its points, as the report
    compares it with the exact front (:func:`gap_to_exact`). The lowest member of each problem is
    then solved at its own running time too. Returns one row per number of nodes: the energies
    and certificates at ``times_s``, the CPU seconds of the solves, and per problem the lowest
    member's gap (%) to the interpolated front and to the optimum at its own time.
    """
    import pandas as pd

    from pymoo_rail.cases import load_case
    from pymoo_rail.indicators.energy import energy_gap
    from pymoo_rail.optimal import ReferenceAtTime

    case = load_case(CASE)
    rows = []
    for n in n_speeds:
        cpu0 = time.process_time()
        ref = ReferenceAtTime(case, n_speeds=int(n))
        row = {"speed nodes": int(n)}
        for t in times_s:
            at = ref.at(t)
            row[f"E({t:g} s) kWh"] = at["optimal_kwh"]
            row[f"certificate {t:g} s kWh"] = at["energy_bound_kwh"]
        front = pd.DataFrame({"running_time_s": front_times_s,
                              "energy_kwh": [ref.at(t)["optimal_kwh"] for t in front_times_s]})
        for problem, group in results.groupby("problem", sort=False):
            points = pd.concat([energy_gap(run["F"][run["CV"] <= 0][:, ::-1], front)["points"]
                                for _, run in group.iterrows()], ignore_index=True)
            lowest = points.loc[points["gap_rel"].idxmin()]
            own = ref.at(lowest["running_time_s"])["optimal_kwh"]
            row[f"lowest {problem} %"] = 100 * lowest["gap_rel"]
            row[f"same at own time {problem} %"] = 100 * (lowest["energy_kwh"] / own - 1)
        row["solve CPU s"] = time.process_time() - cpu0
        rows.append(row)
    return pd.DataFrame(rows)


def most_punctual(F: np.ndarray, planned_time_s: float) -> int:
    """Index of the (energy, running time) member closest to the planned time (ties: the lower energy)."""
    return choose_member(F, np.zeros(len(F)), F[:, 1], F[:, 0], planned_time_s, window_s=0.0)


def least_energy_within(F: np.ndarray, time_s: float) -> float:
    """Least energy of the members that run no longer than ``time_s`` (NaN when none does)."""
    inside = F[:, 1] <= time_s
    return float(F[inside, 0].min()) if inside.any() else float("nan")


def gd_seed(F: np.ndarray, reference: np.ndarray) -> float:
    """Seed 003 eq. 13 (Van Veldhuizen): sqrt(sum d_i^2) / n, in raw objective units."""
    from pymoo_rail.experiments.metrics import gd_van_veldhuizen

    return gd_van_veldhuizen(F, reference)


def exact_energy_kwh(exact, time_s: float) -> float:
    """The exact front's energy at ``time_s`` (linear between its points; NaN outside them)."""
    t, e = exact["running_time_s"].to_numpy(float), exact["energy_kwh"].to_numpy(float)
    return float(np.interp(time_s, t, e)) if t[0] <= time_s <= t[-1] else float("nan")


def gap_to_exact(F: np.ndarray, exact) -> dict:
    """Energy gap of a front (energy, running time) to the exact front: ``pymoo_rail.indicators.energy``."""
    from pymoo_rail.indicators.energy import energy_gap

    gap = energy_gap(F[:, ::-1], exact[["running_time_s", "energy_kwh"]].to_numpy(float))
    return {"gap_mean_pct": 100 * gap["mean_gap_rel"], "gap_min_pct": 100 * gap["min_gap_rel"],
            "gap_max_pct": 100 * gap["max_gap_rel"], "hv_ratio_exact": gap["hv_ratio"]}


def analyse(results, problems_by_label: dict, verify: bool = True, exact=None):
    """Per-run statistics (one dict per run) with reference indicators and member checks.

    ``exact``: the exact front (DataFrame with ``running_time_s``, ``energy_kwh``), optional;
    adds each run's energy gap to it.
    """
    from pymoo_rail.experiments import stats

    results = stats.add_reference_indicators(results)
    refs = stats.reference_fronts(results)
    rows, checks = [], {}
    for index, run in results.iterrows():
        problem = problems_by_label[run["problem"]]
        feasible = run["CV"] <= 0
        F, X = run["F"][feasible], run["X"][feasible]
        planned = problem.case.planned_time_s
        row = {"problem": run["problem"], "algorithm": run["algorithm"], "seed": int(run["seed"]),
               "n_eval": int(run["n_eval"]), "n_gen": int(run["n_gen"]), "wall_time_s": float(run["wall_time_s"]),
               "cpu_time_s": float(run.get("cpu_time_s", np.nan)),
               "n_points": len(F), "n_infeasible": int((~feasible).sum()),
               "hv_ref": run["hv_ref"], "igd_ref": run["igd_ref"], "gd_ref": run["gd_ref"],
               "gd_seed": gd_seed(F, refs[run["problem"]]) if len(F) else np.nan,
               "spacing": run.get("spacing", np.nan)}
        if len(F):
            k = most_punctual(F, planned)
            row.update(e_min=F[:, 0].min(), e_max=F[:, 0].max(), t_min=F[:, 1].min(), t_max=F[:, 1].max(),
                       punctual_e=F[k, 0], punctual_t=F[k, 1], e_at_plan=least_energy_within(F, planned))
            if exact is not None:
                row.update(gap_to_exact(F, exact))
                row["punctual_gap_pct"] = 100 * (F[k, 0] / exact_energy_kwh(exact, F[k, 1]) - 1)
        if verify and len(F):
            member_checks = [check_run(problem.trajectory(x), problem.case) for x in X]
            checks[index] = member_checks
            fixed = problem.encoding.fixed()
            fixed_ok = bool(np.all(X[:, fixed] == problem.xl[fixed]))
            row.update(
                verified=all(c.passes(STOP_TOLERANCE_M, SPEED_TOLERANCE_MS) for c in member_checks) and fixed_ok, fixed_genes_ok=fixed_ok,
                neutral_traction_j_max=max(c.neutral_traction_j for c in member_checks),
                neutral_force_n_max=max(c.neutral_max_force_n for c in member_checks),
                limit_excess_ms_max=max(c.limit_excess_ms for c in member_checks),
                independent_excess_ms_max=max(c.independent_excess_ms for c in member_checks),
                stop_error_m_max=max(c.stop_error_m for c in member_checks),
                energy_mismatch_kwh=max(abs(c.energy_kwh - f) for c, f in zip(member_checks, F[:, 0])),
                time_mismatch_s=max(abs(c.running_time_s - f) for c, f in zip(member_checks, F[:, 1])))
        rows.append(row)
    return results, rows, checks


# ------------------------------------------------------------------------------ formatting


def write_csv(path: Path, rows: list[dict]) -> None:
    keys: list[str] = []
    for row in rows:
        keys += [k for k in row if k not in keys]
    from pymoo_rail.atomic import atomic_path

    with atomic_path(path) as tmp, open(tmp, "w", newline="") as fh:
        writer = csv.DictWriter(fh, fieldnames=keys)
        writer.writeheader()
        for row in rows:
            writer.writerow({k: (f"{v:.6g}" if isinstance(v, float) else v) for k, v in row.items()})


def rank_sum(rows, problem: str, indicator: str, lower_better: bool):
    """(p, verdict, difference of means) of GR-NSGA-II against NSGA-II.

    The difference is relative ((GR - NSGA-II) / |NSGA-II|) except for indicators already in
    percent (``*_pct``), where it is the difference in percentage points.
    """
    from pymoo_rail.experiments.stats import rank_sum as _rank_sum

    gr = [r.get(indicator, np.nan) for r in rows if r["problem"] == problem and r["algorithm"] == GR_LABEL]
    base = [r.get(indicator, np.nan) for r in rows if r["problem"] == problem and r["algorithm"] == NSGA2_LABEL]
    gr = np.asarray([v for v in gr if np.isfinite(v)], dtype=float)
    base = np.asarray([v for v in base if np.isfinite(v)], dtype=float)
    if len(gr) < 2 or len(base) < 2:
        return np.nan, "", np.nan
    _, p, verdict = _rank_sum(gr, base, lower_better=lower_better)
    if indicator.endswith("_pct"):
        return p, verdict, gr.mean() - base.mean()
    rel = (gr.mean() - base.mean()) / abs(base.mean()) if base.mean() != 0 else np.nan
    return p, verdict, rel


def difference(indicator: str, value: float) -> str:
    if not np.isfinite(value):
        return ""
    return f"{value:+.3f} points" if indicator.endswith("_pct") else f"{100 * value:+.3f} %"


# ------------------------------------------------------------------------------ figures


def median_run(rows, problem: str, algorithm: str, indicator: str = "hv_ref") -> dict:
    """The run with the median ``indicator`` (lower seed for the even-count median)."""
    runs = sorted((r for r in rows if r["problem"] == problem and r["algorithm"] == algorithm),
                  key=lambda r: (-r[indicator] if np.isfinite(r[indicator]) else np.inf, r["seed"]))
    return runs[(len(runs) - 1) // 2]


def stored_run(results, problem: str, algorithm: str, seed: int):
    return results[(results["problem"] == problem) & (results["algorithm"] == algorithm)
                   & (results["seed"] == seed)].iloc[0]


def punctual_choices(results, rows, problems_by_label: dict) -> dict:
    """Per (encoding, algorithm): the most punctual member of the median-HV run, re-simulated."""
    chosen = {}
    for enc in sorted({r["problem"] for r in rows}):
        problem = problems_by_label[enc]
        for alg in (NSGA2_LABEL, GR_LABEL):
            med = median_run(rows, enc, alg)
            run = stored_run(results, enc, alg, med["seed"])
            feasible = run["CV"] <= 0
            F, X = run["F"][feasible], run["X"][feasible]
            k = most_punctual(F, problem.case.planned_time_s)
            chosen[enc, alg] = {"seed": med["seed"], "x": X[k], "F": F[k], "front": F,
                                "trajectory": problem.trajectory(X[k])}
    return chosen


def make_figures(results, rows, chosen: dict, problems_by_label: dict, out: Path, prefix: str, exact=None,
                 exact_profile=None) -> dict:
    import matplotlib.pyplot as plt

    from pymoo_rail.experiments import stats
    from pymoo_rail.plotting import plot_boxplots, plot_fronts, save_figure

    label = MAIN_ENCODING
    problem = problems_by_label[label]
    refs = stats.reference_fronts(results)
    planned = problem.case.planned_time_s
    paths = {}
    exact_F = exact[["energy_kwh", "running_time_s"]].to_numpy(float) if exact is not None else None
    fig, axes = plt.subplots(1, 2, figsize=(12.5, 4.8), layout="constrained", sharex=True, sharey=True)
    for ax, alg, number in zip(axes, (NSGA2_LABEL, GR_LABEL), (10, 11)):
        c = chosen[label, alg]
        F = c["front"]
        plot_fronts({f"{alg}, seed {c['seed']} (median HV)": F}, OBJECTIVES, reference=refs[label],
                    reference_label="union of all runs' fronts", highlight=c["F"],
                    highlight_label=f"most punctual: {c['F'][0]:.1f} kWh, {c['F'][1]:.1f} s",
                    title=f"fig. {number}: {alg} front, {label} ({len(F)} points)", ax=ax)
        if exact_F is not None:
            ax.plot(exact_F[:, 0], exact_F[:, 1], "x--", color="black", lw=1.0, ms=6,
                    label="exact optimum (pymoo_rail.optimal)")
            ax.legend(fontsize="small")
        ax.axhline(planned, color="0.5", lw=0.8, ls=":")
    paths["fronts"] = save_figure(fig, out / f"{prefix}_fronts.png")

    fronts = {f"{alg}, {enc} (seed {c['seed']})": c["front"] for (enc, alg), c in chosen.items()}
    fig = plot_fronts(fronts, OBJECTIVES, reference=exact_F, reference_label="exact optimum (pymoo_rail.optimal)",
                      title="median-HV run of each algorithm and encoding")
    fig.axes[0].axhline(planned, color="0.5", lw=0.8, ls=":")
    paths["fronts_overlay"] = save_figure(fig, out / f"{prefix}_fronts_overlay.png")

    # the seed's fig. 12 only covers the neighbourhood of the planned time: zoom there too
    fig = plot_fronts(fronts, OBJECTIVES, reference=exact_F, reference_label="exact optimum (pymoo_rail.optimal)",
                      title="near the planned time (1050 s)")
    ax = fig.axes[0]
    near = np.vstack([F[np.abs(F[:, 1] - planned) <= 15] for F in fronts.values()])
    if len(near):
        ax.set_xlim(near[:, 0].min() - 2, near[:, 0].max() + 2)
        ax.set_ylim(planned - 15, planned + 15)
    ax.axhline(planned, color="0.5", lw=0.8, ls=":")
    paths["fronts_zoom"] = save_figure(fig, out / f"{prefix}_fronts_zoom.png")

    paths["profile"] = profile_figure(chosen, label, exact_profile, planned, exact, problem, out / f"{prefix}_profile.png")

    fig = plot_boxplots(results, "hv_ref")
    paths["box_hv"] = save_figure(fig, out / f"{prefix}_box_hv.png")
    return paths


def profile_figure(chosen, label, exact_profile, planned, exact, problem, path: Path) -> Path:
    """Fig. 12: the most punctual GR-NSGA-II and NSGA-II profiles, and the exact optimum when it was solved."""
    from matplotlib.lines import Line2D

    from pymoo_rail.plotting import plot_speed_profile, save_figure

    gr_traj = chosen[label, GR_LABEL]["trajectory"]
    ns_traj = chosen[label, NSGA2_LABEL]["trajectory"]
    others = [ns_traj]
    other_labels = [f"{NSGA2_LABEL} most punctual ({ns_traj.running_time_s:.1f} s, {ns_traj.energy.net_kwh:.1f} kWh)"]
    if exact_profile is not None:
        others.append(exact_profile)
        other_labels.append(f"exact optimum at {planned:g} s" + (
            f" ({exact_energy_kwh(exact, planned):.1f} kWh)" if exact is not None else ""))
    fig = plot_speed_profile(gr_traj, problem.case, label=f"fig. 12: {GR_LABEL} most punctual", others=others,
                             other_labels=other_labels)
    # the optimum in its own colour; the legend above the runs (the default one hides the stations)
    ax = fig.axes[0]
    style = {"color": "tab:purple", "linestyle": "-", "lw": 1.4}
    for line in ax.lines:
        if exact_profile is not None and line.get_label() == other_labels[-1]:
            line.set(**style)
    legend = ax.get_legend()
    labels = [t.get_text() for t in legend.get_texts()]
    handles = [Line2D([], [], **style) if exact_profile is not None and lab == other_labels[-1] else h
               for h, lab in zip(legend.legend_handles, labels)]
    ax.set_ylim(0.0, 420.0)
    ax.legend(handles, labels, fontsize="small", loc="upper center", ncol=3, framealpha=0.9)
    return save_figure(fig, path)


# ------------------------------------------------------------------------------ report


def encoding_section(rows, n_var: dict, n_fixed: dict) -> list[str]:
    out = ["## 1. Choice of the encoding", ""]
    enc_rows = []
    for enc in ENCODINGS:
        for alg in (NSGA2_LABEL, GR_LABEL):
            rs = [r for r in rows if r["problem"] == enc and r["algorithm"] == alg]
            if not rs:
                continue
            enc_rows.append([enc, n_var[enc], n_fixed[enc], alg, len(rs), mean_std(r.get("hv_ref", np.nan) for r in rs),
                             mean_std(r.get("e_at_plan", np.nan) for r in rs),
                             mean_std(r.get("e_min", np.nan) for r in rs), mean_std(r.get("t_min", np.nan) for r in rs),
                             mean_std(r.get("wall_time_s", np.nan) for r in rs)])
    if not enc_rows:
        return out + ["(encoding study not run)"]
    out.append(markdown_rows(["encoding", "n_var", "fixed genes", "algorithm", "runs",
                         "hv (union of this study)", "least E with T <= 1050 s (kWh)", "E min (kWh)",
                         "T min (s)", "wall s"], enc_rows))
    return out


TABLE4 = [("points in the front", "n_points"), ("SP (Schott, kWh and s)", "spacing"),
          ("GD (eq. 13) to the union front", "gd_seed"), ("IGD to the union front", "igd_ref"),
          ("HV (normalised)", "hv_ref"), ("max running time (s)", "t_max"), ("min running time (s)", "t_min"),
          ("max energy (kWh)", "e_max"), ("min energy (kWh)", "e_min"),
          ("least energy with T <= 1050 s (kWh)", "e_at_plan"),
          ("mean energy gap to the exact front (%)", "gap_mean_pct"),
          ("largest energy gap to the exact front (%)", "gap_max_pct"),
          ("smallest energy gap to the exact front (%)", "gap_min_pct"),
          ("HV / HV of the exact front", "hv_ratio_exact"), ("evaluations", "n_eval"),
          ("generations", "n_gen"), ("wall time (s)", "wall_time_s"),
          ("CPU time (s)", "cpu_time_s")]
SEED_KEYS = {"spacing": "sp", "gd_seed": "gd", "t_max": "t_max", "t_min": "t_min", "e_max": "e_max", "e_min": "e_min"}
TESTED = (("hv_ref", False), ("igd_ref", True), ("gd_ref", True), ("gd_seed", True), ("spacing", True),
          ("gap_mean_pct", True), ("hv_ratio_exact", False), ("e_at_plan", True), ("punctual_e", True),
          ("e_min", True))


def pair_values(rows, enc: str, key: str):
    """(NSGA-II values, GR-NSGA-II values) of ``key`` on encoding ``enc``; None when no run has it."""
    main = [r for r in rows if r["problem"] == enc]
    if not any(np.isfinite(r.get(key, np.nan)) for r in main):
        return None
    return ([r.get(key, np.nan) for r in main if r["algorithm"] == NSGA2_LABEL],
            [r.get(key, np.nan) for r in main if r["algorithm"] == GR_LABEL])


def measured(rows, enc: str, items, key_of):
    """``(item, (NSGA-II values, GR-NSGA-II values))`` for the items whose key some run measured."""
    for item in items:
        if (pair := pair_values(rows, enc, key_of(item))) is not None:
            yield item, pair


def table4(rows, enc: str) -> str:
    t4 = []
    for (name, key), (a, b) in measured(rows, enc, TABLE4, lambda item: item[1]):
        sk = SEED_KEYS.get(key)
        t4.append([name, mean_std(a), mean_std(b), significant(SEED_TABLE4[NSGA2_LABEL][sk]) if sk else "",
                   significant(SEED_TABLE4[GR_LABEL][sk]) if sk else ""])
    return markdown_rows(["statistic", NSGA2_LABEL, GR_LABEL, f"seed {NSGA2_LABEL}", f"seed {GR_LABEL}"], t4)


def tests_table(rows, enc: str) -> str:
    st = []
    for (key, lower), (a, b) in measured(rows, enc, TESTED, lambda item: item[0]):
        p, verdict, rel = rank_sum(rows, enc, key, lower)
        st.append([key, "lower" if lower else "higher", mean_std(a), mean_std(b), difference(key, rel), significant(p, 3),
                   verdict])
    return markdown_rows(["indicator", "better", NSGA2_LABEL, GR_LABEL, "GR vs NSGA-II (means)", "p", "verdict"], st)


def write_report(path: Path, ctx: dict) -> None:
    rows, enc_rows = ctx["rows"], ctx["enc_rows"]
    label = MAIN_ENCODING
    encodings = [e for e in ENCODINGS if any(r["problem"] == e for r in rows)]
    case, problem = ctx["case"], ctx["problems"][label]
    paths = ctx["paths"]
    lines = head_lines(ctx, case, problem, label, encodings)
    lines += encoding_section(enc_rows, ctx["n_var"], ctx["n_fixed"])
    lines += ["", ctx.get("encoding_note", "").strip(), ""]

    lines += ["## 2. Fronts (figs. 10-11) and table 4", "",
              f"![fronts]({paths['fronts'].name})", "",
              f"![fronts overlaid]({paths['fronts_overlay'].name})", "",
              f"![fronts near 1050 s]({paths['fronts_zoom'].name})", ""]
    for enc in encodings:
        lines += [f"Table 4 ({enc}): mean +- std over the runs; the seed's values in the last columns (its line "
                  "profile differs: only magnitudes compare).", "", table4(rows, enc), ""]

    lines += ["## 3. Does GR-NSGA-II beat NSGA-II? (rank-sum test)", ""]
    for enc in encodings:
        lines += [f"**{enc}**", "", tests_table(rows, enc), ""]
    lines += [f"![hypervolume]({paths['box_hv'].name})", ""]

    lines += table5_lines(encodings, ctx, rows, paths)

    lines += exact_front_lines(ctx)
    lines += verification_lines(ctx, case)
    lines += ["## 7. Verdict", "", ctx["verdict"].strip(), ""]
    path.write_text("\n".join(lines) + "\n")


def head_lines(ctx, case, problem, label, encodings):
    """Title, set-up and section 1 of the report."""
    lines = [
        "# CRH3 EMU on the Wuhan-Guangzhou line: golden-ratio NSGA-II vs NSGA-II (seed 003, 4.2)",
        "",
        f"Generated by `benchmarks/emu_wuguang.py` on {time.strftime('%Y-%m-%d')}; one row per run in "
        f"`{ctx['csv_name']}`. The closing discussion is written by hand (`emu_wuguang_notes.md`).",
        "",
        "## Set-up",
        "",
        f"- Case `{CASE}`: {case.line.length_m / 1000:.3f} km, planned {case.planned_time_s:g} s, "
        f"margin {case.time_margin_s:g} s; limits 80/160/300/80 km/h; neutral sections "
        + ", ".join(f"{a / 1000:.3f}-{b / 1000:.3f} km" for a, b in case.line.neutral_sections)
        + ". Gradients and curves reconstructed, 8800 kW power cap assumed (see `docs/cases.md`). "
        f"Shortest possible run {problem.min_running_time_s:.1f} s.",
        f"- Problem: `SpeedProfileProblem(case, objectives=(\"energy\", \"running_time\"), "
        f"time_tolerance_s={case.time_margin_s:g}, ...)`: minimise net energy (kWh) and running time (s) subject "
        f"to |T - {case.planned_time_s:g}| <= {case.time_margin_s:g} s (seed 003 4.2: planned 1050 s, 60 s margin; "
        "its fronts span 1008-1105 s), stop within 0.25 m, never above a limit. The seed's second objective "
        "f_T = T - T_0 (eq. 6) differs from T by a constant.",
        f"- Encodings of the main study: **{label}** ({problem.n_var} variables: one target speed per section "
        f"between gradient, limit and neutral-section break points, {int(problem.encoding.fixed().sum())} "
        "of them fixed: the two sections inside the neutral sections, coasted, seed 003 3.2.1), used for "
        "figs. 10-12; and "
        + ", ".join(f"**{e}** ({ctx['n_var'][e]} variables, {ctx['n_fixed'][e]} fixed)" for e in encodings
                    if e != label)
        + " as a check. Why: section 1.",
        f"- Budget: {ctx['budget']:,} evaluations per run for both algorithms (`(\"n_eval\", {ctx['budget']})`"
        + ("; the seed's 200 x 300 generations" if ctx["budget"] == BUDGET and ctx["pop_size"] == POP_SIZE
           else f"; the seed's is {BUDGET:,} with population {POP_SIZE}")
        + f"); population {ctx['pop_size']}; seeds "
        f"{', '.join(str(s) for s in ctx['seeds'])} ({len(ctx['seeds'])} runs per algorithm and encoding, the "
        "same seeds for both). Evaluations actually used are in table 4 (pymoo stops after the generation "
        "that reaches the budget).",
        f"- `{NSGA2_LABEL}`: pymoo NSGA2, SBX (prob 0.9, eta 15), polynomial mutation (eta 20, per-variable "
        "probability 0.01), the seed's settings.",
        f"- `{GR_LABEL}`: `GoldenRatioNSGA2(pop_size={ctx['pop_size']}, local_size={ctx['local_size']}, "
        "pc_max=0.9, pm_max=0.1)`, same operators, neutral-section genes fixed "
        "(`fixed_genes = problem.encoding.fixed()`, passed by the study runner).",
        f"- Runs: `pymoo_rail.experiments.run_study`, {ctx['workers']} worker processes under `nice -n 10` on "
        "the shared 2-core machine (load average 8-10); wall times are those of a loaded machine.",
        "- The exact front: `pymoo_rail.optimal` (dynamic programming over position and speed on the simulator's "
        "own physics, replayed in the simulator) at "
        + (", ".join(f"{t:g}" for t in ctx["exact"]["requested_time_s"]) + " s, cached in "
           f"`{ctx['exact_csv']}` (section 5). Against it: `gap_mean_pct` / `gap_max_pct` / `gap_min_pct`, the mean / "
           "largest / smallest energy of a front member above the exact front at its running time (linear between "
           "the exact points), and `hv_ratio_exact`, the front's hypervolume over the exact front's (both in raw "
           "units, `pymoo_rail.indicators.energy.energy_gap`)." if ctx["exact"] is not None else "(not computed).")
        + " Since the exact front is a chord between 13 points, it lies slightly above the true optimum "
        "between them, and a member may show a small negative gap there.",
        "- Indicators against the non-dominated union of every final front of both algorithms on that encoding: "
        "`hv_ref` "
        "hypervolume normalised to the union's ideal and nadir (reference point 1.1), `igd_ref` and `gd_ref` "
        "(pymoo, mean distance, raw units kWh and s), `gd_seed` the seed's eq. 13 (sqrt(sum d^2) / n), "
        "`spacing` Schott's SP (eqs. 11-12, raw units), `e_at_plan` the least energy of a member with "
        "T <= 1050 s, `punctual_e` the energy of the member closest to 1050 s. Test: two-sided Wilcoxon "
        "rank-sum (`pymoo_rail.experiments.stats.rank_sum`): `+` GR-NSGA-II significantly better at "
        "alpha = 0.05, `-` worse, `=` no significant difference.",
        "",
    ]
    return lines


def table5_lines(encodings, ctx, rows, paths):
    """Section 4: the most punctual solutions (table 5) and fig. 12."""
    lines = []
    lines += ["## 4. Most punctual solutions (table 5) and fig. 12", "",
              "The front member closest to 1050 s (ties: lower energy) of each algorithm's median-HV run (the "
              "runs of figs. 10-11), re-simulated; then the mean over all runs.", ""]
    t5 = []
    for enc in encodings:
        for alg in (NSGA2_LABEL, GR_LABEL):
            c = ctx["chosen"][enc, alg]
            traj = c["trajectory"]
            rs = [r for r in rows if r["problem"] == enc and r["algorithm"] == alg]
            se, stt = SEED_TABLE5[alg]
            opt = exact_energy_kwh(ctx["exact"], traj.running_time_s) if ctx["exact"] is not None else np.nan
            gap = f"{opt:.2f} (+{100 * (traj.energy.net_kwh / opt - 1):.2f} %)" if np.isfinite(opt) else ""
            t5.append([enc, alg, c["seed"], f"{traj.energy.net_kwh:.2f}", f"{traj.running_time_s:.1f}", gap,
                       f"{traj.energy.traction_kwh:.1f} / {traj.energy.regen_kwh:.1f}",
                       mean_std(r.get("punctual_e", np.nan) for r in rs),
                       mean_std(r.get("punctual_t", np.nan) for r in rs),
                       mean_std(r.get("e_at_plan", np.nan) for r in rs), f"{se} at {stt}"])
    lines += [markdown_rows(["encoding", "algorithm", "run (seed)", "energy (kWh)", "running time (s)",
                        "exact optimum at that time (kWh)",
                        "traction / regen (kWh)", "all runs: energy (kWh)", "all runs: time (s)",
                        "all runs: least E with T <= 1050 s", "seed 003 table 5"], t5), "",
              f"![profile]({paths['profile'].name})", ""]
    return lines


def exact_front_lines(ctx):
    """Section 5: the exact front (when it was solved)."""
    lines = []
    if ctx["exact"] is not None:
        ex = ctx["exact"]
        lines += ["## 5. The exact front", "",
                  "The minimum net energy at each running time (`pymoo_rail.optimal.OptimalSolver`, 5 m grid, "
                  f"{int(ex['n_speeds'].iloc[0])} speed nodes), each run replayed in the simulator, so it obeys the "
                  "same limits, neutral sections and energy accounting as the optimisers' runs; `lambda` is the slope "
                  "-dE/dT, the energy one more second of running time saves.", "",
                  markdown_rows(["requested (s)", "running time (s)", "net energy (kWh)", "traction / regen (kWh)",
                            "lambda (kWh/s)", "neutral traction (J)", "limit excess (m/s)", "stop error (m)",
                            "solve (s)"],
                           [[f"{r.requested_time_s:g}", f"{r.running_time_s:.2f}", f"{r.energy_kwh:.2f}",
                             f"{r.traction_kwh:.1f} / {r.regen_kwh:.1f}", f"{r.lambda_kwh_per_s:.3f}",
                             significant(r.neutral_traction_j), significant(r.limit_excess_ms), significant(r.stop_error_m),
                             f"{r.solve_s:.0f}"] for r in ex.itertuples()]), ""]
    return lines


def verification_lines(ctx, case):
    """Section 6: the checks of every front member."""
    lines = []
    ver = ctx["verification"]
    lines += ["## 6. Verification of every front member", "",
              f"Each feasible member of every final front ({ver['n_members']} members of {ver['n_runs']} runs, the "
              "main and the encoding study) is re-simulated with `problem.trajectory(x)` and checked:", "",
              "- neutral sections: the kernel's `summary[\"neutral_traction_j\"]`, and the largest "
              "`trajectory.force_n` over every grid cell that touches a neutral section (traction > 0, braking < 0);",
              "- limits: the kernel's `summary[\"limit_excess_ms\"]` (max of v - limit over the run), and an "
              "independent check of the speed at every node against the lowest limit of `case.line.speed_limits` "
              f"under the train (head at the node, tail {case.train.length_m:g} m behind) and the train's maximum "
              "speed;",
              "- the stop: `stop_error_m <= 0.25` (distance between the stopping point and the platform mark);",
              "- the stored objectives equal the re-simulated energy and running time;",
              "- the genes of the sections inside the neutral sections (speed codes) still hold their fixed value.",
              ""]
    lines += [markdown_rows(["check", "worst value over all members", "required", "result"], [
        ["neutral traction work (J)", significant(ver["neutral_traction_j_max"]), "0", ver["neutral_ok"]],
        ["largest force in a neutral section (N)", significant(ver["neutral_force_n_max"]), "<= 0", ver["force_ok"]],
        ["kernel limit excess (m/s)", significant(ver["limit_excess_ms_max"]), "<= 0", ver["limit_ok"]],
        ["independent limit excess over the train length (m/s)", significant(ver["independent_excess_ms_max"]), "<= 0",
         ver["independent_ok"]],
        ["stop error (m)", significant(ver["stop_error_m_max"]), "<= 0.25", ver["stop_ok"]],
        ["stored vs re-simulated energy (kWh)", significant(ver["energy_mismatch_kwh"]), "0", ver["energy_ok"]],
        ["stored vs re-simulated running time (s)", significant(ver["time_mismatch_s"]), "0", ver["time_ok"]],
        ["neutral-section genes at their fixed value (10 km/h, coast)", "", "all members", ver["fixed_ok"]],
    ]), "", f"**All {ver['n_members']} members pass: {'yes' if ver['all_ok'] else 'NO'}.**", ""]
    return lines


def verification_summary(rows) -> dict:
    vr = [r for r in rows if "verified" in r]
    v = {"n_runs": len(vr), "n_members": sum(r["n_points"] for r in vr)}
    for key in ("neutral_traction_j_max", "neutral_force_n_max", "limit_excess_ms_max", "independent_excess_ms_max",
                "stop_error_m_max", "energy_mismatch_kwh", "time_mismatch_s"):
        v[key] = float(max(r[key] for r in vr))
    v["neutral_ok"] = "pass" if v["neutral_traction_j_max"] == 0 else "FAIL"
    v["force_ok"] = "pass" if v["neutral_force_n_max"] <= 0 else "FAIL"
    v["limit_ok"] = "pass" if v["limit_excess_ms_max"] <= SPEED_TOLERANCE_MS else "FAIL"
    v["independent_ok"] = "pass" if v["independent_excess_ms_max"] <= SPEED_TOLERANCE_MS else "FAIL"
    v["stop_ok"] = "pass" if v["stop_error_m_max"] <= STOP_TOLERANCE_M else "FAIL"
    v["energy_ok"] = "pass" if v["energy_mismatch_kwh"] <= 1e-9 else "FAIL"
    v["time_ok"] = "pass" if v["time_mismatch_s"] <= 1e-9 else "FAIL"
    v["fixed_ok"] = "pass" if all(r["fixed_genes_ok"] for r in vr) else "FAIL"
    v["all_ok"] = all(r["verified"] for r in vr) and v["energy_ok"] == v["time_ok"] == "pass"
    return v


def verdict_text(rows) -> str:
    lines = []
    for enc in [e for e in ENCODINGS if any(r["problem"] == e for r in rows)]:
        parts = []
        for key, lower, name in (("hv_ref", False, "hypervolume"), ("igd_ref", True, "IGD"),
                                 ("gap_mean_pct", True, "mean energy gap to the exact front"),
                                 ("e_at_plan", True, "least energy with T <= 1050 s")):
            if not any(np.isfinite(r.get(key, np.nan)) for r in rows):
                continue
            p, verdict, rel = rank_sum(rows, enc, key, lower)
            word = {"+": "better (significant)", "-": "worse (significant)",
                    "=": "not significantly different"}.get(verdict, "untested")
            parts.append(f"{name}: GR-NSGA-II {word}, means differ by {difference(key, rel)} (p = {significant(p, 3)})")
        lines.append(f"- Measured on {enc}: " + "; ".join(parts) + ".")
    return "\n".join(lines)


def summarise(results_main, results_enc, problems_by_label, args, out: Path, prefix: str, exact=None,
              exact_profile=None) -> dict:
    from pymoo_rail.cases import load_case

    case = load_case(CASE)
    results_main, rows, _ = analyse(results_main, problems_by_label, exact=exact)
    enc_rows = []
    if results_enc is not None and len(results_enc):
        _, enc_rows, _ = analyse(results_enc, problems_by_label, exact=exact)
    chosen = punctual_choices(results_main, rows, problems_by_label)
    paths = make_figures(results_main, rows, chosen, problems_by_label, out, prefix, exact, exact_profile)
    csv_path = out / f"{prefix}_runs.csv"
    write_csv(csv_path, [{"study": "main", **r} for r in rows] + [{"study": "encodings", **r} for r in enc_rows])
    ctx = {"rows": rows, "enc_rows": enc_rows, "case": case, "problems": problems_by_label, "paths": paths,
           "chosen": chosen, "csv_name": csv_path.name, "budget": args.budget, "pop_size": args.pop_size,
           "local_size": args.local_size, "seeds": sorted({r["seed"] for r in rows}), "workers": args.workers,
           "n_var": {k: p.n_var for k, p in problems_by_label.items()},
           "n_fixed": {k: int(p.encoding.fixed().sum()) for k, p in problems_by_label.items()},
           "verification": verification_summary(rows + enc_rows), "verdict": verdict_text(rows), "exact": exact,
           "exact_csv": f"{prefix}_optimal.csv"}
    notes = out / f"{prefix}_notes.md"
    if notes.exists():  # the hand-written discussion: "<encoding note> <!-- verdict --> <verdict discussion>"
        encoding_note, _, discussion = notes.read_text().partition("<!-- verdict -->")
        ctx["encoding_note"] = encoding_note
        ctx["verdict"] = ctx["verdict"] + "\n\n" + discussion.strip()
    write_report(out / f"{prefix}.md", ctx)
    return ctx


# ------------------------------------------------------------------------------ main


def build_problems():
    from pymoo_rail.cases import load_case
    from pymoo_rail.problems import SpeedProfileProblem

    case = load_case(CASE)
    return {enc: SpeedProfileProblem(case, objectives=OBJECTIVES, time_tolerance_s=case.time_margin_s,
                                     **ENCODINGS[enc]) for enc in ENCODINGS}


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--seeds", type=int, default=10, help="runs per algorithm and encoding in the main study")
    parser.add_argument("--budget", type=int, default=BUDGET, help="evaluations per run (main study)")
    parser.add_argument("--pop-size", type=int, default=POP_SIZE)
    parser.add_argument("--local-size", type=int, default=LOCAL_SIZE)
    parser.add_argument("--encodings", nargs="+", default=list(MAIN_ENCODINGS), choices=list(ENCODINGS),
                        help=f"encodings of the main study (the first one is drawn; default: {MAIN_ENCODINGS})")
    parser.add_argument("--encoding-seeds", type=int, default=ENCODING_SEEDS, help="0 skips the encoding study")
    parser.add_argument("--encoding-budget", type=int, default=ENCODING_BUDGET)
    parser.add_argument("--workers", type=int, default=2)
    parser.add_argument("--work", type=Path, default=ROOT / "out" / "emu_wuguang", help="study directories")
    parser.add_argument("--out", type=Path, default=ROOT / "benchmarks" / "reports", help="report directory")
    parser.add_argument("--prefix", default="emu_wuguang")
    parser.add_argument("--report-only", action="store_true", help="analyse the stored runs only")
    parser.add_argument("--no-exact", action="store_true",
                        help="leave out the exact front of pymoo_rail.optimal (13 solves at 800 speed nodes, cached)")
    parser.add_argument("--no-progress", action="store_true")
    parser.add_argument("--resolution", action="store_true",
                        help="print how the exact front moves with the speed nodes (200/400/800 at 1050, 1060 "
                             "and 1100 s) and the stored main-study fronts' lowest member against each; no report")
    args = parser.parse_args(argv)
    if args.encodings[0] != MAIN_ENCODING:
        parser.error(f"--encodings: the first encoding must be {MAIN_ENCODING!r} (figs. 10-12 are drawn on it)")

    from pymoo_rail.experiments import load_results, run_study

    enc_study = make_study("emu_wuguang_encodings", list(ENCODINGS), range(1, args.encoding_seeds + 1),
                           args.encoding_budget, args.pop_size, args.local_size) if args.encoding_seeds > 0 else None
    main_study = make_study("emu_wuguang", args.encodings, range(1, args.seeds + 1), args.budget, args.pop_size,
                            args.local_size)
    enc_dir, main_dir = args.work / "encodings", args.work / "main"
    if args.resolution:
        from pymoo_rail.experiments.report import markdown

        print(markdown(resolution(load_results(main_dir, study=main_study))), flush=True)
        return 0
    if not args.report_only:
        t0 = time.perf_counter()
        for study, directory in ((enc_study, enc_dir), (main_study, main_dir)):
            if study is not None:  # seed by seed: a study stopped early still compares like with like
                print(run_study(study, directory, workers=args.workers, progress=not args.no_progress,
                                seed_major=True), flush=True)
        print(f"studies done in {time.perf_counter() - t0:.0f} s", flush=True)
    results_enc = load_results(enc_dir, study=enc_study) if enc_study is not None else None
    results_main = load_results(main_dir, study=main_study)
    args.out.mkdir(parents=True, exist_ok=True)
    exact = exact_profile = None
    if not args.no_exact:
        import pandas as pd

        profile_path = args.work / "optimal_profile.csv"
        args.work.mkdir(parents=True, exist_ok=True)
        exact = exact_front(args.out / f"{args.prefix}_optimal.csv", profile_path=profile_path)
        exact_profile = pd.read_csv(profile_path)
    ctx = summarise(results_main, results_enc, build_problems(), args, args.out, args.prefix, exact, exact_profile)
    print(ctx["verdict"])
    ver = ctx["verification"]
    print(f"verification of {ver['n_members']} members in {ver['n_runs']} runs:",
          "all pass" if ver["all_ok"] else "FAILURES")
    return 0 if ver["all_ok"] else 1


if __name__ == "__main__":
    sys.exit(main())
