"""Where the cold compile of the README's main command goes: per Numba function and per stage.

Runs ``pymoo-rail optimize yizhuang --algorithm nsga2`` (or the given CLI arguments) in a child
process with an empty ``NUMBA_CACHE_DIR`` under :func:`pymoo_rail.sim.jit.compile_profile`, and
prints per function the exclusive time of each stage: Numba's passes (type inference, IR inlining
``InlineInlinables``/``InlineOverloads``, ``NativeLowering`` = lowering to LLVM IR) and LLVM's
(function passes, module passes on the linked final module, machine code). Times are CPU time
of the compiling thread (not inflated by load); the child's total CPU time is printed too.

    python benchmarks/compile_profile.py [--top 25] [--signatures] [-- optimize yizhuang --algorithm nsga2]
"""

from __future__ import annotations

import argparse
import os
import resource
import sys
import tempfile
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
DEFAULT = ["optimize", "yizhuang", "--algorithm", "nsga2", "-q"]


def child(cli_args: list[str], top: int, signatures: bool) -> None:
    """Run the CLI under the compile profile (in the child with an empty cache) and print the profile."""
    from pymoo_rail import cli
    from pymoo_rail.sim.jit import compile_profile

    with tempfile.TemporaryDirectory() as out, compile_profile() as profile:
        code = cli.main([*cli_args, "--out", out] if cli_args[0] != "warmup" else cli_args)
    usage = resource.getrusage(resource.RUSAGE_SELF)
    print(f"exit {code}; process CPU {usage.ru_utime + usage.ru_stime:.1f} s; {profile.summary(top, signatures)}")


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--top", type=int, default=25)
    parser.add_argument("--signatures", action="store_true", help="list functions compiled more than once")
    parser.add_argument("--child", action="store_true", help=argparse.SUPPRESS)
    parser.add_argument("cli", nargs="*", help="CLI arguments (default: the README's main command)")
    args = parser.parse_args()
    cli_args = args.cli or DEFAULT
    if args.child:
        child(cli_args, args.top, args.signatures)
        return
    import subprocess

    with tempfile.TemporaryDirectory() as cache:
        env = dict(os.environ, NUMBA_CACHE_DIR=cache, MPLBACKEND="Agg", PYTHONPATH=str(ROOT))
        print(f"load average at start: {os.getloadavg()[0]:.1f} on {os.cpu_count()} CPUs", flush=True)
        subprocess.run([sys.executable, __file__, "--child", "--top", str(args.top),
                        *(["--signatures"] if args.signatures else []), "--", *cli_args],
                       cwd=ROOT, env=env, check=True)
        print(f"load average at end: {os.getloadavg()[0]:.1f}")


if __name__ == "__main__":
    main()
