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
    from pymoo_rail import cli
    from pymoo_rail.sim.jit import compile_profile

    with tempfile.TemporaryDirectory() as out, compile_profile() as profile:
        code = cli.main([*cli_args, "--out", out] if cli_args[0] != "warmup" else cli_args)
    usage = resource.getrusage(resource.RUSAGE_SELF)
    rows = profile.table()
    stages: dict[str, float] = {}
    for _, _, per in rows:
        for stage, s in per.items():
            stages[stage] = stages.get(stage, 0.0) + s
    total = sum(stages.values())
    print(f"exit {code}; process CPU {usage.ru_utime + usage.ru_stime:.1f} s; compile (CPU) {total:.1f} s")
    modules: dict[str, float] = {}
    for qualname, s, _ in rows:
        module = qualname.split(".<locals>")[0].rsplit(".", 1)[0]
        modules[module] = modules.get(module, 0.0) + s
    print("\nby module:")
    for module, s in sorted(modules.items(), key=lambda kv: -kv[1])[:10]:
        print(f"  {s:7.1f} s  {module}")
    print("\nby stage:")
    for stage, s in sorted(stages.items(), key=lambda kv: -kv[1])[:12]:
        print(f"  {s:7.1f} s  {stage}")
    print(f"\nby function (top {top}): total s, signatures, stages >= 0.2 s")
    for qualname, s, per in rows[:top]:
        parts = ", ".join(f"{k} {v:.1f}" for k, v in sorted(per.items(), key=lambda kv: -kv[1]) if v >= 0.2)
        print(f"  {s:7.1f}  x{profile.compiles.get(qualname, 0)}  {qualname}: {parts}")
    if signatures:
        print("\nfunctions compiled for more than one signature (the arguments where they differ):")
        for qualname, sigs in profile.signatures.items():
            if len(sigs) > 1:
                start = max(0, len(os.path.commonprefix(sigs)) - 30)
                print(f"  {qualname}: " + " | ".join(sig[start:][:120] for sig in sigs))


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
