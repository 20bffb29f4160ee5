"""Names of problems and algorithms a study can use, and how to build them.

The tables below are constants: a worker process (local or on a Dask cluster) rebuilds any
problem or algorithm from its name and keyword arguments alone. Beyond the built-in names, any
importable callable works as ``"package.module:attribute"``, called with the spec's keyword
arguments, so users extend a study without touching this module and without registering
anything at run time (a run-time registry would not reach remote workers).

An import path runs code the study file names, so it is refused unless the caller says the file
is trusted (``trusted=True``, ``--trust`` on the command line): a study file or a results folder
received from someone else cannot run anything by default (:func:`check_trust`). Parameters are
checked against the signature of what they are passed to (:func:`check_parameters`), so a
misspelt keyword is an error, not a silently ignored default.

Rail problems and algorithms are imported inside their factories, so this module works, and
lists them, before or without those parts of the package.
"""

from __future__ import annotations

import difflib
import importlib
import inspect
from dataclasses import dataclass
from typing import Any, Callable, Iterator, Mapping

from pymoo_rail.experiments.spec import AlgorithmSpec, ProblemSpec, Study, StudyError

TRUST_HINT = ("an import path runs the code it names: pass trusted=True (command line: --trust) only for a "
              "study file or results folder you trust")


class UntrustedCodeError(StudyError):
    """A study or results folder names code to import (``"module:callable"``) and the caller did not trust it."""


def _forwards(module: str, *attributes: str) -> Callable[[Callable[..., Any]], Callable[..., Any]]:
    """Mark a factory whose ``**params`` go to ``module.attribute`` (whose signatures then check them)."""
    def mark(factory: Callable[..., Any]) -> Callable[..., Any]:
        factory.forwards_to = tuple((module, attribute) for attribute in attributes)
        return factory

    return mark

# --------------------------------------------------------------------------------- problems


def _pymoo_problem(name: str, module: str) -> Callable[..., Any]:
    @_forwards(module, name.upper())
    def factory(**params):
        from pymoo.problems import get_problem

        return get_problem(name, **params)

    factory.__doc__ = f"pymoo's {name.upper()} (keyword arguments go to pymoo.problems.get_problem)."
    return factory


def _sphere(n_var: int = 10):
    """Sphere on [-100, 100]^n (Liu (2019) eq. 3-6)."""
    from pymoo_rail.experiments.functions import Sphere

    return Sphere(n_var)


def _griewank(n_var: int = 10):
    """Griewank on [-600, 600]^n (Liu (2019) eq. 3-7)."""
    from pymoo_rail.experiments.functions import Griewank

    return Griewank(n_var)


def _rosenbrock(n_var: int = 10):
    """Rosenbrock on [-2.048, 2.048]^n (Liu (2019) eq. 3-8)."""
    from pymoo_rail.experiments.functions import Rosenbrock

    return Rosenbrock(n_var)


def _case(case: Any, load: str | None = None):
    from pymoo_rail.cases import load_case, with_load
    from pymoo_rail.model import Case

    if isinstance(case, Case):
        return case if load is None else with_load(case, load)
    if not isinstance(case, str):
        raise StudyError("case", case, "must be a built-in case name or the path of a case file")
    return load_case(case, load=load)


def _tuples(params: dict) -> dict:
    """TOML gives lists; the rail problems take sequences of names (tuples keep them hashable)."""
    return {k: tuple(v) if isinstance(v, list) else v for k, v in params.items()}


def _controller(spec: Any):
    """An ATO controller from a table ``{"controller": "hysteresis", "a_kmh": 2, "b_kmh": 3}`` (a
    study spec holds plain data; the other keys are the controller's fields)."""
    from pymoo_rail.control.controllers import make_controller

    if not isinstance(spec, dict) or "controller" not in spec:
        raise StudyError("problem speed_profile tracking", spec,
                         "must be a table with controller = hysteresis, pid or fuzzy_pid and its fields")
    try:
        return make_controller(spec["controller"], **{k: v for k, v in spec.items() if k != "controller"})
    except ValueError as err:
        raise StudyError("problem speed_profile tracking", spec, str(err)) from None


