"""The throughput measurements: closed forms of the cell count and the static schedule's balance,
the programs within bounds, and tables with the columns the benchmark prints (no timed assertion)."""

from __future__ import annotations

import numpy as np
import pytest

from pymoo_rail.cases import load_case
from pymoo_rail.experiments import throughput as tp
from pymoo_rail.problems import SpeedProfileProblem
from pymoo_rail.sim import kernel as k


def _summaries(stop_m):
    out = np.zeros((len(stop_m), k.OUT_STOP_POSITION_M + 1))
    out[:, k.OUT_STOP_POSITION_M] = stop_m
    return out


def test_a_run_that_stops_inside_a_cell_counts_that_cell():
    assert tp.cells_per_run(_summaries([100.0, 100.5, 0.0]), dx_m=1.0).tolist() == [100.0, 101.0, 0.0]


def test_balance_of_equal_runs_is_the_thread_count_and_a_lone_long_pair_caps_it():
    assert tp.static_balance(_summaries([10.0] * 8), 1.0, threads=2) == 2.0
    # pairs cost 30, 10, 10, 10: blocks [30, 10] and [10, 10] -> 60 / 40
    assert tp.static_balance(_summaries([30.0, 5.0, 10.0, 10.0, 10.0, 1.0, 10.0, 10.0]), 1.0, 2) == 1.5
    assert tp.static_balance(_summaries([10.0] * 3), 1.0, threads=1) == 1.0  # odd batch: a padded empty run


def test_best_time_is_the_least_of_the_rounds():
    ticks = iter([0.0, 3.0, 10.0, 11.0, 20.0, 22.0])
    assert tp.best_time(lambda: None, 3, clock=lambda: next(ticks)) == 1.0


def test_random_programs_are_reproducible_and_within_the_bounds():
    problem = SpeedProfileProblem(load_case("yizhuang"))
    a, b = tp.random_programs(problem, 5), tp.random_programs(problem, 5)
    assert a.shape[0] == 5 and np.array_equal(a, b) and a.flags.c_contiguous


@pytest.mark.slow
def test_kernel_and_rate_tables_have_the_printed_columns():
    kernel = tp.kernel_table(1, cases=("yizhuang",), pop=4)
    assert list(kernel.columns) == ["case", "cells_per_run", "ns_per_cell", "/ bound"]
    assert kernel.attrs["bound_ns"] > 0 and (kernel["ns_per_cell"] > 0).all()
    rates = tp.rate_table(1, cases=("yizhuang",), populations=(2,))
    assert list(rates.columns) == ["case", "pop", "evals_per_s", "Mcells_per_s"]
    scaling = tp.scaling_table(1, populations=(2,))
    assert {"wall 1/2", "cpu 2/1", "expected", "balance", "serial ms"} <= set(scaling.columns)

