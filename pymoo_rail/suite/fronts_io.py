"""The suite's shipped fronts: verification against a fresh solve, and best-known fronts.

Certified fronts are shipped in ``pymoo_rail/suite/fronts/<case>-<key>.csv`` (the key holds the
case's content hash, see :mod:`pymoo_rail.optimal.reference`), so ``pareto_front()`` of a suite
problem reads them instead of solving. :func:`verify` solves again and fails on any drift beyond
the certificate. Forms without an exact front (``metro-a-4obj``) ship a *best-known* front: the
non-dominated union of long optimiser runs, labelled as such and versioned.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pandas as pd

from pymoo_rail.atomic import atomic_write_text
from pymoo_rail.optimal import reference
from pymoo_rail.suite.problems import CASES, METRO_4OBJ, METRO_4OBJ_OBJECTIVES, get_problem

BEST_KNOWN_VERSION = "3"
"""Version of the shipped best-known fronts (2: ``metro-a-4obj`` with ``encoding="braking_onset"``;
3: from seeds the sanity check does not use)."""
BEST_KNOWN_SEEDS = range(101, 106)
"""Seeds of the best-known front's runs: apart from the sanity check's (1-5), whose NSGA-II runs would
otherwise be the first generations of the very runs that made the front."""
FRONTS_DIR = reference.SHIPPED_DIR


def verify(names=None, progress: bool = True) -> pd.DataFrame:
    """Solve every shipped front again and compare, node by node.

    Parameters
    ----------
    names : sequence of str, optional
        Suite case names (default: all).
    progress : bool
        Show a progress bar (one step per case).

    Returns
    -------
    pandas.DataFrame
        One row per node: ``case``, ``requested_time_s``, ``shipped_kwh``, ``recomputed_kwh``,
        ``drift_kwh``, ``certificate_kwh`` and ``ok`` (drift within the certificate). A case whose
        shipped front is missing or was computed for other content gets one row with ``ok = False``
        and a ``problem`` message.
    """
    from tqdm import tqdm

    entries = [c for c in CASES if names is None or c.name in names]
    unknown = set(names or ()) - {c.name for c in CASES}
    if unknown:
        raise ValueError(f"suite cases {sorted(unknown)} are unknown (known: {', '.join(c.name for c in CASES)})")
    rows = []
    for entry in tqdm(entries, desc="verify fronts", unit="case", disable=not progress):
        case = entry.load()
        path = reference.find_front(case)
        if path is None or Path(path).parent != FRONTS_DIR:
            rows.append({"case": entry.name, "ok": False, "problem": "no shipped front for this case's content"})
            continue
        shipped = reference.CertifiedFront.read_csv(path)
        fresh = reference.compute_front(case, shipped.dx_m)
        a, b = shipped.table, fresh.table
        for k in range(len(a)):
            drift = abs(b["energy_kwh"][k] - a["energy_kwh"][k])
            slack = abs(b["running_time_s"][k] - a["running_time_s"][k]) * a["lambda_kwh_per_s"][k]
            rows.append({"case": entry.name, "requested_time_s": a["requested_time_s"][k],
                         "shipped_kwh": a["energy_kwh"][k], "recomputed_kwh": b["energy_kwh"][k],
                         "drift_kwh": drift, "certificate_kwh": a["energy_bound_kwh"][k] + slack,
                         "ok": bool(drift <= a["energy_bound_kwh"][k] + slack + 1e-9), "problem": ""})
    return pd.DataFrame(rows)


def ship_fronts(names=None, progress: bool = True, remove_old: bool = True) -> list[Path]:
    """Compute the certified front of every suite case and store it with the package.

    With ``remove_old`` the case's earlier shipped fronts (same content, older front version) are
    removed. Returns the paths written. Costs the exact solver's time: seconds per metro section, about a minute per
    48.5 km line.
    """
    from tqdm import tqdm

    entries = [c for c in CASES if names is None or c.name in names]
    written = []
    for entry in tqdm(entries, desc="ship fronts", unit="case", disable=not progress):
        case = entry.load()
        front = reference.compute_front(case)
        key = reference.front_key(case, front.dx_m, reference.n_times_for(case))
        path = FRONTS_DIR / f"{entry.name}-{key}.csv"
        for old in FRONTS_DIR.glob(f"{entry.name}-{reference.case_hash(case)[:16]}-*.csv") if remove_old else ():
            if old != path:
                old.unlink()
        atomic_write_text(path, front.to_csv_text())
        written.append(path)
    return written


def best_known_path(name: str = METRO_4OBJ) -> Path:
    """The file of the shipped best-known front of suite problem ``name``."""
    return FRONTS_DIR / f"{name}-best-known-v{BEST_KNOWN_VERSION}.csv"


def best_known_front(name: str = METRO_4OBJ) -> pd.DataFrame:
    """The best-known front of a suite problem without an exact one (labelled, versioned).

    Returns a DataFrame with one column per objective; ``attrs`` holds ``label`` ("best-known:
    non-dominated union of ... runs, not certified"), ``version``, ``case_hash``, ``encoding`` and
    ``time_window_s``. A shipped front computed for other case content, another encoding or another
    running-time window than the problem's raises ``ValueError`` naming both (recompute it with
    :func:`compute_best_known_front`).
    """
    path = best_known_path(name)
    if not path.is_file():
        raise FileNotFoundError(f"{name}: no best-known front shipped ({path.name}); "
                                f"compute one with pymoo_rail.suite.compute_best_known_front({name!r})")
    meta, table = reference.read_commented_csv(path)
    problem = get_problem(name)
    current = best_known_key(problem)
    for key, value in current.items():
        if meta.get(key) != value:
            raise ValueError(f"{path.name}: {key} = {meta.get(key)!r}, but {name} has {key} = {value!r}; "
                             f"recompute it with pymoo_rail.suite.compute_best_known_front({name!r}, write=True)")
    table.attrs.update(meta)
    return table


def best_known_key(problem) -> dict[str, str]:
    """What a best-known front belongs to: the case's content, the encoding and the running-time window."""
    window = problem.time_window_s
    return {"case_hash": reference.case_hash(problem.case), "encoding": problem.encoding.name,
            "time_window_s": "none" if window is None else f"{window[0]:.6f}-{window[1]:.6f}"}