@_forwards("pymoo_rail.problems", "SpeedProfileProblem")
def _speed_profile(case: Any = "yizhuang", load: str | None = None, tracking: Any = None, **params):
    """``pymoo_rail.problems.SpeedProfileProblem`` on a case (built-in name or file path; ``load``:
    a passenger load state such as ``"AW3"``; ``tracking``: a controller as a table,
    ``{"controller": "hysteresis", "a_kmh": 2, "b_kmh": 3}``)."""
    from pymoo_rail.problems import SpeedProfileProblem

    if tracking is not None:
        params["tracking"] = _controller(tracking)
    return SpeedProfileProblem(_case(case, load), **_tuples(params))


@_forwards("pymoo_rail.problems", "CooperativeTrainsProblem")
def _cooperative_trains(case: Any = "cooperative-pair", **params):
    """``pymoo_rail.problems.CooperativeTrainsProblem`` (Chen et al. (2017))."""
    from pymoo_rail.problems import CooperativeTrainsProblem

    return CooperativeTrainsProblem(_case(case), **_tuples(params))


@_forwards("pymoo_rail.problems", "CooperativeTrainsProblem")
def _cooperative_scaled(case: Any = "cooperative-pair", phi: float = 1.0, **params):
    """``CooperativeTrainsProblem`` on a case with every gradient times ``phi`` (Chen et al. 2017, fig. 6)."""
    from pymoo_rail.problems import CooperativeTrainsProblem
    from pymoo_rail.problems.cooperative import scale_gradients

    return CooperativeTrainsProblem(scale_gradients(_case(case), phi), **_tuples(params))


@_forwards("pymoo_rail.problems.cooperative_seed", "CooperativeSeedProblem")
def _cooperative_seed(case: Any = "cooperative-pair", **params):
    """``pymoo_rail.problems.cooperative_seed.CooperativeSeedProblem`` (the paper's encoding on the kernel)."""
    from pymoo_rail.problems.cooperative_seed import CooperativeSeedProblem

    return CooperativeSeedProblem(_case(case), **_tuples(params))


@_forwards("pymoo_rail.problems", "TimetableProblem")
def _timetable(case: Any = "cooperative-pair", **params):
    """``pymoo_rail.problems.TimetableProblem``: several trains sharing braking energy."""
    from pymoo_rail.problems import TimetableProblem

    return TimetableProblem(_case(case), **_tuples(params))


@_forwards("pymoo_rail.problems", "KinematicPhasesProblem")
def _kinematic_phases(case: Any = "metro-a", **params):
    """``pymoo_rail.problems.KinematicPhasesProblem`` (the four-phase model of Meng et al. 2017)."""
    from pymoo_rail.problems import KinematicPhasesProblem

    return KinematicPhasesProblem(_case(case), **_tuples(params))


@_forwards("pymoo_rail.problems.controller_tuning", "ControllerTuningProblem")
def _controller_tuning(case: Any = "metro-a", load: str | None = None, **params):
    """``pymoo_rail.problems.controller_tuning.ControllerTuningProblem`` (PID or fuzzy PID gains on disturbed trains)."""
    from pymoo_rail.problems.controller_tuning import ControllerTuningProblem

    return ControllerTuningProblem(_case(case, load), **params)


@_forwards("pymoo_rail.problems", "SpeedProfileProblem")
def _rail_suite(suite_problem: str, **params):
    """A named problem of the rail benchmark suite (``pymoo_rail.suite.get_problem``) with its
    settings; a seeded family instance is the ``suite_family`` entry (one way to name it)."""
    from pymoo_rail.suite import get_problem, list_families

    if suite_problem in list_families():
        raise StudyError("problem rail_suite suite_problem", suite_problem,
                         'a suite family: name an instance with problem = "suite_family", family, n_var and seed')
    try:
        return get_problem(suite_problem, **_tuples(params))
    except ValueError as err:
        raise StudyError("problem rail_suite suite_problem", suite_problem, str(err)) from None


