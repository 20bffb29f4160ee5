"""Stored runs as a pandas DataFrame."""

from __future__ import annotations

import warnings
from pathlib import Path

import numpy as np
import pandas as pd

from pymoo_rail.experiments.inputs import changed_inputs, changed_keys, code_only, run_inputs
from pymoo_rail.experiments.spec import Study
from pymoo_rail.experiments.store import STUDY_FILE, ResultStore

BASE_COLUMNS = ("run_id", "problem", "algorithm", "seed", "budget", "n_var", "n_obj", "n_eval", "n_gen",
                "wall_time_s", "cpu_time_s", "feasible")


def _study_of(directory: Path, study: Study | None) -> Study | None:
    if study is not None:
        return study
    path = directory / STUDY_FILE
    if path.is_file():
        from pymoo_rail.experiments.study_file import read_study

        return read_study(path)
    return None


def load_records(directory: str | Path, study: Study | None = None, all_runs: bool = False,
                 trusted: bool = False, decisions: bool = True) -> list[dict]:
    """The stored records of a study directory.

    Parameters
    ----------
    directory : path
    study : Study, optional
        Keep the runs of this study and label them with its current labels. By default the
        directory's ``study.toml`` is used; records of runs the study no longer contains
        (e.g. after its parameters were edited) are left out unless ``all_runs``; so are records
        whose data inputs changed since they were stored (an edited case file), with a warning
        that says which: run the study again to redo them. Records computed by other code (another
        pymoo-rail source or library version) are kept, with one warning that says how many.
    all_runs : bool
        Return every record in the directory, with the labels stored in it (nothing is rebuilt
        or looked up).
    trusted : bool
        Allow a study that names code to import (``"module:callable"``): checking its records
        looks the module up, which imports its packages. Without it such a study is an
        :class:`~pymoo_rail.experiments.registry.UntrustedCodeError` naming the entry; nothing
        the folder names is imported.
    decisions : bool
        Keep each final front's decision vectors (``front["X"]``). ``False`` drops them once the
        record has passed its checks: they are most of a large study's records (a suite
        baseline table's report needs its objective vectors alone).

    Raises
    ------
    RecordError
        A record that fails its checks (names the file), including one of an older format.
    """
    from pymoo_rail.experiments.registry import check_trust

    directory = Path(directory)
    study = None if all_runs else _study_of(directory, study)
    store = ResultStore(directory)
    if study is None:
        return [_lean(record, decisions) for record in store.records()]
    check_trust(study, trusted)
    runs = {r.run_id: r for r in study.runs()}
    records = []
    other_code: list[str] = []
    cache: dict = {}
    for record in store.records(set(runs)):
        run = runs[record["run_id"]]
        current = run_inputs(run, cache)
        keys = changed_keys(record.get("inputs"), current)
        if keys and code_only(keys):
            other_code.append(f"{run.describe()}: {'; '.join(changed_inputs(record.get('inputs'), current))}")
        elif keys:
            warnings.warn(f"{store.path(run.run_id)} ({run.describe()}) left out: "
                          f"{'; '.join(changed_inputs(record.get('inputs'), current))}; "
                          "run the study again to redo it", stacklevel=2)
            continue
        record["problem_label"] = run.problem.display
        record["algorithm_label"] = run.algorithm.display
        records.append(_lean(record, decisions))
    if other_code:
        warnings.warn(f"{len(other_code)} of the records in {directory} were computed by other code (e.g. "
                      f"{other_code[0]}); they are shown as stored: run the study again to recompute them",
                      stacklevel=2)
    return records


def _lean(record: dict, decisions: bool) -> dict:
    """``record`` as it is, or without its front's decision vectors."""
    if not decisions:
        record["front"] = {key: value for key, value in record["front"].items() if key != "X"}
    return record


def records_frame(records: list[dict], fronts: bool = True) -> pd.DataFrame:
    """One row per run: ids, labels, budget, evaluations, times, one column per indicator and
    one per run counter.

    ``problem_spec`` and ``algorithm_spec`` hold the specs (dicts) the run was built from.
    With ``fronts``, the columns ``F`` and ``X`` hold the final front as arrays, ``extras`` a
    dict of per-member arrays (rail problems: ``energy_kwh``, ``running_time_s``,
    ``stop_error_m``) and ``history`` the per-generation dict of lists.
    Indicators that do not apply to a run are missing (NaN); ``unavailable`` holds why, per
    indicator (``{"igd": "no true front: ..."}``), as the run recorded it.
    """
    rows = []
    for r in records:
        budget_kind, budget_value = next(iter(r["budget"].items()))
        row = {"run_id": r["run_id"], "problem": r["problem_label"], "algorithm": r["algorithm_label"],
               "seed": r["seed"], "budget": f"{budget_kind}={budget_value}", "n_var": r["n_var"],
               "n_obj": r["n_obj"], "n_eval": r["n_eval"], "n_gen": r["n_gen"], "wall_time_s": r["wall_time_s"],
               "cpu_time_s": r.get("cpu_time_s", np.nan),  # records before cpu_time_s existed
               "feasible": r["feasible"], "problem_spec": r["problem"], "algorithm_spec": r["algorithm"]}
        row.update(r["indicators"])
        row["unavailable"] = dict(r.get("unavailable", {}))
        row.update({k: v for k, v in r.get("counters", {}).items() if k not in row})
        if fronts:
            if "X" not in r["front"]:
                raise ValueError(f"records_frame: run {r['run_id']} was loaded without its decision vectors "
                                 "(load_records(..., decisions=False)); pass fronts=False or load it with them")
            n_obj, n_var = r["n_obj"], r["n_var"]
            row["F"] = np.asarray(r["front"]["F"], dtype=float).reshape(-1, n_obj)
            row["X"] = np.asarray(r["front"]["X"], dtype=float).reshape(-1, n_var)
            row["CV"] = np.asarray(r["front"]["CV"], dtype=float)
            row["extras"] = {k: np.asarray(v, dtype=float) for k, v in r["front"].get("extras", {}).items()}
            row["history"] = r.get("history")
        rows.append(row)
    frame = pd.DataFrame(rows, columns=None if rows else list(BASE_COLUMNS))
    if len(frame):
        frame = frame.sort_values(["problem", "algorithm", "seed"], kind="stable").reset_index(drop=True)
    return frame


def load_results(directory: str | Path, study: Study | None = None, fronts: bool = True,
                 all_runs: bool = False, trusted: bool = False) -> pd.DataFrame:
    """The runs stored in a study directory as a DataFrame (see :func:`records_frame`).

    ``study``, ``all_runs`` and ``trusted`` are those of :func:`load_records`.

    >>> results = load_results("out/zdt")                                    # doctest: +SKIP
    >>> results.groupby(["problem", "algorithm"])["igd"].median()            # doctest: +SKIP
    """
    return records_frame(load_records(directory, study, all_runs, trusted), fronts=fronts)


def indicator_columns(results: pd.DataFrame) -> list[str]:
    """The indicator columns present in a results frame, in a fixed order."""
    from pymoo_rail.experiments.metrics import LOWER_IS_BETTER

    preferred = [c for c in LOWER_IS_BETTER if c in results.columns and c != "n_front"]
    return preferred
