"""Speed-profile problems: evaluation throughput and what DE finds with 4,000 evaluations.

For each built-in single-run case and each encoding, prints
- evaluations per second through ``Problem.evaluate`` (population 200, the vectorised path);
- the best net energy DE (pop 40, 4,000 evaluations, seed 1) finds in the constrained form
  ``min energy s.t. |T - T_plan| <= 1 s``, with its running time.
With ``--reference`` it adds the exact optimum solved at the DE run's own running time
(``pymoo_rail.optimal.solved_energy_gap``), its certificate and the gap. Writes the table to ``benchmarks/reports/problems.md`` as well.

Usage: ``python benchmarks/problems.py [--evals 4000] [--reference]``
"""

from __future__ import annotations

import argparse
import time
from pathlib import Path

import numpy as np
from pymoo.algorithms.soo.nonconvex.de import DE
from pymoo.optimize import minimize

from pymoo_rail.cases import load_case
from pymoo_rail.problems import SpeedProfileProblem

ENCODINGS = {
    "speed codes, gradient/limit partition": dict(encoding="speed_codes"),
    "speed codes, gradient/limit, sections <= 200 m": dict(encoding="speed_codes", max_section_m=200.0),
    "speed codes, 12 equal sections": dict(encoding="speed_codes", partition="equal", n_sections=12),
    "switching points": dict(encoding="switching_points"),
}


def _hold_brake_regimes(case) -> tuple[str, ...]:
    """The default switching-point sequence with every "hold" braking to hold down descents."""
    from pymoo_rail.problems.encodings import SwitchingPoints

    return tuple("hold_brake" if r == "hold" else r for r in SwitchingPoints.build(case).regimes)


def encodings(case) -> dict:
    """The encodings compared on ``case``: :data:`ENCODINGS` and switching points with hold_brake."""
    return {**ENCODINGS, "switching points, hold_brake": dict(encoding="switching_points",
                                                             regimes=_hold_brake_regimes(case))}
CASES = ("yizhuang", "metro-a", "wuguang-crh3")


def throughput(problem: SpeedProfileProblem, pop: int = 200, repeats: int = 5) -> float:
    rng = np.random.default_rng(0)
    X = problem.xl + rng.random((pop, problem.n_var)) * (problem.xu - problem.xl)
    problem.evaluate(X[:2])  # compile / load cache
    t0 = time.perf_counter()
    for _ in range(repeats):
        problem.evaluate(X)
    return pop * repeats / (time.perf_counter() - t0)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--evals", type=int, default=4000)
    parser.add_argument("--reference", action="store_true", help="add the exact optimum and the gap")
    parser.add_argument("--out", default=str(Path(__file__).parent / "reports" / "problems.md"))
    args = parser.parse_args()
    rows = []
    header = "| case | encoding | n_var | evals/s | DE energy kWh | running time s |" + (
        " optimum kWh | certificate kWh | gap % |" if args.reference else "")
    print(header)
    for name in CASES:
        case = load_case(name)
        for label, kwargs in encodings(case).items():
            problem = SpeedProfileProblem(case, objectives=("energy",), time_tolerance_s=1.0, **kwargs)
            rate = throughput(problem)
            res = minimize(problem, DE(pop_size=40), ("n_evals", args.evals), seed=1)
            tr = problem.trajectory(res.X)
            row = f"| {name} | {label} | {problem.n_var} | {rate:,.0f} | {tr.energy.net_kwh:.3f} | {tr.running_time_s:.2f} |"
            if args.reference:
                from pymoo_rail.optimal import solved_energy_gap

                # the optimum at the DE run's own running time (a solver run may end up to 0.5 s
                # off the request; along a slope of ~2.5 kWh/s that alone would be 1 kWh)
                point = solved_energy_gap(np.array([[tr.running_time_s, tr.energy.net_kwh]]), case)["points"]
                best, bound = float(point["optimal_kwh"].iloc[0]), float(point["energy_bound_kwh"].iloc[0])
                row += f" {best:.3f} | {bound:.3f} | {100 * (tr.energy.net_kwh / best - 1):.2f} |"
            print(row, flush=True)
            rows.append(row)
    out = Path(args.out)
    out.parent.mkdir(parents=True, exist_ok=True)
    sep = "|" + "---|" * (header.count("|") - 1)
    out.write_text("# Speed-profile problems: throughput and DE with a fixed budget\n\n"
                   f"DE (pop 40, {args.evals} evaluations, seed 1), constrained form |T - T_plan| <= 1 s; "
                   "evaluations per second through `Problem.evaluate` with a population of 200.\n\n"
                   + "\n".join([header, sep, *rows]) + "\n")


if __name__ == "__main__":
    main()
