"""Bad driving input and impossible cases give errors that name the field and the value."""

import math

import numpy as np
import pytest

from pymoo_rail.model import InfeasibleCaseError
from pymoo_rail.sim import Simulator, gradient_limit_partition, speed_code_programs, switching_programs


def test_nan_in_speed_codes_names_the_index(yizhuang):
    bounds = gradient_limit_partition(yizhuang.line)
    codes = np.full((2, 8), 15.0)
    codes[1, 3] = math.nan
    with pytest.raises(ValueError, match=r"speed_codes\[1, 3\] = nan"):
        speed_code_programs(bounds, codes)


def test_nan_in_switching_points():
    with pytest.raises(ValueError, match=r"switching_points\[0, 1\] = inf"):
        switching_programs([100.0, math.inf], ("traction", "coast", "brake"), 1000.0)


def test_wrong_number_of_codes(yizhuang):
    with pytest.raises(ValueError, match="8 sections"):
        speed_code_programs(gradient_limit_partition(yizhuang.line), np.ones(5))


def test_negative_code(yizhuang):
    with pytest.raises(ValueError, match=r"speed_codes\[0, 2\] = -1.0"):
        speed_code_programs(gradient_limit_partition(yizhuang.line), [1, 1, -1.0, 1, 1, 1, 1, 1])


def test_unknown_regime():
    with pytest.raises(ValueError, match="'warp'"):
        switching_programs([100.0], ("traction", "warp"), 1000.0)


def test_planned_time_below_minimum(yizhuang):
    sim = Simulator(yizhuang.with_planned_time(90.0))
    with pytest.raises(InfeasibleCaseError, match=r"run.planned_time_s.*90.0.*minimum running time"):
        sim.check_planned_time()
    assert 100.0 < Simulator(yizhuang).check_planned_time() < 150.0


def test_program_shape(yizhuang_sim):
    with pytest.raises(ValueError, match="shape"):
        yizhuang_sim.run(np.zeros(3))
