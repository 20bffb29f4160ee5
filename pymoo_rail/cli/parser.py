"""The ``pymoo-rail`` argument parser: the main options, and one subcommand per module of ``cli.commands``.

A command module holds ``ORDER`` (its place in ``--help``), ``add_parser(subparsers)`` (its options,
help and examples) and ``run(args) -> int`` (the exit code); ``add_parser`` binds ``run`` with
``set_defaults``. Adding a command is adding a module to ``pymoo_rail/cli/commands/``.
"""

from __future__ import annotations

import argparse
import importlib
import pkgutil
from types import ModuleType

from pymoo_rail.cli import commands
from pymoo_rail.cli.arguments import Parser

MAIN_EPILOG = """\
examples:
  pymoo-rail cases                                  list the built-in cases
  pymoo-rail cases yizhuang                         describe one case
  pymoo-rail optimize yizhuang --out out/           NSGA-II on energy and time error (about 3 s
                                                    of CPU; the first run compiles, about 15 s more)
  pymoo-rail optimize yizhuang --algorithm moabc --pop-size 40 --n-gen 100 --seed 3 --out out/moabc
  pymoo-rail optimize yizhuang --objectives energy --time-tolerance 1 --algorithm abc --out out/abc
  pymoo-rail reference yizhuang --out out/ref       the exact minimum-energy front
  pymoo-rail study examples/study_zdt.toml --workers 2 --out out/zdt
  pymoo-rail plot study out/zdt                     redraw the tables and figures of a study
  pymoo-rail plot trajectory out/trajectory.csv --case yizhuang
  pymoo-rail warmup --all                           compile the kernels ahead (images, clusters)

The first run in a fresh installation compiles the simulator (Numba; it says so), later runs
load the compiled kernels from the cache.

Run 'pymoo-rail COMMAND --help' for the options of a command.
"""


def command_modules() -> list[ModuleType]:
    """The modules of ``pymoo_rail.cli.commands``, in their ``ORDER``."""
    found = [importlib.import_module(f"{commands.__name__}.{info.name}")
             for info in pkgutil.iter_modules(commands.__path__) if not info.name.startswith("_")]
    return sorted(found, key=lambda module: module.ORDER)


def build_parser() -> argparse.ArgumentParser:
    """The argument parser of the ``pymoo-rail`` command with all its subcommands."""
    parser = Parser(
        prog="pymoo-rail",
        description="Energy-efficient train driving with pymoo: optimise recommended speed profiles of "
                    "built-in or your own cases, compute the exact minimum-energy reference, run algorithm "
                    "studies (many problems x algorithms x seeds) on this machine or a Dask cluster, and "
                    "draw the figures.",
        epilog=MAIN_EPILOG, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--debug", action="store_true", help="show the full traceback of an error")
    sub = parser.add_subparsers(dest="command", metavar="COMMAND", title="commands")
    for module in command_modules():
        module.add_parser(sub)
    return parser
