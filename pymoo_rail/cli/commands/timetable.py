"""``pymoo-rail timetable``: several trains sharing braking energy; NSGA-II on departures and driving."""

from __future__ import annotations

from pymoo_rail.cli.arguments import UsageError, add_command, out_dir, positive_float, positive_int, random_seed, say
from pymoo_rail.cli.case_options import load_case

ORDER = 60


def add_parser(sub) -> None:
    """Add ``timetable`` to the subcommands."""
    p = add_command(
        sub, "timetable", run, compiles=False,
        help="several trains sharing braking energy: departures and driving",
        description="Optimise a timetable of trains on a case (pymoo_rail.problems.TimetableProblem): departures "
                    "free within a window around a regular headway, every train's driving shape paced to its "
                    "planned time, regenerated energy shared within one power-supply section. NSGA-II on net "
                    "substation energy and mean passenger waiting time; writes front.csv (with the reference "
                    "of every train exactly optimal alone when --reference is given).",
        epilog="examples:\n  pymoo-rail timetable cooperative-pair --trains 4 --headway 120 --out out/tt\n"
               "  pymoo-rail timetable cooperative-pair --trains 8 --headway 90 --n-eval 4000 --reference")
    p.add_argument("case", metavar="CASE", help="built-in case name or a .toml case file")
    p.add_argument("--trains", type=positive_int, default=4, metavar="N", help="number of trains (>= 2)")
    p.add_argument("--headway", type=positive_float, default=120.0, metavar="S", help="nominal headway (s)")
    p.add_argument("--window", type=float, default=30.0, metavar="S", help="departure window +- (s)")
    p.add_argument("--efficiency", type=positive_float, default=0.9, metavar="ETA",
                   help="transmission efficiency of the supply between trains")
    p.add_argument("--directions", type=int, choices=(1, 2), default=1,
                   help="2: every second train runs the line the other way (same supply section)")
    p.add_argument("--pop-size", type=positive_int, default=40, metavar="N")
    p.add_argument("--n-eval", type=positive_int, default=2000, metavar="N", help="evaluations")
    p.add_argument("--seed", type=random_seed, default=1)
    p.add_argument("--reference", action="store_true",
                   help="also compute every train's exact optimum alone (an exact solve per leg, about a CPU second each once compiled)")
    p.add_argument("--out", default="out", metavar="DIR", help="output directory")


def _front(problem, opt, trains: int):
    import pandas as pd

    front = pd.DataFrame({"net_kwh": opt.get("net_kwh"), "waiting_time_s": opt.get("waiting_time_s"),
                          "traction_kwh": opt.get("traction_kwh"), "shared_kwh": opt.get("shared_kwh"),
                          "cv": opt.get("CV")[:, 0]})
    for i in range(trains - 1):
        front[f"shift_{i + 1}_s"] = opt.get("X")[:, i]
    return front


def run(args) -> int:
    """Optimise the timetable of ``args`` and write its front; returns the exit code."""
    import numpy as np
    from pymoo.algorithms.moo.nsga2 import NSGA2
    from pymoo.optimize import minimize

    from pymoo_rail.problems import TimetableProblem

    case = load_case("CASE", args.case)
    if args.trains < 2:
        raise UsageError("--trains", f"needs at least 2 trains, got {args.trains}")
    problem = TimetableProblem(case, args.trains, args.headway, window_s=args.window,
                               transmission_efficiency=args.efficiency, directions=args.directions)
    say(problem.describe())
    res = minimize(problem, NSGA2(pop_size=args.pop_size), ("n_eval", args.n_eval), seed=args.seed)
    front = _front(problem, res.algorithm.opt, args.trains)
    if args.reference:
        reference = problem.reference_kwh()
        front["reference_kwh"] = reference
        front["saving_pct"] = 100.0 * (1.0 - front["net_kwh"] / reference)
        say(f"reference (every train exactly optimal alone, nothing shared): {reference:.3f} kWh")
    out = out_dir(args.out)
    front = front.sort_values("net_kwh").reset_index(drop=True)
    front.to_csv(out / "front.csv", index=False)
    best = front.iloc[0]
    say(f"{len(front)} solutions; least energy {best['net_kwh']:.3f} kWh ({best['shared_kwh']:.3f} kWh shared, "
        f"mean wait {best['waiting_time_s']:.1f} s); regular timetable wait "
        f"{args.headway * args.directions / 2:.1f} s")
    say(f"wrote {out / 'front.csv'}")
    return 0 if np.all(front["cv"] <= 0) else 1
