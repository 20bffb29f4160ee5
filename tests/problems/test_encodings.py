"""Encodings as option objects (pymoo style) and the registry that resolves their names."""

import numpy as np
import pytest

from pymoo_rail.cases import load_case
from pymoo_rail.problems import SpeedProfileProblem
from pymoo_rail.problems.encodings import (
    ENCODINGS,
    BrakingOnset,
    EncodingSetup,
    PacedCodes,
    SpeedCodes,
    SwitchingPoints,
    decision_columns,
    encoding_class,
    encoding_names,
    encoding_settings,
    make_encoding,
)


def test_an_object_and_its_name_give_the_same_problem(yizhuang):
    by_name = SpeedProfileProblem(yizhuang, encoding="speed_codes", partition="equal", n_sections=12)
    by_object = SpeedProfileProblem(yizhuang, encoding=SpeedCodes(partition="equal", n_sections=12))
    np.testing.assert_array_equal(by_name.xl, by_object.xl)
    np.testing.assert_array_equal(by_name.xu, by_object.xu)
    X = np.random.default_rng(4).uniform(by_name.xl, by_name.xu, (8, by_name.n_var))
    np.testing.assert_array_equal(by_name.summaries(X), by_object.summaries(X))
    points = SpeedProfileProblem(yizhuang, encoding=SwitchingPoints(regimes=("traction", "coast", "brake")))
    assert points.n_var == 2 and points.encoding.regimes == ("traction", "coast", "brake")


def test_the_registry_names_every_encoding_and_its_settings():
    assert encoding_names() == ENCODINGS == ("speed_codes", "switching_points", "braking_onset", "paced_speed_codes")
    for name in ENCODINGS:
        assert encoding_class(name).name == name
    assert encoding_class("paced_speed_codes") is PacedCodes
    assert "partition" in encoding_settings("speed_codes") and "xl" not in encoding_settings("speed_codes")
    assert encoding_settings("switching_points") == ("regimes",)
    onset = make_encoding("braking_onset", regimes=("traction", "coast"), decel_range_ms2=None)
    assert type(onset) is BrakingOnset and onset.regimes == ("traction", "coast") and onset.decel_range_ms2 is None
    with pytest.raises(ValueError, match=r"encoding = 'zigzag' is unknown \(known: speed_codes, switching_points"):
        encoding_class("zigzag")


def test_a_setting_the_encoding_does_not_take_is_an_error(yizhuang):
    with pytest.raises(ValueError, match=r"partition = 'equal' does not apply to encoding = 'switching_points' "
                                         r"\(it applies to: speed_codes, paced_speed_codes\)"):
        SpeedProfileProblem(yizhuang, encoding="switching_points", partition="equal")
    # at its default value it is ignored, as a caller passing one set of settings to every encoding does
    assert SpeedProfileProblem(yizhuang, encoding="switching_points", partition="gradient_limit").n_var == 3
    with pytest.raises(ValueError, match=r"n_sections = 12 beside encoding = SpeedCodes\(.*set it on the encoding"):
        SpeedProfileProblem(yizhuang, encoding=SpeedCodes(), n_sections=12)
    with pytest.raises(ValueError, match="give an encoding name"):
        SpeedProfileProblem(yizhuang, encoding=3)


def test_an_unbound_encoding_says_so():
    with pytest.raises(ValueError, match="'speed_codes' is not bound to a case"):
        SpeedCodes().programs(np.zeros((1, 3)))
    with pytest.raises(ValueError, match="'switching_points' is not bound"):
        SwitchingPoints().n_var


def test_each_encoding_gives_the_unit_of_each_variable():
    metro_a = load_case("metro-a")
    codes = SpeedProfileProblem(metro_a, encoding="speed_codes")
    assert codes.encoding.units == ["km/h"] * codes.n_var
    assert decision_columns(codes.encoding)[0] == "x0_kmh"
    onset = SpeedProfileProblem(metro_a, encoding="braking_onset", objectives=("energy", "stop_error"))
    assert onset.encoding.units == ["m"] * (onset.n_var - 1) + ["m/s^2"]
    assert decision_columns(onset.encoding)[-1] == f"x{onset.n_var - 1}_ms2"
    paced = SpeedProfileProblem(metro_a, encoding="paced_speed_codes", objectives=("energy",), time_tolerance_s=1.0)
    assert paced.encoding.units == ["1"] * (paced.n_var - 1) + ["s"]
    assert decision_columns(paced.encoding)[-2:] == [f"x{paced.n_var - 2}_share", f"x{paced.n_var - 1}_s"]


def test_binding_twice_gives_the_same_bounds(yizhuang):
    bound = SpeedCodes().bind(EncodingSetup(yizhuang))
    again = bound.bind(EncodingSetup(yizhuang))
    np.testing.assert_array_equal(bound.xl, again.xl)
    assert bound.n_sections == again.n_sections == 8  # the gradient/limit partition of Liu (2019) fig. 4-4
