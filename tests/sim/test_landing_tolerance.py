"""Landing on the braking envelope must not fail by rounding when braking depends on speed."""

import numpy as np
import pytest

from pymoo_rail.cases import load_case
from pymoo_rail.sim import Simulator, gradient_limit_partition, speed_code_programs


@pytest.mark.parametrize("dx_m", [1.0, 0.5])
def test_power_capped_braking_without_decel_cap_stops_at_the_platform(dx_m):
    # yizhuang-ttobench: 260 kN / 4333 kW braking and no deceleration cap. With an absolute 1e-9 N
    # tolerance the train left the envelope by rounding at 67 km/h and stopped 1.2e-5 m short.
    case = load_case("yizhuang-ttobench")
    bounds = gradient_limit_partition(case.line)
    limits = np.array([case.line.limit_kmh_at(0.5 * (a + b)) for a, b in zip(bounds[:-1], bounds[1:])])
    tr = Simulator(case, dx_m=dx_m).run(speed_code_programs(bounds, 0.8 * limits / 3.6)[0])
    assert tr.reached
    assert tr.stop_error_m == 0.0
    assert tr.summary["limit_excess_ms"] == 0.0
