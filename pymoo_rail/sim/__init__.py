"""Numba simulator: dynamics over distance, driving programs, energy accounting, traces.

The simulator never imports pymoo.
"""

from pymoo_rail.sim.drivers import (
    braking_programs,
    equal_partition,
    flat_out_program,
    gradient_limit_partition,
    speed_code_programs,
    switching_programs,
)
from pymoo_rail.sim.kernel import MODE_NAMES, OUT_NAMES, REGIME_NAMES
from pymoo_rail.sim.physics import KernelModel, build_kernel_model
from pymoo_rail.sim.simulator import Simulator
from pymoo_rail.sim.trajectory import EnergyBreakdown, Trajectory

__all__ = ["Simulator", "Trajectory", "EnergyBreakdown", "KernelModel", "build_kernel_model",
           "speed_code_programs", "switching_programs", "braking_programs", "flat_out_program", "gradient_limit_partition",
           "equal_partition", "OUT_NAMES", "REGIME_NAMES", "MODE_NAMES"]
