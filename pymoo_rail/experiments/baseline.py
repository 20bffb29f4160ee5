"""The suite's baseline table: indicators of study runs on family instances, ranks and profiles.

A baseline study (``benchmarks/suite_baseline.toml``) runs algorithms on instances
``problem = "suite_family"`` (family, n_var, seed). A record holds raw objective vectors only: its
final front and the non-dominated feasible vectors at a few evaluation checkpoints
(:data:`pymoo_rail.experiments.runner.CHECKPOINTS_EVAL`). They are scored here against the
instance's front of the version this code has (:func:`front_versions` says which, for the report),
so records stay current when the exact solver improves and their scores follow its fronts:

- ``igd_plus``: pymoo's IGD+ of the feasible final front to the certified front (raw units);
- ``hv_norm``: hypervolume at the family's fixed reference point
  (:meth:`~pymoo_rail.suite.FamilyProblem.hv_reference_point`) over that of the certified front
  (1 = the whole front's hypervolume);
- ``gap_kwh``: median energy gap of the members to the optimum at their own running times
  (:func:`pymoo_rail.optimal.reference.certified_gap`).

A one-objective record (the ``-single`` and ``-trip`` families) is scored by the gap of its best
feasible energy to the instance's optimum (:data:`ONE_OBJECTIVE`): the certified constrained
optimum of a ``-single`` instance (its certificate known), the exact split of a ``-trip``:

- ``gap_kwh``: best feasible energy minus the optimum (>= minus the certificate);
- ``gap_pct``: the same in % of the distance from the optimum to the instance's fixed reference
  point (:meth:`hv_reference_point`), i.e. ``100 (1 - normalised HV)`` of the one-dimensional front;
- ``gap_resolved_pct``: ``gap_pct`` raised to the optimum's resolution (its certificate, or
  :data:`EXACT_RESOLUTION_PCT` for an exact optimum): positive, what the performance profile and the
  convergence figure use, as a gap within the certificate cannot be told from 0.

The 3-objective families have a bounded front (:mod:`pymoo_rail.suite.comfort`): their IGD+ is to
the inner (best-known) points, ``hv_norm`` is over the outer bound's hypervolume (the true front's
lies between the inner points' value and 1), and ``gap_kwh`` is to the line's certified energy /
running-time front, which bounds the energy of any run whatever its comfort.

A record whose instance checksum (``inputs["problem instance checksum"]``) differs from the
instance this code builds is refused: it was computed on another definition. :func:`convergence`
scores the checkpoints the same way (the convergence figure).
:func:`baseline_table` ranks the algorithms per (family, n_var) with
:func:`.stats.friedman_holm`; :func:`performance_profile` gives Dolan & More's (2002) profile.
"""

from __future__ import annotations

import hashlib
import json
import os
import tarfile
from dataclasses import dataclass, replace
from pathlib import Path
from typing import Iterable, Mapping, Sequence

import numpy as np
import pandas as pd

from pymoo_rail.experiments.inputs import front_digest
from pymoo_rail.experiments.registry import canonical_name
from pymoo_rail.experiments.spec import Budget
from pymoo_rail.experiments.stats import friedman_holm, to_markdown
from pymoo_rail.optimal.reference import certified_gap, constrained_optimum
from pymoo_rail.suite import get_problem
from pymoo_rail.suite.comfort import COMFORT_OBJECTIVES
from pymoo_rail.suite.trips import TripProblem

INDICATORS = {"igd_plus": True, "hv_norm": False, "gap_kwh": True}
"""The table's indicators and whether lower is better."""
RANK_INDICATOR = "igd_plus"
"""The indicator the ranks and Holm marks of the table are computed on."""
EXACT_RESOLUTION_PCT = 1e-6
"""The resolution of an exact optimum (a trip's split) in ``gap_resolved_pct``: float rounding of its sum."""
EXACT_FRONT_VERSION = "exact"
"""The front version a report states for a trip: its optimum is exact on the curves its definition holds."""


@dataclass(frozen=True)
class IndicatorSet:
    """The indicators of a table for one objective count (:func:`indicator_set`).

    ``lower_better``: the table's indicators and whether lower is better; ``rank``: the one the
    Friedman ranks and Holm marks are computed on; ``profile``: the positive one of the performance
    profile and the convergence figure; ``label``: how the figures name it.
    """

    lower_better: Mapping[str, bool]
    rank: str
    profile: str
    label: str

    @property
    def columns(self) -> tuple[str, ...]:
        """The scores of a record: the table's indicators and the profile's."""
        return tuple(dict.fromkeys([*self.lower_better, self.profile]))


