"""Digest of kernel results for a bit-identity check before and after a change to the kernels.

Prints one SHA-256 per item: batch summaries of 64 random decisions per encoding on several
built-in cases (both the parallel and the serial batch), full traces, the braking envelope, the
exact solver's optimal run, the ATO tracking of a flat-out run, and the front of the README's main
command (NSGA-II, seed 1). Run it on two versions of the code (each with its own
``NUMBA_CACHE_DIR``) and compare the lines: equal digests mean bit-identical results. A digest is
not portable across machines (libm, CPU), only across versions on one machine.

    python benchmarks/kernel_digest.py > digest.txt
"""

from pymoo_rail.experiments.digest import kernel_digests

if __name__ == "__main__":
    for line in kernel_digests():
        print(line, flush=True)
