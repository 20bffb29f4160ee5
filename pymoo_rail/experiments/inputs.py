"""The fingerprint of what a run's result depends on beyond its spec, and the inputs it is computed from.

A run id (:attr:`RunSpec.run_id`) hashes the spec: problem and algorithm names and parameters,
seed and budget. The result also depends on things a spec only names:

- the case a rail problem loads (``case = "yizhuang"`` or a file path): its *content*, as
  loaded (so editing a comment changes nothing, editing a mass does). The case is loaded once,
  when the study starts (:func:`resolve_run`); its digest goes into the fingerprint and the
  loaded case itself is handed to the run, so a file edited while the study runs can never give
  a record computed on one content and labelled with another;
- any other file a problem or algorithm parameter names (its bytes);
- the definition checksum of a suite family instance (``problem = "suite_family"``), so a record
  computed on another definition of ``(family, n_var, seed)`` is redone. Not its front: a suite
  family run keeps raw objective vectors and computes nothing against the front
  (:func:`.runner.execute_run`); the report scores them against the front of its own time and
  states its version and :func:`front_digest`, so a better exact solver keeps every stored run;
- the module of a ``"package.module:factory"`` spec (its source bytes; looked up only when the
  study is trusted, since finding a module imports its parent packages);
- the code that computes the result: a digest of the package's own source and data files
  (:func:`package_digest`, computed once per process), and the versions of pymoo-rail, pymoo,
  numpy and numba. For a suite family instance the digest covers only the parts a run executes
  (:func:`code_parts`: :data:`SUITE_RUN_PARTS`, and :data:`TRIP_RUN_PARTS` for the ``-trip``
  families), so a commit elsewhere in the package (the exact solver, the controllers, the CLI,
  the plots) keeps the stored runs of a long study; every other problem keeps the digest of the
  whole package.

:func:`run_inputs` returns these as a flat dict of strings stored with each record;
:func:`changed_inputs` says, in words, what differs between a stored and a current fingerprint.
"""

from __future__ import annotations

import functools
import hashlib
import importlib.util
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, Mapping

import numpy as np

from pymoo_rail.experiments.metrics import true_front_and_reason
from pymoo_rail.experiments.registry import is_suite_family
from pymoo_rail.experiments.spec import AlgorithmSpec, ProblemSpec, RunSpec, canonical_json

# fingerprint keys that describe the code rather than the data of a run (see ``code_only``)
CODE_KEYS = ("pymoo-rail code", "pymoo-rail version", "pymoo version", "numpy version", "numba version")
# package files whose content computes a result: its code, built-in cases and shipped fronts
_PACKAGE_SUFFIXES = (".py", ".toml", ".csv", ".json")


def _digest(data: bytes) -> str:
    return "sha256:" + hashlib.sha256(data).hexdigest()[:32]


@dataclass(frozen=True)
class RunInputs:
    """What a run is computed from beyond its spec: the fingerprint, and the cases it names, loaded once.

    Attributes
    ----------
    fingerprint : dict of str
        Stored with the record (see the module docstring).
    cases : mapping
        The ``case`` value of the problem spec -> the :class:`~pymoo_rail.model.Case` whose
        content the fingerprint holds (empty when the spec names no case, or it did not load:
        the run then reports the loader's error).
    """

    fingerprint: Mapping[str, str]
    cases: Mapping[str, Any] = field(default_factory=dict)


def _load_case_once(value: str) -> tuple[str, Any]:
    """The digest of a case's content and the case itself (None when it does not load)."""
    from pymoo_rail.cases import load_case
    from pymoo_rail.model import case_to_dict

    try:
        case = load_case(value)
    except Exception as err:  # noqa: BLE001 - the run itself will report the error
        return f"unreadable: {type(err).__name__}", None
    return _digest(canonical_json(case_to_dict(case)).encode()), case


def _module_digest(path: str) -> str | None:
    module = path.partition(":")[0]
    try:
        found = importlib.util.find_spec(module)
    except (ImportError, ValueError):
        return None
    if found is None or not found.origin or not Path(found.origin).is_file():
        return None
    return _digest(Path(found.origin).read_bytes())