MULTI_OBJECTIVE = IndicatorSet(INDICATORS, RANK_INDICATOR, RANK_INDICATOR, "IGD+")
"""The indicators of the multi-objective families (``-bi``, ``-3obj``)."""
ONE_OBJECTIVE = IndicatorSet({"gap_kwh": True, "gap_pct": True}, "gap_kwh", "gap_resolved_pct",
                             "gap_pct")
"""The indicators of the one-objective families (``-single``, ``-trip``)."""


def indicator_set(n_obj: int) -> IndicatorSet:
    """:data:`ONE_OBJECTIVE` for one objective, :data:`MULTI_OBJECTIVE` for more."""
    return ONE_OBJECTIVE if int(n_obj) == 1 else MULTI_OBJECTIVE


def frame_indicators(frame: pd.DataFrame) -> IndicatorSet:
    """The indicator set of an :func:`indicator_frame` (its ``n_obj``); raises ValueError for a mix of
    one-objective and multi-objective records, whose scores cannot share a table."""
    if frame.empty:
        raise ValueError("frame: no records, so no table")
    counts = sorted(int(n) for n in frame["n_obj"].unique())
    if len({n == 1 for n in counts}) != 1:
        raise ValueError(f"frame['n_obj'] = {counts}: one-objective and multi-objective records make separate tables")
    return indicator_set(counts[0])


def one_objective_optimum(problem) -> tuple[float, float]:
    """The optimum (kWh) of a one-objective family instance and its certificate (kWh).

    A ``-single`` instance: the constrained optimum of the line's certified front within the running-time
    tolerance (:func:`~pymoo_rail.optimal.reference.constrained_optimum`, what ``pareto_front()`` gives)
    and its bound; a ``-trip`` instance: its exact split (:attr:`~pymoo_rail.suite.trips.TripProblem.optimum`),
    certificate 0.
    """
    if isinstance(problem, TripProblem):
        return float(problem.optimum[1]), 0.0
    energy, bound, _ = constrained_optimum(problem.certified_front(), problem.time_tolerance_s,
                                           window_s=problem.time_window_s)
    return float(energy), float(bound)


def instance_of(record: dict):
    """The suite family instance of a study record, refused when its checksum is not the record's."""
    params = record["problem"]
    if canonical_name(str(params.get("problem", ""))) != "suite_family":
        raise ValueError(f"record {record.get('run_id')}: problem {params.get('problem')!r} is not a suite family instance")
    problem = get_problem(params["family"], n_var=params.get("n_var"), seed=params.get("seed"))
    stored = record.get("inputs", {}).get("problem instance checksum")
    if stored != problem.checksum:
        raise ValueError(f"record {record.get('run_id')}: inputs['problem instance checksum'] = {stored!r} is not the "
                         f"checksum of {problem.suite_name} ({problem.checksum}): computed on another definition")
    return problem


@dataclass(frozen=True)
class FrontScorer:
    """The fronts one instance's runs are scored against, read once (:func:`front_scorer`)."""

    problem: object
    pf: np.ndarray
    hv_reference_point: np.ndarray
    hv_whole: float  # the certified front's hypervolume, or the outer bound's for a bounded front
    certificate_kwh: float = 0.0  # one objective: the optimum's bound (0 when exact)

    @property
    def indicators(self) -> IndicatorSet:
        """The scores of this instance's records (:func:`indicator_set`)."""
        return indicator_set(self.problem.n_obj)

    def score(self, F: np.ndarray) -> dict[str, float]:
        """The :attr:`indicators` of the feasible objective vectors ``F`` (NaN for none)."""
        F = np.asarray(F, dtype=float).reshape(-1, self.problem.n_obj)
        out = dict.fromkeys(self.indicators.columns, float("nan"))
        if len(F) == 0:
            return out
        out.update(self._gap(F) if self.problem.n_obj == 1 else self._front(F))
        return out

    def _gap(self, F: np.ndarray) -> dict[str, float]:
        """Best energy minus the optimum; in % of the optimum's distance to the reference point (``hv_whole``)."""
        gap_kwh = float(F[:, 0].min() - self.pf[0, 0])
        resolution_pct = max(100.0 * self.certificate_kwh / self.hv_whole, EXACT_RESOLUTION_PCT)
        gap_pct = 100.0 * gap_kwh / self.hv_whole
        return {"gap_kwh": gap_kwh, "gap_pct": gap_pct, "gap_resolved_pct": max(gap_pct, resolution_pct)}

    def _front(self, F: np.ndarray) -> dict[str, float]:
        """IGD+, normalised HV and median energy gap of a front."""
        from pymoo.indicators.hv import HV
        from pymoo.indicators.igd_plus import IGDPlus

        objectives = list(self.problem.objectives)
        gap = certified_gap(self.problem.certified_front(), F[:, objectives.index("running_time")],
                            F[:, objectives.index("energy")])
        hv = HV(ref_point=self.hv_reference_point)
        return {"igd_plus": float(IGDPlus(self.pf)(F)), "hv_norm": float(hv(F) / self.hv_whole),
                "gap_kwh": gap["gap_median_kwh"]}


