"""``pymoo-rail optimize``: one algorithm on one case; writes the front, the chosen run and figures.

The pipeline is :func:`pymoo_rail.experiments.optimize.optimize_profile`; this module parses,
calls it, writes the files and prints.
"""

from __future__ import annotations

import textwrap
from contextlib import contextmanager
from pathlib import Path
from typing import Iterator

from pymoo_rail.cli.arguments import add_command, count, out_dir, say
from pymoo_rail.cli.case_options import add_case_arguments, case_from_args
from pymoo_rail.cli.progress import GenerationBar, ticking
from pymoo_rail.cli.problem_options import add_problem_arguments, algorithm_from_args, problem_from_args
from pymoo_rail.problems.encodings import encodings_help
from pymoo_rail.problems.objectives import objectives_help

ORDER = 20

COMPILE_NOTICE = ("compiling the simulator and the exact solver (first run only: Numba compiles the kernels of the "
                  "simulation, the batch evaluation and the dynamic programme once, about 18 s of CPU on a 2-core "
                  "machine, and caches them on disk) ...")

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

EPILOG = "\n".join([
    "objectives:",
    textwrap.indent(objectives_help(), "  "),
    "  One objective without a time objective gets the constraint |T - T_plan| <= --time-tolerance",
    "  (default 1 s).",
    "encodings:",
    textwrap.indent(encodings_help(), "  "),
    "  --partition and --n-sections set the sections of speed_codes and paced_speed_codes.",
    ""]) + textwrap.dedent("""\
    algorithms: nsga2, moabc, grnsga2, sms-emoa, age-moea, nsga3, moead (several
                objectives; moead has no constraint handling: it searches with the
                constraints as a penalty); abc, de, ga, pso (one objective, e.g. with
                --time-tolerance)

    examples:
      pymoo-rail optimize yizhuang --out out/
      pymoo-rail optimize yizhuang --algorithm grnsga2 --pop-size 60 --n-gen 80 --out out/gr
      pymoo-rail optimize metro-a --objectives energy accel_variation stop_error time_error --encoding braking_onset --out out/m4
      pymoo-rail optimize yizhuang --objectives energy --time-tolerance 1 --algorithm abc --out out/abc
      pymoo-rail optimize --track T.json --train R.json --from 0 --to -1 --time 1500 --out out/t""")


def add_parser(sub) -> None:
    """Add ``optimize`` (alias ``optimise``) to the subcommands."""
    p = add_command(sub, "optimize", run, compiles=COMPILE_NOTICE, aliases=("optimise",),
                    help="optimise the speed profile of a case", description=DESCRIPTION, epilog=EPILOG)
    add_case_arguments(p)
    add_problem_arguments(p)
    p.add_argument("--out", default="out", metavar="DIR", help="output directory")
    p.add_argument("--quiet", "-q", action="store_true", help="no progress bar")


def _write_tables(result, out: Path) -> list[Path]:
    """front.csv and trajectory.csv: written before the exact reference runs, so a failure there loses nothing."""
    written = [out / "front.csv", out / "trajectory.csv"]
    result.front.to_csv(written[0], index=False)
    result.trajectory.to_frame().to_csv(written[1], index=False)
    return written


def _profile_label(optimum, trajectory) -> str:
    if abs(optimum.profile.running_time_s - trajectory.running_time_s) <= 0.5:
        return "optimal run at the same time"
    return f"optimal run at {optimum.profile.running_time_s:.2f} s"


