"""Every track of the TTOBench release x its suitable train: minimum time, optimum at 1.15 x, NSGA2.

Usage: python benchmarks/ttobench_release.py [TTOBENCH_ROOT] [--nsga2-gen N] [--only ID ...] [--report PATH]
Prints one row per track (first stop -> last stop): length, minimum running time, the exact
optimum's energy at 1.15 x that time, whether that run holds every limit and stops at the platform
(limit excess <= 1e-6 m/s, stop error <= 0.25 m, final speed 0), NSGA2's best feasible energy
(pop 40, N generations, seed 1, objectives energy and time error) among members within 2 s of the
planned time, the gap, the size of NSGA2's front, and the CPU seconds of each step. ``--report``
also writes the table, with the total CPU time, to a markdown file.
"""

from __future__ import annotations

import argparse
import time
from pathlib import Path

from pymoo_rail.cases.ttobench_release import release_pairs
from pymoo_rail.experiments.release_check import release_case, release_row

DEFAULT_ROOT = Path(__file__).resolve().parents[1] / "tests" / "data" / "ttobench"
HEADER = ["| track | train | km | T_min s | optimum kWh @1.15 | limits, stop | CPU s | NSGA2 kWh | gap % "
          "| front size | n_var | CPU s |", "|---|---|---|---|---|---|---|---|---|---|---|---|"]


def main() -> None:
    parser = argparse.ArgumentParser()
    parser.add_argument("root", nargs="?", default=DEFAULT_ROOT)
    parser.add_argument("--nsga2-gen", type=int, default=60)
    parser.add_argument("--only", nargs="*")
    parser.add_argument("--max-section-m", type=float, default=None,
                        help="speed-code sections no longer than this (default: the encoding's default)")
    parser.add_argument("--pop-size", type=int, default=40)
    parser.add_argument("--report", type=Path, default=None, help="also write the table to this markdown file")
    args = parser.parse_args()
    lines = list(HEADER)
    print("\n".join(lines), flush=True)
    cpu0 = time.process_time()
    settings = {} if args.max_section_m is None else {"max_section_m": args.max_section_m}
    for track, train in release_pairs(args.root):
        if args.only and track.stem not in args.only:
            continue
        r = release_row(release_case(track, train), args.nsga2_gen, args.pop_size, settings)
        lines.append(f"| {track.stem} | {train.stem} | {r['km']:.1f} | {r['t_min_s']:.1f} | {r['optimum_kwh']:.2f} | "
                     f"{'held' if r['held'] else 'VIOLATED'} | {r['optimum_cpu_s']:.1f} | {r['nsga2_kwh']:.2f} | "
                     f"{r['gap_pct']:.1f} | {r['front_size']} | {r['n_var']} | {r['nsga2_cpu_s']:.1f} |")
        print(lines[-1], flush=True)
    total = f"Total CPU: {time.process_time() - cpu0:.0f} s (NSGA2 pop {args.pop_size}, {args.nsga2_gen} generations, seed 1)."
    print(total)
    if args.report is not None:
        args.report.write_text("# Every TTOBench track with its train\n\nWritten by `python benchmarks/ttobench_release.py"
                               f" --nsga2-gen {args.nsga2_gen} --report {args.report.as_posix()}`.\n\n"
                               + "\n".join(lines) + f"\n\n{total}\n")


if __name__ == "__main__":
    main()
