"""A study declared as data: problems x algorithms x seeds under one budget.

Problems and algorithms are named, not built: a spec holds a registry name (or an import path
``"package.module:factory"``) and keyword arguments that are plain TOML values. Any worker,
local or on a remote Dask cluster, rebuilds the same objects from the same spec, and the spec
round-trips through a TOML file unchanged.
"""

from __future__ import annotations

import hashlib
import json
import math
from dataclasses import dataclass, field
from typing import Any, Mapping

from pymoo_rail.model.errors import FieldError

BUDGET_KINDS = ("n_gen", "n_eval")


class StudyError(FieldError):
    """A study declaration holds a value that cannot be used; the message names field and value."""


def _plain(value: Any, where: str) -> Any:
    """A deep copy of ``value`` made only of TOML/JSON types (tuples become lists)."""
    if isinstance(value, bool) or isinstance(value, (int, str)):
        return value
    if isinstance(value, float):
        if not math.isfinite(value):
            raise StudyError(where, value, "must be a finite number")
        return value
    if isinstance(value, (list, tuple)):
        return [_plain(v, f"{where}[{i}]") for i, v in enumerate(value)]
    if isinstance(value, Mapping):
        out = {}
        for key, v in value.items():
            if not isinstance(key, str):
                raise StudyError(where, key, "keys must be strings")
            out[key] = _plain(v, f"{where}.{key}")
        return out
    # numpy scalars and the like
    if hasattr(value, "item") and callable(value.item):
        return _plain(value.item(), where)
    raise StudyError(where, value, f"must be a string, number, bool, list or table, not {type(value).__name__}")


def canonical_json(obj: Any) -> str:
    """Key-sorted, compact JSON: the same data always gives the same text (used for run ids)."""
    return json.dumps(obj, sort_keys=True, separators=(",", ":"), ensure_ascii=True)


@dataclass(frozen=True)
class _Spec:
    name: str
    params: Mapping[str, Any] = field(default_factory=dict)
    label: str | None = None

    _key = "?"  # the key naming the factory in a spec table ("problem" or "algorithm")

    def __post_init__(self) -> None:
        if not isinstance(self.name, str) or not self.name.strip():
            raise StudyError(self._key, self.name, "must be a non-empty name")
        if not isinstance(self.params, Mapping):
            raise StudyError(f"{self._key} parameters", self.params, "must be a mapping of keyword arguments")
        params = _plain(dict(self.params), f"{self.name}")
        for reserved in (self._key, "label"):
            if reserved in params:
                raise StudyError(f"{self.name}.{reserved}", params[reserved], "is reserved, not a parameter")
        object.__setattr__(self, "params", params)
        if self.label is not None and (not isinstance(self.label, str) or not self.label.strip()):
            raise StudyError(f"{self.name}.label", self.label, "must be a non-empty string")

    @property
    def display(self) -> str:
        """The name shown in tables and plots: the label, else the registry name."""
        return self.label if self.label is not None else self.name

    def identity(self) -> dict:
        """What determines the built object (the label does not)."""
        return {self._key: self.name, **self.params}

    def to_dict(self) -> dict:
        """The spec as a table: ``{"problem": "zdt1", ...params, "label": ...}``."""
        out = self.identity()
        if self.label is not None:
            out["label"] = self.label
        return out

    @classmethod
    def from_dict(cls, data: Mapping[str, Any], where: str = "", source: str | None = None):
        if not isinstance(data, Mapping):
            raise StudyError(where or cls._key, data, "must be a table", source)
        if cls._key not in data:
            raise StudyError(f"{where}.{cls._key}" if where else cls._key, None,
                             f"is required (e.g. {{{cls._key} = \"name\", ...}})", source)
        params = {k: v for k, v in data.items() if k not in (cls._key, "label")}
        try:
            return cls(name=data[cls._key], params=params, label=data.get("label"))
        except StudyError as err:
            raise StudyError(f"{where}.{err.field}" if where else err.field, err.value, err.reason, source) from None

    def __hash__(self) -> int:
        return hash((type(self).__name__, canonical_json(self.to_dict())))


