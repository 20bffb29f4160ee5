"""The ``pymoo-rail`` command: cases, optimisation, the exact reference, studies and plots.

Every subcommand is a thin layer over the library (``pymoo_rail.cases``, ``.problems``,
``.experiments``, ``.plotting``, ``.optimal``); heavy modules are imported when a subcommand
runs, so ``pymoo-rail --help`` answers at once. Bad arguments (unknown case, algorithm or
objective, impossible values) end with exit code 2 and a message naming the argument and the
value; other failures with exit code 1 and a one-line message (``--debug`` shows the traceback).
"""

from __future__ import annotations

import argparse
import sys
import textwrap
from pathlib import Path
from typing import Sequence

from pymoo_rail.constants import OBJECTIVE_COLUMNS, OBJECTIVES, TIME_OBJECTIVES

DEFAULT_TIME_TOLERANCE_S = 1.0


class UsageError(Exception):
    """A bad argument value found after parsing: reported as ``argument NAME: message``, exit 2."""

    def __init__(self, argument: str, message: str):
        self.argument = argument
        super().__init__(message)


class _Formatter(argparse.RawDescriptionHelpFormatter, argparse.ArgumentDefaultsHelpFormatter):
    """Raw descriptions; "(default: X)" appended once, and only where the help does not say it."""

    def _get_help_string(self, action: argparse.Action) -> str:
        text = action.help or ""
        if "default" in text or action.default in (None, False) or action.default is argparse.SUPPRESS:
            return text
        return super()._get_help_string(action)


MAIN_EPILOG = """\
examples:
  pymoo-rail cases                                  list the built-in cases
  pymoo-rail cases yizhuang                         describe one case
  pymoo-rail optimize yizhuang --out out/           NSGA-II on energy and time error (about 3 s of
                                                    CPU; the first run compiles, about 18 s more)
  pymoo-rail optimize yizhuang --algorithm moabc --pop-size 40 --n-gen 100 --seed 3 --out out/moabc
  pymoo-rail optimize yizhuang --objectives energy --time-tolerance 1 --algorithm abc --out out/abc
  pymoo-rail reference yizhuang --out out/ref       the exact minimum-energy front
  pymoo-rail study examples/study_zdt.toml --workers 2 --out out/zdt
  pymoo-rail plot study out/zdt                     redraw the tables and figures of a study
  pymoo-rail plot trajectory out/trajectory.csv --case yizhuang
  pymoo-rail warmup --all                           compile the kernels ahead (images, clusters)

The first run in a fresh installation compiles the simulator (Numba; it says so), later runs
load the compiled kernels from the cache.

Run 'pymoo-rail COMMAND --help' for the options of a command.
"""


def _parsed(text: str, kind: type, what: str):
    try:
        return kind(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"invalid {what}: {text!r}") from None


def _positive_int(text: str) -> int:
    value = _parsed(text, int, "integer")
    if value < 1:
        raise argparse.ArgumentTypeError(f"must be at least 1, got {value}")
    return value


def _positive_float(text: str) -> float:
    value = _parsed(text, float, "number")
    if not value > 0 or value == float("inf"):
        raise argparse.ArgumentTypeError(f"must be a positive finite number, got {text}")
    return value


def _seed(text: str) -> int:
    value = _parsed(text, int, "integer")
    if value < 0:
        raise argparse.ArgumentTypeError(f"must be >= 0, got {value}")
    return value


