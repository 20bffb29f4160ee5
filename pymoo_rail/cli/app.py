"""``main``: parse, run the command, and turn its errors into one clear line and an exit code."""

from __future__ import annotations

import os
import sys
from typing import Sequence

from pymoo_rail.cli.arguments import UsageError, usage_error
from pymoo_rail.cli.parser import build_parser


def _run(args) -> int:
    if not args.compiles:
        return args.run(args)
    from tqdm import tqdm

    from pymoo_rail.sim.jit import NOTICE, compile_notice

    # a first run compiles the kernels: say so (tqdm.write keeps a progress bar intact)
    message = args.compiles if isinstance(args.compiles, str) else NOTICE
    with compile_notice(say=lambda text: tqdm.write(text, file=sys.stderr), message=message):
        return args.run(args)


def main(argv: Sequence[str] | None = None) -> int:
    """Entry point of ``pymoo-rail``; returns the exit code (0 ok, 1 failure, 2 bad arguments)."""
    # Numba's parallel kernels run on OpenMP threads, which by default spin between parallel regions:
    # on 2 cores that is a tenth of a short run's CPU for no speed (measured: the warm main job 3.1 ->
    # 2.8 s CPU, a 3-solve DP profile unchanged). Set before the first kernel loads OpenMP; a user's
    # own OMP_WAIT_POLICY wins.
    os.environ.setdefault("OMP_WAIT_POLICY", "PASSIVE")
    parser = build_parser()
    try:
        args = parser.parse_args(argv)
    except SystemExit as exit_:  # --help, or argparse's own usage errors (already printed)
        return int(exit_.code or 0)
    if args.command is None:
        parser.print_help()
        return 2
    try:
        return _run(args)
    except UsageError as err:
        print(usage_error(args.usage_parser.prog, f"argument {err.argument}: {err}"), file=sys.stderr)
        return 2
    except KeyboardInterrupt as err:  # the command may say what it kept
        print(f"pymoo-rail {args.command}: interrupted; {str(err) or args.interrupted}", file=sys.stderr)
        return 130
    except Exception as err:  # noqa: BLE001 - one clear line unless --debug
        if args.debug:
            raise
        print(f"pymoo-rail {args.command}: error: {type(err).__name__}: {err}", file=sys.stderr)
        return 1