def _suite_family(family: str, n_var: int = 30, seed: int = 1):
    """An instance of a seeded suite family (``pymoo_rail.suite.get_problem(family, n_var=, seed=)``).

    Its definition checksum goes into the run's input fingerprint (:mod:`.inputs`), so a record
    computed on another definition of the instance is never served.
    """
    from pymoo_rail.suite import get_problem, list_families

    if family not in list_families():
        raise StudyError("problem suite_family family", family, f"not a suite family ({', '.join(list_families())})")
    try:
        return get_problem(family, n_var=n_var, seed=seed)
    except ValueError as err:
        raise StudyError("problem suite_family", {"family": family, "n_var": n_var, "seed": seed}, str(err)) from None


PROBLEMS: dict[str, Callable[..., Any]] = {
    **{f"zdt{i}": _pymoo_problem(f"zdt{i}", "pymoo.problems.multi.zdt") for i in range(1, 7)},
    **{f"dtlz{i}": _pymoo_problem(f"dtlz{i}", "pymoo.problems.many.dtlz") for i in range(1, 8)},
    "sphere": _sphere,
    "griewank": _griewank,
    "rosenbrock": _rosenbrock,
    "speed_profile": _speed_profile,
    "cooperative_trains": _cooperative_trains,
    "kinematic_phases": _kinematic_phases,
    "controller_tuning": _controller_tuning,
    "rail_suite": _rail_suite,
    "suite_family": _suite_family,
    "cooperative_trains_scaled": _cooperative_scaled,
    "timetable": _timetable,
    "cooperative_seed": _cooperative_seed,
}

# ------------------------------------------------------------------------------- algorithms


def _ref_dirs(n_obj: int, n_points: int):
    """Reference directions with about ``n_points`` members (exactly that many for 2 objectives)."""
    from pymoo.util.ref_dirs import get_reference_directions

    if n_obj == 2:
        return get_reference_directions("uniform", 2, n_partitions=max(n_points - 1, 1))
    return get_reference_directions("energy", n_obj, n_points, seed=1)


def _pymoo_algorithm(module: str, name: str, *also: str) -> Callable[..., Any]:
    """The factory of pymoo's ``module.name`` built from its keywords alone (``also``: classes they reach too)."""
    @_forwards(module, name, *also)
    def factory(problem, **params):
        return getattr(importlib.import_module(module), name)(**params)

    factory.__doc__ = f"pymoo's {name} (keyword arguments go to {module}.{name})."
    return factory


_nsga2 = _pymoo_algorithm("pymoo.algorithms.moo.nsga2", "NSGA2")


@_forwards("pymoo.algorithms.moo.nsga3", "NSGA3")
def _nsga3(problem, pop_size: int = 100, **params):
    from pymoo.algorithms.moo.nsga3 import NSGA3

    return NSGA3(ref_dirs=_ref_dirs(problem.n_obj, pop_size), pop_size=pop_size, **params)


@_forwards("pymoo.algorithms.moo.ctaea", "CTAEA")
def _ctaea(problem, pop_size: int = 100, **params):
    """C-TAEA (Li et al. 2019) with ``pop_size`` reference directions: its population and each
    generation's offspring are one per direction, so an ``n_eval`` budget counts ``pop_size`` a generation."""
    from pymoo.algorithms.moo.ctaea import CTAEA

    return CTAEA(ref_dirs=_ref_dirs(problem.n_obj, pop_size), **params)


@_forwards("pymoo.algorithms.moo.moead", "MOEAD")
def _moead(problem, pop_size: int = 100, n_neighbors: int = 20, **params):
    """MOEA/D with ``pop_size`` uniform weight vectors (the population is one per vector)."""
    from pymoo.algorithms.moo.moead import MOEAD

    ref_dirs = _ref_dirs(problem.n_obj, pop_size)
    return MOEAD(ref_dirs=ref_dirs, n_neighbors=min(n_neighbors, len(ref_dirs)), **params)


_smsemoa = _pymoo_algorithm("pymoo.algorithms.moo.sms", "SMSEMOA")
_agemoea = _pymoo_algorithm("pymoo.algorithms.moo.age", "AGEMOEA")
_random = _pymoo_algorithm("pymoo.algorithms.soo.nonconvex.random_search", "RandomSearch")
_de = _pymoo_algorithm("pymoo.algorithms.soo.nonconvex.de", "DE", "Variant")  # DE hands its keywords to its variant too
_pso = _pymoo_algorithm("pymoo.algorithms.soo.nonconvex.pso", "PSO")
_ga = _pymoo_algorithm("pymoo.algorithms.soo.nonconvex.ga", "GA")