def front_digest(problem) -> str:
    """The digest of the content of the reference front the runs of ``problem`` are scored against.

    Stated by the baseline report (:func:`pymoo_rail.experiments.baseline.front_versions`), not in
    a suite run's fingerprint: its record holds raw objective vectors only.

    A front the exact solver certified counts as the file it is cached in (its nodes to 9
    significant digits, :meth:`~pymoo_rail.optimal.reference.CertifiedFront.to_csv_text`): the
    process that computes a front holds its nodes to the last bit, every later one reads them back
    from the cache, and both must give one digest. The ``-bi`` and ``-single`` fronts
    (``pareto_front()``) are computed from those nodes by code in :data:`SUITE_RUN_PARTS`. Any
    other front counts by its array as the run reads it (shape and float64 bytes): a ``-3obj``
    instance's inner points (cached to 17 digits, exact) next to its line's certified front, a
    trip's exact optimum. A problem without a front gives the reason instead.
    """
    pf, reason = true_front_and_reason(problem)
    if pf is None:
        return f"none: {reason}"
    pf = np.ascontiguousarray(pf, dtype=float)
    array = str(pf.shape).encode() + pf.tobytes()
    certified = getattr(problem, "certified_front", None)
    if not callable(certified):
        return _digest(array)
    nodes = certified().to_csv_text().encode()
    derived = len(problem.objectives) < 3  # -bi, -single: pareto_front() comes from the nodes
    return _digest(nodes if derived else nodes + b"\0" + array)


def _instance_inputs(params: Mapping[str, Any]) -> dict[str, str]:
    """The definition checksum of the suite family instance ``params`` name (or why it has none)."""
    from pymoo_rail.suite import get_problem

    try:
        instance = get_problem(params.get("family"), n_var=params.get("n_var"), seed=params.get("seed"))
    except Exception as err:  # noqa: BLE001 - the run itself will report the error
        return {"problem instance checksum": f"unbuildable: {type(err).__name__}"}
    return {"problem instance checksum": instance.checksum}


def resolve_spec(spec: ProblemSpec | AlgorithmSpec) -> RunInputs:
    """Digests of the case, files and module a problem or algorithm spec refers to, with the case loaded.

    Call it only for a trusted spec when the spec names an import path (see the module docstring).
    """
    kind = "problem" if isinstance(spec, ProblemSpec) else "algorithm"
    out: dict[str, str] = {}
    cases: dict[str, Any] = {}
    if ":" in spec.name:
        digest = _module_digest(spec.name)
        if digest is not None:
            out[f"{kind} module {spec.name.partition(':')[0]}"] = digest
    if kind == "problem" and is_suite_family(spec):
        out.update(_instance_inputs(spec.params))
    for key, value in spec.params.items():
        if not isinstance(value, str):
            continue
        if key == "case":
            out[f"{kind}.case ({value})"], case = _load_case_once(value)
            if case is not None:
                cases[value] = case
        elif len(value) < 4096 and Path(value).is_file():
            out[f"{kind}.{key} file {value}"] = _digest(Path(value).read_bytes())
    return RunInputs(out, cases)


def spec_inputs(spec: ProblemSpec | AlgorithmSpec) -> dict[str, str]:
    """Digests of the case, files and module a problem or algorithm spec refers to."""
    return dict(resolve_spec(spec).fingerprint)


# The parts of the package (paths relative to it, as package_digest takes them) whose code computes
# the numbers of a suite family run: the model and the simulator, the problem that evaluates an
# instance, the family definitions, the algorithms and indicators, and the runner's loop (building
# the problem and the algorithm, the penalty, the history and its checkpoints). Not in it, because
# a run never executes them or gets their output only as content fingerprinted on its own: cases
# (the generated line and train are in the instance checksum, by content), optimal (the planner's
# window and time tolerance are in the checksum; a run never reads the front: its record holds raw
# objective vectors, scored by the report against the front of its time), control (imported for a type; a suite instance has no tracker), journeys (for the -trip families
# only), suite's loggers and shipped files, cli, plotting and the other studies.
# tests/experiments/test_suite_fingerprint.py runs suite runs in a fresh interpreter and fails if
# a run executes code outside these parts that is not listed there with its reason.
SUITE_RUN_PARTS = (
    "constants.py", "model", "sim",
    "problems/__init__.py", "problems/lazy.py", "problems/speed_profile.py", "problems/objectives.py",
    "problems/reference.py", "problems/encodings",
    "suite/families.py", "suite/comfort.py", "suite/trips.py", "suite/identity.py", "suite/problems.py",
    "algorithms", "indicators",
    "experiments/runner.py", "experiments/registry.py", "experiments/spec.py", "experiments/penalty.py",
    "experiments/metrics.py", "experiments/fronts.py",
)
# a -trip family's problem is the journeys' running-time allocation problem
TRIP_RUN_PARTS = (*SUITE_RUN_PARTS, "journeys")


