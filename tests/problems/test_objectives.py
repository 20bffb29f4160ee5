"""The objective table: every record reads a kernel column, names resolve, labels and scales follow it."""

import pytest

from pymoo_rail.problems.objectives import (
    OBJECTIVE_TABLE,
    Objective,
    canonical_objective,
    check_objectives,
    get_objective,
    objective_columns,
    objective_labels,
    objective_names,
    time_objectives,
)
from pymoo_rail.sim import OUT_NAMES


def test_every_objective_reads_a_kernel_column_and_has_a_unit_in_its_column():
    for obj in OBJECTIVE_TABLE:
        assert obj.kernel_column in OUT_NAMES, obj.name
        assert obj.column.startswith(obj.name.split("_")[0]), obj.name
    assert objective_names() == ("energy", "running_time", "time_error", "accel_variation", "jerk", "stop_error",
                                 "peak_power")
    assert objective_columns()["peak_power"] == "peak_power_kw"
    assert time_objectives() == ("running_time", "time_error")


def test_aliases_and_unknown_names():
    assert canonical_objective("jerk") == "accel_variation" and get_objective("jerk").name == "accel_variation"
    assert objective_labels()["jerk"] == "jerk: total variation of acceleration (m/s²)"
    with pytest.raises(ValueError, match=r"objective 'power' is unknown \(known: energy, .*peak_power\)"):
        check_objectives(("energy", "power"))
    with pytest.raises(ValueError, match="repeats an objective"):
        check_objectives(("jerk", "accel_variation"))
    with pytest.raises(ValueError, match="unknown here"):
        check_objectives(("energy", "peak_power"), known=("energy", "stop_error"))
    with pytest.raises(ValueError, match="scale_basis = 'median'"):
        Objective("x", "1", "x", "x", "net_kwh", "x", scale_basis="median")


def test_default_scales():
    assert get_objective("time_error").default_scale(3.0, 200.0) == pytest.approx(10.0)  # 5 % of the plan
    assert get_objective("running_time").default_scale(3.0, 200.0) == 200.0
    assert get_objective("stop_error").default_scale(3.0, 200.0) == 0.25
    assert get_objective("energy").default_scale(12.5, 200.0) == 12.5  # the flat-out run's value
    assert get_objective("accel_variation").default_scale(0.0, 200.0) == 1e-9  # never 0: it divides