def _rail_algorithm(name: str, module: str) -> Any:
    """``pymoo_rail.algorithms.<name>``, or straight from its module before it is exported."""
    try:
        return getattr(importlib.import_module("pymoo_rail.algorithms"), name)
    except (ImportError, AttributeError):
        pass
    try:
        return getattr(importlib.import_module(f"pymoo_rail.algorithms.{module}"), name)
    except (ImportError, AttributeError) as err:
        raise StudyError("algorithm", name, f"pymoo_rail.algorithms.{name} is not available in this "
                                            f"installation ({err})") from None


@_forwards("pymoo_rail.algorithms", "ABC")
def _abc(problem, **params):
    """``pymoo_rail.algorithms.ABC`` (Liu (2019), 3.2-3.3)."""
    return _rail_algorithm("ABC", "abc")(**params)


@_forwards("pymoo_rail.algorithms", "MOABC")
def _moabc(problem, **params):
    """``pymoo_rail.algorithms.MOABC`` (Liu (2019), 4.5.2)."""
    return _rail_algorithm("MOABC", "moabc")(**params)


def _fixed_genes(problem):
    """Genes a rail encoding holds constant (speed codes inside neutral sections), if any."""
    fixed = getattr(getattr(problem, "encoding", None), "fixed", None)
    if not callable(fixed):
        return None
    mask = fixed()
    return mask if mask.any() else None


@_forwards("pymoo_rail.algorithms", "GoldenRatioNSGA2")
def _grnsga2(problem, **params):
    """``pymoo_rail.algorithms.GoldenRatioNSGA2`` (Tang et al. (2020), 3.1); on a rail problem the genes of
    neutral sections are passed as ``fixed_genes`` unless given."""
    if "fixed_genes" not in params:
        fixed = _fixed_genes(problem)
        if fixed is not None:
            params["fixed_genes"] = fixed
    return _rail_algorithm("GoldenRatioNSGA2", "golden_ratio_nsga2")(**params)


@dataclass(frozen=True)
class AlgorithmEntry:
    """A built-in algorithm: its factory ``(problem, **params)`` and what problems it takes."""

    factory: Callable[..., Any]
    objectives: str  # "single" (n_obj == 1), "multi" (n_obj >= 2) or "any"
    summary: str


ALGORITHMS: dict[str, AlgorithmEntry] = {
    "nsga2": AlgorithmEntry(_nsga2, "any", "NSGA-II (pymoo)"),
    "nsga3": AlgorithmEntry(_nsga3, "multi", "NSGA-III with pop_size reference directions (pymoo)"),
    "ctaea": AlgorithmEntry(_ctaea, "multi", "C-TAEA, two archives for constrained problems, pop_size reference "
                                             "directions (pymoo)"),
    "moead": AlgorithmEntry(_moead, "multi", "MOEA/D with pop_size weight vectors (pymoo)"),
    "sms-emoa": AlgorithmEntry(_smsemoa, "multi", "SMS-EMOA (pymoo)"),
    "age-moea": AlgorithmEntry(_agemoea, "multi", "AGE-MOEA, adaptive geometry estimation (pymoo)"),
    "random": AlgorithmEntry(_random, "any", "random search: n_points_per_iteration uniform samples a step, "
                                             "the non-dominated ones kept (pymoo)"),
    "de": AlgorithmEntry(_de, "single", "differential evolution (pymoo)"),
    "pso": AlgorithmEntry(_pso, "single", "particle swarm (pymoo)"),
    "ga": AlgorithmEntry(_ga, "single", "genetic algorithm (pymoo)"),
    "abc": AlgorithmEntry(_abc, "single", "artificial bee colony (pymoo_rail, Liu (2019))"),
    "moabc": AlgorithmEntry(_moabc, "any", "multi-objective bee colony (pymoo_rail, Liu (2019))"),
    "grnsga2": AlgorithmEntry(_grnsga2, "any", "golden-ratio NSGA-II (pymoo_rail, Tang et al. (2020))"),
}