def build_parser() -> argparse.ArgumentParser:
    """The argument parser of the ``pymoo-rail`` command with all its subcommands."""
    parser = argparse.ArgumentParser(
        prog="pymoo-rail",
        description="Energy-efficient train driving with pymoo: optimise recommended speed profiles of "
                    "built-in or your own cases, compute the exact minimum-energy reference, run algorithm "
                    "studies (many problems x algorithms x seeds) on this machine or a Dask cluster, and "
                    "draw the figures.",
        epilog=MAIN_EPILOG, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--debug", action="store_true", help="show the full traceback of an error")
    sub = parser.add_subparsers(dest="command", metavar="COMMAND", title="commands")

    p = sub.add_parser("cases", help="list the built-in cases, or describe one", formatter_class=_Formatter,
                       description="List the built-in cases (length, planned time, train, source), or describe "
                                   "one case (built-in name or path of a .toml case file) in full.",
                       epilog="examples:\n  pymoo-rail cases\n  pymoo-rail cases wuguang-crh3\n"
                              "  pymoo-rail cases my_line.toml")
    p.add_argument("case", nargs="?", metavar="CASE", help="a case to describe (name or .toml path)")

    p = sub.add_parser(
        "optimize", aliases=["optimise"], help="optimise the speed profile of a case", formatter_class=_Formatter,
        description=textwrap.dedent("""\
            Optimise the recommended speed profile of one case and write into --out:
              front.csv        every front member: objectives, running time, energy, stop error,
                               constraint violation and decision vector
              trajectory.csv   the chosen run (the least energy within --time-tolerance, default 1 s,
                               of the planned time; else the member closest to it; for a single
                               objective the best one), one row per grid node
              front.png        the front in objective space, the chosen member circled, over the
                               certified optimal front (energy with running time / time error)
              profile.png      speed against distance over the line (limits, gradients, regimes),
                               the optimal run at the chosen member's running time dashed
              speed_time.png   speed against time with the planned time
            and print the chosen member's gap to the optimum. Fronts with running time or time
            error are kept inside a running-time window (--time-window; by default the minimum
            running time to 1.3 x planned, the times a timetable planner uses)."""),
        epilog=textwrap.dedent("""\
            objectives: energy (net kWh), running_time (s), time_error (|T - T_plan|, s),
                        accel_variation (comfort: sum of |a_i - a_(i-1)|, m/s^2; alias jerk),
                        stop_error (m). One objective without a time objective gets the
                        constraint |T - T_plan| <= --time-tolerance (default 1 s).
            algorithms: nsga2, moabc, grnsga2, sms-emoa, moead, nsga3 (several objectives);
                        abc, de, ga, pso (one objective, e.g. with --time-tolerance)

            examples:
              pymoo-rail optimize yizhuang --out out/
              pymoo-rail optimize yizhuang --algorithm grnsga2 --pop-size 60 --n-gen 80 --out out/gr
              pymoo-rail optimize metro-a --objectives energy accel_variation stop_error time_error --encoding braking_onset --out out/m4
              pymoo-rail optimize yizhuang --objectives energy --time-tolerance 1 --algorithm abc --out out/abc
              pymoo-rail optimize --track T.json --train R.json --from 0 --to -1 --time 1500 --out out/t"""))
    p.add_argument("case", metavar="CASE", nargs="?", default=None,
                   help="built-in case name (see 'pymoo-rail cases') or a .toml case file; or give --track ...")
    _add_ttobench_options(p)
    p.add_argument("--algorithm", "-a", default="nsga2", metavar="NAME", help="optimisation algorithm")
    p.add_argument("--pop-size", "-p", type=_positive_int, default=40, metavar="N", help="population size")
    p.add_argument("--n-gen", "-g", type=_positive_int, default=50, metavar="N", help="number of generations")
    p.add_argument("--objectives", "-o", nargs="+", default=["energy", "time_error"], metavar="NAME",
                   help="objectives to minimise")
    p.add_argument("--seed", "-s", type=_seed, default=1, help="random seed (same seed, same result)")
    p.add_argument("--encoding", default="speed_codes", choices=["speed_codes", "switching_points", "braking_onset"],
                   help="decision variables: a speed code per section, regime switching positions, or "
                        "phases with the braking onset and deceleration (a live stop error)")
    p.add_argument("--partition", default="gradient_limit", choices=["gradient_limit", "equal"],
                   help="sections of the speed-code encoding")
    p.add_argument("--n-sections", type=_positive_int, default=None, metavar="N",
                   help="number of equal sections (with --partition equal)")
    p.add_argument("--time-tolerance", type=_positive_float, default=None, metavar="S",
                   help="constraint |T - T_plan| <= S seconds (the single-objective form of Liu (2019)); "
                        "default: 1 s for one objective without running_time or time_error, else none")
    p.add_argument("--weights", type=float, nargs="+", default=None, metavar="W",
                   help="one weight per objective: minimise the weighted sum (Meng et al. (2017))")
    _add_window_arguments(p)
    p.add_argument("--out", default="out", metavar="DIR", help="output directory")
    p.add_argument("--quiet", "-q", action="store_true", help="no progress bar")

    p = sub.add_parser(
        "journey", help="solve a TTOBench journey (timing points) with the exact solver", formatter_class=_Formatter,
        description="Read a TTOBench journey file, its track and a train, find the least-energy run that meets "
                    "every timing point, and write into --out: timing.csv (time and speed at every timing "
                    "point, window and check), trajectory_<k>.csv per section and journey.png.",
        epilog="example:\n  pymoo-rail journey tracks/../journeys/J.json --train trains/CH_Stadler_KISS_SBB.json")
    p.add_argument("journey", metavar="JOURNEY", help="TTOBench journey JSON file, or a .toml journey "
                                                       "(track, train and timing points, docs/ttobench.md)")
    p.add_argument("--track", default=None, metavar="T.json",
                   help="TTOBench track file (default: ../tracks/<associated track>.json next to the journey)")
    p.add_argument("--train", default=None, metavar="R.json", help="TTOBench train file (for a JSON journey)")
    p.add_argument("--curve-model", default="tang2020", choices=["tang2020", "roeckl"], help="curve resistance")
    p.add_argument("--out", default="out", metavar="DIR", help="output directory")

    p = sub.add_parser(
        "reference", help="the exact minimum-energy front of a case", formatter_class=_Formatter,
        description="Compute the exact minimum-energy run for a range of running times (dynamic programming, "
                    "pymoo_rail.optimal) and write optimal_front.csv / .png and the optimal run at the planned "
                    "time (optimal_trajectory.csv, optimal_profile.png).",
        epilog="examples:\n  pymoo-rail reference yizhuang --out out/ref\n"
               "  pymoo-rail reference yizhuang --times 140 150 160 170 --out out/ref")
    p.add_argument("case", metavar="CASE", nargs="?", default=None,
                   help="built-in case name or a .toml case file; or give --track ...")
    _add_ttobench_options(p)
    p.add_argument("--times", type=_positive_float, nargs="+", default=None, metavar="S",
                   help="running times (s); default: --n-points from the minimum time to 1.3 x planned")
    p.add_argument("--n-points", type=_positive_int, default=8, metavar="N", help="number of running times")
    p.add_argument("--out", default="out", metavar="DIR", help="output directory")

    p = sub.add_parser(
        "study", help="run a study file (problems x algorithms x seeds)", formatter_class=_Formatter,
        description="Run every run of a study file not yet stored in --out (an interrupted study resumes "
                    "where it stopped), then write the statistics tables (--out/tables: summary, mean (std) "
                    "per indicator, Wilcoxon rank-sum tests against the baseline) and the figures "
                    "(--out/figures). Same seeds, same results on the local pool and on Dask.",
        epilog=textwrap.dedent("""\
            examples:
              pymoo-rail study examples/study_zdt.toml --workers 2 --out out/zdt
              pymoo-rail study examples/study_zdt.toml --scheduler local --workers 4 --out out/zdt
              pymoo-rail study examples/study_zdt.toml --scheduler tcp://10.0.0.5:8786 --out out/zdt

            See docs/experiments.md for the study file format."""))
    p.add_argument("file", metavar="FILE", help="study file (.toml)")
    p.add_argument("--workers", "-w", type=_positive_int, default=None, metavar="N",
                   help="worker processes (default: all CPUs; 1 runs in this process)")
    p.add_argument("--scheduler", default=None, metavar="ADDRESS",
                   help="run on Dask: 'local' for a LocalCluster of --workers processes, or the address "
                        "of a running scheduler (tcp://host:8786)")
    p.add_argument("--out", default=None, metavar="DIR", help="study directory (default: out/<study name>)")
    p.add_argument("--baseline", default=None, metavar="ALGORITHM",
                   help="algorithm the others are tested against (default: the file's baseline)")
    p.add_argument("--no-plots", action="store_true", help="write the tables only")
    p.add_argument("--seed-major", action="store_true",
                   help="start the runs seed by seed, so a study stopped early has every algorithm on every "
                        "problem for the same seeds (results are the same)")
    p.add_argument("--quiet", "-q", action="store_true", help="no progress bar")

    p = sub.add_parser(
        "timetable", help="several trains sharing braking energy: departures and driving", formatter_class=_Formatter,
        description="Optimise a timetable of trains on a case (pymoo_rail.problems.TimetableProblem): departures "
                    "free within a window around a regular headway, every train's driving shape paced to its "
                    "planned time, regenerated energy shared within one power-supply section. NSGA-II on net "
                    "substation energy and mean passenger waiting time; writes front.csv (with the reference "
                    "of every train exactly optimal alone when --reference is given).",
        epilog="examples:\n  pymoo-rail timetable cooperative-pair --trains 4 --headway 120 --out out/tt\n"
               "  pymoo-rail timetable cooperative-pair --trains 8 --headway 90 --n-eval 4000 --reference")
    p.add_argument("case", metavar="CASE", help="built-in case name or a .toml case file")
    p.add_argument("--trains", type=_positive_int, default=4, metavar="N", help="number of trains (>= 2)")
    p.add_argument("--headway", type=_positive_float, default=120.0, metavar="S", help="nominal headway (s)")
    p.add_argument("--window", type=float, default=30.0, metavar="S", help="departure window +- (s)")
    p.add_argument("--efficiency", type=_positive_float, default=0.9, metavar="ETA",
                   help="transmission efficiency of the supply between trains")
    p.add_argument("--directions", type=int, choices=(1, 2), default=1,
                   help="2: every second train runs the line the other way (same supply section)")
    p.add_argument("--pop-size", type=_positive_int, default=40, metavar="N")
    p.add_argument("--n-eval", type=_positive_int, default=2000, metavar="N", help="evaluations")
    p.add_argument("--seed", type=_seed, default=1)
    p.add_argument("--reference", action="store_true",
                   help="also compute every train's exact optimum alone (about a CPU minute per leg)")
    p.add_argument("--out", default="out", metavar="DIR", help="output directory")

    p = sub.add_parser(
        "warmup", help="compile the simulator's kernels now (container images, clusters)", formatter_class=_Formatter,
        description="Compile the Numba kernels a command uses and store them in Numba's cache (next to the "
                    "installed package, or in NUMBA_CACHE_DIR), so that the first real run starts at once. Run "
                    "it when building a container image, or once before a study on a cluster whose workers "
                    "share the cache directory. Already compiled kernels are only loaded.",
        epilog="examples:\n  pymoo-rail warmup\n  pymoo-rail warmup --all\n"
               "  NUMBA_CACHE_DIR=/shared/numba pymoo-rail warmup --all")
    p.add_argument("--all", action="store_true",
                   help="also the exact reference solver ('reference') and the ATO tracking controllers")
    _add_suite_parser(sub)

    p = sub.add_parser("plot", help="redraw figures from stored results or CSV files", formatter_class=_Formatter,
                       description="Redraw figures without recomputing anything.",
                       epilog=textwrap.dedent("""\
                           examples:
                             pymoo-rail plot study out/zdt
                             pymoo-rail plot front out/front.csv
                             pymoo-rail plot front out/front.csv --x running_time_s --y energy_kwh \\
                                 --reference out/ref/optimal_front.csv
                             pymoo-rail plot trajectory out/trajectory.csv --case yizhuang"""))
    plot_sub = p.add_subparsers(dest="what", metavar="WHAT", title="what to plot")
    q = plot_sub.add_parser("study", help="tables and figures of a study directory", formatter_class=_Formatter)
    q.add_argument("directory", metavar="DIR", help="study directory written by 'pymoo-rail study'")
    q.add_argument("--out", default=None, metavar="DIR", help="where to write (default: DIR)")
    q.add_argument("--baseline", default=None, metavar="ALGORITHM", help="baseline of the rank-sum tests")
    q = plot_sub.add_parser("front", help="a front from front.csv", formatter_class=_Formatter)
    q.add_argument("csv", metavar="CSV", help="front.csv written by 'pymoo-rail optimize'")
    q.add_argument("--x", default=None, metavar="COLUMN", help="column on the x axis (default: first objective)")
    q.add_argument("--y", default=None, metavar="COLUMN", help="column on the y axis (default: second objective)")
    q.add_argument("--reference", default=None, metavar="CSV",
                   help="a reference front to draw as a line (optimal_front.csv, same column names)")
    q.add_argument("--out", default=None, metavar="PNG",
                   help="image file (default: the CSV's name with _plot.png, e.g. front_plot.png, so the "
                        "figure 'optimize' wrote is kept)")
    q = plot_sub.add_parser("trajectory", help="a speed profile from trajectory.csv", formatter_class=_Formatter)
    q.add_argument("csv", metavar="CSV", help="trajectory.csv written by 'pymoo-rail optimize'")
    q.add_argument("--case", default=None, metavar="CASE",
                   help="the case, to draw the line (limits, gradients, neutral sections)")
    q.add_argument("--out", default=None, metavar="PNG", help="image file (default: next to the CSV)")
    return parser


# ------------------------------------------------------------------------------ helpers


def _load_case(argument: str, value: str):
    from pymoo_rail.cases import list_cases, load_case
    from pymoo_rail.model import CaseError

    try:
        return load_case(value)
    except CaseError as err:
        if Path(value).suffix == ".toml" or Path(value).exists():
            raise UsageError(argument, str(err)) from None
        raise UsageError(argument, f"unknown case {value!r} (built-in: {', '.join(list_cases())}; "
                                   "or give the path of a .toml case file)") from None


def _out_dir(value: str) -> Path:
    path = Path(value)
    if path.exists() and not path.is_dir():
        raise UsageError("--out", f"{value!r} exists and is not a directory")
    path.mkdir(parents=True, exist_ok=True)
    return path


def _say(text: str) -> None:
    print(text, flush=True)


def _count(n: int, noun: str) -> str:
    """``1 solution``, ``2 solutions``."""
    return f"{n} {noun}" if n == 1 else f"{n} {noun}s"


# ------------------------------------------------------------------------------ commands


def cmd_cases(args) -> int:
    """``pymoo-rail cases``: list the built-in cases, or describe one; returns the exit code."""
    from pymoo_rail.cases import list_cases, load_case

    if args.case is None:
        rows = []
        for name in list_cases():
            case = load_case(name)
            source = " ".join(case.source.split())
            rows.append((name, f"{case.line.length_m:,.0f} m", f"{case.planned_time_s:g} s",
                         case.train.name or f"{case.train.mass_t:g} t", source[:60] + ("..." if len(source) > 60 else "")))
        widths = [max(len(r[i]) for r in rows + [("case", "length", "planned", "train", "source")]) for i in range(5)]
        header = ("case", "length", "planned", "train", "source")
        for row in [header] + rows:
            _say("  ".join(cell.ljust(w) for cell, w in zip(row, widths)).rstrip())
        _say("\n'pymoo-rail cases NAME' describes one case.")
        return 0
    case = _load_case("CASE", args.case)
    line, train = case.line, case.train
    wrap = lambda text: textwrap.fill(" ".join(text.split()), 96, initial_indent="  ", subsequent_indent="  ")  # noqa: E731
    _say(f"{case.name}")
    if case.description:
        _say(wrap(case.description))
    _say(f"run:    {line.length_m:,.1f} m in {case.planned_time_s:g} s planned"
         + (f" (+{case.time_margin_s:g} s margin)" if case.time_margin_s else "")
         + (f", dwell {case.dwell_s:g} s" if case.dwell_s else "")
         + (f", {len(case.legs)} legs" if case.legs else ""))
    _say(f"train:  {train.name or '-'}: {train.mass_t:g} t, {train.length_m:g} m, max {train.max_speed_kmh:g} km/h")
    limits = ", ".join(f"{a:g}-{b:g} m: {v:g} km/h" for a, b, v in line.speed_limits)
    _say(f"limits: {limits}")
    grads = ", ".join(f"{a:g}-{b:g} m: {g:+g}" for a, b, g in line.gradients)
    _say(textwrap.fill(f"gradients (permille): {grads}", 96, subsequent_indent="  "))
    if line.neutral_sections:
        _say("neutral sections: " + ", ".join(f"{a:g}-{b:g} m" for a, b in line.neutral_sections))
    _say("source:")
    _say(wrap(case.source))
    return 0


def _objectives(values: Sequence[str]) -> tuple[str, ...]:
    for name in values:
        if name not in OBJECTIVES:
            raise UsageError("--objectives", f"unknown objective {name!r} (choose from {', '.join(OBJECTIVES)})")
    if len(set(values)) != len(values):
        raise UsageError("--objectives", f"{' '.join(values)}: an objective is repeated")
    return tuple(values)


class _Progress:
    """pymoo callback that advances a tqdm bar by one per generation."""

    def __init__(self, bar):
        self.bar = bar

    def __call__(self, algorithm) -> None:
        self.bar.update(1)


def _add_ttobench_options(p: argparse.ArgumentParser) -> None:
    """``--track T.json --train R.json --from A --to B --time S``: a TTOBench run instead of CASE."""
    p.add_argument("--track", default=None, metavar="T.json", help="TTOBench track file (instead of CASE)")
    p.add_argument("--train", default=None, metavar="R.json", help="TTOBench train file (with --track)")
    p.add_argument("--from", dest="from_stop", default="0", metavar="A",
                   help="departure stop: index (0, 1, ..., -1 = last) or position in m (e.g. 8500.0)")
    p.add_argument("--to", dest="to_stop", default="-1", metavar="B", help="arrival stop (as --from)")
    p.add_argument("--time", dest="planned_time", type=float, default=None, metavar="S",
                   help="planned running time in s; without it, 1.15 x the minimum running time")
    p.add_argument("--curve-model", default="tang2020", choices=["tang2020", "roeckl"],
                   help="curve resistance of the track's curvatures")


def _stop_ref(value: str):
    try:
        return int(value)
    except ValueError:
        try:
            return float(value)
        except ValueError:
            raise UsageError("--from/--to", f"{value!r} is neither a stop index nor a position in m") from None


def _case_from_args(args):
    """The case of CASE, or of --track/--train/--from/--to/--time."""
    if args.track is None:
        if args.train is not None:
            raise UsageError("--train", "needs --track")
        if args.case is None:
            raise UsageError("CASE", "give a case name or file, or --track T.json --train R.json")
        return _load_case("CASE", args.case)
    if args.case is not None:
        raise UsageError("CASE", "give either CASE or --track, not both")
    if args.train is None:
        raise UsageError("--train", "--track needs --train R.json")
    from pymoo_rail.cases.ttobench import from_ttobench
    from pymoo_rail.optimal import min_running_time

    case = from_ttobench(args.track, args.train, _stop_ref(args.from_stop), _stop_ref(args.to_stop), 1.0,
                         curve_model=args.curve_model)
    time_s = args.planned_time if args.planned_time is not None else 1.15 * min_running_time(case)
    return case.with_planned_time(time_s)


def cmd_journey(args) -> int:
    """``pymoo-rail journey``: solve a multi-stop journey with timing points; returns the exit code."""
    from pymoo_rail.journeys.timing import (read_timing_points, solve_timed_journey, timed_journey_from_toml,
                                            timed_journey_from_ttobench)
    from pymoo_rail.plotting.journey import plot_timed_run
    from pymoo_rail.plotting import save_figure

    import pandas as pd

    out = _out_dir(args.out)
    if args.journey.endswith(".toml"):
        timed = timed_journey_from_toml(args.journey)
    else:
        if args.train is None:
            raise UsageError("--train", "a TTOBench journey file names no train: give --train R.json")
        track = args.track
        if track is None:
            _, track_id, _, _ = read_timing_points(args.journey)
            track = Path(args.journey).resolve().parent.parent / "tracks" / f"{track_id}.json"
        timed = timed_journey_from_ttobench(args.journey, track, args.train, curve_model=args.curve_model)
    run = solve_timed_journey(timed)
    pd.DataFrame(list(run.checks)).to_csv(out / "timing.csv", index=False)
    for k, traj in enumerate(run.trajectories):
        traj.to_frame().to_csv(out / f"trajectory_{k}.csv", index=False)
    save_figure(plot_timed_run(timed, run), out / "journey.png")
    _say(f"{timed.journey.name}: {run.energy_kwh:.2f} kWh net, every timing point met; wrote {out}/timing.csv, "
         f"trajectory_*.csv, journey.png")
    return 0


def cmd_optimize(args) -> int:
    """``pymoo-rail optimize``: run one algorithm on one case and write the front, the chosen run and figures;
    returns the exit code.
    """
    import numpy as np
    import pandas as pd
    from pymoo.optimize import minimize
    from tqdm import tqdm

    from pymoo_rail.experiments.fronts import distinct_front
    from pymoo_rail.experiments.registry import algorithm_names, build_algorithm, canonical_name, ALGORITHMS
    from pymoo_rail.experiments.spec import AlgorithmSpec, StudyError
    from pymoo_rail.model import CaseError
    from pymoo_rail.plotting import plot_front, plot_speed_profile, plot_speed_time, save_figure
    from pymoo_rail.problems import SpeedProfileProblem

    case = _case_from_args(args)
    objectives = _objectives(args.objectives)
    if canonical_name(args.algorithm) not in ALGORITHMS:
        raise UsageError("--algorithm", f"unknown algorithm {args.algorithm!r} (choose from "
                                        f"{', '.join(algorithm_names())})")
    if args.weights is not None and len(args.weights) != len(objectives):
        raise UsageError("--weights", f"{len(args.weights)} weights for {len(objectives)} objectives "
                                      f"({' '.join(objectives)}): give one weight per objective")
    if args.n_sections is not None and args.partition != "equal":
        raise UsageError("--n-sections", "only applies with --partition equal")
    time_tolerance_s = args.time_tolerance
    if time_tolerance_s is None and len(objectives) == 1 and args.weights is None \
            and objectives[0] not in TIME_OBJECTIVES:
        # one objective that ignores the running time: without this the run may take any time
        time_tolerance_s = DEFAULT_TIME_TOLERANCE_S
        _say(f"time constraint |T - T_plan| <= {time_tolerance_s:g} s (the default for one objective; "
             "set it with --time-tolerance)")
    out = _out_dir(args.out)

    kwargs = {"objectives": objectives, "encoding": args.encoding, "partition": args.partition,
              "time_tolerance_s": time_tolerance_s}
    if args.n_sections is not None:
        kwargs["n_sections"] = args.n_sections
    if args.weights is not None:
        kwargs["weights"] = args.weights
    kwargs["time_window_s"] = _time_window(args, objectives)
    try:
        problem = SpeedProfileProblem(case, **kwargs)
    except CaseError as err:  # the case cannot be run (e.g. a planned time below the minimum): not an option's fault
        raise UsageError("CASE", str(err)) from None
    except ValueError as err:  # the message names the parameter; blame --objectives only for its own
        raise UsageError("--objectives" if "objective" in str(err) else "options", str(err)) from None
    try:
        algorithm = build_algorithm(AlgorithmSpec(args.algorithm, {"pop_size": args.pop_size}), problem)
    except StudyError as err:
        raise UsageError("--algorithm", f"{args.algorithm!r}: {err.reason}") from None
    except ValueError as err:
        raise UsageError("--pop-size", f"{args.pop_size} with {args.algorithm}: {err}") from None

    _say(f"{problem.describe()}\n{args.algorithm}, population {args.pop_size}, {args.n_gen} generations, "
         f"seed {args.seed}")
    with tqdm(total=args.n_gen, desc=f"optimize {case.name}", unit="gen", disable=args.quiet) as bar:
        res = minimize(problem, algorithm, ("n_gen", args.n_gen), seed=args.seed, verbose=False,
                       callback=_Progress(bar))

    opt = distinct_front(res.algorithm.opt)  # one member per objective vector
    X = np.asarray(opt.get("X"), dtype=float)
    F = np.asarray(opt.get("F"), dtype=float)
    CV = np.asarray(opt.get("CV"), dtype=float).reshape(-1)
    trajectories = [problem.trajectory(x) for x in X]
    running = np.array([t.running_time_s for t in trajectories])
    energy = np.array([t.energy.net_kwh for t in trajectories])
    order = np.lexsort((energy, running))
    X, F, CV, running, energy = X[order], F[order], CV[order], running[order], energy[order]
    trajectories = [trajectories[i] for i in order]

    unit = "kmh" if args.encoding == "speed_codes" else "m"
    objective_cols = ([f"f_{name}" for name in objectives] if problem.n_obj == len(objectives)
                      else ["f_weighted_sum"])
    front = pd.DataFrame(F, columns=objective_cols)
    front["running_time_s"] = running
    front["energy_kwh"] = energy
    front["stop_error_m"] = [t.stop_error_m for t in trajectories]
    front["accel_variation_ms2"] = [t.accel_variation_ms2 for t in trajectories]
    front["feasible"] = CV <= 0
    front["cv"] = CV
    for j in range(X.shape[1]):
        front[f"x{j}_{unit}"] = X[:, j]
    from pymoo_rail.experiments.fronts import choose_member  # the one member rule (studies use it too)

    chosen = choose_member(F, CV, running, energy, case.planned_time_s,
                           time_tolerance_s if time_tolerance_s is not None else DEFAULT_TIME_TOLERANCE_S)
    front.insert(0, "chosen", np.arange(len(front)) == chosen)
    trajectory = trajectories[chosen]

    written = [out / "front.csv", out / "trajectory.csv"]
    front.to_csv(written[0], index=False)
    trajectory.to_frame().to_csv(written[1], index=False)
    label = f"{args.algorithm}, seed {args.seed}"
    optimum = _optimum_for(problem, trajectory, args)
    if F.shape[1] >= 2:  # 4 or more objectives: a scatter matrix
        written.append(save_figure(plot_front(F, objectives, highlight=F[chosen], label=label,
                                              reference=optimum.get("front"),
                                              title=f"{case.name}: front after {res.algorithm.evaluator.n_eval} "
                                                    "evaluations"), out / "front.png"))
    others = [optimum["profile"]] if "profile" in optimum else []
    written.append(save_figure(plot_speed_profile(trajectory, case, label=args.algorithm, others=others,
                                                  other_labels=["optimal run at the same time"],
                                                  other_linestyle="--"), out / "profile.png"))
    written.append(save_figure(plot_speed_time(trajectory, case), out / "speed_time.png"))

    n_feasible = int((CV <= 0).sum())
    _say(f"front: {_count(len(front), 'solution')} ({n_feasible} feasible), "
         f"{_count(res.algorithm.evaluator.n_eval, 'evaluation')}")
    _say(f"chosen: running time {trajectory.running_time_s:.2f} s (planned {case.planned_time_s:g} s), "
         f"energy {trajectory.energy.net_kwh:.3f} kWh, stop error {trajectory.stop_error_m:.3f} m"
         + ("" if CV[chosen] <= 0 else "  [INFEASIBLE: no feasible solution found]"))
    _say(optimum["message"])
    for path in written:
        _say(f"wrote {path}")
    return 0


def _add_window_arguments(p) -> None:
    p.add_argument("--time-window", nargs="+", default=["default"], metavar="S",
                   help="running-time window constraint LO HI in seconds; 'default' (the minimum running time "
                        "to 1.3 x planned, where the certified optimal front is known: the times a timetable "
                        "planner uses) or 'none'; applies to running_time / time_error fronts")
    p.add_argument("--no-reference", action="store_true",
                   help="skip the certified optimal front, the optimal profile and the gap to the optimum")


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


def _optimum_for(problem, trajectory, args) -> dict:
    """The certified front in objective space, the optimal run at the chosen member's time, and the gap."""
    from pymoo_rail.problems import reference

    if args.no_reference:
        return {"message": "optimum: skipped (--no-reference)"}
    try:
        front = problem.certified_front()
    except reference.NoExactFrontError as err:
        return {"message": f"optimum: none certified for this form ({str(err).split('no exact front: ')[-1]})"}
    result = {}
    if problem.n_obj == 2:
        result["front"], _ = reference.mirrored(front, problem.objectives, 200, problem.time_window_s)
    lo, hi = front.time_range_s
    t = trajectory.running_time_s
    if not lo <= t <= hi:
        result["message"] = (f"optimum: the chosen run's {t:.2f} s lies outside the certified front's "
                             f"{lo:.2f}-{hi:.2f} s; no gap reported")
        return result
    (energy,), (bound,) = front.energy_at(t)
    gap = trajectory.energy.net_kwh - energy
    result["message"] = (f"gap to the optimum at {t:.2f} s: {gap:+.3f} kWh ({100 * gap / abs(energy):+.2f} %); "
                         f"optimum {energy:.3f} kWh (certified within {bound:.3f} kWh, {front.certificate})")
    try:
        from pymoo_rail.optimal import optimal_profile

        result["profile"] = optimal_profile(problem.case, t)
    except ValueError as err:  # a time the solver's grid cannot hit closely: the figure goes without it
        result["message"] += f"; no optimal profile drawn ({err})"
    return result


def _default_times(t_min: float, planned_time_s: float, n_points: int):
    import numpy as np

    upper = max(1.3 * planned_time_s, 1.1 * t_min)
    return np.linspace(1.01 * t_min, upper, n_points)


def cmd_reference(args) -> int:
    """``pymoo-rail reference``: the exact optimal front and profile of a case; returns the exit code."""
    case = _case_from_args(args)
    try:
        from pymoo_rail.optimal import optimal_front, optimal_profile
    except ImportError as err:
        raise RuntimeError("'pymoo-rail reference' needs the exact reference solver pymoo_rail.optimal "
                           f"(optimal_front, optimal_profile), which this installation lacks: {err}") from None
    import numpy as np

    from pymoo_rail.model import InfeasibleCaseError
    from pymoo_rail.optimal import min_running_time
    from pymoo_rail.plotting import plot_fronts, plot_speed_profile, save_figure

    try:  # every check before any computing or writing
        t_min = float(min_running_time(case))
    except InfeasibleCaseError as err:
        raise UsageError("CASE", str(err)) from None
    if args.times is not None:
        times = np.asarray(args.times, dtype=float)
        too_short = times[times < t_min]
        if too_short.size:
            raise UsageError("--times", f"{too_short.min():g} s is below the minimum running time {t_min:.2f} s "
                                        f"of {case.name} (flat out): give times of at least {t_min:.2f} s")
    else:
        times = _default_times(t_min, case.planned_time_s, args.n_points)
    if case.planned_time_s < t_min:
        raise UsageError("CASE", f"planned_time_s = {case.planned_time_s:g} s of {case.name} is below its minimum "
                                 f"running time {t_min:.2f} s (flat out)")
    out = _out_dir(args.out)
    _say(f"{case.name}: exact minimum-energy runs for {len(times)} running times "
         f"({times.min():.1f}-{times.max():.1f} s)")
    front = optimal_front(case, times)
    front.to_csv(out / "optimal_front.csv", index=False)
    points = front[["running_time_s", "energy_kwh"]].to_numpy(float)
    written = [out / "optimal_front.csv",
               save_figure(plot_fronts({"optimal": points}, ["running_time", "energy"], reference=points,
                                       reference_label="optimal front", title=f"{case.name}: minimum energy "
                                                                               "against running time"),
                           out / "optimal_front.png")]
    trajectory = optimal_profile(case, case.planned_time_s)
    trajectory.to_frame().to_csv(out / "optimal_trajectory.csv", index=False)
    written.append(out / "optimal_trajectory.csv")
    written.append(save_figure(plot_speed_profile(trajectory, case, label="optimal"), out / "optimal_profile.png"))
    _say(f"at the planned {case.planned_time_s:g} s: {trajectory.energy.net_kwh:.3f} kWh "
         f"(running time {trajectory.running_time_s:.2f} s)")
    for path in written:
        _say(f"wrote {path}")
    return 0


def cmd_timetable(args) -> int:
    """``pymoo-rail timetable``: optimise the departure times of a line's trains; returns the exit code."""
    import numpy as np
    import pandas as pd
    from pymoo.algorithms.moo.nsga2 import NSGA2
    from pymoo.optimize import minimize

    from pymoo_rail.problems import TimetableProblem

    case = _load_case("CASE", args.case)
    if args.trains < 2:
        raise UsageError("--trains", f"needs at least 2 trains, got {args.trains}")
    problem = TimetableProblem(case, args.trains, args.headway, window_s=args.window,
                               transmission_efficiency=args.efficiency, directions=args.directions)
    _say(problem.describe())
    res = minimize(problem, NSGA2(pop_size=args.pop_size), ("n_eval", args.n_eval), seed=args.seed)
    opt = res.algorithm.opt
    front = pd.DataFrame({"net_kwh": opt.get("net_kwh"), "waiting_time_s": opt.get("waiting_time_s"),
                          "traction_kwh": opt.get("traction_kwh"), "shared_kwh": opt.get("shared_kwh"),
                          "cv": opt.get("CV")[:, 0]})
    for i in range(args.trains - 1):
        front[f"shift_{i + 1}_s"] = opt.get("X")[:, i]
    if args.reference:
        reference = problem.reference_kwh()
        front["reference_kwh"] = reference
        front["saving_pct"] = 100.0 * (1.0 - front["net_kwh"] / reference)
        _say(f"reference (every train exactly optimal alone, nothing shared): {reference:.3f} kWh")
    out = _out_dir(args.out)
    front = front.sort_values("net_kwh").reset_index(drop=True)
    front.to_csv(out / "front.csv", index=False)
    best = front.iloc[0]
    _say(f"{len(front)} solutions; least energy {best['net_kwh']:.3f} kWh ({best['shared_kwh']:.3f} kWh shared, "
         f"mean wait {best['waiting_time_s']:.1f} s); regular timetable wait "
         f"{args.headway * args.directions / 2:.1f} s")
    _say(f"wrote {out / 'front.csv'}")
    return 0 if np.all(front["cv"] <= 0) else 1


def _study_outputs(directory: Path, out: Path, baseline: str | None, plots: bool) -> list[Path]:
    from pymoo_rail.experiments import load_results
    from pymoo_rail.experiments.stats import write_tables
    from pymoo_rail.plotting import plot_study

    results = load_results(directory)
    if results.empty:
        raise RuntimeError(f"no stored runs in {directory}")
    algorithms = sorted(results["algorithm"].unique())
    if baseline is not None and baseline not in algorithms:
        raise UsageError("--baseline", f"unknown algorithm {baseline!r} (the study has {', '.join(algorithms)})")
    written = write_tables(results, out / "tables", baseline=baseline)
    if plots:
        written += plot_study(results, out / "figures")
    return written


def cmd_study(args) -> int:
    """``pymoo-rail study``: run (or resume) a study file and write its tables; returns the exit code."""
    from pymoo_rail.experiments import read_study, run_study
    from pymoo_rail.experiments.spec import StudyError

    try:
        study = read_study(args.file)
    except StudyError as err:
        raise UsageError("FILE", str(err)) from None
    baseline = args.baseline or study.baseline
    if baseline is not None and baseline not in {a.display for a in study.algorithms}:
        raise UsageError("--baseline", f"unknown algorithm {baseline!r} (the study has "
                                       f"{', '.join(a.display for a in study.algorithms)})")
    out = _out_dir(args.out or str(Path("out") / study.name))
    where = f"Dask scheduler {args.scheduler}" if args.scheduler else "a local process pool"
    _say(f"study {study.name}: {len(study.problems)} problems x {len(study.algorithms)} algorithms x "
         f"{len(study.seeds)} seeds = {len(study.runs())} runs on {where}; results in {out}")
    try:
        report = run_study(study, out, workers=args.workers, scheduler=args.scheduler, progress=not args.quiet,
                           seed_major=args.seed_major)
    except StudyError as err:
        raise UsageError("--scheduler" if err.field == "scheduler" else "FILE", str(err)) from None
    _say(str(report))
    written = _study_outputs(out, out, baseline, plots=not args.no_plots)
    _say(f"wrote {len(written)} tables and figures under {out / 'tables'}"
         + ("" if args.no_plots else f" and {out / 'figures'}"))
    return 0 if not report.failures else 1


def cmd_plot(args, parser: argparse.ArgumentParser) -> int:
    """``pymoo-rail plot``: draw a front or a trajectory from the files ``optimize`` wrote; returns the exit code."""
    import pandas as pd

    from pymoo_rail.plotting import plot_fronts, plot_speed_profile, save_figure

    if args.what is None:
        raise UsageError("WHAT", "say what to plot: study, front or trajectory")
    if args.what == "study":
        directory = Path(args.directory)
        if not (directory / "runs").is_dir():
            raise UsageError("DIR", f"{str(directory)!r} is not a study directory (no runs/ folder)")
        out = _out_dir(args.out) if args.out else directory
        written = _study_outputs(directory, out, args.baseline, plots=True)
        for path in written:
            _say(f"wrote {path}")
        return 0
    csv = Path(args.csv)
    if not csv.is_file():
        raise UsageError("CSV", f"no such file: {str(csv)!r}")
    table = pd.read_csv(csv)
    if args.what == "front":
        objectives = [c for c in table.columns if c.startswith("f_")]
        x = args.x or (objectives[0] if objectives else None)
        y = args.y or (objectives[1] if len(objectives) > 1 else None)
        for argument, column in (("--x", x), ("--y", y)):
            if column is None or column not in table.columns:
                raise UsageError(argument, f"column {column!r} is not in {csv.name} (columns: {', '.join(table.columns)})")
        names = [_objective_of_column(x), _objective_of_column(y)]
        highlight = None
        if "chosen" in table.columns and table["chosen"].any():
            highlight = table.loc[table["chosen"].astype(bool), [x, y]].to_numpy(float)[0]
        reference = None
        if args.reference:
            ref = pd.read_csv(args.reference)
            missing = [c for c in (x, y) if c not in ref.columns]
            if missing:
                raise UsageError("--reference", f"{args.reference!r} lacks column(s) {missing}")
            reference = ref[[x, y]].to_numpy(float)
        fig = plot_fronts({csv.stem: table[[x, y]].to_numpy(float)}, names, reference=reference,
                          highlight=highlight, reference_label="reference front")
        # not front.png: that is the figure 'optimize' wrote next to front.csv
        path = save_figure(fig, Path(args.out) if args.out else csv.with_name(f"{csv.stem}_plot.png"))
    else:
        case = _load_case("--case", args.case) if args.case else None
        try:
            fig = plot_speed_profile(table, case)
        except ValueError as err:
            raise UsageError("CSV", str(err)) from None
        path = save_figure(fig, Path(args.out) if args.out else csv.with_suffix(".png"))
    _say(f"wrote {path}")
    return 0


def _run(commands: dict, args, parser: argparse.ArgumentParser) -> int:
    if args.command == "plot":
        return cmd_plot(args, parser)
    return commands[args.command](args)


def _objective_of_column(column: str) -> str:
    """Axis label key of a front column: ``f_energy`` -> energy, ``running_time_s`` -> running_time."""
    if column.startswith("f_"):
        return column[2:]
    for name, col in OBJECTIVE_COLUMNS.items():
        if column == col:
            return name
    return column


def cmd_warmup(args) -> int:
    """``pymoo-rail warmup``: compile the Numba kernels ahead of the first run; returns the exit code."""
    from pymoo_rail.warmup import WARMUP_PARTS, warmup

    parts = WARMUP_PARTS if args.all else ("simulator",)
    for part, seconds in warmup(parts).items():
        _say(f"{part}: ready ({seconds:.1f} s)")
    return 0


COMPILING_COMMANDS = ("optimize", "optimise", "reference", "warmup", "plot", "suite", "journey")


def _add_suite_parser(sub) -> None:
    p = sub.add_parser(
        "suite", help="the benchmark suite: list its problems, verify its shipped fronts", formatter_class=_Formatter,
        description="The benchmark suite (pymoo_rail.suite, docs/suite.md): rail problems with certified exact "
                    "fronts. 'list' prints the problems; 'verify' solves every shipped front again and exits 1 "
                    "if any node drifts beyond its certificate (minutes per long line).",
        epilog="examples:\n  pymoo-rail suite list\n  pymoo-rail suite verify metro-a yizhuang")
    p.add_argument("action", choices=["list", "verify"], help="what to do")
    p.add_argument("cases", nargs="*", metavar="CASE", help="suite cases to verify (default: all)")


def cmd_suite(args) -> int:
    """``pymoo-rail suite``: list, describe or verify the benchmark suite's problems; returns the exit code."""
    from pymoo_rail.problems.reference import find_front
    from pymoo_rail.suite import CASES, list_problems, suite_case, verify
    from pymoo_rail.suite.problems import split

    if args.action == "list":
        for name in list_problems():
            entry, form = split(name)
            case = suite_case(entry.name)
            if form == "4obj":
                front = "best-known front (no exact front for four objectives)"
            else:
                path = find_front(case)
                front = f"certified front {path.name}" if path is not None else "front computed on first use"
            _say(f"{name:42s} {form:6s} {case.line.length_m:8.0f} m  {case.planned_time_s:6.0f} s  {front}")
        return 0
    known = [c.name for c in CASES]
    for name in args.cases:
        if name not in known:
            raise UsageError("CASE", f"unknown suite case {name!r} (known: {', '.join(known)})")
    report = verify(args.cases or None)
    for case_name, rows in report.groupby("case", sort=False):
        if "drift_kwh" in rows and rows["drift_kwh"].notna().any():
            _say(f"{case_name:32s} {'ok' if rows['ok'].all() else 'DRIFT'}: largest drift "
                 f"{rows['drift_kwh'].max():.4g} kWh, smallest certificate {rows['certificate_kwh'].min():.4g} kWh")
        else:
            _say(f"{case_name:32s} FAILED: {rows['problem'].iloc[0]}")
    return 0 if bool(report["ok"].all()) else 1


def main(argv: Sequence[str] | None = None) -> int:
    """Entry point of ``pymoo-rail``; returns the exit code (0 ok, 1 failure, 2 bad arguments)."""
    parser = build_parser()
    try:
        args = parser.parse_args(argv)
    except SystemExit as exit_:  # --help, or argparse's own usage errors (already printed)
        return int(exit_.code or 0)
    if args.command is None:
        parser.print_help()
        return 2
    commands = {"cases": cmd_cases, "optimize": cmd_optimize, "optimise": cmd_optimize, "reference": cmd_reference,
                "study": cmd_study, "warmup": cmd_warmup, "suite": cmd_suite, "journey": cmd_journey, "timetable": cmd_timetable}
    subparser = parser._subparsers._group_actions[0].choices[args.command]  # for its usage line
    try:
        if args.command not in COMPILING_COMMANDS:
            return _run(commands, args, parser)
        from tqdm import tqdm

        from pymoo_rail.sim.jit import compile_notice

        # a first run compiles the kernels: say so (tqdm.write keeps a progress bar intact)
        with compile_notice(say=lambda text: tqdm.write(text, file=sys.stderr)):
            return _run(commands, args, parser)
    except UsageError as err:
        if args.command == "plot" and getattr(args, "what", None):
            subparser = subparser._subparsers._group_actions[0].choices[args.what]
        subparser.print_usage(sys.stderr)
        print(f"{subparser.prog}: error: argument {err.argument}: {err}", file=sys.stderr)
        return 2
    except KeyboardInterrupt:
        print("pymoo-rail: interrupted (a study keeps every run it finished; run it again to resume)",
              file=sys.stderr)
        return 130
    except Exception as err:  # noqa: BLE001 - one clear line unless --debug
        if args.debug:
            raise
        print(f"pymoo-rail {args.command}: error: {type(err).__name__}: {err}", file=sys.stderr)
        return 1


if __name__ == "__main__":  # pragma: no cover
    sys.exit(main())
