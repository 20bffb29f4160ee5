"""The paper's operating sequences on the one kernel against the former subsection integrator.

The subsection driver of Chen et al. (2017) used to have its own integrator
(``pymoo_rail/sim/subsections.py``, removed after commit ``d322f8f``). This script loads that
integrator and the problem around it from the git history, decodes on-time strategies with it
(the paper's hand-made example and repaired random vectors), writes each decoded strategy as
kernel rows (traction share ``gamma`` up to the decoded turning speed, then coasting or regenerative
holding from where the old run entered its last phase, then ``MODE_STOP`` from the decoded braking
point) and runs them on the kernel. It prints, per strategy and train, the traction and
regenerated energy and the running time of both, the largest speed difference, and whether the
old decoding was physically valid (its feasibility constraint: no force beyond the train's traction
or braking limit, every exit speed reachable). Nothing is paced here: the same strategy, two
integrators.

Usage: ``python benchmarks/cooperative_seed_kernel.py [--vectors 8]`` (needs the git history).
"""

from __future__ import annotations

import argparse
import importlib.util
import subprocess
import sys
import tempfile
from pathlib import Path

import numpy as np

from pymoo_rail.cases import load_case
from pymoo_rail.sim.kernel import MODE_COAST, MODE_HOLD_BRAKE, MODE_STOP, MODE_TOWARD

OLD = "d322f8f"
ROOT = Path(__file__).resolve().parent.parent
GENES_A = [(0.7, 55, 1), (0.7, 65, 1), (0.5, 60, 1), (0.5, 70, 1), (0.5, 70, 1), (0.6, 60, 1), (0.5, 55, 1)]
GENES_B = [(0.7, 55, 1), (0.5, 65, 1), (0.5, 65, 1), (0.6, 60, 1), (0.5, 55, 1)]


def load_old(tmp: Path):
    """The former subsection integrator and problem module, from the git history."""
    modules = {}
    for name, path in (("pymoo_rail.sim.subsections", "pymoo_rail/sim/subsections.py"),
                       ("old_cooperative_seed", "pymoo_rail/problems/cooperative_seed.py")):
        source = subprocess.run(["git", "-C", str(ROOT), "show", f"{OLD}:{path}"], check=True, capture_output=True,
                                text=True).stdout
        file = tmp / (name.replace(".", "_") + ".py")
        file.write_text(source)
        spec = importlib.util.spec_from_file_location(name, file)
        module = importlib.util.module_from_spec(spec)
        sys.modules[name] = module
        spec.loader.exec_module(module)
        modules[name] = module
    return modules["old_cooperative_seed"]


def kernel_program(train, run) -> np.ndarray:
    """The decoded strategy of one old run as kernel rows (rows, 4)."""
    tr = run.trajectory
    x, f = tr.position_m, tr.force_n
    rows = []
    for _, sub in run.subsections.iterrows():
        s, e = int(round(sub["start_m"] / train.model.dx_m)), int(round(sub["end_m"] / train.model.dx_m))
        last = e
        descent = int(sub["type"]) == 3
        while last > s and ((f[last - 1] < 0.0) if descent else (f[last - 1] == 0.0)):
            last -= 1
        rows.append((x[last], MODE_TOWARD, sub["v_turn_ms"], sub["gamma"]))
        rows.append((x[e], MODE_HOLD_BRAKE if descent else MODE_COAST, 0.0, 1.0))
    rows.append((x[-1], MODE_STOP, 0.0, 1.0))
    return np.array(rows)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--vectors", type=int, default=8, help="repaired random vectors besides the example")
    args = parser.parse_args()
    from pymoo_rail.sim import Simulator

    pair = load_case("cooperative-pair")
    with tempfile.TemporaryDirectory() as tmp:
        old = load_old(Path(tmp))
        absolute = old.CooperativeSeedProblem(pair, 45.0, speed_genes="absolute")
        relative = old.CooperativeSeedProblem(pair, 45.0)
        example = [250.0, 200.0] + [g for t in GENES_A + GENES_B for g in t]
        rng = np.random.default_rng(0)
        X = relative.xl + rng.random((4 * args.vectors, relative.n_var)) * (relative.xu - relative.xl)
        X = old.PunctualityRepair().apply(relative, X)
        on_time = np.all(relative.evaluate(X, return_as_dictionary=True)["G"][:, :2] <= 0, axis=1)
        cases = [("example", absolute, np.array(example))] + [
            (f"random {i}", relative, x) for i, x in enumerate(X[on_time][:args.vectors])]
        sims = [Simulator(pair.leg(k)) for k in (0, 1)]
        print("| strategy | train | old run valid | traction old / kernel (kWh) | regen old / kernel (kWh) | "
              "time old / kernel (s) | largest speed difference (km/h) |")
        print("|---|---|---|---|---|---|---|")
        diffs = []
        for label, problem, x in cases:
            sol = problem.decode(x)
            for k, (run, name) in enumerate(((sol.a, "A"), (sol.b, "B"))):
                tr_new = sims[k].run(kernel_program(problem.trains[k], run))
                tr_old = run.trajectory
                n = min(tr_new.speed_ms.shape[0], tr_old.speed_ms.shape[0])
                dv = 3.6 * float(np.max(np.abs(tr_new.speed_ms[:n] - tr_old.speed_ms[:n])))
                rel = tr_new.energy.traction_kwh / run.traction_kwh - 1.0
                s = run.summary
                valid = s["force_excess_ms2"] <= 1e-3 and s["decode_excess_ms"] <= 1e-9
                if valid:
                    diffs.append((rel, tr_new.running_time_s - tr_old.running_time_s, dv))
                verdict = "yes" if valid else (f"no: forces {s['force_excess_ms2']:.2g} m/s2 beyond the limits, exit "
                                               f"speeds {s['decode_excess_ms']:.2g} m/s out of reach")
                print(f"| {label} | {name} | {verdict} | {run.traction_kwh:.3f} / {tr_new.energy.traction_kwh:.3f} | "
                      f"{run.regen_kwh:.3f} / {tr_new.energy.regen_kwh:.3f} | {tr_old.running_time_s:.2f} / "
                      f"{tr_new.running_time_s:.2f} | {dv:.2f} |")
        rel = np.array(diffs)
        print(f"\nover the {len(rel)} valid old runs: largest speed difference {rel[:, 2].max():.2f} km/h; "
              f"traction kernel / old - 1: median {100 * np.median(rel[:, 0]):+.2f} %, range "
              f"{100 * rel[:, 0].min():+.2f} to {100 * rel[:, 0].max():+.2f} %; running time kernel - old: median "
              f"{np.median(rel[:, 1]):+.2f} s, range {rel[:, 1].min():+.2f} to {rel[:, 1].max():+.2f} s")


if __name__ == "__main__":
    main()