ALIASES = {"smsemoa": "sms-emoa", "agemoea": "age-moea", "moea/d": "moead", "nsga-ii": "nsga2", "nsga-iii": "nsga3", "c-taea": "ctaea",
           "golden-ratio-nsga2": "grnsga2", "goldenrationsga2": "grnsga2", "speed-profile": "speed_profile",
           "cooperative-trains": "cooperative_trains", "rail-suite": "rail_suite",
           "suite-family": "suite_family", "random-search": "random",
           "kinematic-phases": "kinematic_phases", "controller-tuning": "controller_tuning"}

# -------------------------------------------------------------------------------- operators

# Variation operators a spec may name: ``crossover = {operator = "sbx", prob = 0.9, eta = 15}``
# (or just ``crossover = "sbx"``). Values are (module, class) of pymoo; "module:Class" works too.
OPERATORS: dict[str, dict[str, tuple[str, str]]] = {
    "crossover": {
        "sbx": ("pymoo.operators.crossover.sbx", "SBX"),
        "ux": ("pymoo.operators.crossover.ux", "UX"),
        "hux": ("pymoo.operators.crossover.hux", "HUX"),
        "one_point": ("pymoo.operators.crossover.pntx", "SinglePointCrossover"),
        "two_point": ("pymoo.operators.crossover.pntx", "TwoPointCrossover"),
        "de": ("pymoo.operators.crossover.dex", "DEX"),
    },
    "mutation": {
        "pm": ("pymoo.operators.mutation.pm", "PM"),
        "gauss": ("pymoo.operators.mutation.gauss", "GaussianMutation"),
        "bitflip": ("pymoo.operators.mutation.bitflip", "BitflipMutation"),
    },
    "sampling": {
        "random": ("pymoo.operators.sampling.rnd", "FloatRandomSampling"),
        "lhs": ("pymoo.operators.sampling.lhs", "LHS"),
        "binary": ("pymoo.operators.sampling.rnd", "BinaryRandomSampling"),
        "integer": ("pymoo.operators.sampling.rnd", "IntegerRandomSampling"),
    },
}


def _operator_name(kind: str, value: Any, where: str) -> tuple[str, dict]:
    """The name and keyword arguments of an operator entry (``"name"`` or ``{operator = "name", ...}``)."""
    if isinstance(value, str):
        name, params = value, {}
    elif isinstance(value, dict):
        if "operator" not in value:
            raise StudyError(f"{where}.operator", None, f"names the {kind} (one of {', '.join(OPERATORS[kind])})")
        name = value["operator"]
        params = {k: v for k, v in value.items() if k != "operator"}
    else:
        raise StudyError(where, value, f"must be a {kind} name or a table {{operator = \"name\", ...}}")
    if not isinstance(name, str):
        raise StudyError(f"{where}.operator", name, "must be a name")
    return name, params


def _operator(kind: str, value: Any, where: str, trusted: bool) -> Any:
    """A pymoo operator from ``"name"`` or ``{operator = "name", ...keyword arguments}``."""
    name, params = _operator_name(kind, value, where)
    if ":" in name:
        factory = _import_path(name, f"{where}.operator", trusted)
    else:
        key = name.strip().lower().replace("-", "_")
        if key not in OPERATORS[kind]:
            raise StudyError(f"{where}.operator", name,
                             f"unknown {kind} (built-in: {', '.join(OPERATORS[kind])}; or 'module:Class')")
        module, attribute = OPERATORS[kind][key]
        factory = getattr(importlib.import_module(module), attribute)
    _check_keywords(factory, params, where, f"{kind} '{name}'")
    try:
        return factory(**params)
    except TypeError as err:
        raise StudyError(where, value, f"bad parameters: {err}") from None


def _with_operators(params: dict, where: str, trusted: bool) -> dict:
    """``params`` with its crossover / mutation / sampling tables made into pymoo operators."""
    out = dict(params)
    for kind in OPERATORS:
        if kind in out:
            out[kind] = _operator(kind, out[kind], f"{where}.{kind}", trusted)
    return out


# ------------------------------------------------------------------------- trust and checks


