"""Statistics of a study: summaries per problem and algorithm, rank-sum tests, publishable tables.

Everything here takes the results frame of :func:`pymoo_rail.experiments.load_results` (one
row per run, one column per indicator) and returns pandas objects, so the tables can be
reshaped further; :func:`write_tables` writes the usual set as CSV and Markdown.

Tests: Wilcoxon's rank-sum test (the two-sample Mann-Whitney U test), two-sided, exact for
small samples without ties (scipy chooses), of each algorithm against a baseline on each
problem and indicator. A verdict ``+`` means significantly better than the baseline at level
``alpha``, ``-`` significantly worse, ``=`` no significant difference; "better" follows the
indicator's direction (lower IGD, higher HV, ...) and the side of the U statistic.

Ranks over several algorithms run on the same seeds (:func:`friedman_holm`): Friedman's test over
the algorithms with the seeds as blocks, mean ranks, then Wilcoxon's signed-rank test on every
pair (paired by seed) with Holm's step-down correction of the p-values (Demsar (2006),
"Statistical comparisons of classifiers over multiple data sets"; Garcia & Herrera (2008)).
"""

from __future__ import annotations

from dataclasses import dataclass
from itertools import combinations
from pathlib import Path
from typing import Mapping, Sequence

import numpy as np
import pandas as pd

from pymoo_rail.experiments.metrics import LOWER_IS_BETTER, gd_van_veldhuizen, normalised_hv
from pymoo_rail.experiments.results import indicator_columns

STATS = ("min", "mean", "median", "max", "std")


def _check_indicators(results: pd.DataFrame, indicators: Sequence[str] | None) -> list[str]:
    if indicators is None:
        indicators = indicator_columns(results)
    for name in indicators:
        if name not in results.columns:
            raise ValueError(f"indicator {name!r} is not in the results (present: {', '.join(indicator_columns(results))})")
    return list(indicators)


def lower_is_better(indicator: str) -> bool:
    """Direction of an indicator (unknown names are taken as 'lower is better')."""
    return LOWER_IS_BETTER.get(indicator, True)


def summarize(results: pd.DataFrame, indicators: Sequence[str] | None = None,
              stats: Sequence[str] = STATS) -> pd.DataFrame:
    """Min / mean / median / max / std of each indicator per problem and algorithm.

    Returns a frame indexed by (problem, algorithm) with columns (indicator, statistic) and a
    column ``("runs", "n")``: the number of runs. ``std`` is the sample standard deviation
    (n - 1). Runs where an indicator does not apply are left out of that indicator's figures;
    ``(indicator, "n")`` says how many runs it covers when that differs from ``runs``.
    """
    indicators = _check_indicators(results, indicators)
    grouped = results.groupby(["problem", "algorithm"], sort=True)
    parts = {("runs", "n"): grouped.size()}
    for name in indicators:
        agg = grouped[name].agg(list(stats))
        for stat in stats:
            parts[(name, stat)] = agg[stat]
        counts = grouped[name].count()
        if not counts.equals(parts[("runs", "n")]):
            parts[(name, "n")] = counts
    frame = pd.DataFrame(parts)
    frame.columns = pd.MultiIndex.from_tuples(frame.columns, names=["indicator", "statistic"])
    return frame


def rank_sum(sample: Sequence[float], baseline: Sequence[float], lower_better: bool = True,
             alpha: float = 0.05) -> tuple[float, float, str]:
    """Wilcoxon rank-sum test of ``sample`` against ``baseline``: ``(U, p, verdict)``.

    ``U`` counts the pairs where the sample value exceeds the baseline value (ties count 1/2).
    The verdict is ``"+"`` (sample significantly better), ``"-"`` (worse), ``"="`` (no
    significant difference), or ``"n/a"`` when a side has fewer than 2 values (U and p NaN).
    """
    from scipy.stats import mannwhitneyu

    a = np.asarray(sample, dtype=float)
    b = np.asarray(baseline, dtype=float)
    a, b = a[np.isfinite(a)], b[np.isfinite(b)]
    if len(a) < 2 or len(b) < 2:
        return float("nan"), float("nan"), "n/a"
    if np.all(a == a[0]) and np.all(b == a[0]):
        return len(a) * len(b) / 2.0, 1.0, "="
    u, p = mannwhitneyu(a, b, alternative="two-sided")
    u, p = float(u), float(p)
    if p >= alpha:
        return u, p, "="
    sample_larger = u > len(a) * len(b) / 2.0
    better = (not sample_larger) if lower_better else sample_larger
    return u, p, "+" if better else "-"