def code_parts(spec: ProblemSpec) -> tuple[str, ...] | None:
    """The package parts whose digest is a run's ``pymoo-rail code``: :data:`SUITE_RUN_PARTS` (or
    :data:`TRIP_RUN_PARTS`) for a suite family instance, None (the whole package) for any other problem.

    Named rail problems and the others keep the whole package: they reach cases, controllers or
    solvers in too many ways to list, and their studies are short.
    """
    if not is_suite_family(spec):
        return None
    from pymoo_rail.suite.families import family

    try:
        form = family(spec.params.get("family")).form
    except ValueError:  # an unknown family: the run reports it
        return SUITE_RUN_PARTS
    return TRIP_RUN_PARTS if form == "trip" else SUITE_RUN_PARTS


def in_parts(path: str, parts: tuple[str, ...] | None) -> bool:
    """True when ``path`` (relative to the package, ``/``-separated) is one of ``parts`` or inside
    one of them (None: the whole package)."""
    return parts is None or any(path == part or path.startswith(part.rstrip("/") + "/") for part in parts)


@functools.lru_cache(maxsize=8)
def package_digest(parts: tuple[str, ...] | None = None) -> str:
    """A digest of pymoo-rail's own source and data files (path and bytes of each, in path order).

    Computed once per process: a change to the code with the same version string still changes
    every fingerprint, so no record computed by other code is taken as current. ``parts`` limits
    it to these subpackages or files (paths relative to the package, e.g. ``("control", "sim")``).
    """
    import pymoo_rail

    root = Path(pymoo_rail.__file__).resolve().parent
    sha = hashlib.sha256()
    for path in sorted(p for p in root.rglob("*") if p.suffix in _PACKAGE_SUFFIXES and p.is_file()
                       and "__pycache__" not in p.parts and in_parts(p.relative_to(root).as_posix(), parts)):
        sha.update(path.relative_to(root).as_posix().encode() + b"\0")
        sha.update(hashlib.sha256(path.read_bytes()).digest())
    return "sha256:" + sha.hexdigest()[:32]


def versions_input(parts: tuple[str, ...] | None = None) -> dict[str, str]:
    """The code that computes a result: the package's source digest (of ``parts`` only, if given:
    :func:`package_digest`) and the library versions."""
    import numba
    import numpy
    import pymoo

    import pymoo_rail

    return {"pymoo-rail code": package_digest(parts), "pymoo-rail version": pymoo_rail.__version__,
            "pymoo version": pymoo.__version__, "numpy version": numpy.__version__,
            "numba version": numba.__version__}


def resolve_run(run: RunSpec, cache: dict[Any, RunInputs] | None = None) -> RunInputs:
    """The fingerprint of ``run``'s inputs and the cases they were computed from (see the module docstring).

    ``cache`` (a dict kept by the caller) loads each case once per study, so every seed of a
    problem runs on the same loaded case.
    """
    cache = {} if cache is None else cache
    fingerprint = dict(versions_input(code_parts(run.problem)))
    cases: dict[str, Any] = {}
    for spec in (run.problem, run.algorithm):
        key = canonical_json(spec.identity())  # holds the kind: {"problem": ...} or {"algorithm": ...}
        if key not in cache:
            cache[key] = resolve_spec(spec)
        fingerprint.update(cache[key].fingerprint)
        cases.update(cache[key].cases)
    return RunInputs(fingerprint, cases)


def run_inputs(run: RunSpec, cache: dict[Any, RunInputs] | None = None) -> dict[str, str]:
    """The fingerprint of ``run``'s inputs (see the module docstring and :func:`resolve_run`)."""
    return dict(resolve_run(run, cache).fingerprint)


def code_only(keys: list[str]) -> bool:
    """True when every changed fingerprint key describes the code (``CODE_KEYS``), not the data."""
    return bool(keys) and all(key in CODE_KEYS for key in keys)


def changed_keys(stored: Mapping[str, str] | None, current: Mapping[str, str]) -> list[str]:
    """The fingerprint keys whose values differ (every current key when nothing is stored)."""
    if stored is None:
        return sorted(current)
    return [key for key in sorted(set(stored) | set(current)) if stored.get(key) != current.get(key)]


def changed_inputs(stored: Mapping[str, str] | None, current: Mapping[str, str]) -> list[str]:
    """What differs between a stored fingerprint and the current one, in words (empty: nothing)."""
    if stored is None:
        return ["the record has no input fingerprint (written by an older pymoo-rail)"]
    reasons = []
    for key in changed_keys(stored, current):
        before, now = stored.get(key), current.get(key)
        if before is None:
            reasons.append(f"{key} is new")
        elif now is None:
            reasons.append(f"{key} is no longer used")
        elif "version" in key:
            reasons.append(f"{key} changed from {before} to {now}")
        elif key == "pymoo-rail code":
            reasons.append("the pymoo-rail code changed since the run was stored (same version string)")
        else:
            reasons.append(f"{key} changed since the run was stored")
    return reasons