def import_paths(study: Study) -> Iterator[tuple[str, str]]:
    """``(field, value)`` of every import path a study names: problems, algorithms, operators."""
    for i, p in enumerate(study.problems):
        if ":" in p.name:
            yield f"problems[{i}].problem", p.name
    for i, a in enumerate(study.algorithms):
        if ":" in a.name:
            yield f"algorithms[{i}].algorithm", a.name
        for kind in OPERATORS:
            value = a.params.get(kind)
            name = value.get("operator") if isinstance(value, dict) else value
            if isinstance(name, str) and ":" in name:
                yield f"algorithms[{i}].{kind}.operator", name


def check_trust(study: Study, trusted: bool) -> None:
    """Raise :class:`UntrustedCodeError` naming the first import path of ``study`` unless ``trusted``.

    Nothing is imported: the check reads names only, so it is safe on a received study file.
    """
    if trusted:
        return
    for where, value in import_paths(study):
        raise UntrustedCodeError(where, value, TRUST_HINT)


# pymoo's base classes take **kwargs and drop what they do not know: a keyword that reaches them
# unused is a mistake, not an extension point
_DROPPING_BASES = {("pymoo.core.algorithm", "Algorithm"), ("pymoo.core.problem", "Problem"),
                   ("pymoo.core.infill", "InfillCriterion")}


def accepted_parameters(target: Callable[..., Any]) -> frozenset[str] | None:
    """The keyword arguments ``target`` (a class or function) uses, or None when it cannot be told.

    A class is followed up its bases while each ``__init__`` passes ``**kwargs`` on; pymoo's
    ``Algorithm`` and ``Problem``, which drop unknown keywords, end the chain. A registry factory
    marked with the class its ``**params`` go to adds that class's names. None: the target hands
    ``**kwargs`` to code that cannot be inspected (then nothing is checked).
    """
    names: set[str] = set()
    if inspect.isclass(target):
        for klass in target.__mro__:
            if klass is object or "__init__" not in vars(klass):
                continue
            open_end = _add_parameters(names, klass.__init__)
            if (klass.__module__, klass.__qualname__) in _DROPPING_BASES or not open_end:
                return frozenset(names - {"self"})
        return None
    try:
        open_end = _add_parameters(names, target)
    except (TypeError, ValueError):
        return None
    if not open_end:
        return frozenset(names)
    forwards = getattr(target, "forwards_to", None)
    if forwards is None:
        return None
    for module, attribute in forwards:
        try:
            inner = accepted_parameters(getattr(importlib.import_module(module), attribute))
        except (ImportError, AttributeError):
            return None
        if inner is None:
            return None
        names |= inner
    return frozenset(names)


def _add_parameters(names: set[str], function: Callable[..., Any]) -> bool:
    """Add the keyword names of ``function`` to ``names``; True when it also takes ``**kwargs``."""
    open_end = False
    for parameter in inspect.signature(function).parameters.values():
        if parameter.kind is inspect.Parameter.VAR_KEYWORD:
            open_end = True
        elif parameter.kind in (inspect.Parameter.POSITIONAL_OR_KEYWORD, inspect.Parameter.KEYWORD_ONLY):
            names.add(parameter.name)
    return open_end


def _check_keywords(target: Callable[..., Any], params: Mapping[str, Any], where: str, what: str,
                    internal: tuple[str, ...] = ()) -> None:
    accepted = accepted_parameters(target)
    if accepted is None:
        return
    accepted = accepted - set(internal)
    for key in params:
        if key not in accepted:
            close = difflib.get_close_matches(key, accepted, n=1)
            hint = f"did you mean '{close[0]}'? " if close else ""
            raise StudyError(f"{where}.{key}", params[key],
                             f"unknown parameter of {what} ({hint}accepted: {', '.join(sorted(accepted))})")
    defaults = _defaults(target)
    for key, value in params.items():
        reason = _type_mismatch(key, defaults.get(key), value)
        if reason:
            raise StudyError(f"{where}.{key}", value, f"{reason} (parameter of {what})")


