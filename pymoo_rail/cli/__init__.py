"""The ``pymoo-rail`` command: cases, optimisation, the exact reference, studies and plots.

Every subcommand is a thin layer over the library (``pymoo_rail.cases``, ``.problems``,
``.experiments``, ``.plotting``, ``.optimal``), one module each in ``pymoo_rail/cli/commands/``;
heavy modules are imported when a subcommand runs, so ``pymoo-rail --help`` answers at once. Bad
arguments (unknown case, algorithm or objective, impossible values) end with exit code 2 and a
message naming the argument and the value; other failures with exit code 1 and a one-line message
(``--debug`` shows the traceback).

- :mod:`~pymoo_rail.cli.app`: ``main`` (parse, run, report errors)
- :mod:`~pymoo_rail.cli.parser`: ``build_parser`` (the main options, one subparser per command)
- :mod:`~pymoo_rail.cli.arguments`: the usage error, help formatter, argument types, output helpers
- :mod:`~pymoo_rail.cli.case_options`: CASE or a TTOBench track and train
"""

from pymoo_rail.cli.app import main
from pymoo_rail.cli.parser import build_parser

__all__ = ["main", "build_parser"]
