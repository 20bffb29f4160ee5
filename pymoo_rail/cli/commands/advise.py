"""``pymoo-rail advise``: one disturbed closed-loop run of a driver following the optimal policy's advice."""

from __future__ import annotations

import textwrap

from pymoo_rail.cli.arguments import UsageError, add_command, out_dir, say
from pymoo_rail.cli.case_options import load_case

ORDER = 45

EPILOG = textwrap.dedent("""\
    examples:
      pymoo-rail advise yizhuang --delay 20 --restriction 1200:1400:50
      pymoo-rail advise wuguang-crh3 --delay 20 --restriction 30000:33000:120 --announce 20000 --out out/advice""")


def add_parser(sub) -> None:
    """Add ``advise`` to the subcommands."""
    p = add_command(sub, "advise", run, compiles=True, help="simulate a driver following the optimal advice",
                    description="Simulate one disturbed run of CASE (a late departure, a temporary speed "
                                "restriction announced on the way, a heavier train) driven by a driver who "
                                "follows the advice of the optimal policy (re-planned every --every seconds, "
                                "acted on --reaction seconds late); print the advice, write it as CSV and JSON "
                                "and draw the run with the advice.", epilog=EPILOG)
    p.add_argument("case", metavar="CASE", help="built-in case name or .toml path")
    p.add_argument("--delay", type=float, default=0.0, metavar="S", help="departure delay (s)")
    p.add_argument("--restriction", default=None, metavar="START:END:KMH",
                   help="temporary speed restriction, e.g. 3000:3600:40 (m, m, km/h)")
    p.add_argument("--announce", type=float, default=None, metavar="M",
                   help="where the restriction is announced (default: 1 km before it, or the start)")
    p.add_argument("--mass-factor", type=float, default=1.0, metavar="F", help="real mass / nominal mass")
    p.add_argument("--planned", type=float, default=None, metavar="S", help="planned time (default: the case's)")
    p.add_argument("--every", type=float, default=10.0, metavar="S", help="re-planning period (s)")
    p.add_argument("--reaction", type=float, default=1.5, metavar="S", help="the driver's reaction delay (s)")
    p.add_argument("--out", default="out/advise", metavar="DIR", help="where to write advice.csv/.json, advice.png")


def run(args) -> int:
    """Simulate, print the advice, write the files; returns the exit code."""
    from pymoo_rail.control import AdvisedDriving, LoopDisturbance, OptimalPolicy, SpeedRestriction, closed_loop
    from pymoo_rail.control.advice import advice_frame
    from pymoo_rail.model.errors import FieldError
    from pymoo_rail.plotting import plot_advised_run, save_figure

    case = load_case("CASE", args.case)
    try:
        restriction = SpeedRestriction.parse(args.restriction) if args.restriction else None
        if restriction is not None:
            restriction.check_on(case)
        announce = args.announce if args.announce is not None else (
            max(restriction.start_m - 1000.0, 0.0) if restriction else 0.0)
        world = LoopDisturbance(mass_factor=args.mass_factor, departure_delay_s=args.delay, restriction=restriction,
                                announce_m=announce)
        policy = OptimalPolicy(case, case.planned_time_s if args.planned is None else args.planned)
        driver = AdvisedDriving(policy, args.every, reaction_s=args.reaction)
    except FieldError as err:
        raise UsageError(f"--{err.field.split('.')[0].replace('_', '-')}", str(err)) from None
    out = out_dir(args.out)
    run_ = closed_loop(case, driver, world, planned_time_s=policy.planned_time_s)
    seen = driver.seen(run_)
    for time_s, position_m, advice in seen:
        say(f"t {time_s:7.1f} s  x {position_m:8.0f} m  {advice.text()}")
    s = run_.summary
    say(f"arrival {s['arrival_s']:.1f} s (plan {policy.planned_time_s:g} s, lateness {s['lateness_s']:+.1f} s), "
        f"{run_.energy.net_kwh:.2f} kWh, {driver.changes(run_)} advice changes, stop error {run_.stop_error_m:.2f} m")
    table = advice_frame(seen)
    table.to_csv(out / "advice.csv", index=False)
    table.to_json(out / "advice.json", orient="records", indent=1)
    save_figure(plot_advised_run(run_, seen, case, policy.plan, title=f"{case.name}: run with driver advice"),
                out / "advice.png")
    say(f"wrote {out / 'advice.csv'}, {out / 'advice.json'}, {out / 'advice.png'}")
    return 0