def compare_means(sample: Sequence[float], baseline: Sequence[float],
                  lower_better: bool = True) -> tuple[bool, float, float] | None:
    """Whether ``sample``'s mean beats ``baseline``'s, by how much, and the rank-sum p of the difference.

    Returns
    -------
    (bool, float, float) or None
        (sample's mean better, (mean sample - mean baseline) / |mean baseline| in percent (NaN for a
        zero baseline mean), two-sided p of :func:`rank_sum`); None when a side has fewer than 2 values.
    """
    a, b = np.asarray(sample, dtype=float), np.asarray(baseline, dtype=float)
    if len(a) < 2 or len(b) < 2:
        return None
    better = a.mean() < b.mean() if lower_better else a.mean() > b.mean()
    rel = (a.mean() - b.mean()) / abs(b.mean()) * 100 if b.mean() != 0 else float("nan")
    return bool(better), float(rel), rank_sum(a, b)[1]


def describe_comparison(result: tuple[bool, float, float], alpha: float = 0.05) -> str:
    """A :func:`compare_means` result in words: ``better (-11.5 %, p = 3e-11)``, ``worse (...)`` or
    ``no significant difference (...)`` (p >= ``alpha``); differences under 1 % get two decimals."""
    better, rel, pval = result
    word = "no significant difference" if pval >= alpha else "better" if better else "worse"
    return f"{word} ({signed_percent(rel)}, p = {pval:.2g})"


def signed_percent(rel: float) -> str:
    """A relative difference in percent with its sign: two decimals under 1 %, one above."""
    return f"{rel:+.2f} %" if abs(rel) < 1.0 else f"{rel:+.1f} %"


