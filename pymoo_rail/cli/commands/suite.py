"""``pymoo-rail suite``: list the benchmark suite's problems, or verify its shipped fronts."""

from __future__ import annotations

from pymoo_rail.cli.arguments import UsageError, add_command, say
from pymoo_rail.cli.progress import ticking

ORDER = 80


def add_parser(sub) -> None:
    """Add ``suite`` to the subcommands."""
    p = add_command(
        sub, "suite", run, compiles=True, help="the benchmark suite: list its problems, verify its shipped fronts",
        description="The benchmark suite (pymoo_rail.suite, docs/suite.md): rail problems with certified exact "
                    "fronts. 'list' prints the problems; 'verify' solves every shipped front again and exits 1 "
                    "if any node drifts beyond its certificate (minutes per long line).",
        epilog="examples:\n  pymoo-rail suite list\n  pymoo-rail suite verify metro-a yizhuang")
    p.add_argument("action", choices=["list", "verify"], help="what to do")
    p.add_argument("cases", nargs="*", metavar="CASE", help="suite cases to verify (default: all)")


def _list() -> int:
    from pymoo_rail.optimal.reference import find_front
    from pymoo_rail.suite import list_problems, suite_case
    from pymoo_rail.suite.problems import split

    for name in list_problems():
        entry, form = split(name)
        case = suite_case(entry.name)
        if form == "4obj":
            front = "best-known front (no exact front for four objectives)"
        else:
            path = find_front(case)
            front = f"certified front {path.name}" if path is not None else "front computed on first use"
        say(f"{name:42s} {form:6s} {case.line.length_m:8.0f} m  {case.planned_time_s:6.0f} s  {front}")
    return 0


def _verify(cases: list[str]) -> int:
    from pymoo_rail.suite import CASES, verify

    known = [c.name for c in CASES]
    for name in cases:
        if name not in known:
            raise UsageError("CASE", f"unknown suite case {name!r} (known: {', '.join(known)})")
    with ticking("exact solver: solving the shipped fronts again (minutes per long line)"):
        report = verify(cases or None)
    for case_name, rows in report.groupby("case", sort=False):
        if "drift_kwh" in rows and rows["drift_kwh"].notna().any():
            say(f"{case_name:32s} {'ok' if rows['ok'].all() else 'DRIFT'}: largest drift "
                f"{rows['drift_kwh'].max():.4g} kWh, smallest certificate {rows['certificate_kwh'].min():.4g} kWh")
        else:
            say(f"{case_name:32s} FAILED: {rows['problem'].iloc[0]}")
    return 0 if bool(report["ok"].all()) else 1


def run(args) -> int:
    """List or verify the suite; returns the exit code."""
    return _list() if args.action == "list" else _verify(args.cases)
