"""Throughput of the simulator and of MOABC, and how close the kernel is to the hardware.

Prints, measured in this one run:

1. the kernel on one core (``simulate_batch_serial``, CPU time per cell) for each built-in case,
   against the latency bound of docs/performance.md: the dependency chain of one cell (two square
   roots, two force-curve evaluations, two resistance evaluations and the two integration
   updates), timed on this CPU by a loop that runs exactly that chain;
2. evaluations and cells per second of ``Simulator.run_batch`` per case and population size;
3. thread scaling: wall time of the same batch on 1 and on 2 Numba threads (both through the
   parallel kernel), and the serial kernel against the parallel one for small batches, which
   is where ``PARALLEL_MIN_CELLS`` comes from;
4. MOABC, 40 bees x 100 cycles on ``yizhuang`` (energy, time error), warm (second run), with
   1 thread and with all threads: CPU and wall time;
5. the done-when lines: <= 20 ns per cell per core, >= 1.7x on 2 threads at population >= 200,
   MOABC <= 0.3 s.

``--jit`` measures instead the batch kernel (yizhuang, 200 speed-code programs) against the same
code without JIT (``NUMBA_DISABLE_JIT=1``), and the first call with an empty and a warm Numba cache,
each in a child process of this script.

Wall-clock ratios are only meaningful on a quiet machine: the script prints the load average
next to them. CPU time per cell is not distorted by other load (as long as the core is not
shared with a sibling thread). Every timing is the minimum over ``--repeats`` rounds.

Usage: ``python benchmarks/throughput.py [--repeats 5] [--quick]``, ``python benchmarks/throughput.py --jit``
"""

from __future__ import annotations

import argparse
import os
from pathlib import Path

import numba
import pandas as pd

from pymoo_rail.experiments import throughput as tp
from pymoo_rail.experiments.report import fill_template, markdown
from pymoo_rail.sim.simulator import PARALLEL_MIN_CELLS

TEMPLATES = Path(__file__).resolve().parent / "templates"


def jit_report(repeats: int) -> str:
    """The JIT against pure Python, and the first call with an empty and a warm cache."""
    r = tp.jit_comparison(repeats)
    warm, nojit, cold = r["warm"], r["nojit"], r["cold"]
    return fill_template(TEMPLATES / "throughput_jit.md", {
        "warm_rate": f"{warm['evals_per_s']:.1f}", "nojit_rate": f"{nojit['evals_per_s']:.1f}",
        "wall_ratio": f"{warm['evals_per_s'] / nojit['evals_per_s']:.1f}",
        "cpu_ratio": f"{nojit['cpu_us_per_eval'] / warm['cpu_us_per_eval']:.1f}",
        "warm_cpu": f"{warm['cpu_us_per_eval']:.1f}", "nojit_cpu": f"{nojit['cpu_us_per_eval']:.1f}",
        "cold_first": f"{cold['first_call_s']:.2f}", "warm_first": f"{warm['first_call_s']:.2f}"}).rstrip("\n")


def report(repeats: int, quick: bool) -> str:
    """Sections 1 to 5."""
    cases = tp.CASES[:1] if quick else tp.CASES
    kernel, rates = tp.kernel_table(repeats, cases), tp.rate_table(repeats, cases)
    scaling = tp.scaling_table(repeats)
    load = os.getloadavg()[0]
    moabc = [tp.moabc_timing(1), tp.moabc_timing(numba.config.NUMBA_NUM_THREADS)]
    ns, big = float(kernel["ns_per_cell"].iloc[0]), scaling[scaling["pop"] >= 200]
    wall, cpu, speedup = min(row["wall_s"] for row in moabc), moabc[0]["cpu_s"], big["wall 1/2"].min()
    verdict = {True: "yes", False: "NO"}
    return fill_template(TEMPLATES / "throughput.md", {
        "bound": f"{kernel.attrs['bound_ns']:.1f}", "kernel": markdown(kernel, 2), "rates": markdown(rates, 1),
        "repeats": repeats, "load": f"{load:.2f}", "layer": numba.threading_layer(), "min_cells": PARALLEL_MIN_CELLS,
        "scaling": markdown(scaling, 3), "moabc": markdown(pd.DataFrame(moabc), 3),
        "load_end": f"{os.getloadavg()[0]:.2f}", "ns": f"{ns:.1f}", "ns_ok": verdict[ns <= 20],
        "speedup": f"{speedup:.2f}", "speedup_ok": verdict[speedup >= 1.7], "expected": f"{big['expected'].min():.2f}",
        "moabc_wall": f"{wall:.3f}", "moabc_wall_ok": verdict[wall <= 0.3], "moabc_cpu": f"{cpu:.3f}",
        "moabc_cpu_ok": verdict[cpu <= 0.3]}).rstrip("\n")


def main(argv=None) -> None:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--repeats", type=int, default=5)
    parser.add_argument("--quick", action="store_true", help="yizhuang only")
    parser.add_argument("--jit", action="store_true", help="the kernel against the same code without JIT")
    args = parser.parse_args(argv)
    print(f"{os.cpu_count()} CPUs, {numba.config.NUMBA_NUM_THREADS} Numba threads, load average "
          f"{os.getloadavg()[0]:.2f} at start")
    print(jit_report(4 * args.repeats) if args.jit else report(args.repeats, args.quick))


if __name__ == "__main__":
    main()