@dataclass(frozen=True)
class ProblemSpec(_Spec):
    """A problem by registry name (or ``"module:factory"``) and keyword arguments.

    Examples
    --------
    >>> ProblemSpec("zdt1").to_dict()
    {'problem': 'zdt1'}
    >>> ProblemSpec("speed_profile", {"case": "yizhuang", "objectives": ["energy", "time_error"]},
    ...             label="yizhuang").display
    'yizhuang'
    """

    _key = "problem"

    def __hash__(self) -> int:  # dataclass(frozen) would hash the params dict
        return _Spec.__hash__(self)


@dataclass(frozen=True)
class AlgorithmSpec(_Spec):
    """An algorithm by registry name (or ``"module:factory"``) and keyword arguments.

    >>> AlgorithmSpec("nsga2", {"pop_size": 100}).to_dict()
    {'algorithm': 'nsga2', 'pop_size': 100}
    """

    _key = "algorithm"

    def __hash__(self) -> int:
        return _Spec.__hash__(self)


def problem(name: str, label: str | None = None, **params) -> ProblemSpec:
    """Shorthand: ``problem("speed_profile", case="yizhuang", objectives=["energy", "time_error"])``."""
    return ProblemSpec(name, params, label)


def algorithm(name: str, label: str | None = None, **params) -> AlgorithmSpec:
    """Shorthand: ``algorithm("nsga2", pop_size=100)``."""
    return AlgorithmSpec(name, params, label)


def tang2020_nsga2(label: str = "NSGA-II", pop_size: int = 200) -> AlgorithmSpec:
    """pymoo's NSGA-II with the settings of Tang et al. (2020), 4.1, the baseline of GR-NSGA-II.

    SBX with crossover probability 0.9 (eta 15) and polynomial mutation with per-variable
    probability 0.01 (eta 20): the paper's "crossover 0.9, mutation 0.01".

    Parameters
    ----------
    label : str
        The algorithm's label in the study.
    pop_size : int
        Population size (the paper's 200).

    Returns
    -------
    AlgorithmSpec
    """
    return algorithm("nsga2", label=label, pop_size=pop_size, crossover={"operator": "sbx", "prob": 0.9, "eta": 15},
                     mutation={"operator": "pm", "prob": 1.0, "prob_var": 0.01, "eta": 20})


@dataclass(frozen=True)
class Budget:
    """When a run stops: ``Budget("n_gen", 100)`` or ``Budget("n_eval", 10_000)``."""

    kind: str
    value: int

    def __post_init__(self) -> None:
        if self.kind not in BUDGET_KINDS:
            raise StudyError("budget", self.kind, f"unknown budget kind (use one of {', '.join(BUDGET_KINDS)})")
        if isinstance(self.value, bool) or not isinstance(self.value, int) or self.value < 1:
            raise StudyError(f"budget.{self.kind}", self.value, "must be a positive integer")

    @property
    def termination(self) -> tuple[str, int]:
        """The termination tuple pymoo's ``minimize`` takes."""
        return (self.kind, self.value)

    def to_dict(self) -> dict:
        """The budget as a study file writes it: ``{kind: value}``."""
        return {self.kind: self.value}

    @classmethod
    def from_dict(cls, data: Mapping[str, Any], source: str | None = None) -> Budget:
        """The budget of a study file's ``{kind: value}`` table; :class:`StudyError` naming the field otherwise."""
        if not isinstance(data, Mapping) or len(data) != 1:
            raise StudyError("budget", data, f"must be a table with exactly one of {', '.join(BUDGET_KINDS)}", source)
        (kind, value), = data.items()
        try:
            return cls(kind, value)
        except StudyError as err:
            raise StudyError(err.field, err.value, err.reason, source) from None


