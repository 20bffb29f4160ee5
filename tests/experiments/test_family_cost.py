"""pymoo_rail.experiments.family_cost: the suite families' throughput table (fast; the fronts' CPU is the script's)."""

from __future__ import annotations

from pymoo_rail.experiments.family_cost import BATCH, evaluations_per_s, throughput_table
from pymoo_rail.suite import get_problem


def test_the_throughput_table_has_a_row_per_family_and_n_var():
    table = throughput_table(["generated-metro-bi"], [10, 30], seed=7, min_cpu_s=0.02)
    assert list(table["n_var"]) == [10, 30] and set(table["family"]) == {"generated-metro-bi"}
    assert (table["evals_per_cpu_s"] > 0).all()


def test_the_rate_counts_whole_batches_in_the_cpu_time_spent():
    problem = get_problem("generated-metro-bi", n_var=10, seed=7)
    rate = evaluations_per_s(problem, min_cpu_s=0.05)
    assert rate >= BATCH / 10.0  # at least one batch, in a time not far above the asked minimum
