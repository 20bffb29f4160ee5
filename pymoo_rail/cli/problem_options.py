"""The options of ``pymoo-rail optimize`` that build the problem and the algorithm, checked before any run."""

from __future__ import annotations

import argparse
from typing import Sequence

from pymoo_rail.cli.arguments import UsageError, positive_float, positive_int, random_seed, say
from pymoo_rail.constants import OBJECTIVES


def add_problem_arguments(p: argparse.ArgumentParser) -> None:
    """Algorithm, budget, objectives, encoding, constraints and the reference options."""
    p.add_argument("--algorithm", "-a", default="nsga2", metavar="NAME", help="optimisation algorithm")
    p.add_argument("--pop-size", "-p", type=positive_int, default=40, metavar="N", help="population size")
    p.add_argument("--n-gen", "-g", type=positive_int, default=50, metavar="N", help="number of generations")
    p.add_argument("--objectives", "-o", nargs="+", default=["energy", "time_error"], metavar="NAME",
                   help="objectives to minimise")
    p.add_argument("--seed", "-s", type=random_seed, default=1, help="random seed (same seed, same result)")
    p.add_argument("--encoding", default="speed_codes", choices=["speed_codes", "switching_points", "braking_onset"],
                   help="decision variables: a speed code per section, regime switching positions, or "
                        "phases with the braking onset and deceleration (a live stop error)")
    p.add_argument("--partition", default="gradient_limit", choices=["gradient_limit", "equal"],
                   help="sections of the speed-code encoding")
    p.add_argument("--n-sections", type=positive_int, default=None, metavar="N",
                   help="number of equal sections (with --partition equal)")
    p.add_argument("--time-tolerance", type=positive_float, default=None, metavar="S",
                   help="constraint |T - T_plan| <= S seconds (the single-objective form of Liu (2019)); "
                        "default: 1 s for one objective without running_time or time_error, else none")
    p.add_argument("--weights", type=float, nargs="+", default=None, metavar="W",
                   help="one weight per objective: minimise the weighted sum (Meng et al. (2017))")
    p.add_argument("--time-window", nargs="+", default=["default"], metavar="S",
                   help="running-time window constraint LO HI in seconds; 'default' (the minimum running time "
                        "to 1.3 x planned, where the certified optimal front is known: the times a timetable "
                        "planner uses) or 'none'; applies to running_time / time_error fronts")
    p.add_argument("--no-reference", action="store_true",
                   help="skip the certified optimal front, the optimal profile and the gap to the optimum")


def _objectives(values: Sequence[str]) -> tuple[str, ...]:
    for name in values:
        if name not in OBJECTIVES:
            raise UsageError("--objectives", f"unknown objective {name!r} (choose from {', '.join(OBJECTIVES)})")
    if len(set(values)) != len(values):
        raise UsageError("--objectives", f"{' '.join(values)}: an objective is repeated")
    return tuple(values)


def _time_window(args, objectives):
    values = [v.lower() for v in args.time_window]
    if values == ["none"]:
        return None
    if values == ["default"]:
        if args.weights is None and {"running_time", "time_error"} & set(objectives) and len(objectives) > 1:
            return "default"
        return None
    try:
        lo, hi = (float(v) for v in values)
    except ValueError:
        raise UsageError("--time-window", f"{' '.join(args.time_window)!r}: give LO HI seconds, 'default' or "
                                          "'none'") from None
    if not 0 <= lo < hi < float("inf"):
        raise UsageError("--time-window", f"{lo:g} {hi:g}: need 0 <= LO < HI seconds")
    return (lo, hi)


def _check_options(args, objectives) -> None:
    from pymoo_rail.experiments.registry import ALGORITHMS, algorithm_names, canonical_name

    if canonical_name(args.algorithm) not in ALGORITHMS:
        raise UsageError("--algorithm", f"unknown algorithm {args.algorithm!r} (choose from "
                                        f"{', '.join(algorithm_names())})")
    if args.weights is not None and len(args.weights) != len(objectives):
        raise UsageError("--weights", f"{len(args.weights)} weights for {len(objectives)} objectives "
                                      f"({' '.join(objectives)}): give one weight per objective")
    if args.n_sections is not None and args.partition != "equal":
        raise UsageError("--n-sections", "only applies with --partition equal")


def problem_from_args(case, args):
    """The ``SpeedProfileProblem`` the options describe; a ``UsageError`` naming the option at fault."""
    from pymoo_rail.experiments.optimize import default_time_tolerance_s
    from pymoo_rail.model import CaseError
    from pymoo_rail.problems import SpeedProfileProblem

    objectives = _objectives(args.objectives)
    _check_options(args, objectives)
    time_tolerance_s = default_time_tolerance_s(objectives, args.weights, args.time_tolerance)
    if time_tolerance_s != args.time_tolerance:
        say(f"time constraint |T - T_plan| <= {time_tolerance_s:g} s (the default for one objective; "
            "set it with --time-tolerance)")
    kwargs = {"objectives": objectives, "encoding": args.encoding, "partition": args.partition,
              "time_tolerance_s": time_tolerance_s, "time_window_s": _time_window(args, objectives)}
    if args.n_sections is not None:
        kwargs["n_sections"] = args.n_sections
    if args.weights is not None:
        kwargs["weights"] = args.weights
    try:
        return SpeedProfileProblem(case, **kwargs)
    except CaseError as err:  # the case cannot be run (e.g. a planned time below the minimum): not an option's fault
        raise UsageError("CASE", str(err)) from None
    except ValueError as err:  # the message names the parameter; blame --objectives only for its own
        raise UsageError("--objectives" if "objective" in str(err) else "options", str(err)) from None


def algorithm_from_args(problem, args):
    """The pymoo algorithm of ``--algorithm`` and ``--pop-size`` for ``problem``."""
    from pymoo_rail.experiments.registry import build_algorithm
    from pymoo_rail.experiments.spec import AlgorithmSpec, StudyError

    try:
        return build_algorithm(AlgorithmSpec(args.algorithm, {"pop_size": args.pop_size}), problem)
    except StudyError as err:
        raise UsageError("--algorithm", f"{args.algorithm!r}: {err.reason}") from None
    except ValueError as err:
        raise UsageError("--pop-size", f"{args.pop_size} with {args.algorithm}: {err}") from None
