"""Digests of kernel results, for a bit-identity check before and after a change to the kernels.

:func:`kernel_digests` yields one line per item: batch summaries of 64 random decisions per
encoding on several built-in cases (both the parallel and the serial batch), full traces, the
braking envelope, the exact solver's optimal run, the ATO tracking of a flat-out run, and the
front of the README's main command (NSGA-II, seed 1). Equal lines from two versions of the code
(each with its own ``NUMBA_CACHE_DIR``) mean bit-identical results. A digest is not portable
across machines (libm, CPU), only across versions on one machine.
"""

from __future__ import annotations

import hashlib
import warnings
from typing import Iterator

import numpy as np

from pymoo_rail.cases import load_case
from pymoo_rail.control import PID, track
from pymoo_rail.optimal import min_running_time, optimal_profile
from pymoo_rail.problems import SpeedProfileProblem
from pymoo_rail.sim import Simulator
from pymoo_rail.sim import kernel as k

DIGEST_CASES = ("yizhuang", "metro-a", "wuguang-crh3", "ttobench-ref-downhill")
ENCODINGS = ("speed_codes", "switching_points", "braking_onset")


def digest(*arrays) -> str:
    """The first 16 hex digits of the SHA-256 of the arrays' shapes and float64 bytes."""
    h = hashlib.sha256()
    for a in arrays:
        a = np.ascontiguousarray(np.asarray(a, dtype=float))
        h.update(str(a.shape).encode())
        h.update(a.tobytes())
    return h.hexdigest()[:16]


def all_mode_programs(length_m: float, runs: int = 50, segments: int = 6, seed: int = 3) -> np.ndarray:
    """Random kernel programs that use every driving mode, ending at ``length_m``."""
    programs = np.random.default_rng(seed).uniform(0, 1, (runs, segments, 3))
    programs[:, :, 0] = np.sort(programs[:, :, 0], axis=1) * length_m
    programs[:, -1, 0] = length_m
    programs[:, :, 1] = np.floor(programs[:, :, 1] * 7)
    programs[:, :, 2] = programs[:, :, 2] * 25.0
    decel = programs[:, :, 1] == k.MODE_DECEL
    programs[:, :, 2][decel] = 0.3 + programs[:, :, 2][decel] / 25.0
    return programs


def _frame_digest(run) -> str:
    return digest(run.to_frame().select_dtypes("number").to_numpy())


def case_digests(name: str) -> Iterator[str]:
    """The lines of one case: summaries and a trace per encoding, the envelope, all-mode batches."""
    case = load_case(name)
    for encoding in ENCODINGS:
        problem = SpeedProfileProblem(case, encoding=encoding)
        X = np.random.default_rng(7).uniform(problem.xl, problem.xu, (64, problem.n_var))
        yield (f"{name:24} {encoding:17} summaries {digest(problem.summaries(X))}"
               f"  trace {_frame_digest(problem.trajectory(X[0]))}")
    sim = Simulator(case)
    yield f"{name:24} envelope {digest(sim.model.envelope_ms)}"
    programs = all_mode_programs(sim.length_m)
    yield (f"{name:24} all modes serial {digest(k.simulate_batch_serial(sim.model, programs))} "
           f"parallel {digest(k.simulate_batch(sim.model, programs))}")


def kernel_digests(cases=DIGEST_CASES) -> Iterator[str]:
    """Every digest line (see the module docstring), computed lazily, in a fixed order."""
    from pymoo.algorithms.moo.nsga2 import NSGA2
    from pymoo.optimize import minimize

    warnings.simplefilter("ignore")
    for name in cases:
        yield from case_digests(name)
    case = load_case("yizhuang")
    yield f"optimal_profile yizhuang {_frame_digest(optimal_profile(case, 1.1 * min_running_time(case)))}"
    yield f"track PID yizhuang {_frame_digest(track(case, Simulator(case).flat_out(), PID()))}"
    res = minimize(SpeedProfileProblem(case), NSGA2(pop_size=40), ("n_gen", 50), seed=1, verbose=False)
    yield f"nsga2 yizhuang seed 1 front {digest(res.F[np.lexsort(res.F.T)])}"
