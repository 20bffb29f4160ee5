"""``pymoo-rail cases``: list the built-in cases, or describe one."""

from __future__ import annotations

import textwrap

from pymoo_rail.cli.arguments import UsageError, add_command, say
from pymoo_rail.cli.case_options import load_case

ORDER = 10


def add_parser(sub) -> None:
    """Add ``cases`` to the subcommands."""
    p = add_command(sub, "cases", run, compiles=False, help="list the built-in cases, or describe one",
                    description="List the built-in cases (length, planned time, train, source), or describe "
                                "one case (built-in name or path of a .toml case file) in full.",
                    epilog="examples:\n  pymoo-rail cases\n  pymoo-rail cases wuguang-crh3\n"
                           "  pymoo-rail cases my_line.toml\n"
                           "  pymoo-rail cases osrd_run.toml --write full_case.toml")
    p.add_argument("case", nargs="?", metavar="CASE", help="a case to describe (name or .toml path)")
    p.add_argument("--write", metavar="OUT.toml", help="also write CASE as a complete case file (e.g. an OSRD "
                                                        "railjson case, docs/railjson.md)")


def _list() -> None:
    from pymoo_rail.cases import list_cases
    from pymoo_rail.cases import load_case as load

    header = ("case", "length", "planned", "train", "source")
    rows = []
    for name in list_cases():
        case = load(name)
        source = " ".join(case.source.split())
        rows.append((name, f"{case.line.length_m:,.0f} m", f"{case.planned_time_s:g} s",
                     case.train.name or f"{case.train.mass_t:g} t", source[:60] + ("..." if len(source) > 60 else "")))
    widths = [max(len(r[i]) for r in rows + [header]) for i in range(5)]
    for row in [header] + rows:
        say("  ".join(cell.ljust(w) for cell, w in zip(row, widths)).rstrip())
    say("\n'pymoo-rail cases NAME' describes one case.")


def _wrap(text: str) -> str:
    return textwrap.fill(" ".join(text.split()), 96, initial_indent="  ", subsequent_indent="  ")


def _describe(case) -> None:
    line, train = case.line, case.train
    say(f"{case.name}")
    if case.description:
        say(_wrap(case.description))
    say(f"run:    {line.length_m:,.1f} m in {case.planned_time_s:g} s planned"
        + (f" (+{case.time_margin_s:g} s margin)" if case.time_margin_s else "")
        + (f", dwell {case.dwell_s:g} s" if case.dwell_s else "")
        + (f", {len(case.legs)} legs" if case.legs else ""))
    say(f"train:  {train.name or '-'}: {train.mass_t:g} t, {train.length_m:g} m, max {train.max_speed_kmh:g} km/h")
    say("limits: " + ", ".join(f"{a:g}-{b:g} m: {v:g} km/h" for a, b, v in line.speed_limits))
    grads = ", ".join(f"{a:g}-{b:g} m: {g:+g}" for a, b, g in line.gradients)
    say(textwrap.fill(f"gradients (permille): {grads}", 96, subsequent_indent="  "))
    if line.neutral_sections:
        say("neutral sections: " + ", ".join(f"{a:g}-{b:g} m" for a, b in line.neutral_sections))
    say("source:")
    say(_wrap(case.source))


def run(args) -> int:
    """List the built-in cases, or describe ``args.case``; returns the exit code."""
    if args.case is None:
        if args.write:
            raise UsageError("--write", "needs a CASE to write")
        _list()
    else:
        case = load_case("CASE", args.case)
        _describe(case)
        if args.write:
            from pymoo_rail.cases import write_case

            say(f"written: {write_case(case, args.write)}")
    return 0