def front_scorer(problem) -> FrontScorer:
    """The current front of a family instance, its fixed HV reference point and the HV that counts as 1.

    One objective: the optimum and its certificate (:func:`one_objective_optimum`); the HV that
    counts as 1 is the optimum's, its distance to the reference point.
    """
    from pymoo.indicators.hv import HV

    ref = problem.hv_reference_point()
    if problem.n_obj == 1:
        optimum, certificate = one_objective_optimum(problem)
        if not ref[0] > optimum:
            raise ValueError(f"{problem.suite_name}: hv_reference_point() = {ref.tolist()} is not above the "
                             f"optimum {optimum!r} kWh, so no gap can be scaled by it")
        return FrontScorer(problem, np.array([[optimum]]), ref, float(ref[0] - optimum), certificate)
    pf = problem.pareto_front()
    # a bounded front (the -3obj families): HV over the outer bound's, so 1 is out of reach of any run
    whole = problem.bounded_front().hv_outer if problem.objectives == COMFORT_OBJECTIVES else HV(ref_point=ref)(pf)
    return FrontScorer(problem, pf, ref, float(whole))


def baseline_indicators(record: dict, problem=None, scorer: FrontScorer | None = None) -> dict[str, float]:
    """The scores of one record's final front (:meth:`FrontScorer.score`; NaN where no member is feasible)."""
    problem = scorer.problem if scorer is not None else instance_of(record) if problem is None else problem
    scorer = front_scorer(problem) if scorer is None else scorer
    F = np.asarray(record["front"]["F"], dtype=float).reshape(-1, problem.n_obj)
    return scorer.score(F[np.asarray(record["front"]["CV"], dtype=float).reshape(-1) <= 0])


def _instances(records: Iterable[dict]) -> dict:
    """One problem per distinct instance of ``records``, by the record's problem parameters."""
    instances = {}
    for record in records:
        key = tuple(sorted(record["problem"].items()))
        if key not in instances:
            instances[key] = instance_of(record)
    return instances


def _scorers(records: Iterable[dict]) -> dict:
    """One :class:`FrontScorer` per distinct instance of ``records``, by the record's problem parameters."""
    return {key: front_scorer(problem) for key, problem in _instances(records).items()}


def indicator_frame(records: Iterable[dict]) -> pd.DataFrame:
    """One row per record: family, n_var, n_obj, instance seed, run seed, algorithm, its scores
    (:attr:`FrontScorer.indicators`), CPU and evaluations."""
    records = list(records)
    scorers, rows = _scorers(records), []
    for record in records:
        scorer = scorers[tuple(sorted(record["problem"].items()))]
        problem = scorer.problem
        rows.append({"family": problem.family, "n_var": int(problem.n_var), "n_obj": int(problem.n_obj),
                     "instance_seed": problem.seed, "seed": int(record["seed"]), "algorithm": record["algorithm_label"],
                     **baseline_indicators(record, scorer=scorer),
                     "cpu_time_s": float(record["cpu_time_s"]), "n_eval": int(record["n_eval"])})
    return pd.DataFrame(rows)


