"""``pymoo-rail optimize``: one algorithm on one case; writes the front, the chosen run and figures.

The pipeline is :func:`pymoo_rail.experiments.optimize.optimize_profile`; this module parses,
calls it, writes the files and prints.
"""

from __future__ import annotations

import textwrap
from pathlib import Path

from pymoo_rail.cli.arguments import add_command, count, out_dir, say
from pymoo_rail.cli.case_options import add_case_arguments, case_from_args
from pymoo_rail.cli.problem_options import add_problem_arguments, algorithm_from_args, problem_from_args

ORDER = 20

DESCRIPTION = textwrap.dedent("""\
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
    running time to 1.3 x planned, the times a timetable planner uses).""")

EPILOG = textwrap.dedent("""\
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
      pymoo-rail optimize --track T.json --train R.json --from 0 --to -1 --time 1500 --out out/t""")


def add_parser(sub) -> None:
    """Add ``optimize`` (alias ``optimise``) to the subcommands."""
    p = add_command(sub, "optimize", run, compiles=True, aliases=("optimise",),
                    help="optimise the speed profile of a case", description=DESCRIPTION, epilog=EPILOG)
    add_case_arguments(p)
    add_problem_arguments(p)
    p.add_argument("--out", default="out", metavar="DIR", help="output directory")
    p.add_argument("--quiet", "-q", action="store_true", help="no progress bar")


class _Progress:
    """pymoo callback that advances a tqdm bar by one per generation."""

    def __init__(self, bar):
        self.bar = bar

    def __call__(self, algorithm) -> None:
        self.bar.update(1)


def _write(result, out: Path, algorithm: str, seed: int) -> list[Path]:
    """front.csv, trajectory.csv and the figures of an optimisation; returns the files written."""
    from pymoo_rail.plotting import plot_front, plot_speed_profile, plot_speed_time, save_figure

    problem, trajectory, optimum = result.problem, result.trajectory, result.optimum
    written = [out / "front.csv", out / "trajectory.csv"]
    result.front.to_csv(written[0], index=False)
    trajectory.to_frame().to_csv(written[1], index=False)
    F = result.F
    if F.shape[1] >= 2:  # 4 or more objectives: a scatter matrix
        figure = plot_front(F, problem.objectives, highlight=F[result.chosen], label=f"{algorithm}, seed {seed}",
                            reference=optimum.front_F,
                            title=f"{problem.case.name}: front after {result.n_eval} evaluations")
        written.append(save_figure(figure, out / "front.png"))
    others = [optimum.profile] if optimum.profile is not None else []
    written.append(save_figure(plot_speed_profile(trajectory, problem.case, label=algorithm,
                                                  others=others, other_labels=["optimal run at the same time"],
                                                  other_linestyle="--"), out / "profile.png"))
    written.append(save_figure(plot_speed_time(trajectory, problem.case), out / "speed_time.png"))
    return written


def _report(result) -> None:
    trajectory, case = result.trajectory, result.problem.case
    say(f"front: {count(len(result.front), 'solution')} ({result.n_feasible} feasible), "
        f"{count(result.n_eval, 'evaluation')}")
    feasible = bool(result.front["feasible"].iloc[result.chosen])
    say(f"chosen: running time {trajectory.running_time_s:.2f} s (planned {case.planned_time_s:g} s), "
        f"energy {trajectory.energy.net_kwh:.3f} kWh, stop error {trajectory.stop_error_m:.3f} m"
        + ("" if feasible else "  [INFEASIBLE: no feasible solution found]"))
    say(result.optimum.message)


def run(args) -> int:
    """Optimise the case of ``args`` and write the front, the chosen run and figures; returns the exit code."""
    from tqdm import tqdm

    from pymoo_rail.experiments.optimize import optimize_profile

    case = case_from_args(args)
    problem = problem_from_args(case, args)
    algorithm = algorithm_from_args(problem, args)
    out = out_dir(args.out)
    say(f"{problem.describe()}\n{args.algorithm}, population {args.pop_size}, {args.n_gen} generations, "
        f"seed {args.seed}")
    with tqdm(total=args.n_gen, desc=f"optimize {case.name}", unit="gen", disable=args.quiet) as bar:
        result = optimize_profile(problem, algorithm, ("n_gen", args.n_gen), seed=args.seed,
                                  callback=_Progress(bar), reference=not args.no_reference)
    written = _write(result, out, args.algorithm, args.seed)
    _report(result)
    for path in written:
        say(f"wrote {path}")
    return 0
