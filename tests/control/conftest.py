"""References for the tracking tests: ideal simulator runs of speed-code programs."""

import numpy as np
import pytest

from pymoo_rail.sim import gradient_limit_partition, speed_code_programs


def cruise_reference(sim, cruise_kmh):
    """The simulator's run of one target speed on every section (traction, hold, latest braking)."""
    bounds = gradient_limit_partition(sim.case.line)
    return sim.run(speed_code_programs(bounds, np.full(bounds.shape[0] - 1, cruise_kmh / 3.6))[0])


@pytest.fixture(scope="session")
def yizhuang_cruise(yizhuang_sim):
    return cruise_reference(yizhuang_sim, 65.0)


@pytest.fixture(scope="session")
def yizhuang_varied(yizhuang_sim):
    """Traction phases in the middle as well as cruising and coasting."""
    bounds = gradient_limit_partition(yizhuang_sim.case.line)
    codes = np.array([55.0, 70.0, 72.0, 60.0, 75.0, 66.0, 50.0, 55.0]) / 3.6
    return yizhuang_sim.run(speed_code_programs(bounds, codes)[0])