def _defaults(target: Callable[..., Any]) -> dict[str, Any]:
    """Default values of ``target``'s keywords (and, for a registry factory, of the classes it builds)."""
    out: dict[str, Any] = {}
    functions = [klass.__init__ for klass in reversed(target.__mro__) if "__init__" in vars(klass)
                 and klass is not object] if inspect.isclass(target) else [target]
    for module, attribute in getattr(target, "forwards_to", ()):
        try:
            out.update(_defaults(getattr(importlib.import_module(module), attribute)))
        except (ImportError, AttributeError):
            pass
    for function in functions:
        try:
            parameters = inspect.signature(function).parameters.values()
        except (TypeError, ValueError):
            continue
        out.update({p.name: p.default for p in parameters if p.default is not inspect.Parameter.empty})
    return out


POSITIVE_COUNTS = ("pop_size", "n_var", "n_obj", "n_offsprings", "n_neighbors", "n_sections", "limit", "k")


def _is_count(name: str) -> bool:
    return name.startswith("n_") or name.endswith("_size") or name in ("limit", "k")


def _type_mismatch(name: str, default: Any, value: Any) -> str:
    """Why ``value`` cannot stand where the signature's default is ``default`` (empty: it can).

    Only plain defaults say anything: a bool wants a bool, a number a number (a count such as
    ``pop_size`` or ``n_var`` an integer), a string a string; ``None`` or an object says nothing.
    """
    is_bool = isinstance(value, bool)
    if isinstance(default, bool):
        return "" if is_bool else "must be true or false"
    if isinstance(default, int) and _is_count(name):
        # sizes of a population, a problem or a neighbourhood are at least 1; other counts may be 0
        # (GoldenRatioNSGA2's local_size = 0 turns the local search off); the constructors check
        # their own upper bounds
        least = 1 if default > 0 and name in POSITIVE_COUNTS else 0
        ok = isinstance(value, int) and not is_bool and value >= least
        return "" if ok else f"must be an integer >= {least}"
    if isinstance(default, (int, float)):
        return "" if isinstance(value, (int, float)) and not is_bool else "must be a number"
    if isinstance(default, str) and not isinstance(value, (str, dict)):  # a name, or an operator table
        return "must be a string"
    return ""


def check_parameters(spec: ProblemSpec | AlgorithmSpec, where: str, trusted: bool = False) -> None:
    """Raise :class:`StudyError` naming ``where.<key>`` for a parameter the named factory does not take.

    Checked against the signature of the factory and of the class it passes its keywords to
    (:func:`accepted_parameters`), so ``pop_sise = 40`` or ``n_vars = 8`` fail before any run.
    """
    kind = "problem" if isinstance(spec, ProblemSpec) else "algorithm"
    factory = _factory(spec, kind, trusted)
    # the registry's own positional argument (the problem an algorithm is built for) is not a parameter
    internal = ("problem",) if kind == "algorithm" and ":" not in spec.name else ()
    _check_keywords(factory, spec.params, where, f"{kind} '{spec.name}'", internal)
    if kind == "algorithm":
        for key in OPERATORS:
            if key in spec.params:
                name, params = _operator_name(key, spec.params[key], f"{where}.{key}")
                if ":" not in name:
                    module, attribute = OPERATORS[key].get(name.strip().lower().replace("-", "_"), (None, None))
                    if module is not None:
                        _check_keywords(getattr(importlib.import_module(module), attribute), params,
                                        f"{where}.{key}", f"{key} '{name}'")


# ------------------------------------------------------------------------------ resolving


def canonical_name(name: str) -> str:
    """Lower case, ``_`` and ``-`` accepted for each other, common aliases mapped."""
    key = name.strip().lower()
    if key in ALIASES:
        return ALIASES[key]
    if key.replace("_", "-") in ALGORITHMS:
        return key.replace("_", "-")
    return ALIASES.get(key.replace("_", "-"), key)


def is_suite_family(spec) -> bool:
    """True when a problem spec names a suite family instance (``problem = "suite_family"``)."""
    return canonical_name(spec.name) == "suite_family"


