"""``pymoo-rail plot``: redraw the figures of a study, a front or a trajectory without recomputing."""

from __future__ import annotations

import textwrap
from pathlib import Path

from pymoo_rail.cli.arguments import HelpFormatter, UsageError, add_command, out_dir, say
from pymoo_rail.cli.case_options import load_case
from pymoo_rail.cli.commands.study import add_trust_argument, study_outputs
from pymoo_rail.problems.objectives import objective_columns

ORDER = 90

EPILOG = textwrap.dedent("""\
    examples:
      pymoo-rail plot study out/zdt
      pymoo-rail plot front out/front.csv
      pymoo-rail plot front out/front.csv --x running_time_s --y energy_kwh \\
          --reference out/ref/optimal_front.csv
      pymoo-rail plot trajectory out/trajectory.csv --case yizhuang""")


def _add(plot_sub, name: str, help: str) -> object:
    q = plot_sub.add_parser(name, help=help, formatter_class=HelpFormatter)
    q.set_defaults(usage_parser=q)  # a bad value prints this parser's usage line
    return q


def add_parser(sub) -> None:
    """Add ``plot study|front|trajectory`` to the subcommands."""
    p = add_command(sub, "plot", run, compiles=True, help="redraw figures from stored results or CSV files",
                    description="Redraw figures without recomputing anything.", epilog=EPILOG)
    plot_sub = p.add_subparsers(dest="what", metavar="WHAT", title="what to plot")
    q = _add(plot_sub, "study", "tables and figures of a study directory")
    q.add_argument("directory", metavar="DIR", help="study directory written by 'pymoo-rail study'")
    q.add_argument("--out", default=None, metavar="DIR", help="where to write (default: DIR)")
    q.add_argument("--baseline", default=None, metavar="ALGORITHM", help="baseline of the rank-sum tests")
    add_trust_argument(q)
    q = _add(plot_sub, "front", "a front from front.csv")
    q.add_argument("csv", metavar="CSV", help="front.csv written by 'pymoo-rail optimize'")
    q.add_argument("--x", default=None, metavar="COLUMN", help="column on the x axis (default: first objective)")
    q.add_argument("--y", default=None, metavar="COLUMN", help="column on the y axis (default: second objective)")
    q.add_argument("--reference", default=None, metavar="CSV",
                   help="a reference front to draw as a line (optimal_front.csv, same column names)")
    q.add_argument("--out", default=None, metavar="PNG",
                   help="image file (default: the CSV's name with _plot.png, e.g. front_plot.png, so the "
                        "figure 'optimize' wrote is kept)")
    q = _add(plot_sub, "trajectory", "a speed profile from trajectory.csv")
    q.add_argument("csv", metavar="CSV", help="trajectory.csv written by 'pymoo-rail optimize'")
    q.add_argument("--case", default=None, metavar="CASE",
                   help="the case, to draw the line (limits, gradients, neutral sections)")
    q.add_argument("--out", default=None, metavar="PNG", help="image file (default: next to the CSV)")


def _objective_of_column(column: str) -> str:
    """Axis label key of a front column: ``f_energy`` -> energy, ``running_time_s`` -> running_time."""
    if column.startswith("f_"):
        return column[2:]
    for name, col in objective_columns().items():
        if column == col:
            return name
    return column


def _study(args) -> list[Path]:
    directory = Path(args.directory)
    if not (directory / "runs").is_dir():
        raise UsageError("DIR", f"{str(directory)!r} is not a study directory (no runs/ folder)")
    out = out_dir(args.out) if args.out else directory
    return study_outputs(directory, out, args.baseline, plots=True, trusted=args.trust)


def _save(fig, args, default: Path) -> Path:
    """Save to ``--out`` or ``default``; a path that cannot be written is a usage error naming it."""
    from pymoo_rail.plotting import save_figure

    path = Path(args.out) if args.out else default
    try:
        return save_figure(fig, path)
    except OSError as err:
        raise UsageError("--out" if args.out else "CSV", f"cannot write {str(path)!r}: {err.strerror or err}") from None


def _front(args, table, csv: Path) -> Path:
    import pandas as pd

    from pymoo_rail.plotting import plot_fronts

    objectives = [c for c in table.columns if c.startswith("f_")]
    x = args.x or (objectives[0] if objectives else None)
    y = args.y or (objectives[1] if len(objectives) > 1 else None)
    for argument, column in (("--x", x), ("--y", y)):
        if column is None or column not in table.columns:
            raise UsageError(argument, f"column {column!r} is not in {csv.name} (columns: {', '.join(table.columns)})")
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
    fig = plot_fronts({csv.stem: table[[x, y]].to_numpy(float)}, [_objective_of_column(x), _objective_of_column(y)],
                      reference=reference, highlight=highlight, reference_label="reference front")
    # not front.png: that is the figure 'optimize' wrote next to front.csv
    return _save(fig, args, csv.with_name(f"{csv.stem}_plot.png"))


def _trajectory(args, table, csv: Path) -> Path:
    from pymoo_rail.plotting import plot_speed_profile

    case = load_case("--case", args.case) if args.case else None
    try:
        fig = plot_speed_profile(table, case)
    except ValueError as err:
        raise UsageError("CSV", str(err)) from None
    return _save(fig, args, csv.with_suffix(".png"))


def run(args) -> int:
    """Draw what ``args.what`` names; returns the exit code."""
    import pandas as pd

    if args.what is None:
        raise UsageError("WHAT", "say what to plot: study, front or trajectory")
    if args.what == "study":
        written = _study(args)
    else:
        csv = Path(args.csv)
        if not csv.is_file():
            raise UsageError("CSV", f"no such file: {str(csv)!r}")
        draw = _front if args.what == "front" else _trajectory
        written = [draw(args, pd.read_csv(csv), csv)]
    for path in written:
        say(f"wrote {path}")
    return 0
