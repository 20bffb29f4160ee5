"""``pymoo-rail journey``: the least-energy run of a multi-stop journey that meets every timing point."""

from __future__ import annotations

from pathlib import Path

from pymoo_rail.cli.arguments import EXACT_SOLVER_NOTICE, UsageError, add_command, out_dir, say
from pymoo_rail.cli.progress import ticking

ORDER = 30


def add_parser(sub) -> None:
    """Add ``journey`` to the subcommands."""
    p = add_command(sub, "journey", run, compiles=EXACT_SOLVER_NOTICE,
                    help="solve a TTOBench journey (timing points) with the exact solver",
                    description="Read a TTOBench journey file, its track and a train, find the least-energy run "
                                "that meets every timing point, and write into --out: timing.csv (time and speed "
                                "at every timing point, window and check), trajectory_<k>.csv per section and "
                                "journey.png.",
                    epilog="example (from the repository's root: a journey TTOBench first published, which "
                           "the SBB KISS can meet; the released version cannot be met):\n"
                           "  pymoo-rail journey tests/data/ttobench/journeys/"
                           "CH_StGallen_Wil_Journey_01_first_published.json \\\n"
                           "      --train tests/data/ttobench/trains/CH_Stadler_KISS_SBB.json --out out/j")
    p.add_argument("journey", metavar="JOURNEY", help="TTOBench journey JSON file, or a .toml journey "
                                                       "(track, train and timing points, docs/ttobench.md)")
    p.add_argument("--track", default=None, metavar="T.json",
                   help="TTOBench track file (default: ../tracks/<associated track>.json next to the journey)")
    p.add_argument("--train", default=None, metavar="R.json", help="TTOBench train file (for a JSON journey)")
    p.add_argument("--curve-model", default="tang2020", choices=["tang2020", "roeckl"], help="curve resistance")
    p.add_argument("--out", default="out", metavar="DIR", help="output directory")


def _timed_journey(args):
    from pymoo_rail.journeys.formats import read_timing_points, timed_journey_from_toml, timed_journey_from_ttobench

    if args.journey.endswith(".toml"):
        return timed_journey_from_toml(args.journey)
    if args.train is None:
        raise UsageError("--train", "a TTOBench journey file names no train: give --train R.json")
    track = args.track
    if track is None:
        _, track_id, _, _ = read_timing_points(args.journey)
        track = Path(args.journey).resolve().parent.parent / "tracks" / f"{track_id}.json"
    return timed_journey_from_ttobench(args.journey, track, args.train, curve_model=args.curve_model)


def run(args) -> int:
    """Solve the journey of ``args`` and write its timing table, runs and figure; returns the exit code."""
    import pandas as pd

    from pymoo_rail.journeys.timing import solve_timed_journey
    from pymoo_rail.plotting import save_figure
    from pymoo_rail.plotting.journey import plot_timed_run

    out = out_dir(args.out)
    timed = _timed_journey(args)
    with ticking(f"exact solver: {timed.journey.name}, every section and timing point"):
        run_ = solve_timed_journey(timed)
    pd.DataFrame(list(run_.checks)).to_csv(out / "timing.csv", index=False)
    for k, traj in enumerate(run_.trajectories):
        traj.to_frame().to_csv(out / f"trajectory_{k}.csv", index=False)
    save_figure(plot_timed_run(timed, run_), out / "journey.png")
    say(f"{timed.journey.name}: {run_.energy_kwh:.2f} kWh net, every timing point met; wrote {out}/timing.csv, "
        f"trajectory_*.csv, journey.png")
    return 0