@dataclass(frozen=True)
class RunSpec:
    """One run of a study: one problem, one algorithm, one seed, one budget."""

    problem: ProblemSpec
    algorithm: AlgorithmSpec
    seed: int
    budget: Budget
    history: bool = True

    def identity(self) -> dict:
        """Everything that determines the run's result (labels excluded)."""
        return {"problem": self.problem.identity(), "algorithm": self.algorithm.identity(),
                "seed": self.seed, "budget": self.budget.to_dict()}

    @property
    def run_id(self) -> str:
        """A stable 16-hex-digit id of :meth:`identity`: same run, same id, on any machine."""
        return hashlib.sha256(canonical_json(self.identity()).encode()).hexdigest()[:16]

    def describe(self) -> str:
        """``problem / algorithm / seed``, for progress lines and messages."""
        return f"{self.problem.display} / {self.algorithm.display} / seed {self.seed}"


def _seeds(seeds: Any, source: str | None = None) -> tuple[int, ...]:
    if isinstance(seeds, int) and not isinstance(seeds, bool):
        if seeds < 1:
            raise StudyError("seeds", seeds, "a number of seeds must be >= 1", source)
        return tuple(range(1, seeds + 1))
    try:
        values = tuple(seeds)
    except TypeError:
        raise StudyError("seeds", seeds, "must be a list of integers or a number of seeds", source) from None
    if not values:
        raise StudyError("seeds", list(values), "needs at least one seed", source)
    for s in values:
        if isinstance(s, bool) or not isinstance(s, int) or s < 0:
            raise StudyError("seeds", list(values), f"seed {s!r} is not an integer >= 0", source)
    if len(set(values)) != len(values):
        raise StudyError("seeds", list(values), "repeats a seed", source)
    return values


def check_name(name: Any, source: str | None = None) -> str:
    """A study's name as given, after checking it is a name and not a path (it names ``out/<name>``)."""
    if not isinstance(name, str) or not name.strip():
        raise StudyError("name", name, "must be a non-empty string", source)
    bad = [c for c in name if c in "/\\:" or ord(c) < 32 or ord(c) == 127]
    if bad or name.strip() in (".", "..") or name.startswith(".") or name != name.strip():
        raise StudyError("name", name, "must be a name, not a path: no '/', '\\', ':' or control characters, "
                                       "no leading '.' or surrounding spaces (it names the output folder "
                                       "out/<name>); use --out or the directory argument to choose where "
                                       "results go", source)
    return name


def _unique_labels(kind: str, specs: tuple[_Spec, ...], source: str | None) -> None:
    seen: dict[str, _Spec] = {}
    for spec in specs:
        if spec.display in seen:
            raise StudyError(f"{kind}s", spec.display,
                             f"two {kind}s are shown as '{spec.display}': give them distinct labels "
                             f"(label = \"...\")", source)
        seen[spec.display] = spec


