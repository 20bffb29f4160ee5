"""Exact reference solver: the minimum-energy run for a given running time (the physical limit).

Dynamic programming over (position, speed) on the simulator's own physics; see
``docs/optimal.md`` for the method and its measured accuracy.
"""

from pymoo_rail.optimal.reference import ReferenceAtTime, solved_energy_gap
from pymoo_rail.optimal.solver import OptimalSolver, min_running_time, optimal_front, optimal_profile

__all__ = ["optimal_profile", "optimal_front", "min_running_time", "OptimalSolver", "ReferenceAtTime",
           "solved_energy_gap"]
