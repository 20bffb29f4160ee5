"""Reference evaluations of the families: decision vectors and their F, G and H, frozen in a JSON file.

A port of a family to another language, or a later version of this package, proves that it computes
the same instances by evaluating the shipped vectors and comparing with the shipped ``F`` and ``G``
(:func:`check_reference_evaluations`). Each record names its instance (family, ``n_var``, seed)
and its checksum (:func:`pymoo_rail.suite.families.definition`): a record whose checksum no longer
matches the instance is a changed definition, not a numerical drift.
"""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pandas as pd

from pymoo_rail import __version__
from pymoo_rail.atomic import atomic_write_text
from pymoo_rail.suite.families import FAMILY_VERSION, get_family_problem, list_families

REFERENCE_PATH = Path(__file__).resolve().parent / "reference_evaluations.json"
REFERENCE_DIMENSIONS = (10, 100)
REFERENCE_SEED = 1
N_RANDOM_VECTORS = 2
OUTPUTS = ("F", "G", "H")
"""pymoo's objectives, inequality constraints (``<= 0``) and equality constraints (``= 0``; the trips' budget)."""
RTOL, ATOL = 1e-6, 1e-6
"""Agreement asked of a recomputation: the running time is a sum over thousands of grid cells and
the paced forms solve for a pace, so the last bits may differ between compilers and machines."""


def reference_vectors(xl: np.ndarray, xu: np.ndarray, rng_seed: int = 0) -> np.ndarray:
    """The vectors evaluated: the middle and both corners of the box, and :data:`N_RANDOM_VECTORS` uniform draws.

    The corners of the speed-code forms are infeasible (crawling at the floor is too slow for the
    window, the flat-out run too fast), so the constraints are checked too, not only the objectives.
    """
    rng = np.random.default_rng(rng_seed)
    return np.vstack([(xl + xu) / 2.0, xl, xu, rng.uniform(xl, xu, (N_RANDOM_VECTORS, xl.shape[0]))])


def compute_reference_evaluations(families=None, dimensions=REFERENCE_DIMENSIONS, seed: int = REFERENCE_SEED) -> dict:
    """Evaluate :func:`reference_vectors` on every family at each dimension; the content of the JSON file."""
    records = []
    for name in families or list_families():
        for n_var in dimensions:
            problem = get_family_problem(name, n_var, seed)
            X = reference_vectors(problem.xl, problem.xu)
            out = problem.evaluate(X, return_values_of=list(OUTPUTS), return_as_dictionary=True)
            records.append({"family": name, "n_var": int(n_var), "seed": int(seed), "checksum": problem.checksum,
                            "X": X.tolist(), **{key: out[key].tolist() for key in OUTPUTS}})
    return {"what": "pymoo_rail.suite reference evaluations: F, G and H of decision vectors X per family instance",
            "family_version": FAMILY_VERSION, "computed_by": f"pymoo_rail {__version__}",
            "rtol": RTOL, "atol": ATOL, "records": records}


def write_reference_evaluations(path: str | Path = REFERENCE_PATH, **kwargs) -> Path:
    """Compute and write the reference evaluations (atomically); returns the path."""
    data = compute_reference_evaluations(**kwargs)
    atomic_write_text(Path(path), json.dumps(data, indent=1) + "\n")
    return Path(path)


def check_reference_evaluations(path: str | Path = REFERENCE_PATH) -> pd.DataFrame:
    """Recompute every record of a reference file: one row per record with its deviations.

    Returns a DataFrame with ``family``, ``n_var``, ``seed``, ``checksum_ok``, ``max_abs_dev_F``,
    ``max_abs_dev_G``, ``max_abs_dev_H`` and ``ok`` (checksum equal and every value within
    ``rtol``/``atol`` of the file's).
    """
    data = json.loads(Path(path).read_text(encoding="utf-8"))
    rtol, atol = float(data["rtol"]), float(data["atol"])
    rows = []
    for record in data["records"]:
        problem = get_family_problem(record["family"], record["n_var"], record["seed"])
        out = problem.evaluate(np.asarray(record["X"], dtype=float), return_values_of=list(OUTPUTS),
                                return_as_dictionary=True)
        row = {"family": record["family"], "n_var": record["n_var"], "seed": record["seed"],
               "checksum_ok": problem.checksum == record["checksum"]}
        close = row["checksum_ok"]
        for key in OUTPUTS:
            expected = np.asarray(record[key], dtype=float).reshape(out[key].shape)
            row[f"max_abs_dev_{key}"] = float(np.max(np.abs(out[key] - expected), initial=0.0))
            close = close and bool(np.allclose(out[key], expected, rtol=rtol, atol=atol))
        rows.append({**row, "ok": close})
    return pd.DataFrame(rows)
