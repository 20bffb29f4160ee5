"""What every command shares: the usage error, the help formatter, argument types and output helpers."""

from __future__ import annotations

import argparse
import tempfile
from pathlib import Path


class UsageError(Exception):
    """A bad argument value found after parsing: reported as ``argument NAME: message``, exit 2."""

    def __init__(self, argument: str, message: str):
        self.argument = argument
        super().__init__(message)


def usage_error(prog: str, message: str) -> str:
    """The two lines of a bad argument: the error, and where the options are explained."""
    return f"{prog}: error: {message}\n{prog}: run '{prog} --help' for the options and examples"


class Parser(argparse.ArgumentParser):
    """``argparse.ArgumentParser`` whose errors are one line and a hint, not the whole usage block."""

    def parse_args(self, args=None, namespace=None):
        """argparse's ``parse_args``; an unknown option is blamed on the command it was given to."""
        parsed, extras = self.parse_known_args(args, namespace)
        if extras:
            prog = getattr(parsed, "usage_parser", self).prog
            self.exit(2, usage_error(prog, f"unrecognized arguments: {' '.join(extras)}") + "\n")
        return parsed

    def error(self, message: str):
        """Print the error and the ``--help`` hint on standard error; exit 2 (argparse's hook)."""
        self.exit(2, usage_error(self.prog, message) + "\n")


class HelpFormatter(argparse.RawDescriptionHelpFormatter, argparse.ArgumentDefaultsHelpFormatter):
    """Raw descriptions; "(default: X)" appended once, and only where the help does not say it."""

    def _get_help_string(self, action: argparse.Action) -> str:
        text = action.help or ""
        if "default" in text or action.default in (None, False) or action.default is argparse.SUPPRESS:
            return text
        return super()._get_help_string(action)


def _parsed(text: str, kind: type, what: str):
    try:
        return kind(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"invalid {what}: {text!r}") from None


def _int_at_least(text: str, least: int) -> int:
    value = _parsed(text, int, "integer")
    if value < least:
        raise argparse.ArgumentTypeError(f"must be at least {least}, got {value}")
    return value


def positive_int(text: str) -> int:
    """argparse type: an integer of at least 1."""
    return _int_at_least(text, 1)


def positive_float(text: str) -> float:
    """argparse type: a positive finite number."""
    value = _parsed(text, float, "number")
    if not value > 0 or value == float("inf"):
        raise argparse.ArgumentTypeError(f"must be a positive finite number, got {text}")
    return value


def random_seed(text: str) -> int:
    """argparse type: a random seed, an integer >= 0."""
    return _int_at_least(text, 0)


def out_dir(value: str) -> Path:
    """The output directory of ``--out``, created; a ``UsageError`` naming ``--out`` if it cannot be."""
    path = Path(value)
    if path.exists() and not path.is_dir():
        raise UsageError("--out", f"{value!r} exists and is not a directory")
    try:
        path.mkdir(parents=True, exist_ok=True)
        with tempfile.TemporaryFile(dir=path):  # writable? (a read-only disk lets mkdir of an existing folder pass)
            pass
    except OSError as err:
        raise UsageError("--out", f"cannot write into {value!r}: {err.strerror or err}") from None
    return path


def say(text: str) -> None:
    """Print one line of a command's output at once (a progress bar may follow)."""
    print(text, flush=True)


def count(n: int, noun: str) -> str:
    """``1 solution``, ``2 solutions``."""
    return f"{n} {noun}" if n == 1 else f"{n} {noun}s"


EXACT_SOLVER_NOTICE = ("compiling the simulator and the exact solver (first run only: Numba compiles the kernels "
                       "of the simulation and the dynamic programme once and caches them on disk; this takes a "
                       "while on a small machine) ...")
"""What a first run of a command that solves exactly compiles (``add_command(compiles=...)``)."""

NOTHING_KEPT = "nothing to resume: run the command again"


def add_command(subparsers, name: str, run, *, compiles: bool | str, aliases: tuple[str, ...] = (),
                interrupted: str = NOTHING_KEPT, **kwargs) -> argparse.ArgumentParser:
    """Add a subcommand whose ``run(args)`` gives the exit code.

    ``compiles`` says that the command may compile the simulator's kernels on a first run: the
    user is told, with this text if it is one (what is compiled and roughly how long it takes).
    ``interrupted`` says what Ctrl-C keeps (a ``KeyboardInterrupt`` raised with a message says it
    instead). The parser is remembered as ``args.usage_parser``: a ``UsageError`` names its
    program.
    """
    p = subparsers.add_parser(name, aliases=list(aliases), formatter_class=HelpFormatter, **kwargs)
    p.set_defaults(run=run, compiles=compiles, usage_parser=p, interrupted=interrupted)
    return p