def _import_path(path: str, kind: str, trusted: bool) -> Callable[..., Any]:
    if not trusted:
        raise UntrustedCodeError(kind, path, TRUST_HINT)
    module_name, _, attribute = path.partition(":")
    try:
        module = importlib.import_module(module_name)
    except ImportError as err:
        raise StudyError(kind, path, f"cannot import module '{module_name}': {err}") from None
    try:
        return getattr(module, attribute)
    except AttributeError:
        raise StudyError(kind, path, f"module '{module_name}' has no attribute '{attribute}'") from None


def problem_names() -> list[str]:
    """Names of the registered problems, sorted."""
    return sorted(PROBLEMS)


def algorithm_names() -> list[str]:
    """Names of the registered algorithms, sorted."""
    return sorted(ALGORITHMS)


def check_problem_name(name: str) -> None:
    """Raise :class:`StudyError` for a name that is neither built in nor an import path."""
    if ":" not in name and canonical_name(name) not in PROBLEMS:
        raise StudyError("problem", name, f"unknown problem (built-in: {', '.join(problem_names())}; "
                                          "or give 'package.module:factory' with trusted=True)")


def check_algorithm_name(name: str) -> None:
    """Raise :class:`StudyError` naming the known algorithms when ``name`` is neither one of them nor
    ``module:factory``.
    """
    if ":" not in name and canonical_name(name) not in ALGORITHMS:
        raise StudyError("algorithm", name, f"unknown algorithm (built-in: {', '.join(algorithm_names())}; "
                                            "or give 'package.module:factory' with trusted=True)")


def _factory(spec: ProblemSpec | AlgorithmSpec, kind: str, trusted: bool) -> Callable[..., Any]:
    """The callable a spec names: a registry factory, or an import path when ``trusted``."""
    if ":" in spec.name:
        return _import_path(spec.name, kind, trusted)
    if kind == "problem":
        check_problem_name(spec.name)
        return PROBLEMS[canonical_name(spec.name)]
    check_algorithm_name(spec.name)
    return ALGORITHMS[canonical_name(spec.name)].factory


def _call(factory: Callable[..., Any], kind: str, spec, params: Mapping[str, Any], *args) -> Any:
    try:
        return factory(*args, **params)
    except TypeError as err:
        # an unknown or missing keyword argument: say which spec it came from
        raise StudyError(f"{kind} '{spec.display}'", spec.params, f"bad parameters: {err}") from None


def build_problem(spec: ProblemSpec, trusted: bool = False, cases: Mapping[str, Any] | None = None):
    """The pymoo problem a spec names.

    Parameters
    ----------
    spec : ProblemSpec
    trusted : bool
        Allow an import path (``"module:factory"``), which runs the code it names.
    cases : mapping, optional
        Cases already loaded, by the spec's ``case`` value: a built-in problem then uses exactly
        the case its fingerprint was computed from (:func:`pymoo_rail.experiments.inputs.resolve_run`),
        not the file as it is when the run starts. An import path gets its parameters as written
        (its ``case`` stays the string it reads itself).
    """
    factory = _factory(spec, "problem", trusted)
    check_parameters(spec, f"problem '{spec.display}'", trusted)
    params = dict(spec.params)
    if cases and ":" not in spec.name and isinstance(params.get("case"), str) and params["case"] in cases:
        params["case"] = cases[params["case"]]
    return _call(factory, "problem", spec, params)


def build_algorithm(spec: AlgorithmSpec, problem, trusted: bool = False):
    """The pymoo algorithm a spec names, set up for ``problem``'s number of objectives.

    ``trusted`` allows import paths for the algorithm and its operators (see :func:`build_problem`).
    """
    factory = _factory(spec, "algorithm", trusted)
    check_parameters(spec, f"algorithm '{spec.display}'", trusted)
    params = _with_operators(spec.params, f"algorithm '{spec.display}'", trusted)
    if ":" in spec.name:
        return _call(factory, "algorithm", spec, params)
    entry = ALGORITHMS[canonical_name(spec.name)]
    n_obj = problem.n_obj
    if entry.objectives == "single" and n_obj != 1:
        raise StudyError("algorithm", spec.name, f"is single-objective; the problem has {n_obj} objectives")
    if entry.objectives == "multi" and n_obj < 2:
        raise StudyError("algorithm", spec.name, "is multi-objective; the problem has 1 objective")
    return _call(factory, "algorithm", spec, params, problem)
