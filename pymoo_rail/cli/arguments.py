"""What every command shares: the usage error, the help formatter, argument types and output helpers."""

from __future__ import annotations

import argparse
from pathlib import Path


class UsageError(Exception):
    """A bad argument value found after parsing: reported as ``argument NAME: message``, exit 2."""

    def __init__(self, argument: str, message: str):
        self.argument = argument
        super().__init__(message)


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


def positive_int(text: str) -> int:
    """argparse type: an integer of at least 1."""
    value = _parsed(text, int, "integer")
    if value < 1:
        raise argparse.ArgumentTypeError(f"must be at least 1, got {value}")
    return value


def positive_float(text: str) -> float:
    """argparse type: a positive finite number."""
    value = _parsed(text, float, "number")
    if not value > 0 or value == float("inf"):
        raise argparse.ArgumentTypeError(f"must be a positive finite number, got {text}")
    return value


def random_seed(text: str) -> int:
    """argparse type: a random seed, an integer >= 0."""
    value = _parsed(text, int, "integer")
    if value < 0:
        raise argparse.ArgumentTypeError(f"must be >= 0, got {value}")
    return value


def out_dir(value: str) -> Path:
    """The output directory of ``--out``, created; a ``UsageError`` naming ``--out`` if it cannot be."""
    path = Path(value)
    if path.exists() and not path.is_dir():
        raise UsageError("--out", f"{value!r} exists and is not a directory")
    path.mkdir(parents=True, exist_ok=True)
    return path


def say(text: str) -> None:
    """Print one line of a command's output at once (a progress bar may follow)."""
    print(text, flush=True)


def count(n: int, noun: str) -> str:
    """``1 solution``, ``2 solutions``."""
    return f"{n} {noun}" if n == 1 else f"{n} {noun}s"


def add_command(subparsers, name: str, run, *, compiles: bool, aliases: tuple[str, ...] = (),
                **kwargs) -> argparse.ArgumentParser:
    """Add a subcommand whose ``run(args)`` gives the exit code.

    ``compiles`` says that the command may compile the simulator's kernels on a first run (the
    user is told). The parser is remembered as ``args.usage_parser``: a ``UsageError`` prints its
    usage line.
    """
    p = subparsers.add_parser(name, aliases=list(aliases), formatter_class=HelpFormatter, **kwargs)
    p.set_defaults(run=run, compiles=compiles, usage_parser=p)
    return p