def median_run(rows: Sequence[Mapping], problem: str, algorithm: str, key: str = "hv_ref",
               lower_better: bool = False) -> Mapping:
    """The run of ``algorithm`` on ``problem`` with the median ``key``, among per-run dicts.

    Runs are ordered best first (NaN last, ties by seed); for an even count the better of the two
    middle runs is returned. Each row needs ``problem``, ``algorithm``, ``seed`` and ``key``.
    """
    runs = sorted((r for r in rows if r["problem"] == problem and r["algorithm"] == algorithm),
                  key=lambda r: ((r[key] if lower_better else -r[key]) if np.isfinite(r[key]) else np.inf, r["seed"]))
    if not runs:
        raise ValueError(f"rows: no run of algorithm {algorithm!r} on problem {problem!r}")
    return runs[(len(runs) - 1) // 2]


def rank_sum_tests(results: pd.DataFrame, baseline: str, indicators: Sequence[str] | None = None,
                   alpha: float = 0.05) -> pd.DataFrame:
    """Each algorithm against ``baseline`` on each problem and indicator (see :func:`rank_sum`).

    Columns: problem, algorithm, indicator, n, n_baseline, median, median_baseline, U, p_value,
    verdict.
    """
    indicators = _check_indicators(results, indicators)
    algorithms = sorted(results["algorithm"].unique())
    if baseline not in algorithms:
        raise ValueError(f"baseline {baseline!r} is not among the algorithms ({', '.join(algorithms)})")
    rows = []
    for problem_name, group in results.groupby("problem", sort=True):
        base = group[group["algorithm"] == baseline]
        for algorithm_name in algorithms:
            if algorithm_name == baseline:
                continue
            other = group[group["algorithm"] == algorithm_name]
            if other.empty:
                continue
            for name in indicators:
                a, b = other[name].dropna().to_numpy(float), base[name].dropna().to_numpy(float)
                if len(a) == 0 and len(b) == 0:
                    continue  # the indicator does not apply to this problem
                u, p, verdict = rank_sum(a, b, lower_is_better(name), alpha)
                rows.append({"problem": problem_name, "algorithm": algorithm_name, "indicator": name,
                             "n": len(a), "n_baseline": len(b),
                             "median": float(np.median(a)) if len(a) else np.nan,
                             "median_baseline": float(np.median(b)) if len(b) else np.nan,
                             "U": u, "p_value": p, "verdict": verdict})
    return pd.DataFrame(rows, columns=["problem", "algorithm", "indicator", "n", "n_baseline", "median",
                                       "median_baseline", "U", "p_value", "verdict"])


def indicator_table(results: pd.DataFrame, indicator: str, baseline: str | None = None, alpha: float = 0.05,
                    digits: int = 4) -> pd.DataFrame:
    """The table papers print: problems x algorithms, cells ``mean (std)``.

    With a baseline, each other cell ends in the rank-sum verdict ``+``, ``-`` or ``=``. The best
    mean per problem is marked with ``*`` (Markdown bold in :func:`write_tables`). A cell whose
    runs have no value of the indicator says why (``n/a: no true front: ...``, the reason the runs
    recorded): no problem or algorithm is dropped from the table.
    """
    _check_indicators(results, [indicator])
    lower = lower_is_better(indicator)
    tests = rank_sum_tests(results, baseline, [indicator], alpha) if baseline else None
    table = {}
    for problem_name, group in results.groupby("problem", sort=True):
        stats = group.groupby("algorithm")[indicator].agg(["mean", "std", "count"])
        row = {name: "n/a: " + missing_reason(group[group["algorithm"] == name], indicator)
               for name in stats.index[stats["count"] == 0]}
        stats = stats[stats["count"] > 0]
        table[problem_name] = row
        if stats.empty:
            continue
        best = stats["mean"].idxmin() if lower else stats["mean"].idxmax()
        for algorithm_name, s in stats.iterrows():
            std = f"{s['std']:.{digits}g}" if s["count"] > 1 else "-"
            cell = f"{s['mean']:.{digits}g} ({std})"
            if tests is not None and algorithm_name != baseline:
                hit = tests[(tests["problem"] == problem_name) & (tests["algorithm"] == algorithm_name)]
                if len(hit):
                    cell += f" {hit['verdict'].iloc[0]}"
            if algorithm_name == best:
                cell = "*" + cell
            row[algorithm_name] = cell
    frame = pd.DataFrame.from_dict(table, orient="index")
    frame.index.name = "problem"
    columns = sorted(frame.columns)
    if baseline in columns:
        columns.remove(baseline)
        columns.insert(0, baseline)
    return frame[columns].fillna("")


def missing_reason(runs: pd.DataFrame, indicator: str) -> str:
    """Why ``runs`` (rows of a results frame) have no value of ``indicator``, in the runs' own words."""
    reasons: list[str] = []
    for notes in runs.get("unavailable", pd.Series(dtype=object)):
        reason = notes.get(indicator) if isinstance(notes, dict) else None
        if reason and reason not in reasons:
            reasons.append(reason)
    if not reasons:
        return "not computed for these runs (records written before the reason was stored)"
    return "; ".join(reasons)


def verdict_counts(tests: pd.DataFrame) -> pd.DataFrame:
    """How often each algorithm is better / equal / worse than the baseline, per indicator."""
    if tests.empty:
        return pd.DataFrame(columns=["+", "=", "-"])
    counts = tests.groupby(["algorithm", "indicator"])["verdict"].value_counts().unstack(fill_value=0)
    for column in ("+", "=", "-"):
        if column not in counts.columns:
            counts[column] = 0
    return counts[["+", "=", "-"]]


# ------------------------------------------------------------------- reference indicators


def nondominated(F: np.ndarray) -> np.ndarray:
    """The non-dominated rows of ``F`` (duplicates kept once)."""
    from pymoo.util.nds.non_dominated_sorting import NonDominatedSorting

    F = np.unique(np.asarray(F, dtype=float), axis=0)
    if len(F) == 0:
        return F
    return F[NonDominatedSorting().do(F, only_non_dominated_front=True)]


def reference_fronts(results: pd.DataFrame) -> dict[str, np.ndarray]:
    """Per problem, the non-dominated union of every run's feasible final front.

    The usual reference when the true front is unknown (rail problems): the best front the
    study found. Indicators against it compare the algorithms of *this* study only.
    """
    out = {}
    for problem_name, group in results.groupby("problem", sort=True):
        fronts = [F[CV <= 0] for F, CV in zip(group["F"], group["CV"]) if len(F)]
        fronts = [F for F in fronts if len(F)]
        if fronts:
            out[problem_name] = nondominated(np.vstack(fronts))
    return out


def add_reference_indicators(results: pd.DataFrame, references: Mapping[str, np.ndarray] | None = None,
                             problems: Sequence[str] | None = None) -> pd.DataFrame:
    """Add ``igd_ref``, ``gd_ref`` and ``hv_ref``: indicators against a reference front.

    Parameters
    ----------
    results : DataFrame with fronts (``load_results(..., fronts=True)``).
    references : mapping problem -> front (n, m), optional
        Default: :func:`reference_fronts`, the non-dominated union of the study's fronts.
    problems : sequence of str, optional
        Problems to treat (default: the multi-objective ones without a true-front ``igd``).

    ``hv_ref`` is normalised by the reference front's ideal and nadir points with the reference
    point 1.1 (as ``hv``); ``gd_ref`` is pymoo's (mean-distance) GD. A copy is returned.
    """
    from pymoo.indicators.gd import GD
    from pymoo.indicators.igd import IGD

    if "F" not in results.columns:
        raise ValueError("results have no fronts: load them with load_results(..., fronts=True)")
    references = dict(reference_fronts(results) if references is None else references)
    if problems is None:
        multi = results[results["n_obj"] >= 2]
        has_true = set(multi.loc[multi["igd"].notna(), "problem"]) if "igd" in multi.columns else set()
        problems = sorted(set(multi["problem"]) - has_true)
    out = results.copy()
    for column in ("igd_ref", "gd_ref", "hv_ref"):
        if column not in out.columns:
            out[column] = np.nan
    for index, row in out.iterrows():
        if row["problem"] not in problems or row["problem"] not in references:
            continue
        ref = np.asarray(references[row["problem"]], dtype=float)
        F = row["F"][row["CV"] <= 0]
        if len(F) == 0:
            continue
        out.at[index, "igd_ref"] = float(IGD(ref)(F))
        out.at[index, "gd_ref"] = float(GD(ref)(F))
        out.at[index, "hv_ref"] = normalised_hv(F, ref.min(axis=0), ref.max(axis=0))
    return out


def _energy_gap_function():
    """``pymoo_rail.indicators.energy.energy_gap`` when that part is installed, else None."""
    try:
        from pymoo_rail.indicators.energy import energy_gap
    except ImportError:
        return None
    return energy_gap


def add_energy_gap(results: pd.DataFrame, references: Mapping[str, pd.DataFrame]) -> pd.DataFrame:
    """Add the gap of each rail front to the exact optimal front.

    Columns: ``energy_gap`` (mean relative energy above the optimum at the same running time,
    over the front's points inside the reference's time range), ``energy_gap_max`` and
    ``hv_ratio`` (the front's hypervolume over the reference's).

    ``references`` maps a problem label to the optimal front of its case, a DataFrame with
    columns ``running_time_s`` and ``energy_kwh`` (``pymoo_rail.optimal.optimal_front``). Each
    run's front is taken from its stored ``running_time_s`` and ``energy_kwh`` per member, and
    compared with ``pymoo_rail.indicators.energy.energy_gap``. Problems without a reference,
    or runs without those extras, get no value. Raises ImportError when the indicator is not
    installed.
    """
    energy_gap = _energy_gap_function()
    if energy_gap is None:
        raise ImportError("energy_gap needs pymoo_rail.indicators.energy (the exact reference solver part)")
    out = results.copy()
    for column in ("energy_gap", "energy_gap_max", "hv_ratio"):
        if column not in out.columns:
            out[column] = np.nan
    for index, row in out.iterrows():
        reference = references.get(row["problem"])
        extras = row.get("extras") or {}
        if reference is None or "running_time_s" not in extras or "energy_kwh" not in extras:
            continue
        feasible = row["CV"] <= 0
        if not feasible.any():
            continue
        front = pd.DataFrame({"running_time_s": extras["running_time_s"][feasible],
                              "energy_kwh": extras["energy_kwh"][feasible]})
        gap = energy_gap(front, reference)
        out.at[index, "energy_gap"] = gap["mean_gap_rel"]  # mean relative energy above the optimum
        out.at[index, "energy_gap_max"] = gap["max_gap_rel"]
        out.at[index, "hv_ratio"] = gap["hv_ratio"]
    return out


# --------------------------------------------------------------------------------- tables


def _cell(value) -> str:
    if isinstance(value, float):
        if np.isnan(value):
            return ""
        return f"{value:.4g}"
    return str(value)


def to_markdown(frame: pd.DataFrame, bold_marker: str | None = "*") -> str:
    """A GitHub-flavoured Markdown table (no extra dependency). Cells starting with
    ``bold_marker`` are printed in bold without it."""
    flat = frame.reset_index() if frame.index.name or any(frame.index.names) else frame.copy()
    if isinstance(flat.columns, pd.MultiIndex):
        flat.columns = [" ".join(str(c) for c in col if str(c)) for col in flat.columns]
    header = [str(c) for c in flat.columns]
    lines = ["| " + " | ".join(header) + " |", "|" + "|".join("---" for _ in header) + "|"]
    for _, row in flat.iterrows():
        cells = []
        for value in row:
            text = _cell(value)
            if bold_marker and text.startswith(bold_marker):
                text = f"**{text[len(bold_marker):]}**"
            cells.append(text.replace("|", "\\|"))
        lines.append("| " + " | ".join(cells) + " |")
    return "\n".join(lines) + "\n"


def write_tables(results: pd.DataFrame, directory: str | Path, baseline: str | None = None,
                 indicators: Sequence[str] | None = None, alpha: float = 0.05) -> list[Path]:
    """Write the statistics of a study as CSV and Markdown into ``directory``.

    Files: ``summary.csv`` / ``summary.md`` (min / mean / median / max / std per problem and
    algorithm), ``<indicator>.md`` / ``.csv`` (mean (std) tables with verdicts), and with a
    baseline ``ranksum.csv`` / ``ranksum.md`` (every test) and ``verdicts.md`` (+/=/- counts).
    Returns the paths written.
    """
    from pymoo_rail.atomic import atomic_write_text

    directory = Path(directory)
    directory.mkdir(parents=True, exist_ok=True)
    indicators = _check_indicators(results, indicators)
    written = []

    def emit(name: str, text: str) -> None:
        written.append(atomic_write_text(directory / name, text))

    summary = summarize(results, indicators)
    emit("summary.csv", summary.to_csv())
    sections = []
    for name in indicators:
        if results[name].notna().any():
            part = summary[name].copy()
            part.insert(0, "n", summary[("runs", "n")] if "n" not in part.columns else part.pop("n"))
            sections.append(f"## {name}\n\n" + to_markdown(part, bold_marker=None))
    emit("summary.md", "# Summary over seeds (std: sample standard deviation)\n\n" + "\n".join(sections))
    for name in indicators:
        if results[name].notna().any():  # an indicator no run has is not a table of "n/a"
            table = indicator_table(results, name, baseline, alpha)
            emit(f"{name}.csv", table.to_csv())
            title = f"{name}: mean (std) over seeds" + (
                f"; vs {baseline}: + better, - worse, = no significant difference "
                f"(Wilcoxon rank-sum, alpha = {alpha})" if baseline else "") + "; best mean in bold\n\n"
            emit(f"{name}.md", title + to_markdown(table))
    if baseline is not None:
        tests = rank_sum_tests(results, baseline, indicators, alpha)
        emit("ranksum.csv", tests.to_csv(index=False))
        emit("ranksum.md", to_markdown(tests, bold_marker=None))
        emit("verdicts.md", to_markdown(verdict_counts(tests), bold_marker=None))
    return written


__all__ = ["summarize", "rank_sum", "median_run", "describe_comparison", "signed_percent", "rank_sum_tests", "indicator_table", "missing_reason", "verdict_counts", "reference_fronts",
           "add_reference_indicators", "add_energy_gap", "to_markdown", "write_tables", "nondominated",
           "gd_van_veldhuizen", "friedman_holm", "holm", "RankTest"]


def signed_rank_vs(sample: Sequence[float], reference: float, lower_better: bool = True,
                   alpha: float = 0.05) -> tuple[float, str]:
    """One-sample Wilcoxon signed-rank test of ``sample`` against a fixed ``reference`` value: ``(p, verdict)``.

    For results compared with an exact reference (e.g. a baseline computed once, not sampled).
    The verdict is ``"+"`` (sample significantly better than the reference), ``"-"`` (worse),
    ``"="``, or ``"n/a"`` with fewer than 2 finite values (p NaN).
    """
    from scipy.stats import wilcoxon

    a = np.asarray(sample, dtype=float)
    a = a[np.isfinite(a)]
    if len(a) < 2:
        return float("nan"), "n/a"
    d = a - float(reference)
    if np.all(d == 0):
        return 1.0, "="
    p = float(wilcoxon(d, alternative="two-sided").pvalue)
    if p >= alpha:
        return p, "="
    better = np.median(d) < 0 if lower_better else np.median(d) > 0
    return p, "+" if better else "-"


@dataclass(frozen=True)
class RankTest:
    """Friedman's test of several algorithms on the same seeds, mean ranks and Holm-corrected pairs.

    Attributes
    ----------
    statistic, p_value : float
        Friedman's chi-square and its p-value (NaN with fewer than 3 algorithms or 2 seeds).
    mean_ranks : pandas.Series
        Mean rank of each algorithm over the seeds (1 = best; ties share the mean rank), ascending.
    pairs : pandas.DataFrame
        One row per pair (``a``, ``b``): ``p`` the two-sided signed-rank p-value, ``p_holm`` after
        Holm's correction over all pairs, ``better`` the algorithm with the better median
        difference when ``p_holm < alpha`` (else empty).
    best : str
        The algorithm of the lowest mean rank.
    """

    statistic: float
    p_value: float
    mean_ranks: pd.Series
    pairs: pd.DataFrame
    best: str

    def mark(self, algorithm: str) -> str:
        """``"best"``, ``"="`` (not significantly different from the best) or ``"-"`` (significantly worse)."""
        if algorithm == self.best:
            return "best"
        row = self.pairs[((self.pairs["a"] == algorithm) & (self.pairs["b"] == self.best))
                         | ((self.pairs["b"] == algorithm) & (self.pairs["a"] == self.best))]
        return "-" if len(row) and row["better"].iloc[0] == self.best else "="


def _signed_rank_p(d: np.ndarray) -> float:
    from scipy.stats import wilcoxon

    return 1.0 if np.all(d == 0) else float(wilcoxon(d, alternative="two-sided").pvalue)


def holm(p_values: Sequence[float]) -> np.ndarray:
    """Holm's step-down adjusted p-values (statsmodels' ``multipletests(method="holm")``)."""
    from statsmodels.stats.multitest import multipletests

    p = np.asarray(p_values, dtype=float)
    return p.copy() if len(p) == 0 else multipletests(p, method="holm")[1]


def friedman_holm(scores: pd.DataFrame, lower_better: bool = True, alpha: float = 0.05) -> RankTest:
    """Friedman's test, mean ranks and Holm-corrected pairwise signed-rank tests of one indicator.

    Parameters
    ----------
    scores : pandas.DataFrame
        One row per seed (the blocks), one column per algorithm; a seed with any missing value
        is dropped (the tests are paired).
    lower_better : bool
        Direction of the indicator.
    alpha : float
        Level of the pairwise verdicts.
    """
    from scipy.stats import friedmanchisquare, rankdata

    if scores.shape[1] < 2:
        raise ValueError(f"scores: {scores.shape[1]} algorithm column(s); ranks need at least 2")
    if not 0 < alpha < 1:
        raise ValueError(f"alpha = {alpha!r} must lie in (0, 1)")
    table = scores.dropna(axis=0, how="any").astype(float)
    if len(table) < 2:
        raise ValueError(f"scores: {len(table)} seed(s) with every algorithm's value; ranks need at least 2")
    values = table.to_numpy() if lower_better else -table.to_numpy()
    ranks = pd.Series(rankdata(values, axis=1).mean(axis=0), index=table.columns).sort_values(kind="stable")
    if table.shape[1] >= 3 and np.ptp(values, axis=1).any():
        statistic, p_value = (float(v) for v in friedmanchisquare(*values.T))
    else:
        statistic, p_value = float("nan"), float("nan") if table.shape[1] < 3 else 1.0
    rows = []
    for a, b in combinations(table.columns, 2):
        d = values[:, table.columns.get_loc(a)] - values[:, table.columns.get_loc(b)]
        rows.append({"a": a, "b": b, "p": _signed_rank_p(d), "median_diff": float(np.median(d))})
    pairs = pd.DataFrame(rows)
    pairs["p_holm"] = holm(pairs["p"])
    pairs["better"] = [("" if r.p_holm >= alpha or r.median_diff == 0 else (r.a if r.median_diff < 0 else r.b))
                       for r in pairs.itertuples()]
    return RankTest(statistic, p_value, ranks, pairs.drop(columns="median_diff"), str(ranks.index[0]))
