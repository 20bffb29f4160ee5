"""A run that cannot reach the platform is blamed on the entry that causes it, not on 'line'."""

from __future__ import annotations

import pytest

from pymoo_rail.cases import load_case
from pymoo_rail.model import InfeasibleCaseError, case_from_dict, case_to_dict
from pymoo_rail.sim import Simulator


def _variant(edit):
    data = case_to_dict(load_case("metro-a"))  # 1000 m, 332 t, braking 1.1 m/s^2 (about 365 kN)
    edit(data)
    return case_from_dict(data, "variant", allow_implausible=True)  # the simulator's diagnosis behind the bounds


def _cause(edit) -> InfeasibleCaseError:
    with pytest.raises(InfeasibleCaseError) as raised:
        Simulator(_variant(edit)).check_planned_time()
    return raised.value


def test_a_neutral_section_over_the_whole_line_is_named():
    err = _cause(lambda d: d["line"].__setitem__("neutral_sections", [[0.0, 1000.0]]))
    assert err.field == "line.neutral_sections[0]" and "whole line" in str(err)


def test_an_absurd_mass_is_named():
    err = _cause(lambda d: d["train"].__setitem__("mass_t", 1e9))
    assert err.field == "train.mass_t" and err.value == 1e9 and "% of the train's weight" in str(err)


def test_no_minimum_running_time_for_a_run_that_never_arrives():
    slow = _variant(lambda d: d["train"].__setitem__("max_speed_kmh", 1e-200))
    with pytest.raises(InfeasibleCaseError):
        Simulator(slow).min_running_time_s()


def test_a_descent_the_train_cannot_brake_on_is_not_called_a_stall():
    # -500 permille pulls 332 t x 9.81 x 0.5 = 1628 kN down the hill: far above the ~400 kN of braking
    err = _cause(lambda d: d["line"].__setitem__("gradients", [[0.0, 500.0, -500.0], [500.0, 1000.0, 10.0]]))
    assert err.field == "line.gradients[0]" and "cannot brake" in str(err) and "1628 kN" in str(err)


def test_a_climb_too_steep_is_named():
    err = _cause(lambda d: d["line"].__setitem__("gradients", [[0.0, 500.0, 0.0], [500.0, 1000.0, 400.0]]))
    assert err.field == "line.gradients[1]" and "too steep" in str(err)


def test_a_limit_next_to_zero_is_named_not_the_line():
    err = _cause(lambda d: d["line"]["speed_limits"][0].__setitem__(2, 1e-300))
    assert err.field == "line.speed_limits[0]" and "below 1 km/h" in str(err)


def test_a_power_cap_next_to_zero_is_named_not_the_line():
    err = _cause(lambda d: d["train"]["traction"].__setitem__("max_power_kw", 1e-6))
    assert err.field == "train.traction.max_power_kw" and err.value == 1e-6
