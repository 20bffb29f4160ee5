"""Solvers shared by the optimal tests (their transition tables are built once)."""

import pytest

from pymoo_rail.optimal import OptimalSolver
from tests.optimal.cases import hilly_case


@pytest.fixture(scope="session")
def yizhuang_solver(yizhuang):
    return OptimalSolver(yizhuang)


@pytest.fixture(scope="session")
def hilly_solver():
    return OptimalSolver(hilly_case())
