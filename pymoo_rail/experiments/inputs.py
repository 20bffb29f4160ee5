"""The fingerprint of what a run's result depends on beyond its spec.

A run id (:attr:`RunSpec.run_id`) hashes the spec: problem and algorithm names and parameters,
seed and budget. The result also depends on things a spec only names:

- the case a rail problem loads (``case = "yizhuang"`` or a file path): its *content*, as
  loaded (so editing a comment changes nothing, editing a mass does);
- any other file a problem or algorithm parameter names (its bytes);
- the module of a ``"package.module:factory"`` spec (its source bytes);
- the versions of pymoo-rail and pymoo, whose code computes the result.

:func:`run_inputs` returns these as a flat dict of strings stored with each record;
:func:`changed_inputs` says, in words, what differs between a stored and a current fingerprint.
"""

from __future__ import annotations

import hashlib
import importlib.util
from pathlib import Path
from typing import Any

from pymoo_rail.experiments.spec import AlgorithmSpec, ProblemSpec, RunSpec, canonical_json


def _digest(data: bytes) -> str:
    return "sha256:" + hashlib.sha256(data).hexdigest()[:32]


def _case_digest(value: str) -> str:
    from pymoo_rail.cases import load_case
    from pymoo_rail.model import case_to_dict

    try:
        case = load_case(value)
    except Exception as err:  # noqa: BLE001 - the run itself will report the error
        return f"unreadable: {type(err).__name__}"
    return _digest(canonical_json(case_to_dict(case)).encode())


def _module_digest(path: str) -> str | None:
    module = path.partition(":")[0]
    try:
        found = importlib.util.find_spec(module)
    except (ImportError, ValueError):
        return None
    if found is None or not found.origin or not Path(found.origin).is_file():
        return None
    return _digest(Path(found.origin).read_bytes())


def spec_inputs(spec: ProblemSpec | AlgorithmSpec) -> dict[str, str]:
    """Digests of the case, files and module a problem or algorithm spec refers to."""
    kind = "problem" if isinstance(spec, ProblemSpec) else "algorithm"
    out: dict[str, str] = {}
    if ":" in spec.name:
        digest = _module_digest(spec.name)
        if digest is not None:
            out[f"{kind} module {spec.name.partition(':')[0]}"] = digest
    for key, value in spec.params.items():
        if not isinstance(value, str):
            continue
        if key == "case":
            out[f"{kind}.case ({value})"] = _case_digest(value)
        elif len(value) < 4096 and Path(value).is_file():
            out[f"{kind}.{key} file {value}"] = _digest(Path(value).read_bytes())
    return out


def versions_input() -> dict[str, str]:
    """Versions of the code that computes a result."""
    import pymoo

    import pymoo_rail

    return {"pymoo-rail version": pymoo_rail.__version__, "pymoo version": pymoo.__version__}


def run_inputs(run: RunSpec, cache: dict[Any, dict[str, str]] | None = None) -> dict[str, str]:
    """The fingerprint of ``run``'s inputs (see the module docstring).

    ``cache`` (a dict kept by the caller) avoids loading the same case once per seed.
    """
    cache = {} if cache is None else cache
    out = dict(versions_input())
    for spec in (run.problem, run.algorithm):
        key = canonical_json(spec.identity())  # holds the kind: {"problem": ...} or {"algorithm": ...}
        if key not in cache:
            cache[key] = spec_inputs(spec)
        out.update(cache[key])
    return out


def changed_inputs(stored: dict[str, str] | None, current: dict[str, str]) -> list[str]:
    """What differs between a stored fingerprint and the current one, in words (empty: nothing)."""
    if stored is None:
        return ["the record has no input fingerprint (written by an older pymoo-rail)"]
    reasons = []
    for key in sorted(set(stored) | set(current)):
        before, now = stored.get(key), current.get(key)
        if before == now:
            continue
        if before is None:
            reasons.append(f"{key} is new")
        elif now is None:
            reasons.append(f"{key} is no longer used")
        elif "version" in key:
            reasons.append(f"{key} changed from {before} to {now}")
        else:
            reasons.append(f"{key} changed since the run was stored")
    return reasons