def compute_best_known_front(name: str = METRO_4OBJ, seeds=BEST_KNOWN_SEEDS, pop_size: int = 100,
                             n_gen: int = 300, write: bool = False) -> pd.DataFrame:
    """Non-dominated union of NSGA-III and NSGA-II runs (feasible members) on a many-objective problem.

    Each seed runs both algorithms (pymoo's, default operators) for ``n_gen`` generations.
    ``write=True`` stores the result as the shipped best-known front. Not repeatable bit for bit:
    pymoo 0.6.2's NSGA-III gives another population from the same seed on each run (measured:
    three runs of seed 101 in one process), so the shipped file, not a recomputation, is the reference.
    """
    from pymoo.algorithms.moo.nsga2 import NSGA2
    from pymoo.algorithms.moo.nsga3 import NSGA3
    from pymoo.optimize import minimize
    from pymoo.util.nds.non_dominated_sorting import find_non_dominated
    from pymoo.util.ref_dirs import get_reference_directions

    if name != METRO_4OBJ:
        raise ValueError(f"name = {name!r}: only {METRO_4OBJ!r} has no exact front in the suite")
    problem = get_problem(name)
    seeds = list(seeds)
    ref_dirs = get_reference_directions("energy", problem.n_obj, pop_size, seed=1)
    points = []
    for seed in seeds:
        for algorithm in (NSGA3(ref_dirs=ref_dirs), NSGA2(pop_size=pop_size)):
            res = minimize(problem, algorithm, ("n_gen", n_gen), seed=seed)
            feasible = res.pop.get("CV")[:, 0] <= 0
            points.append(res.pop.get("F")[feasible])
    F = np.unique(np.vstack(points), axis=0)
    F = F[find_non_dominated(F)]
    table = pd.DataFrame(F, columns=list(METRO_4OBJ_OBJECTIVES)).sort_values("energy").reset_index(drop=True)
    label = (f"best-known: non-dominated union of the feasible final populations of NSGA-III and NSGA-II "
             f"(pymoo defaults, population {pop_size}, {n_gen} generations, seeds {seeds[0]}-{seeds[-1]}, "
             f"encoding {problem.encoding.name}); not certified")
    table.attrs.update(label=label, version=BEST_KNOWN_VERSION, **best_known_key(problem), runs=2 * len(seeds))
    if write:
        atomic_write_text(best_known_path(name), reference.commented_csv_text(table.attrs, table))
    return table