def _write_figures(result, out: Path, algorithm: str, seed: int) -> list[Path]:
    """front.png (two or more objectives), profile.png and speed_time.png; returns the files written."""
    from pymoo_rail.plotting import plot_front, plot_speed_profile, plot_speed_time, save_figure

    problem, trajectory, optimum = result.problem, result.trajectory, result.optimum
    written = []
    F = result.F
    if F.shape[1] >= 2:  # 4 or more objectives: a scatter matrix
        figure = plot_front(F, problem.objectives, highlight=F[result.chosen], label=f"{algorithm}, seed {seed}",
                            reference=optimum.front_F,
                            title=f"{problem.case.name}: front after {result.n_eval} evaluations")
        written.append(save_figure(figure, out / "front.png"))
    others, labels = ([optimum.profile], [_profile_label(optimum, trajectory)]) if optimum.profile else ([], [])
    written.append(save_figure(plot_speed_profile(trajectory, problem.case, label=algorithm, others=others,
                                                  other_labels=labels, other_linestyle="--"), out / "profile.png"))
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


SERIAL_MAX_CELLS = 50_000_000
"""Below this many simulated cells (population x generations x grid nodes) a run uses one thread.

At about 14 ns per cell (``benchmarks/throughput.py``) that is under a second of simulation,
while compiling the parallel batch kernel costs about 6 s of CPU on a first run
(``benchmarks/compile_profile.py`` with and without ``NUMBA_NUM_THREADS=1``); results are the same.
"""


@contextmanager
def _threads_for(problem, args) -> Iterator[None]:
    """One Numba thread for a small job (see :data:`SERIAL_MAX_CELLS`), the machine's otherwise."""
    import numba

    cells = args.pop_size * args.n_gen * problem.simulator.grid.n_nodes
    before = numba.get_num_threads()
    if cells < SERIAL_MAX_CELLS:
        numba.set_num_threads(1)
    try:
        yield
    finally:
        numba.set_num_threads(before)


def _load_kernels(problem, n_rows: int) -> None:
    """Evaluate a population's worth of one decision and trace its run: a first run compiles here, before the bar.

    ``n_rows`` as many as a generation evaluates, so the batch takes the same (serial or parallel) kernel.
    """
    import numpy as np

    x = (problem.xl + problem.xu) / 2.0
    problem.evaluate(np.repeat(x[None, :], n_rows, axis=0))
    problem.trajectory(x)


def _optimize(args, written: list[Path]) -> None:
    """The command's work; ``written`` collects the files as they are written (an interruption names them)."""
    from dataclasses import replace

    from tqdm import tqdm

    from pymoo_rail.experiments.optimize import optimize_profile, optimum_at

    case = case_from_args(args)
    problem = problem_from_args(case, args)
    algorithm, penalty = algorithm_from_args(problem, args)
    out = out_dir(args.out)
    say(f"{problem.describe()}\n{args.algorithm}, population {args.pop_size}, {args.n_gen} generations, "
        f"seed {args.seed}")
    with _threads_for(problem, args):
        with ticking("preparing the simulator", disable=args.quiet):
            _load_kernels(problem, args.pop_size)  # so that the bar's rate and ETA are the search's own
        with tqdm(total=args.n_gen, desc=f"optimize {case.name}", unit="gen", disable=args.quiet) as bar:
            result = optimize_profile(problem, algorithm, ("n_gen", args.n_gen), seed=args.seed,
                                      callback=GenerationBar(bar), reference=False, penalty=penalty)
    written += _write_tables(result, out)
    with ticking(f"exact reference: the optimum at the chosen time, and the certified front of {case.name} if "
                 "not yet cached", disable=args.quiet):
        result = replace(result, optimum=optimum_at(problem, result.trajectory, reference=not args.no_reference))
    written += _write_figures(result, out, args.algorithm, args.seed)
    _report(result)
    for path in written:
        say(f"wrote {path}")


def run(args) -> int:
    """Optimise the case of ``args`` and write the front, the chosen run and figures; returns the exit code."""
    written: list[Path] = []
    try:
        _optimize(args, written)
    except KeyboardInterrupt:
        kept = f"kept {', '.join(str(p) for p in written)}" if written else f"nothing written to {args.out}"
        raise KeyboardInterrupt(f"{kept}; an optimisation does not resume: run it again") from None
    return 0
