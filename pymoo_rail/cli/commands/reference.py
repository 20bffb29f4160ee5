"""``pymoo-rail reference``: the exact minimum-energy front and the optimal run of a case."""

from __future__ import annotations

from pymoo_rail.cli.arguments import (EXACT_SOLVER_NOTICE, UsageError, add_command, out_dir, positive_float,
                                      positive_int, say)
from pymoo_rail.cli.case_options import add_case_arguments, case_from_args
from pymoo_rail.cli.problem_options import add_grid_argument
from pymoo_rail.cli.progress import ticking

ORDER = 40


def add_parser(sub) -> None:
    """Add ``reference`` to the subcommands."""
    p = add_command(sub, "reference", run, compiles=EXACT_SOLVER_NOTICE,
                    help="the exact minimum-energy front of a case",
                    description="Compute the exact minimum-energy run for a range of running times (dynamic "
                                "programming, pymoo_rail.optimal) and write optimal_front.csv / .png and the "
                                "optimal run at the planned time (optimal_trajectory.csv, optimal_profile.png).",
                    epilog="examples:\n  pymoo-rail reference yizhuang --out out/ref\n"
                           "  pymoo-rail reference yizhuang --times 140 150 160 170 --out out/ref")
    add_case_arguments(p)
    p.add_argument("--times", type=positive_float, nargs="+", default=None, metavar="S",
                   help="running times (s); default: --n-points from the minimum time to 1.3 x planned")
    p.add_argument("--n-points", type=positive_int, default=8, metavar="N", help="number of running times")
    add_grid_argument(p)
    p.add_argument("--out", default="out", metavar="DIR", help="output directory")


def _times(case, args):
    """The running times to solve, checked against the case's minimum running time before any work."""
    import numpy as np

    from pymoo_rail.model import InfeasibleCaseError
    from pymoo_rail.optimal import min_running_time

    try:
        t_min = float(min_running_time(case, args.dx))
    except InfeasibleCaseError as err:
        raise UsageError("CASE", str(err)) from None
    if args.times is not None:
        times = np.asarray(args.times, dtype=float)
        too_short = times[times < t_min]
        if too_short.size:
            raise UsageError("--times", f"{too_short.min():g} s is below the minimum running time {t_min:.2f} s "
                                        f"of {case.name} (flat out): give times of at least {t_min:.2f} s")
    else:
        times = np.linspace(1.01 * t_min, max(1.3 * case.planned_time_s, 1.1 * t_min), args.n_points)
    if case.planned_time_s < t_min:
        raise UsageError("CASE", f"planned_time_s = {case.planned_time_s:g} s of {case.name} is below its minimum "
                                 f"running time {t_min:.2f} s (flat out)")
    return times


def run(args) -> int:
    """Solve the case of ``args`` exactly and write its optimal front and run; returns the exit code."""
    case = case_from_args(args)
    try:
        from pymoo_rail.optimal import optimal_front, optimal_profile
    except ImportError as err:
        raise RuntimeError("'pymoo-rail reference' needs the exact reference solver pymoo_rail.optimal "
                           f"(optimal_front, optimal_profile), which this installation lacks: {err}") from None
    from pymoo_rail.plotting import plot_fronts, plot_speed_profile, save_figure

    times = _times(case, args)  # every check before any computing or writing
    out = out_dir(args.out)
    say(f"{case.name}: exact minimum-energy runs for {len(times)} running times "
        f"({times.min():.1f}-{times.max():.1f} s)")
    with ticking(f"exact solver: {len(times)} running times"):
        front = optimal_front(case, times, dx_m=args.dx)
    front.to_csv(out / "optimal_front.csv", index=False)
    points = front[["running_time_s", "energy_kwh"]].to_numpy(float)
    figure = plot_fronts({"optimal": points}, ["running_time", "energy"], reference=points,
                         reference_label="optimal front", title=f"{case.name}: minimum energy against running time")
    written = [out / "optimal_front.csv", save_figure(figure, out / "optimal_front.png")]
    with ticking("exact solver: the optimal run at the planned time"):
        trajectory = optimal_profile(case, case.planned_time_s, dx_m=args.dx)
    trajectory.to_frame().to_csv(out / "optimal_trajectory.csv", index=False)
    written.append(out / "optimal_trajectory.csv")
    written.append(save_figure(plot_speed_profile(trajectory, case, label="optimal"), out / "optimal_profile.png"))
    say(f"at the planned {case.planned_time_s:g} s: {trajectory.energy.net_kwh:.3f} kWh "
        f"(running time {trajectory.running_time_s:.2f} s)")
    for path in written:
        say(f"wrote {path}")
    return 0
