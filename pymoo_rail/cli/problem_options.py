"""The options of ``pymoo-rail optimize`` that build the problem and the algorithm, checked before any run."""

from __future__ import annotations

import argparse
from typing import Sequence

from pymoo_rail.cli.arguments import UsageError, positive_float, positive_int, random_seed, say
from pymoo_rail.problems.encodings import encoding_names
from pymoo_rail.problems.objectives import check_objectives


def add_problem_arguments(p: argparse.ArgumentParser) -> None:
    """Algorithm, budget, objectives, encoding, constraints and the reference options."""
    p.add_argument("--algorithm", "-a", default="nsga2", metavar="NAME", help="optimisation algorithm")
    p.add_argument("--pop-size", "-p", type=positive_int, default=40, metavar="N", help="population size")
    p.add_argument("--n-gen", "-g", type=positive_int, default=50, metavar="N", help="number of generations")
    p.add_argument("--objectives", "-o", nargs="+", default=["energy", "time_error"], metavar="NAME",
                   help="objectives to minimise")
    p.add_argument("--seed", "-s", type=random_seed, default=1, help="random seed (same seed, same result)")
    p.add_argument("--encoding", default="speed_codes", choices=encoding_names(),
                   help="decision variables (see 'encodings' below)")
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
    add_grid_argument(p)
    p.add_argument("--no-reference", action="store_true",
                   help="skip the certified optimal front, the optimal profile and the gap to the optimum")


def add_grid_argument(p: argparse.ArgumentParser) -> None:
    """``--dx M``: the position step of the simulation and of the exact reference."""
    p.add_argument("--dx", type=positive_float, default=None, metavar="M",
                   help="position step of the simulation grid and of the exact reference, in m (default: the "
                        "case's, 1 m on metro lines); a finer step lets the exact reference meet running times "
                        "a coarse grid jumps over")


def _objectives(values: Sequence[str]) -> tuple[str, ...]:
    try:
        return check_objectives(values)  # the objective table: known names, none repeated (aliases count)
    except ValueError as err:
        raise UsageError("--objectives", str(err)) from None


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
    if args.dx is not None:
        kwargs["dx_m"] = args.dx
    if args.weights is not None:
        kwargs["weights"] = args.weights
    try:
        return SpeedProfileProblem(case, **kwargs)
    except CaseError as err:  # the case cannot be run (e.g. a planned time below the minimum): not an option's fault
        raise UsageError("CASE", str(err)) from None
    except ValueError as err:  # the message names the parameter; blame --objectives only for its own
        raise UsageError("--objectives" if "objective" in str(err) else "options", str(err)) from None


def algorithm_from_args(problem, args):
    """The pymoo algorithm of ``--algorithm`` and ``--pop-size`` for ``problem``, and its constraint penalty.

    Returns
    -------
    (Algorithm, float or None)
        The algorithm, and the penalty for ``optimize_profile`` when the algorithm has no
        constraint handling (MOEA/D) and the problem has constraints (the user is told), else None.
    """
    from pymoo_rail.experiments.penalty import DEFAULT_PENALTY, handles_constraints
    from pymoo_rail.experiments.registry import ALGORITHMS, build_algorithm, canonical_name
    from pymoo_rail.experiments.spec import AlgorithmSpec, StudyError

    try:
        algorithm = build_algorithm(AlgorithmSpec(args.algorithm, {"pop_size": args.pop_size}), problem)
    except StudyError as err:
        raise UsageError("--algorithm", f"{args.algorithm!r}: {err.reason}") from None
    except ValueError as err:
        raise UsageError("--pop-size", f"{args.pop_size} with {args.algorithm}: {err}") from None
    if handles_constraints(algorithm) or not problem.has_constraints():
        return algorithm, None
    others = [name for name, entry in ALGORITHMS.items()
              if entry.objectives != "single" and name != canonical_name(args.algorithm)]
    say(f"{args.algorithm} has no constraint handling (pymoo's {type(algorithm).__name__}): the problem's "
        f"{problem.n_ieq_constr} constraints are added to every objective as a penalty ({DEFAULT_PENALTY:g} per "
        f"unit of violation), and the front is reported with its true objectives and violations; "
        f"{', '.join(others)} handle the constraints themselves")
    return algorithm, DEFAULT_PENALTY
