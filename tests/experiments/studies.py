"""Study declarations shared by the experiment tests (importable from a subprocess)."""

from __future__ import annotations

from pymoo_rail.experiments import Study, algorithm, problem


def small_study(n_gen: int = 8, name: str = "zdt-small") -> Study:
    """The done-when study of issue 5 (3 problems x 3 algorithms x 5 seeds) with tiny budgets."""
    return Study(
        name,
        problems=[problem("zdt1", n_var=8), problem("zdt2", n_var=8), problem("zdt3", n_var=8)],
        algorithms=[algorithm("nsga2", pop_size=12), algorithm("moead", pop_size=12),
                    algorithm("sms-emoa", pop_size=12)],
        seeds=[1, 2, 3, 4, 5],
        budget={"n_gen": n_gen},
        baseline="nsga2",
    )