def front_versions(records: Iterable[dict]) -> pd.DataFrame:
    """The fronts a report scores ``records`` against: per instance its front version and content digest.

    ``front_version``: :attr:`pymoo_rail.suite.FamilyProblem.front_version` (:data:`EXACT_FRONT_VERSION`
    for a trip); ``front_digest``:
    :func:`pymoo_rail.experiments.inputs.front_digest`. Neither is part of a record: a report states them.
    """
    rows = []
    for problem in _instances(records).values():  # no scorer: the front's hypervolume is not needed here
        rows.append({"family": problem.family, "n_var": int(problem.n_var), "instance_seed": problem.seed,
                     "front_version": EXACT_FRONT_VERSION if isinstance(problem, TripProblem) else problem.front_version,
                     "front_digest": front_digest(problem)})
    return pd.DataFrame(rows).sort_values(["family", "n_var", "instance_seed"]).reset_index(drop=True)


def checkpoints_kb(records: Iterable[dict]) -> str:
    """The size of the records' ``checkpoints`` (compact JSON, kB): median and largest, for the report."""
    sizes = np.array([len(json.dumps(r.get("checkpoints"), separators=(",", ":"))) / 1000 for r in records])
    return f"median {np.median(sizes):.1f} kB, largest {sizes.max():.1f} kB" if len(sizes) else "no records"


def fronts_statement(fronts: pd.DataFrame) -> str:
    """A report's sentence on the fronts it scored against (:func:`front_versions`): their versions and
    one digest of their content digests, so two reports say whether they scored against the same fronts."""
    digest = hashlib.sha256("\n".join(fronts["front_digest"]).encode()).hexdigest()[:16]
    versions = ", ".join(f"{v} ({n} instance{'s' if n > 1 else ''})"
                         for v, n in fronts["front_version"].value_counts().sort_index().items())
    return (f"Scored against the fronts of version {versions}; their content digests "
            f"(`pymoo_rail.experiments.inputs.front_digest`, one per instance) hash to `{digest}`.")


def _cell(values: pd.Series) -> str:
    values = values.dropna()
    if values.empty:
        return "n/a"
    return f"{values.mean():.4g} +- {values.std(ddof=1):.2g}" if len(values) > 1 else f"{values.mean():.4g}"


def baseline_table(frame: pd.DataFrame, alpha: float = 0.05,
                   indicators: Sequence[str] | None = None) -> pd.DataFrame:
    """Mean +- std of each indicator, mean rank and Holm mark vs the best, per (family, n_var) and algorithm.

    The indicators (default) and the one ranked are the frame's set (:func:`frame_indicators`: IGD+
    for several objectives, the gap in kWh for one). Ranks and marks are paired by run seed;
    ``friedman_p`` is the Friedman p-value of the cell. Mark ``best``, ``=`` (not significantly
    worse than the best at ``alpha`` after Holm's correction) or ``-`` (significantly worse);
    ``n/a`` (rank NaN) in a cell with fewer than 2 seeds where every algorithm has a value.
    """
    scores_of = frame_indicators(frame)
    indicators = tuple(scores_of.lower_better) if indicators is None else indicators
    rows = []
    for (family, n_var), cell in frame.groupby(["family", "n_var"], sort=True):
        scores = cell.pivot_table(index="seed", columns="algorithm", values=scores_of.rank, aggfunc="first")
        complete = scores.dropna(axis=0, how="any")
        test = (friedman_holm(complete, lower_better=scores_of.lower_better[scores_of.rank], alpha=alpha)
                if len(complete) >= 2 and complete.shape[1] >= 2 else None)  # else no ranks: too few paired seeds
        for algorithm, runs in cell.groupby("algorithm", sort=False):
            rows.append({"family": family, "n_var": n_var, "algorithm": algorithm,
                         **{name: _cell(runs[name]) for name in indicators},
                         "mean_rank": float(test.mean_ranks.get(algorithm, np.nan)) if test else float("nan"),
                         "mark": test.mark(algorithm) if test else "n/a",
                         "friedman_p": test.p_value if test else float("nan"), "runs": len(runs)})
    return pd.DataFrame(rows).sort_values(["family", "n_var", "mean_rank"], kind="stable").reset_index(drop=True)


def performance_profile(frame: pd.DataFrame, indicator: str | None = None,
                        taus: Sequence[float] = tuple(np.geomspace(1, 100, 60))) -> pd.DataFrame:
    """Dolan & More's performance profile: share of (instance, seed) pairs an algorithm solves within tau x the best.

    The ratio of an algorithm on a pair is its ``indicator`` (default: the profile indicator of the
    frame's set, :func:`frame_indicators`) over the pair's best (lower is better; a missing value
    counts as never within). Returns one column per algorithm, indexed by tau.
    """
    indicator = frame_indicators(frame).profile if indicator is None else indicator
    keys = ["family", "n_var", "instance_seed", "seed"]
    table = frame.pivot_table(index=keys, columns="algorithm", values=indicator, aggfunc="first")
    best = table.min(axis=1)
    ratio = table.div(best.where(best > 0), axis=0)
    return pd.DataFrame({name: [(ratio[name] <= tau).mean() for tau in taus] for name in table.columns},
                        index=pd.Index(taus, name="tau"))