@dataclass(frozen=True)
class Study:
    """Problems x algorithms x seeds under one budget.

    Parameters
    ----------
    name : str
    problems, algorithms : sequence of ProblemSpec / AlgorithmSpec (or their dict forms)
    seeds : sequence of int, or int n meaning seeds 1..n
    budget : Budget, or a dict like ``{"n_gen": 100}``
    history : bool
        Record per-generation convergence (evaluations, best objectives, IGD/HV where the
        true front is known) in each run's record.
    baseline : str, optional
        The algorithm (label) other algorithms are tested against in the statistics.

    Examples
    --------
    >>> study = Study("zdt", problems=[problem("zdt1"), problem("zdt2")],
    ...               algorithms=[algorithm("nsga2", pop_size=20)], seeds=3, budget={"n_gen": 10})
    >>> len(study.runs())
    6
    """

    name: str
    problems: tuple[ProblemSpec, ...]
    algorithms: tuple[AlgorithmSpec, ...]
    seeds: tuple[int, ...] = (1,)
    budget: Budget = Budget("n_gen", 100)
    history: bool = True
    baseline: str | None = None

    def __post_init__(self) -> None:
        check_name(self.name)
        problems = tuple(p if isinstance(p, ProblemSpec) else ProblemSpec.from_dict(p, f"problems[{i}]")
                         for i, p in enumerate(self.problems))
        algorithms = tuple(a if isinstance(a, AlgorithmSpec) else AlgorithmSpec.from_dict(a, f"algorithms[{i}]")
                           for i, a in enumerate(self.algorithms))
        if not problems:
            raise StudyError("problems", [], "a study needs at least one problem")
        if not algorithms:
            raise StudyError("algorithms", [], "a study needs at least one algorithm")
        _unique_labels("problem", problems, None)
        _unique_labels("algorithm", algorithms, None)
        budget = self.budget if isinstance(self.budget, Budget) else Budget.from_dict(self.budget)
        object.__setattr__(self, "problems", problems)
        object.__setattr__(self, "algorithms", algorithms)
        object.__setattr__(self, "seeds", _seeds(self.seeds))
        object.__setattr__(self, "budget", budget)
        if not isinstance(self.history, bool):
            raise StudyError("history", self.history, "must be true or false")
        if self.baseline is not None and not isinstance(self.baseline, str):
            raise StudyError("baseline", self.baseline, "must be the label of one of the study's algorithms")
        if self.baseline is not None and self.baseline not in {a.display for a in algorithms}:
            raise StudyError("baseline", self.baseline,
                             f"is not one of the study's algorithms ({', '.join(a.display for a in algorithms)})")

    def runs(self) -> list[RunSpec]:
        """Every run, problem-major then algorithm then seed."""
        return [RunSpec(p, a, s, self.budget, self.history)
                for p in self.problems for a in self.algorithms for s in self.seeds]

    def to_dict(self) -> dict:
        """The study as plain data (what ``write_study`` stores as TOML)."""
        out: dict[str, Any] = {"name": self.name, "seeds": list(self.seeds), "budget": self.budget.to_dict(),
                               "history": self.history}
        if self.baseline is not None:
            out["baseline"] = self.baseline
        out["problems"] = [p.to_dict() for p in self.problems]
        out["algorithms"] = [a.to_dict() for a in self.algorithms]
        return out

    @classmethod
    def from_dict(cls, data: Mapping[str, Any], source: str | None = None) -> Study:
        """A study from plain data (a study file's tables); :class:`StudyError` naming the field of a bad entry."""
        allowed = {"name", "seeds", "budget", "history", "baseline", "problems", "algorithms"}
        if not isinstance(data, Mapping):
            raise StudyError("study", data, "must be a table", source)
        unknown = sorted(set(data) - allowed)
        if unknown:
            raise StudyError(unknown[0], data[unknown[0]], f"unknown key (allowed: {', '.join(sorted(allowed))})",
                             source)
        for key in ("name", "problems", "algorithms", "budget"):
            if key not in data:
                raise StudyError(key, None, "is required", source)
        for key in ("problems", "algorithms"):
            if not isinstance(data[key], list):
                raise StudyError(key, data[key], f"must be an array of tables ([[{key}]])", source)
        try:
            return cls(
                name=data["name"],
                problems=tuple(ProblemSpec.from_dict(p, f"problems[{i}]", source) for i, p in enumerate(data["problems"])),
                algorithms=tuple(AlgorithmSpec.from_dict(a, f"algorithms[{i}]", source)
                                 for i, a in enumerate(data["algorithms"])),
                seeds=_seeds(data.get("seeds", 1), source),
                budget=Budget.from_dict(data["budget"], source),
                history=data.get("history", True),
                baseline=data.get("baseline"),
            )
        except StudyError as err:
            if err.source is None and source is not None:
                raise StudyError(err.field, err.value, err.reason, source) from None
            raise
