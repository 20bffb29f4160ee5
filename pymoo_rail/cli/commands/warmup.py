"""``pymoo-rail warmup``: compile the Numba kernels ahead of the first run."""

from __future__ import annotations

from pymoo_rail.cli.arguments import add_command, say

ORDER = 70


def add_parser(sub) -> None:
    """Add ``warmup`` to the subcommands."""
    p = add_command(
        sub, "warmup", run, compiles=True, help="compile the simulator's kernels now (container images, clusters)",
        description="Compile the Numba kernels a command uses and store them in Numba's cache (next to the "
                    "installed package, or in NUMBA_CACHE_DIR), so that the first real run starts at once. Run "
                    "it when building a container image, or once before a study on a cluster whose workers "
                    "share the cache directory. Already compiled kernels are only loaded.",
        epilog="examples:\n  pymoo-rail warmup\n  pymoo-rail warmup --all\n"
               "  NUMBA_CACHE_DIR=/shared/numba pymoo-rail warmup --all")
    p.add_argument("--all", action="store_true",
                   help="also the exact reference solver ('reference') and the ATO tracking controllers")


def run(args) -> int:
    """Compile (or load) the kernels; returns the exit code."""
    from pymoo_rail.warmup import WARMUP_PARTS, warmup

    parts = WARMUP_PARTS if args.all else ("simulator",)
    for part, seconds in warmup(parts).items():
        say(f"{part}: ready ({seconds:.1f} s)")
    return 0
