"""Studies of trains sharing braking energy (Chen et al. 2017): their definitions and their statistics.

:func:`offsets_study` is the paper's experiment as a :class:`~pymoo_rail.experiments.Study`: every
departure offset, optionally with every gradient scaled by phi (fig. 6), solved by plain pymoo GA;
:func:`exact_baselines` the uncoordinated reference per phi (each train exactly optimal alone);
:func:`savings_table` the median, IQR and one-sample Wilcoxon signed-rank test of the stored
results against it; :func:`sharing_potential` how much regenerated energy there is to share at
all, from the kernel's traces. ``benchmarks/cooperative.py`` is a thin script over these.
"""

from __future__ import annotations

import time
from typing import Sequence

import numpy as np
import pandas as pd

from pymoo_rail.constants import J_PER_KWH
from pymoo_rail.experiments.spec import Study, algorithm, problem
from pymoo_rail.experiments.stats import signed_rank_vs
from pymoo_rail.problems.cooperative import SEED_001_OFFSETS_S, scale_gradients
from pymoo_rail.problems.cooperative import CooperativeTrainsProblem
from pymoo_rail.problems.cooperative_baseline import ExactBaseline, exact_baseline
from pymoo_rail.problems.cooperative_seed import CooperativeSeedProblem, nested_minimize
from pymoo_rail.sim import cooperation as coop


def problem_label(phi: float, offset_s: float) -> str:
    """The label of one (phi, offset) problem in the studies."""
    return f"phi={phi:g} x={offset_s:+g}"


def offsets_study(name: str, phis: Sequence[float], seeds: int, offsets_s: Sequence[float] = SEED_001_OFFSETS_S,
                  pop_size: int = 60, n_eval: int = 6000, paper_encoding: bool = False) -> Study:
    """``CooperativeTrainsProblem`` at every offset and gradient factor, plain pymoo GA, ``seeds`` seeds.

    ``paper_encoding``: ``CooperativeSeedProblem`` instead (phi 1 only)."""
    problems = []
    for phi in phis:
        for x in offsets_s:
            label = problem_label(phi, x)
            if paper_encoding:
                if phi != 1.0:
                    raise ValueError(f"phi = {phi!r}: the paper-encoding study runs the case as it is (phi 1)")
                problems.append(problem("cooperative_seed", label=label, offset_s=x))
            elif phi == 1.0:
                problems.append(problem("cooperative_trains", label=label, offset_s=x))
            else:
                problems.append(problem("cooperative_trains_scaled", label=label, offset_s=x, phi=phi))
    return Study(name, problems=problems, algorithms=[algorithm("ga", label="GA", pop_size=pop_size)], seeds=seeds,
                 budget={"n_eval": n_eval})


def exact_baselines(case, phis: Sequence[float]) -> dict[float, ExactBaseline]:
    """The exact uncoordinated baseline of ``case`` with its gradients times each phi (about a CPU second each)."""
    return {phi: exact_baseline(case if phi == 1.0 else scale_gradients(case, phi)) for phi in phis}


def savings_table(results: pd.DataFrame, baselines: dict[float, ExactBaseline],
                  offsets_s: Sequence[float] = SEED_001_OFFSETS_S) -> pd.DataFrame:
    """Per (phi, offset): seeds, median / best result, median saving with its IQR, Wilcoxon p and verdict.

    ``results`` are a study's stored runs (:func:`~pymoo_rail.experiments.load_results`); savings are
    ``1 - result / baseline`` in percent; the test is one-sample signed-rank against the baseline.
    """
    rows = []
    for phi, base in baselines.items():
        for x in offsets_s:
            sel = results[results["problem"] == problem_label(phi, x)]
            if sel.empty:
                continue
            f = np.array([float(np.min(F[:, 0])) for F in sel["F"]])
            saving = 100.0 * (1.0 - f / base.energy_kwh)
            q1, med, q3 = np.percentile(saving, [25, 50, 75])
            p, verdict = signed_rank_vs(f, base.energy_kwh)
            rows.append(dict(phi=phi, offset_s=x, seeds=len(f), baseline_kwh=base.energy_kwh,
                             chance_kwh=base.shared_by_chance_kwh(x), median_kwh=float(np.median(f)),
                             best_kwh=float(f.min()), saving_median_pct=med, saving_q1_pct=q1, saving_q3_pct=q3,
                             p=p, verdict=verdict, feasible=int(sel["feasible"].sum()),
                             cpu_s=float(sel["cpu_time_s"].sum())))
    return pd.DataFrame(rows)