def convergence(records: Iterable[dict]) -> pd.DataFrame:
    """The records' indicators against the current fronts at each checkpoint and at the end of the run.

    One row per record and checkpoint (``checkpoints`` of a suite run: the non-dominated feasible
    objective vectors at the first generation past each of
    :data:`~pymoo_rail.experiments.runner.CHECKPOINTS_EVAL` evaluations), and one for its final front
    at its ``n_eval``: family, n_var, algorithm, seed, n_eval, ``target_n_eval`` and the record's
    scores (:attr:`FrontScorer.indicators`; for one objective the best feasible energy found so far).
    ``target_n_eval`` is the checkpoint a row stands for (the final row's: the budget's evaluations),
    so runs whose generations end at other evaluation counts share a row of the figure.
    """
    records = list(records)
    scorers, rows = _scorers(records), []
    for record in records:
        scorer = scorers[tuple(sorted(record["problem"].items()))]
        checkpoints = record.get("checkpoints") or {"target_n_eval": [], "n_eval": [], "F": []}
        cell = {"family": scorer.problem.family, "n_var": int(scorer.problem.n_var),
                "algorithm": record["algorithm_label"], "seed": int(record["seed"])}
        rows += [{**cell, "n_eval": int(n_eval), "target_n_eval": int(target), **scorer.score(F)}
                 for target, n_eval, F in zip(checkpoints["target_n_eval"], checkpoints["n_eval"], checkpoints["F"])
                 if n_eval < record["n_eval"]]
        budget = int((record.get("budget") or {}).get("n_eval", record["n_eval"]))
        rows.append({**cell, "n_eval": int(record["n_eval"]), "target_n_eval": budget,
                     **baseline_indicators(record, scorer=scorer)})
    return pd.DataFrame(rows)


def _form(families: pd.Series) -> pd.Series:
    """Each family's form, the last part of its name (``generated-metro-bi`` -> ``bi``)."""
    return families.str.rsplit("-", n=1).str[-1]


def rank_by_dimension(table: pd.DataFrame) -> pd.DataFrame:
    """How the ranking changes with the dimension: each algorithm's Friedman mean rank averaged over
    the families of the same form (``-bi``, ``-3obj``, ...), per ``n_var``.

    ``table``: :func:`baseline_table`. One row per (form, algorithm), one column per ``n_var``; a cell
    without ranks (fewer than 2 paired seeds) stays NaN. Sorted by form, then by the mean rank at the
    largest ``n_var``.
    """
    ranks = table.assign(form=_form(table["family"]),
                         mean_rank=pd.to_numeric(table["mean_rank"], errors="coerce"))
    # NaN unless every family of the form has ranks there: a mean over some families would mislead
    out = ranks.pivot_table(index=["form", "algorithm"], columns="n_var", values="mean_rank", dropna=False,
                            aggfunc=lambda r: r.mean() if r.notna().all() else np.nan)
    out.columns = [f"n_var {int(n)}" for n in out.columns]
    return out.sort_values(["form", out.columns[-1]]).round(2).reset_index()


def top_group_by_dimension(table: pd.DataFrame) -> pd.DataFrame:
    """Where each algorithm wins, per form and ``n_var``: ``"best / top"``, the number of families in
    which it has the lowest mean rank (mark ``best``) and in which it is not significantly worse than
    that best (mark ``best`` or ``=``, Holm-corrected), out of the form's families with ranks there.

    ``table``: :func:`baseline_table`. One row per (form, algorithm), one column per ``n_var``; ``"-"``
    where no family of the form has ranks at that ``n_var``. Sorted as :func:`rank_by_dimension`.
    """
    marks = table.assign(form=_form(table["family"]))
    marks = marks[marks["mark"].isin(["best", "=", "-"])]  # "n/a": too few paired seeds to rank
    counts = marks.assign(best=marks["mark"] == "best", top=marks["mark"].isin(["best", "="])).groupby(
        ["form", "algorithm", "n_var"])[["best", "top"]].sum()
    cells = (counts["best"].astype(str) + " / " + counts["top"].astype(str)).unstack("n_var")
    cells.columns = [f"n_var {int(n)}" for n in cells.columns]
    ranks = rank_by_dimension(table)  # its rows and columns, so the two tables line up
    cells = cells.reindex(pd.MultiIndex.from_frame(ranks[["form", "algorithm"]])).reindex(
        columns=[c for c in ranks.columns if c.startswith("n_var")])
    return cells.fillna("-").reset_index()


