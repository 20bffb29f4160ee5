"""How a command names its case: a built-in name, a .toml file, or a TTOBench track and train."""

from __future__ import annotations

import argparse
from pathlib import Path

from pymoo_rail.cli.arguments import UsageError


def load_case(argument: str, value: str):
    """The case named by ``value`` (built-in name or .toml path); a ``UsageError`` on ``argument`` if none."""
    from pymoo_rail.cases import list_cases
    from pymoo_rail.cases import load_case as load
    from pymoo_rail.model import CaseError

    try:
        return load(value)
    except CaseError as err:
        if Path(value).suffix == ".toml" or Path(value).exists():
            raise UsageError(argument, str(err)) from None
        raise UsageError(argument, f"unknown case {value!r} (built-in: {', '.join(list_cases())}; "
                                   "or give the path of a .toml case file)") from None


def add_case_arguments(p: argparse.ArgumentParser) -> None:
    """``CASE``, or ``--track T.json --train R.json --from A --to B --time S``: a TTOBench run instead."""
    p.add_argument("case", metavar="CASE", nargs="?", default=None,
                   help="built-in case name (see 'pymoo-rail cases') or a .toml case file; or give --track ...")
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


def case_from_args(args):
    """The case of CASE, or of --track/--train/--from/--to/--time."""
    if args.track is None:
        if args.train is not None:
            raise UsageError("--train", "needs --track")
        if args.case is None:
            raise UsageError("CASE", "give a case name or file, or --track T.json --train R.json")
        return load_case("CASE", args.case)
    if args.case is not None:
        raise UsageError("CASE", "give either CASE or --track, not both")
    if args.train is None:
        raise UsageError("--train", "--track needs --train R.json")
    from pymoo_rail.cases import load_case as load
    from pymoo_rail.optimal import min_running_time

    # through the format registry, as every case file (pymoo_rail.cases.formats)
    case = load(args.track, train=args.train, from_stop=_stop_ref(args.from_stop), to_stop=_stop_ref(args.to_stop),
                planned_time_s=1.0, curve_model=args.curve_model)
    time_s = args.planned_time if args.planned_time is not None else 1.15 * min_running_time(case)
    return case.with_planned_time(time_s)
