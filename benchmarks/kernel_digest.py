"""Digest of kernel results for a bit-identity check before and after a change to the kernels.

Prints one SHA-256 per item: batch summaries of 64 random decisions per encoding on several
built-in cases (both the parallel and the serial batch), full traces, the braking envelope, the
exact solver's optimal run, the ATO tracking of a flat-out run, and the front of the README's main
command (NSGA-II, seed 1). Run it on two versions of the code (each with its own
``NUMBA_CACHE_DIR``) and compare the lines: equal digests mean bit-identical results. A digest is
not portable across machines (libm, CPU), only across versions on one machine.

    python benchmarks/kernel_digest.py > digest.txt
"""

from __future__ import annotations

import hashlib
import warnings

import numpy as np


def digest(*arrays) -> str:
    h = hashlib.sha256()
    for a in arrays:
        a = np.ascontiguousarray(np.asarray(a, dtype=float))
        h.update(str(a.shape).encode())
        h.update(a.tobytes())
    return h.hexdigest()[:16]


def main() -> None:
    from pymoo.algorithms.moo.nsga2 import NSGA2
    from pymoo.optimize import minimize

    from pymoo_rail.cases import load_case
    from pymoo_rail.control import PID, track
    from pymoo_rail.optimal import min_running_time, optimal_profile
    from pymoo_rail.problems import SpeedProfileProblem
    from pymoo_rail.sim import Simulator
    from pymoo_rail.sim import kernel as k

    warnings.simplefilter("ignore")
    for name in ("yizhuang", "metro-a", "wuguang-crh3", "ttobench-ref-downhill"):
        case = load_case(name)
        for encoding in ("speed_codes", "switching_points", "braking_onset"):
            problem = SpeedProfileProblem(case, encoding=encoding)
            X = np.random.default_rng(7).uniform(problem.xl, problem.xu, (64, problem.n_var))
            S = problem.summaries(X)
            line = f"{name:24} {encoding:17} summaries {digest(S)}"
            t = problem.trajectory(X[0]).to_frame()
            line += f"  trace {digest(t.select_dtypes('number').to_numpy())}"
            print(line, flush=True)
        sim = Simulator(case)
        print(f"{name:24} envelope {digest(sim.model.envelope_ms)}", flush=True)
        programs = np.random.default_rng(3).uniform(0, 1, (50, 6, 3))
        length = sim.length_m
        programs[:, :, 0] = np.sort(programs[:, :, 0], axis=1) * length
        programs[:, -1, 0] = length
        programs[:, :, 1] = np.floor(programs[:, :, 1] * 7)
        programs[:, :, 2] = programs[:, :, 2] * 25.0
        decel = programs[:, :, 1] == k.MODE_DECEL
        programs[:, :, 2][decel] = 0.3 + programs[:, :, 2][decel] / 25.0
        print(f"{name:24} all modes serial {digest(k.simulate_batch_serial(sim.model, programs))} "
              f"parallel {digest(k.simulate_batch(sim.model, programs))}", flush=True)
    case = load_case("yizhuang")
    run = optimal_profile(case, 1.1 * min_running_time(case))
    print(f"optimal_profile yizhuang {digest(run.to_frame().select_dtypes('number').to_numpy())}", flush=True)
    tracked = track(case, Simulator(case).flat_out(), PID())
    frame = tracked.to_frame()
    print(f"track PID yizhuang {digest(frame.select_dtypes('number').to_numpy())}", flush=True)
    problem = SpeedProfileProblem(case)
    res = minimize(problem, NSGA2(pop_size=40), ("n_gen", 50), seed=1, verbose=False)
    print(f"nsga2 yizhuang seed 1 front {digest(res.F[np.lexsort(res.F.T)])}", flush=True)


if __name__ == "__main__":
    main()