def leaders_by_checkpoint(history: pd.DataFrame, indicator: str) -> pd.DataFrame:
    """Who leads along the run: per form and checkpoint, in how many (family, n_var) cells each
    algorithm has the lowest median ``indicator`` over its seeds (tied algorithms each count).

    ``history``: :func:`convergence` (its ``target_n_eval``, the checkpoint a row stands for; the last
    is the budget). A cell counts at a checkpoint where some median is finite. One row per (form,
    algorithm), one column per checkpoint; sorted by form, then by the count at the budget (most first).
    """
    h = history.assign(form=_form(history["family"]))
    keys = ["form", "family", "n_var", "target_n_eval"]
    medians = h.groupby([*keys, "algorithm"])[indicator].median().dropna().reset_index()
    lead = medians[medians[indicator] == medians.groupby(keys)[indicator].transform("min")]
    counts = lead.groupby(["form", "algorithm", "target_n_eval"]).size().unstack("target_n_eval")
    rows = pd.MultiIndex.from_frame(h[["form", "algorithm"]].drop_duplicates().sort_values(["form", "algorithm"]))
    checkpoints = sorted(h["target_n_eval"].unique())
    counts = counts.reindex(index=rows, columns=checkpoints).fillna(0).astype(int)
    counts.columns = [f"{int(n):,} evals" for n in checkpoints]
    counts = counts.reset_index()
    return counts.sort_values(["form", counts.columns[-1]], ascending=[True, False], kind="stable").reset_index(drop=True)


def report_values(study, full, frame: pd.DataFrame, records: Sequence[dict], pictures: Sequence[str],
                  command: str, study_file: str, history: pd.DataFrame) -> dict[str, str]:
    """The values of a baseline report's template: what ran (``study``, cut from ``full``), its CPU,
    the table (:func:`baseline_table`), the fronts scored against, who leads at each checkpoint of
    ``history`` (:func:`convergence`, :func:`leaders_by_checkpoint` on the rank indicator) and the
    figures (``pictures``, file names)."""
    table = baseline_table(frame)
    table["friedman_p"] = table["friedman_p"].map(lambda p: f"{p:.2g}")
    reduced = (len(study.problems), len(study.seeds), study.budget) != (len(full.problems), len(full.seeds), full.budget)
    return {"reduced": " (reduced run: not the whole table of the study file)" if reduced else "",
            "command": command, "study_file": study_file,
            "cells": str(frame.groupby(["family", "n_var"]).ngroups), "algorithms": str(len(study.algorithms)),
            "seeds": str(len(study.seeds)), "budget_kind": study.budget.kind, "budget": f"{study.budget.value:,}",
            "runs": str(len(frame)), "cpu_min": f"{frame['cpu_time_s'].sum() / 60:.1f}",
            "cpu_mean": f"{frame['cpu_time_s'].mean():.2f}",
            "indicators": ", ".join(frame_indicators(frame).lower_better),
            "table": to_markdown(table, bold_marker=None), "fronts": fronts_statement(front_versions(records)),
            "ranks": to_markdown(rank_by_dimension(table), bold_marker=None),
            "top_group": to_markdown(top_group_by_dimension(table), bold_marker=None),
            "leaders": to_markdown(leaders_by_checkpoint(history, frame_indicators(frame).rank), bold_marker=None),
            "checkpoints_kb": checkpoints_kb(records), "pictures": "\n".join(f"![{n}]({n})" for n in pictures)}