def sharing_potential(runs, time_step_s: float = 0.1) -> pd.DataFrame:
    """How much of each run's regenerated energy another run could take at all (kWh), from their traces.

    ``runs`` are :class:`~pymoo_rail.sim.cooperation.ClockedRun` on one clock. Per run: ``regen_kwh``
    (all it regenerates), ``while_others_move_kwh`` (the part regenerated while another train is
    between departure and arrival: no other train can draw power while standing), and
    ``others_draw_kwh`` (the part matched, bin by bin, by another train's traction as driven: what
    eq. 5 shares from this run).
    """
    t0, n_bins = coop.clock_span(runs, time_step_s)
    trac, regen = coop.power_bins(runs, t0, time_step_s, n_bins)
    mid = t0 + time_step_s * (np.arange(n_bins) + 0.5)
    rows = []
    for j, run in enumerate(runs):
        others = [i for i in range(len(runs)) if i != j]
        moving = np.zeros(n_bins, dtype=bool)
        for i in others:
            moving |= (mid >= runs[i].departure_s) & (mid < runs[i].arrival_s)
        drawn = trac[others].sum(axis=0)
        rows.append(dict(regen_kwh=regen[j].sum() / J_PER_KWH,
                         while_others_move_kwh=regen[j][moving].sum() / J_PER_KWH,
                         others_draw_kwh=np.minimum(regen[j], drawn).sum() / J_PER_KWH,
                         braking_from_s=float(mid[regen[j] > 0].min()) if regen[j].any() else np.nan,
                         braking_to_s=float(mid[regen[j] > 0].max()) if regen[j].any() else np.nan))
    return pd.DataFrame(rows)


def best_clocked_runs(results: pd.DataFrame | None, offset_s: float, problem) -> list | None:
    """The two trains' clocked runs of the best stored result at ``offset_s`` (phi 1), or None without one.

    Parameters
    ----------
    results : pandas.DataFrame or None
        A study's stored runs with their decisions (``X``) and objectives (``F``).
    offset_s : float
        The departure offset (s).
    problem : callable
        ``offset_s -> `` the problem that simulates a decision (``simulate(X)["clocked"]``).
    """
    sel = results[results["problem"] == problem_label(1.0, offset_s)] if results is not None else []
    if len(sel) == 0:
        return None
    best = sel.iloc[int(np.argmin([float(np.min(F[:, 0])) for F in sel["F"]]))]
    x_best = np.asarray(best["X"])[int(np.argmin(best["F"][:, 0]))]
    return problem(offset_s).simulate(x_best[None, :])["clocked"][0]


def sharing_rows(case, results: pd.DataFrame, paper_results: pd.DataFrame | None, base: ExactBaseline,
                 offsets_s: Sequence[float] = SEED_001_OFFSETS_S) -> list[tuple]:
    """What there is to share at each offset: the exact runs alone, the best GA runs on speed codes and
    on the paper's encoding (when ``paper_results`` is given).

    Returns
    -------
    list of (float, str, pandas.DataFrame)
        ``(offset s, label, sharing_potential of its two runs)``; runs missing from a study are left out.
    """
    rows = []
    for x in offsets_s:
        candidates = [("exact, alone", base.clocked_pair(x)),
                      ("best GA, speed codes", best_clocked_runs(results, x, lambda o: CooperativeTrainsProblem(case, o))),
                      ("best GA, paper's encoding",
                       best_clocked_runs(paper_results, x, lambda o: CooperativeSeedProblem(case, o)))]
        rows += [(x, label, sharing_potential(runs)) for label, runs in candidates if runs is not None]
    return rows


def nested_run(case, offset_s: float, outer_pop: int, outer_gen: int, seed: int = 1, verbose: bool = True) -> dict:
    """The nested GA of Chen et al. (2017) once (inner GA 100 x 80), after timing one evaluation.

    Returns
    -------
    dict
        ``problem``, ``per_eval_s`` (CPU s per evaluation of the paper's encoding), ``x``, ``f_kwh``,
        ``solution`` (``problem.decode(x)``), ``cpu_s`` of the nested run and the exact ``baseline``.
    """
    problem = CooperativeSeedProblem(case, offset_s)
    X = problem.xl + np.random.default_rng(0).random((100, problem.n_var)) * (problem.xu - problem.xl)
    problem.evaluate(X[:2])  # compile first
    start = time.process_time()
    for _ in range(3):
        problem.evaluate(X)
    per_eval_s = (time.process_time() - start) / (3 * X.shape[0])
    base, start = exact_baseline(case), time.process_time()
    x, f, _ = nested_minimize(problem, outer_pop_size=outer_pop, outer_n_gen=outer_gen, seed=seed, verbose=verbose)
    return {"problem": problem, "per_eval_s": per_eval_s, "x": x, "f_kwh": f, "solution": problem.decode(x),
            "cpu_s": time.process_time() - start, "baseline": base}