def cut_study(study, families=None, ladder=None, seeds: int | None = None, n_eval: int | None = None):
    """``study`` cut to the families and dimensions (n_var) asked for, seeds 1..``seeds`` and ``n_eval`` per run.

    ``None`` (or empty) keeps the study's own. Raises ``SystemExit`` naming the cut when no problem is left.
    """
    problems = [p for p in study.problems if (not families or p.params["family"] in families)
                and (not ladder or p.params["n_var"] in ladder)]
    if not problems:
        raise SystemExit(f"--families {families} --ladder {ladder}: no problem of the study {study.name} left")
    study = replace(study, problems=tuple(problems))
    if seeds:
        study = replace(study, seeds=tuple(range(1, seeds + 1)))
    return replace(study, budget=Budget("n_eval", n_eval)) if n_eval else study


def cpu_per_evaluation_ms(frame: pd.DataFrame) -> pd.DataFrame:
    """Median CPU milliseconds per evaluation of the stored runs, one row per algorithm, one column per n_var.

    The median over the families and seeds of each (algorithm, n_var) keeps out the first run of a
    process, which pays the compilation (the input of :func:`projected_cpu_h`).
    """
    return _median_ms(frame).unstack("n_var")


def _median_ms(frame: pd.DataFrame, keys: Sequence[str] = ("algorithm", "n_var")) -> pd.Series:
    ms = frame.assign(ms=1000.0 * frame["cpu_time_s"] / frame["n_eval"])
    return ms.groupby(list(keys))["ms"].median()


def projected_cpu_h(frame: pd.DataFrame, full, per_family: bool = False) -> tuple[float, str]:
    """CPU hours of the ``full`` study from measured CPU per evaluation (linear in n_var between measured sizes).

    Per algorithm (``per_family``: per algorithm and family, for a study whose families' costs differ
    much, as the ``-single`` and ``-trip`` forms do; a family not measured takes the algorithm's), the median over the stored runs (all families
    and seeds) of the CPU seconds per evaluation, taken per n_var and interpolated (held constant
    outside the measured range), then multiplied by the full study's evaluations, problems and
    seeds. The median keeps out the first run of a process, which pays the compilation. Returns the
    hours and the measured sizes.
    """
    per_eval = _median_ms(frame) / 1000.0
    per_family_eval = _median_ms(frame, ("algorithm", "family", "n_var")) / 1000.0
    total_s = 0.0
    for a in full.algorithms:
        if a.display not in per_eval.index.get_level_values(0):
            raise SystemExit(f"--estimate: no stored run of {a.display}")
        for p in full.problems:
            key = (a.display, p.params["family"])
            known = per_family_eval.loc[key] if per_family and key in per_family_eval.index.droplevel(2) \
                else per_eval.loc[a.display]
            total_s += float(np.interp(p.params["n_var"], known.index, known.to_numpy()))
    sizes = ", ".join(str(n) for n in sorted(frame["n_var"].unique()))
    return total_s * full.budget.value * len(full.seeds) / 3600, sizes


def archive_records(work: str | Path, path: str | Path, top: str = "suite_baseline") -> str:
    """Pack the study file and every record of the study folder ``work`` into ``path`` (.tar.gz, under ``top``/).

    The archive is written beside ``path`` and moved there when complete, so an interrupted call leaves
    no partial archive under that name. Returns the archive's SHA-256 (hex).
    """
    work, path = Path(work), Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    partial = path.with_name(path.name + ".partial")
    digest = hashlib.sha256()
    try:
        with tarfile.open(partial, "w:gz") as tar:
            for member in sorted(p for p in work.rglob("*") if p.is_file() and p.suffix in (".json", ".toml")):
                tar.add(member, arcname=str(Path(top) / member.relative_to(work)))
        with partial.open("rb") as packed:  # in chunks: a whole table's archive is gigabytes
            for chunk in iter(lambda: packed.read(1 << 20), b""):
                digest.update(chunk)
        os.replace(partial, path)
    finally:
        partial.unlink(missing_ok=True)
    return digest.hexdigest()


__all__ = ["INDICATORS", "RANK_INDICATOR", "EXACT_RESOLUTION_PCT", "EXACT_FRONT_VERSION", "IndicatorSet",
           "MULTI_OBJECTIVE", "ONE_OBJECTIVE", "indicator_set", "frame_indicators", "one_objective_optimum",
           "instance_of", "FrontScorer", "front_scorer", "baseline_indicators",
           "indicator_frame", "front_versions", "fronts_statement", "checkpoints_kb", "baseline_table",
           "performance_profile", "convergence", "rank_by_dimension", "top_group_by_dimension", "leaders_by_checkpoint", "report_values", "cut_study", "cpu_per_evaluation_ms", "projected_cpu_h",
           "archive_records"]
